#!/bin/bash
# Every lesson's key frames held to the lecture-room rules, headless: for
# each lesson, the frames `make lesson` renders (its start and the key frames
# of lesson.conf, with the lesson's own pdtview options) and the moments its
# checks name (the bookmarks: each step of "In the viewer"), at 1024x768 and
# 1920x1080, font scales 1, 1.5 and 2, through the layout report
# (scripts/layout-check.py): no text overlaps another or is cut, none is
# under 16 px at 1024x768, the code and the event line at least 18 px, the
# event line present; a panel with no room is named on the bottom line.
# (The real window, with and without a window manager: view_layout_window.)
# PDT_LESSONS="07 08" runs only those lessons.
. "$(dirname "$0")/lib.sh"
unset DISPLAY WAYLAND_DISPLAY
V=$BIN/pdtview
CHECK="python3 $ROOT/scripts/layout-check.py"
[ -x "$V" ] || { ok "lesson frames # SKIP pdtview is not built"; summary; exit 0; }
have_par=0
printf '0 0\n4 0\n0 4\n4 4\n2 1\n' >"$TMP/probe.txt"
mpirun -np 2 --oversubscribe "$BIN/pdt" triangulate "$TMP/probe.txt" --trace "$TMP/probe" >/dev/null 2>&1 &&
    grep -q '^ranks = 2$' "$TMP/probe/manifest" 2>/dev/null && have_par=1

# a pdtview that logs the frames lesson.sh asks for (and renders none): the
# test renders them at every size and scale
printf '#!/bin/bash\nfor a; do [ "$a" = --headless ] && { echo "$*" >>"%s/frames.log"; exit 0; }; done\nexec "%s" "$@"\n' \
    "$TMP" "$V" >"$TMP/pv.sh"
chmod +x "$TMP/pv.sh"

# the names of the hidden panels a report lists are on its bottom line
named() {
    python3 - "$@" <<'EOF'
import json, sys
names = {"legend": "legend", "timeline": "timeline", "stack": "stacks", "lifted": "lifted",
         "code": "pseudo-code"}
bad = 0
for f in sys.argv[1:]:
    d = json.load(open(f))
    more = " ".join(t["text"] for t in d["texts"] if t["panel"] == "more")
    for p in d.get("hidden", []):
        if names[p] not in more or "Tab" not in more:
            print(f"{f}: {p} hidden, not named: {more!r}")
            bad = 1
sys.exit(bad)
EOF
}

for ldir in "$ROOT"/lessons/[0-9][0-9]-*/; do
    ldir=${ldir%/}
    name=$(basename "$ldir")
    case " ${PDT_LESSONS:-${name%%-*}} " in *" ${name%%-*} "*) ;; *) continue ;; esac # (one or a few)
    if [ "$have_par" = 0 ] && grep -qE '^[[:space:]]*ranks[[:space:]]*=[[:space:]]*([2-9]|[1-9][0-9])' "$ldir/lesson.conf"; then
        ok "$name # SKIP pdt does not run in parallel under mpirun in this build"
        continue
    fi
    if grep -qE '^[[:space:]]*simulate[[:space:]]*=' "$ldir/lesson.conf" &&
        { [ ! -f "$ROOT/bin/smpi/pdt" ] || ! command -v smpirun >/dev/null; } &&
        ! grep -qE '^[[:space:]]*recorded[[:space:]]*=' "$ldir/lesson.conf"; then
        ok "$name # SKIP bin/smpi/pdt is not built (make smpi)"
        continue
    fi
    : >"$TMP/frames.log"
    out=$TMP/$name
    if ! PDTVIEW=$TMP/pv.sh BIN=$BIN bash "$ROOT/scripts/lesson.sh" --quiet --headless --out "$out" "$ldir" \
            >"$TMP/$name.log" 2>&1; then
        fail "$name: lesson.sh" "$(tail -3 "$TMP/$name.log")"
        continue
    fi
    # the frames: lesson.sh's, then each run's moments (its first frame's options)
    : >"$TMP/$name.frames"
    while read -r line; do
        set -- $line
        args=()
        while [ $# -gt 0 ]; do
            case $1 in -o) shift ;; --headless) ;; *) args+=("$1") ;; esac
            shift
        done
        echo "${args[*]}" >>"$TMP/$name.frames"
    done <"$TMP/frames.log"
    for m in "$out"/*/moments.tsv; do
        [ -s "$m" ] || continue
        run=$(basename "$(dirname "$m")")
        first=$(grep -F -- "/$run/trace " "$TMP/$name.frames" | head -1)
        [ -n "$first" ] || first=$(head -1 "$TMP/$name.frames") # (a run recorded ahead)
        [ -n "$first" ] || continue
        opts=$(echo "$first" | sed -E 's/ --(at|phase) [^ ]+//; s/ --end//')
        cut -f1 "$m" | sort -un | while read -r k; do echo "$opts --at $k"; done >>"$TMP/$name.frames"
    done
    sort -u "$TMP/$name.frames" -o "$TMP/$name.frames"
    nf=$(wc -l <"$TMP/$name.frames")
    for sz in 1024x768 1920x1080; do
        for fs in 1 1.5 2; do
            tag=${sz}_$(echo $fs | tr . _)
            reports=(); i=0; bad=""
            while read -r f; do
                i=$((i + 1))
                # shellcheck disable=SC2086
                "$V" --headless $f --size $sz --font-scale $fs -o "$TMP/$name-$tag-$i.png" \
                    --layout-report "$TMP/$name-$tag-$i.json" --quiet 2>>"$TMP/$name.err" ||
                    bad="$bad [$f]"
                reports+=("$TMP/$name-$tag-$i.json")
            done <"$TMP/$name.frames"
            if [ -z "$bad" ] && [ "$nf" -gt 0 ] &&
               $CHECK --min-px 16 --min-big 18 --panel event "${reports[@]}" >"$TMP/$name-$tag.out" &&
               named "${reports[@]}" >>"$TMP/$name-$tag.out"; then
                ok "${name}_${tag}: $nf key frames readable"
            else
                fail "${name}_${tag}" "$bad $(grep -v '^ok ' "$TMP/$name-$tag.out" | head -4)"
            fi
            rm -f "$TMP/$name-$tag-"*.png
        done
    done
done
summary
