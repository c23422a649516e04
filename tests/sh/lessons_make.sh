#!/bin/bash
# make lesson / make demo for a lecturer: no apt-get when every package is
# present (scripts/deps.sh checks first; an apt-get on PATH that only logs
# stands in for the real one), the packages make lesson checks are the
# build's (not the test tools'), and VIEW="..." reaches pdtview, in the
# window and in the headless frames.
. "$(dirname "$0")/lib.sh"
unset DISPLAY WAYLAND_DISPLAY
mkdir -p "$TMP/fake"
printf '#!/bin/sh\necho "apt-get $*" >>"%s/apt.log"\n' "$TMP" >"$TMP/fake/apt-get"
chmod +x "$TMP/fake/apt-get"

# ---- deps: present -> no apt-get; missing -> apt-get for that one only ---------------
pkgs=$(make -s -C "$ROOT" -n deps-lesson | sed -n 's|.*scripts/deps.sh ||p')
if [ -z "$pkgs" ]; then fail deps_lesson_packages "make -n deps-lesson names no packages"
elif echo " $pkgs " | grep -qE ' (valgrind|slurmctld|xvfb) '; then
    fail deps_lesson_packages "make lesson checks test tools too: $pkgs"
else ok deps_lesson_packages; fi
present=""
for p in $pkgs; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" && present="$present $p"
done
rm -f "$TMP/apt.log"
# shellcheck disable=SC2086
PATH=$TMP/fake:$PATH sh "$ROOT/scripts/deps.sh" $present >"$TMP/deps.out" 2>&1
if [ ! -s "$TMP/apt.log" ] && [ ! -s "$TMP/deps.out" ]; then ok deps_present_no_apt_get
else fail deps_present_no_apt_get "$(cat "$TMP/apt.log" "$TMP/deps.out")"; fi
rm -f "$TMP/apt.log"
# shellcheck disable=SC2086
PATH=$TMP/fake:$PATH sh "$ROOT/scripts/deps.sh" $present pdt-no-such-package >/dev/null 2>&1
if grep -q 'install -y -q pdt-no-such-package$' "$TMP/apt.log" 2>/dev/null; then ok deps_missing_installs_only_it
else fail deps_missing_installs_only_it "$(cat "$TMP/apt.log" 2>/dev/null)"; fi

# ---- VIEW="..." -> lesson.sh --view / demo.sh --view ----------------------------------------
cmd=$(make -s -C "$ROOT" -n lesson L=01 VIEW="--theme dark --font-scale 1.5" 2>/dev/null | grep 'lesson.sh')
if echo "$cmd" | grep -qF -- "--view '--theme dark --font-scale 1.5'"; then ok make_lesson_passes_view
else fail make_lesson_passes_view "$cmd"; fi
cmd=$(make -s -C "$ROOT" -n demo VIEW="--theme dark" 2>/dev/null | grep 'demo.sh')
if echo "$cmd" | grep -qF -- "--view '--theme dark'"; then ok make_demo_passes_view
else fail make_demo_passes_view "$cmd"; fi
if [ -x "$BIN/pdtview" ]; then
    # a pdtview that logs its arguments, then renders
    printf '#!/bin/bash\necho "$*" >>"%s/pv.log"\nexec "%s" "$@"\n' "$TMP" "$BIN/pdtview" >"$TMP/pv.sh"
    chmod +x "$TMP/pv.sh"
    PDTVIEW=$TMP/pv.sh BIN=$BIN bash "$ROOT/scripts/lesson.sh" --quiet --headless --out "$TMP/l01" \
        --view "--theme dark --font-scale 1.5" "$ROOT/lessons/01-orientation" >"$TMP/l01.log" 2>&1
    n=$(grep -c -- '--headless .*--theme dark --font-scale 1.5 -o ' "$TMP/pv.log" 2>/dev/null)
    nf=$(ls "$TMP"/l01/run/frames/*.png 2>/dev/null | wc -l)
    if [ "${n:-0}" -ge 1 ] && [ "$n" -eq "$nf" ]; then ok lesson_view_reaches_every_frame
    else fail lesson_view_reaches_every_frame "$n of $nf frames: $(tail -3 "$TMP/l01.log")"; fi
else
    ok "lesson_view_reaches_every_frame # SKIP pdtview is not built"
fi
summary
