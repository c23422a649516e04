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
check "demo: the run is recorded (manifest and 4 rank files)" \
    test "$(ls "$out/run" 2>/dev/null | grep -c .)" -ge 5
check "demo: its triangulation passes pdt check" "$BIN/pdt" check "$ROOT/assets/points/demo-48.txt" "$out/triangles.tri"
if [ -x "$BIN/pdtview" ]; then
    n=$(ls "$out"/frames/*.png 2>/dev/null | wc -l)
    check "demo: 5 key frames rendered" test "$n" -eq 5
    check "demo: says where the frames are" grep -q "$out/frames/" "$TMP/demo.log"
else
    ok "demo: frames # SKIP pdtview is not built"
fi
summary
