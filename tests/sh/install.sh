#!/bin/bash
# make install / make uninstall: the installed pdt, pdtview and pdt-lesson work
# from any folder with no path into the checkout; man pages pass mandoc's lint;
# the bash completions complete.
source "$(dirname "$0")/lib.sh"
STAGE=$TMP/stage
make -s -C "$ROOT" install PREFIX=/opt/pdt DESTDIR="$STAGE" > "$TMP/install.log" 2>&1 \
    && ok make_install || fail make_install "$(tail -5 "$TMP/install.log")"
for f in bin/pdt bin/pdtview bin/pdt-lesson share/pdt/lessons/02-graham/lesson.conf \
         share/pdt/assets/runs/uniform-300-p8/manifest share/pdt/lesson-check.py \
         share/man/man1/pdt.1 share/man/man1/pdtview.1 \
         share/bash-completion/completions/pdt share/bash-completion/completions/pdtview; do
    [ -e "$STAGE/opt/pdt/$f" ] || fail "installed_$f" "missing"
done
ok installed_files_present
# Move the installed tree elsewhere: nothing in it may name the checkout or the prefix it
# was staged under.
INST=$TMP/moved/pdt
mkdir -p "$TMP/moved" && mv "$STAGE/opt/pdt" "$INST"
# (the programs' debugging sections name their sources: look at what runs, not at those)
mkdir -p "$TMP/stripped"
for p in pdt pdtview; do objcopy --strip-debug "$INST/bin/$p" "$TMP/stripped/$p"; done
if grep -rlF "$ROOT" "$TMP/stripped" "$INST/share" "$INST/bin/pdt-lesson" > "$TMP/refs"; then
    fail no_checkout_paths "$(head -3 "$TMP/refs")"
else ok no_checkout_paths; fi
mkdir -p "$TMP/elsewhere" && cd "$TMP/elsewhere" || exit 1
E=(env -i PATH="$INST/bin:/usr/bin:/bin" HOME="$TMP/elsewhere" LANG=C.UTF-8
   OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1)
"${E[@]}" pdt gen uniform 40 --seed 3 -o u.txt && "${E[@]}" pdt triangulate u.txt -o u.tri \
    --trace run && "${E[@]}" pdt check u.txt u.tri > /dev/null && ok installed_pdt_runs \
    || fail installed_pdt_runs
"${E[@]}" pdtview --headless run --end -o end.png --size 320x200 > view.out 2>&1 && [ -s end.png ] \
    && ok installed_pdtview_headless || fail installed_pdtview_headless "$(cat view.out)"
"${E[@]}" pdtview --headless "$INST/share/pdt/assets/runs/uniform-300-p8" --phase merge \
    -o merge.png --size 320x200 > view2.out 2>&1 && [ -s merge.png ] \
    && ok installed_pdtview_bundled_run || fail installed_pdtview_bundled_run "$(cat view2.out)"
"${E[@]}" pdt-lesson --headless --quiet 02 > lesson.out 2>&1; rc=$?
nf=$(find pdt-lessons/02 -name '*.png' 2>/dev/null | wc -l)
[ $rc -eq 0 ] && [ "$nf" -ge 1 ] && ok "installed_lesson_02 ($nf frames)" \
    || fail installed_lesson_02 "rc=$rc frames=$nf $(tail -3 lesson.out)"
"${E[@]}" pdt-lesson --headless --quiet 09 > lesson9.out 2>&1; rc=$?
[ $rc -eq 0 ] && ok installed_lesson_09_recorded_run || fail installed_lesson_09_recorded_run \
    "rc=$rc $(tail -3 lesson9.out)"
"${E[@]}" PDT_DATADIR="$TMP/nowhere" pdt-lesson 02 > /dev/null 2> lesson.err; rc=$?
[ $rc -eq 2 ] && grep -q PDT_DATADIR lesson.err && ok lesson_datadir_override \
    || fail lesson_datadir_override "rc=$rc"
cd "$TMP" || exit 1

# man pages
if command -v mandoc > /dev/null; then
    mandoc -T lint -W warning "$INST/share/man/man1/pdt.1" "$INST/share/man/man1/pdtview.1" \
        > "$TMP/lint" 2>&1 && [ ! -s "$TMP/lint" ] && ok mandoc_lint || fail mandoc_lint "$(head -5 "$TMP/lint")"
    mandoc -T utf8 "$INST/share/man/man1/pdt.1" | sed 's/.\x08//g' | grep -q '^EXIT STATUS' && ok man_pdt_renders \
        || fail man_pdt_renders
else
    fail mandoc_lint "mandoc is not installed (make deps)"
fi

# bash completion
BC=/usr/share/bash-completion/bash_completion
if [ -f "$BC" ]; then
    comp() { # FILE WORDS... : prints COMPREPLY for the last word
        bash -c 'source "$1"; source "$2"; shift 2; COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1))
                 COMP_LINE="$*"; COMP_POINT=${#COMP_LINE}; fn=$(complete -p "$1" | sed "s/.*-F \([^ ]*\).*/\1/")
                 "$fn" "$1" "${COMP_WORDS[COMP_CWORD]}" "${COMP_WORDS[COMP_CWORD-1]}"
                 printf "%s\n" "${COMPREPLY[@]}"' _ "$BC" "$@"
    }
    C=$INST/share/bash-completion/completions
    got=$(comp "$C/pdt" pdt tr | tr '\n' ' ')
    [[ "$got" == *triangulate* ]] && [[ "$got" == *trace* ]] && [[ "$got" != *hull* ]] \
        && ok complete_pdt_command || fail complete_pdt_command "got [$got]"
    got=$(comp "$C/pdt" pdt gen ci | tr '\n' ' ')
    [ "$got" = "circle circle-round " ] && ok complete_gen_kind || fail complete_gen_kind "got [$got]"
    got=$(comp "$C/pdt" pdt trace c | tr '\n' ' ')
    [ "$got" = "check " ] && ok complete_trace_sub || fail complete_trace_sub "got [$got]"
    got=$(comp "$C/pdtview" pdtview --pan | tr '\n' ' ')
    [ "$got" = "--panels " ] && ok complete_pdtview_option || fail complete_pdtview_option "got [$got]"
else
    fail complete_pdt_command "bash-completion is not installed (make deps)"
fi

# uninstall removes every file it installed
mv "$INST" "$STAGE/opt/pdt"
make -s -C "$ROOT" uninstall PREFIX=/opt/pdt DESTDIR="$STAGE" > /dev/null 2>&1
left=$(find "$STAGE" -type f | head -5)
[ -z "$left" ] && ok make_uninstall || fail make_uninstall "left: $left"
summary
