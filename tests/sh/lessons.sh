#!/bin/bash
# Lessons: every lesson's run is recorded, passes `pdt trace check`, its start
# frame and key frames render headless, and every line of its `checks` file
# (the facts its text states) holds against the recorded trace.
. "$(dirname "$0")/lib.sh"
unset DISPLAY WAYLAND_DISPLAY
have_view=0
[ -x "$BIN/pdtview" ] && have_view=1

for ldir in "$ROOT"/lessons/[0-9][0-9]-*/; do
    ldir=${ldir%/}
    name=$(basename "$ldir")
    out=$TMP/$name
    if [ "$have_view" = 1 ]; then mode=--headless; else mode=--record-only; fi
    if BIN=$BIN bash "$ROOT/scripts/lesson.sh" --quiet $mode --out "$out" "$ldir" >"$TMP/$name.log" 2>&1; then
        ok "$name: recorded, pdt trace check passed"
    else
        fail "$name: lesson.sh failed" "$(tail -5 "$TMP/$name.log")"
        continue
    fi
    # frames: the start frame plus one per key frame, for every run, each a PNG
    if [ "$have_view" = 1 ]; then
        nbad=0; nframes=0
        for rdir in "$out"/*/; do
            for png in "$rdir"frames/*.png; do
                [ -f "$png" ] || { nbad=$((nbad + 1)); continue; }
                nframes=$((nframes + 1))
                head -c 8 "$png" | od -An -c | grep -q 'P   N   G' || nbad=$((nbad + 1))
            done
        done
        if [ "$nbad" -eq 0 ] && [ "$nframes" -gt 0 ]; then ok "$name: $nframes frames rendered headless"
        else fail "$name: frames" "$nframes rendered, $nbad missing or not PNG"; fi
    else
        ok "$name: frames # SKIP pdtview is not built"
    fi
    # the facts of the text
    if python3 "$ROOT/scripts/lesson-check.py" "$ldir" "$out" >"$TMP/$name.check" 2>&1; then
        ok "$name: $(tail -1 "$TMP/$name.check")"
    else
        fail "$name: checks" "$(head -20 "$TMP/$name.check")"
    fi
    # every event the text names ("event 12", or the viewer's counter "13 / 40")
    # is one of the checked facts
    missing=""
    for n in $(grep -oE '[Ee]vents? #?[0-9]+' "$ldir/README.md" | grep -oE '[0-9]+$' | sort -u); do
        grep -qE "^event $n " "$ldir/checks" || missing="$missing event-$n"
    done
    for km in $(grep -oE '[0-9]+ / [0-9]+' "$ldir/README.md" | tr -d ' ' | sort -u); do
        k=${km%/*}; m=${km#*/}
        grep -qE "^count \* = $m( |$)" "$ldir/checks" || missing="$missing total-$m"
        [ "$k" = 0 ] || [ "$k" = "$m" ] || grep -qE "^at $k " "$ldir/checks" || missing="$missing $k/$m"
    done
    if [ -z "$missing" ] && ! grep -qE 'TODO|FACTS|ANSWERS|ANSWER[0-9_]|RECORDED|CLUSTER|EXAMPLE$' "$ldir/README.md"; then
        ok "$name: every event the text names is checked; no placeholders left"
    else
        fail "$name: text" "not in checks:$missing; or a placeholder is left"
    fi
done
summary
