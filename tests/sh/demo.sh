#!/bin/bash
# make demo without a display: records the 4-rank run, checks it, renders its
# key frames into a folder, says where, exits 0.
. "$(dirname "$0")/lib.sh"
unset DISPLAY WAYLAND_DISPLAY
out=$TMP/demo
if env BIN="$BIN" OUT="$out" bash "$ROOT/scripts/demo.sh" >"$TMP/demo.log" 2>&1; then
    ok "demo runs without a display and exits 0"
else
    fail "demo exits 0" "$(tail -5 "$TMP/demo.log")"
fi
check "demo: the recording passes pdt trace check" "$BIN/pdt" trace check "$out/run"
check "demo: its triangulation passes pdt check" \
    "$BIN/pdt" check "$ROOT/assets/points/demo-48.txt" "$out/triangles.tri"
ranks=$(sed -n 's/^ranks = //p' "$out/run/manifest" 2>/dev/null)
if grep -q "does not run the parallel algorithm" "$TMP/demo.log"; then
    ok "demo: 4 ranks # SKIP this build's pdt does not run in parallel under mpirun"
else
    check "demo: the run was recorded on 4 ranks" test "$ranks" = 4
fi
if [ -x "$BIN/pdtview" ]; then
    # every picture the demo names exists and is a PNG
    n=0; bad=0
    for png in $(grep -oE '/[^ ]*/frames/[^ ]*\.png' "$TMP/demo.log"); do
        n=$((n + 1))
        head -c 8 "$png" 2>/dev/null | od -An -c | grep -q 'P   N   G' || bad=$((bad + 1))
    done
    check "demo: names at least 4 key frames, all PNG ($n named, $bad bad)" test "$n" -ge 4 -a "$bad" -eq 0
    check "demo: every frame in the folder was named" test "$(ls "$out"/frames/*.png | wc -l)" -eq "$n"
else
    ok "demo: frames # SKIP pdtview is not built"
fi
# with a display the demo opens the viewer on the recorded run (Xvfb; a
# wrapper quits the viewer at once)
if [ -x "$BIN/pdtview" ] && command -v Xvfb >/dev/null; then
    # -displayfd: Xvfb picks a free display and writes its number when ready
    Xvfb -displayfd 3 -screen 0 1280x800x24 3>"$TMP/xvfb.num" >/dev/null 2>&1 &
    xpid=$!
    for _ in $(seq 100); do [ -s "$TMP/xvfb.num" ] && break; sleep 0.1; done
    dpy=:$(head -1 "$TMP/xvfb.num")
    mkdir -p "$TMP/bin"
    ln -s "$BIN/pdt" "$TMP/bin/pdt"
    printf '#!/bin/bash\necho "$*" >"%s/pv.log"\nexec "%s" "$@" --script "q"\n' "$TMP" "$BIN/pdtview" \
        >"$TMP/bin/pdtview"
    chmod +x "$TMP/bin/pdtview"
    if DISPLAY=$dpy BIN=$TMP/bin OUT=$TMP/demo-win timeout 60 bash "$ROOT/scripts/demo.sh" \
            >"$TMP/demo-win.log" 2>&1 && grep -q "$TMP/demo-win/run" "$TMP/pv.log"; then
        ok "demo with a display opens pdtview on the recorded run"
    else
        fail "demo with a display" "$(tail -3 "$TMP/demo-win.log")"
    fi
    kill "$xpid" 2>/dev/null; wait "$xpid" 2>/dev/null
else
    ok "demo with a display # SKIP no pdtview or no Xvfb"
fi
summary
