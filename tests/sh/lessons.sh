#!/bin/bash
# Lessons: every lesson's run is recorded, passes `pdt trace check`, its start
# frame and key frames render headless, and every line of its `checks` file
# (the facts its text states) holds against the recorded trace and against
# what the viewer itself shows (`pdtview --describe`: event lines, lit code
# lines, the start); every counter, every event line, every "lights line N"
# and every phase the text has PgDn visit (or quotes as a phase) is one of
# those checks.
. "$(dirname "$0")/lib.sh"
unset DISPLAY WAYLAND_DISPLAY
have_view=0
[ -x "$BIN/pdtview" ] && have_view=1
# Does this build run the parallel algorithm under mpirun?  (Lessons with
# several ranks need it.)
have_par=0
printf '0 0\n4 0\n0 4\n4 4\n2 1\n' >"$TMP/probe.txt"
if mpirun -np 2 --oversubscribe "$BIN/pdt" triangulate "$TMP/probe.txt" --trace "$TMP/probe" \
        >/dev/null 2>&1 && grep -q '^ranks = 2$' "$TMP/probe/manifest" 2>/dev/null; then
    have_par=1
fi

for ldir in "$ROOT"/lessons/[0-9][0-9]-*/; do
    ldir=${ldir%/}
    name=$(basename "$ldir")
    out=$TMP/$name
    if [ "$have_par" = 0 ] && grep -qE '^[[:space:]]*ranks[[:space:]]*=[[:space:]]*([2-9]|[1-9][0-9])' "$ldir/lesson.conf"; then
        ok "$name # SKIP pdt does not run in parallel under mpirun in this build"
        continue
    fi
    # a lesson that simulates a cluster (`simulate = P`) needs the SMPI build;
    # the test does not install SimGrid (make smpi does)
    if grep -qE '^[[:space:]]*simulate[[:space:]]*=' "$ldir/lesson.conf" &&
        { [ ! -f "$ROOT/bin/smpi/pdt" ] || ! command -v smpirun >/dev/null; }; then
        ok "$name # SKIP bin/smpi/pdt is not built (make smpi)"
        continue
    fi
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
    if python3 -B "$ROOT/scripts/lesson-check.py" "$ldir" "$out" >"$TMP/$name.check" 2>&1; then
        ok "$name: $(tail -1 "$TMP/$name.check")"
    else
        fail "$name: checks" "$(head -20 "$TMP/$name.check")"
    fi
    # every event the text names by the viewer's counter ("13 / 40") is one of
    # the checked facts (an `at 13` line, and `count * = 40`)
    missing=""
    for km in $(grep -oE '[0-9]+ / [0-9]+' "$ldir/README.md" | tr -d ' ' | sort -u); do
        k=${km%/*}; m=${km#*/}
        grep -qE "^count \* = $m( |$)" "$ldir/checks" || missing="$missing total-$m"
        [ "$k" = 0 ] || [ "$k" = "$m" ] || grep -qE "^(at $k |line $k |code $k |first .* = $k$)" "$ldir/checks" || missing="$missing $k/$m"
    done
    # every event line the text quotes ("rank 2: defer ...") is checked
    # against what the viewer shows (a `line` check with the same text), and
    # no quoted event line is broken over two lines of the text
    while IFS= read -r q; do
        grep -qF -- "$q" "$ldir/checks" || missing="$missing [$q]"
    done < <(grep -oE '"rank [0-9]+: [^"]*"' "$ldir/README.md")
    if grep -qE '"rank [0-9]+: [^"]*$' "$ldir/README.md"; then missing="$missing [a quoted event line broken over two lines]"; fi
    # every "lights line N" of the text is a `code` check of line N (at a counter,
    # a range K..M or `each` event of a kind), and every phase the text has
    # PgDn go through, or quotes as a phase ("output"), is in a check (`phases`, `pgdn`,
    # `at K phase-begin NAME`, `@phase=NAME`, ...)
    flat=$(tr '\n' ' ' <"$ldir/README.md")
    for n in $(echo "$flat" | grep -oE 'lights line [0-9]+' | awk '{print $3}' | sort -u); do
        grep -qE "^code .* = ([a-z]+ )?$n\$" "$ldir/checks" || missing="$missing [lights line $n]"
    done
    phnames='read|partition|lift|kernel|hull|classify|merge|order|write|output|graham-sort|graham-scan'
    for ph in $( { echo "$flat" | grep -oE '[^.]*PgDn[^.]*' | grep -owE "$phnames"
                   echo "$flat" | grep -oE "phase [\"\`]($phnames)[\"\`]|[\"\`]($phnames)[\"\`] phases?" |
                       grep -oE "[\"\`]($phnames)[\"\`]" | tr -d '"\`'; } | sort -u); do
        grep -qE "^phases .*= (.* )?$ph( |\$)|^pgdn = (.* )?$ph( |\$)|phase-(begin|end) $ph( |\$)|@phase=$ph( |\$)" "$ldir/checks" ||
            missing="$missing [phase $ph]"
    done
    # where a lesson on several ranks opens is a checked state (`begun start`),
    # a text that has PgDn go through phases lists its stops (`pgdn`), and every
    # step of "In the viewer" is a bookmark (`step N POS`)
    if grep -qE '^[[:space:]]*ranks[[:space:]]*=[[:space:]]*([2-9]|[1-9][0-9])' "$ldir/lesson.conf"; then
        grep -qE '^begun start ' "$ldir/checks" || missing="$missing [begun start]"
    fi
    grep -q 'PgDn' "$ldir/README.md" && ! grep -qE '^pgdn = ' "$ldir/checks" && missing="$missing [pgdn]"
    for n in $(sed -n '/^## In the viewer/,/^## /p' "$ldir/README.md" | grep -oE '^[0-9]+\.' | tr -d .); do
        grep -qE "^step $n " "$ldir/checks" || missing="$missing [step $n]"
    done
    if [ -z "$missing" ] && ! grep -qE 'TODO|FACTS|ANSWERS|ANSWER[0-9_]|RECORDED|CLUSTER|EXAMPLE$' "$ldir/README.md"; then
        ok "$name: every event the text names is checked; no placeholders left"
    else
        fail "$name: text" "not in checks:$missing; or a placeholder is left"
    fi
