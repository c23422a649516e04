#!/bin/bash
# pdtview in a real window: start it under Xvfb, drive it with --script and
# with X key presses (xdotool), take an X-level screenshot of the screen
# (import -window root) and compare it with the headless render of the same
# state.  Metric: the share of pixels whose colour differs by more than 10 %
# (ImageMagick compare -metric AE -fuzz 10%); it must stay under 2 % (the
# status text in the top-right corner is only drawn in the window).
. "$(dirname "$0")/lib.sh"
V=$BIN/pdtview
for t in Xvfb xdotool import compare; do
    command -v $t >/dev/null || { fail "have_$t" "$t is not installed (DEB_TEST)"; summary; exit 1; }
done
W=1024; H=640
RUN=synth:srm:12:6:4

xvfb_start ${W}x${H}
trap xvfb_cleanup EXIT

# script: 5 events, next phase twice, the next rejection (Shift+→ after
# selecting "rejection" with k k), then a screenshot; then wait for xdotool.
"$V" "$RUN" --size ${W}x${H} --screenshot "$TMP/win.png" \
     --script "right right right right right pgdn pgdn k k S-right wait:5 s wait:1000000" \
     >"$TMP/out.log" 2>"$TMP/err.log" &
VPID=$!
for i in $(seq 150); do grep -q screenshot "$TMP/err.log" && break; sleep 0.1; done
if [ -s "$TMP/win.png" ]; then ok window_script_screenshot; else fail window_script_screenshot "$(cat "$TMP/err.log")"; fi
k=$(sed -n 's/.*event \([0-9]*\)).*/\1/p' "$TMP/err.log" | tail -1)
sleep 0.5
import -window root "$TMP/x11.png" 2>"$TMP/imp.err"
if [ -s "$TMP/x11.png" ]; then ok x11_capture; else fail x11_capture "$(cat "$TMP/imp.err")"; fi

# the state the script reached: the first ra-defer after the second phase
"$V" --headless "$RUN" --at "${k:-0}" --size ${W}x${H} -o "$TMP/head.png" --quiet
ae=$(compare -metric AE -fuzz 10% "$TMP/x11.png" "$TMP/head.png" "$TMP/diff.png" 2>&1 >/dev/null | sed 's/[^0-9.e+].*//')
share=$(python3 -c "print(f'{float(\"${ae:-1e9}\") / ($W * $H) * 100:.3f}')")
echo "# window vs headless at event $k: $ae of $((W * H)) pixels differ by more than 10% ($share %)"
if python3 -c "import sys; sys.exit(0 if float('$share') < 2.0 else 1)"; then ok window_equals_headless
else fail window_equals_headless "$share % of the pixels differ"; fi

# the script reached a rejection event
last=$("$V" --headless "$RUN" --at "${k:-0}" -o "$TMP/x.png" --size 320x200 2>&1)
if [ -n "$k" ] && [ "$k" -gt 5 ]; then ok script_moved; else fail script_moved "cursor $k"; fi

# real X key presses: → twice, s, then q
wid=$(pdtview_window pdtview)
if [ -n "$wid" ]; then
    xdotool key --window "$wid" Right Right s 2>/dev/null
    for i in $(seq 50); do [ "$(grep -c screenshot "$TMP/err.log")" -ge 2 ] && break; sleep 0.1; done
    k2=$(sed -n 's/.*event \([0-9]*\)).*/\1/p' "$TMP/err.log" | tail -1)
    if [ "$k2" = "$((k + 2))" ]; then ok xdotool_keys; else fail xdotool_keys "cursor $k -> $k2"; fi
    xdotool key --window "$wid" q 2>/dev/null
else
    fail xdotool_keys "no window named pdtview"
fi
for i in $(seq 50); do kill -0 "$VPID" 2>/dev/null || break; sleep 0.1; done
if ! kill -0 "$VPID" 2>/dev/null; then wait "$VPID"; rc=$?; VPID=
    if [ "$rc" -eq 0 ]; then ok quit_with_q; else fail quit_with_q "exit $rc"; fi
else fail quit_with_q "still running"; fi

# go to event N: g, the digits, Enter; then Ctrl+→ (the next event of the
# same rank) and the font scale keys, F11 (full screen) and the toggles
"$V" "$RUN" --size ${W}x${H} --screenshot "$TMP/goto.png" \
     --script "g 7 5 enter wait:3 s C-right wait:3 s C-plus C-plus t c o v f11 wait:5 s wait:3 q" \
     >"$TMP/g.out" 2>"$TMP/g.err"
rc=$?
evs=$(sed -n 's/.*event \([0-9]*\)).*/\1/p' "$TMP/g.err" | tr '\n' ' ')
set -- $evs
if [ "$rc" -eq 0 ] && [ "${1:-}" = 75 ]; then ok goto_event_75; else fail goto_event_75 "rc $rc, events: $evs"; fi
if [ -n "${2:-}" ] && [ "$2" -gt 75 ]; then ok ctrl_right_next_of_rank; else fail ctrl_right_next_of_rank "events: $evs"; fi
# the keys above leave a working window that still writes its screenshot
if [ -s "$TMP/goto.png" ] && grep -q "screenshot.*(${W}x${H}, event" "$TMP/g.err"; then ok keys_font_theme_toggles_f11
else fail keys_font_theme_toggles_f11 "$(tail -2 "$TMP/g.err")"; fi
summary