done

# the class plan (lessons/README.md): every counter a row names ("14 / 20")
# is a checked fact of the lesson the row opens (`make lesson L=NN`)
missing=""
while IFS= read -r row; do
    nn=$(echo "$row" | grep -oE 'make lesson L=[0-9]+' | head -1 | grep -oE '[0-9]+$')
    cf=$(ls "$ROOT"/lessons/"$nn"-*/checks 2>/dev/null | head -1)
    [ -n "$cf" ] || { missing="$missing [no lesson $nn]"; continue; }
    for km in $(echo "$row" | grep -oE '[0-9]+ / [0-9]+' | tr -d ' ' | sort -u); do
        k=${km%/*}; m=${km#*/}
        grep -qE "^count \* = $m( |$)" "$cf" || missing="$missing $nn:total-$m"
        [ "$k" = 0 ] || [ "$k" = "$m" ] || grep -qE "^(at $k |line $k |code $k |first .* = $k$|start = $k$)" "$cf" ||
            missing="$missing $nn:$k/$m"
    done
done < <(grep -E '^\| [0-9]+–[0-9]+ \| `make lesson L=' "$ROOT/lessons/README.md")
if [ -z "$missing" ]; then ok "class plan: every counter it names is checked"
else fail "class plan" "not in the lessons' checks:$missing"; fi

# lesson 9: the Chrome/Perfetto export of the recorded run: valid JSON, one
# row per rank, one flow arrow per message
run9=$ROOT/assets/runs/uniform-300-p8
if "$BIN/pdt" trace export --chrome "$run9" -o "$TMP/run9.json" >"$TMP/export.log" 2>&1 &&
   python3 - "$TMP/run9.json" "$(grep -c ' send ' <("$BIN/pdt" trace dump "$run9"))" <<'EOF_PY'
import json, sys
d = json.load(open(sys.argv[1]))
ev = d['traceEvents'] if isinstance(d, dict) else d
rows = {e['tid'] for e in ev if e.get('ph') == 'M' and e.get('name') == 'thread_name'}
flows = sum(1 for e in ev if e.get('ph') == 's')
assert len(rows) == 8, rows
assert flows == int(sys.argv[2]), (flows, sys.argv[2])
EOF_PY
then ok "09-replay: Chrome export has 8 rows and one flow arrow per message"
else fail "09-replay: Chrome export" "$(tail -3 "$TMP/export.log")"; fi
# with a display, lesson.sh opens the viewer at the lesson's start (Xvfb; the
# viewer is driven by a wrapper that quits at once and saves a screenshot)
if [ "$have_view" = 1 ] && command -v Xvfb >/dev/null; then
    # -displayfd: Xvfb picks a free display and writes its number when ready
    Xvfb -displayfd 3 -screen 0 1280x800x24 3>"$TMP/xvfb.num" >/dev/null 2>&1 &
    xpid=$!
    for _ in $(seq 100); do [ -s "$TMP/xvfb.num" ] && break; sleep 0.1; done
    dpy=:$(head -1 "$TMP/xvfb.num")
    printf '#!/bin/bash\necho "$*" >>"%s/pv.log"\nexec "%s" "$@" --script "s q" --screenshot "%s/pv.png"\n' \
        "$TMP" "$BIN/pdtview" "$TMP" >"$TMP/pv.sh"
    chmod +x "$TMP/pv.sh"
    if DISPLAY=$dpy PDTVIEW=$TMP/pv.sh timeout 60 bash "$ROOT/scripts/lesson.sh" --out "$TMP/win" \
            "$ROOT/lessons/01-orientation" >"$TMP/win.log" 2>&1 &&
       grep -q -- "--phase graham-scan" "$TMP/pv.log" && [ -s "$TMP/pv.png" ]; then
        ok "lesson.sh with a display opens pdtview at the lesson's start"
    else
        fail "lesson.sh with a display" "$(tail -3 "$TMP/win.log")"
    fi
    kill "$xpid" 2>/dev/null; wait "$xpid" 2>/dev/null
else
    ok "lesson.sh with a display # SKIP no pdtview or no Xvfb"
fi
summary
