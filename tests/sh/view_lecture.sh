#!/bin/bash
# A lecturer's window under Xvfb: the bookmarks (b, Shift+b) go to the
# moments --bookmarks lists, in its order; a bad bookmarks file is refused
# with file:line; the notes pane, the pen and the pointer draw over the
# picture (X captures before and after differ) and e erases the drawing; a
# click on a triangle whose circle leaves the picture zooms out only until
# the cursor moves (End then shows what f shows).
. "$(dirname "$0")/lib.sh"
V=$BIN/pdtview
for t in Xvfb xdotool import compare; do
    command -v $t >/dev/null || { fail "have_$t" "$t is not installed (DEB_TEST)"; summary; exit 1; }
done
W=1024; H=768
RUN=synth:srm:12:6:4
xvfb_start ${W}x${H}
trap xvfb_cleanup EXIT

# the cursor of each screenshot the window wrote (its stderr)
events() { sed -n 's/.*screenshot .*event \([0-9]*\)).*/\1/p' "$1" | tr '\n' ' ' | sed 's/ $//'; }

# ---- bookmarks: in the file's order, both ways, wrapping around -------------------------------
printf '40\tstart\tthe opening\n5\tstep 1\tfirst\n70\tstep 2\tsecond\n' >"$TMP/bm.tsv"
"$V" "$RUN" --size ${W}x${H} --bookmarks "$TMP/bm.tsv" --panels all,notes \
     --screenshot "$TMP/b.png" --script "key:b wait:2 s key:b wait:2 s key:b wait:2 s key:b wait:2 s key:S-b wait:2 s q" \
     >/dev/null 2>"$TMP/b.err"
got=$(events "$TMP/b.err" | cut -d' ' -f1-5)  # (and one more as the window closes)
if [ "$got" = "40 5 70 40 70" ]; then ok bookmarks_in_order_both_ways
else fail bookmarks_in_order_both_ways "screenshots at events: '$got' (want 40 5 70 40 70)"; fi

printf '40\tstart\tok\nforty\tbad\n' >"$TMP/bad.tsv"
"$V" "$RUN" --bookmarks "$TMP/bad.tsv" --script q >/dev/null 2>"$TMP/bad.err"; rc=$?
if [ "$rc" = 2 ] && grep -q "bad.tsv:2" "$TMP/bad.err"; then ok bad_bookmarks_refused_with_line
else fail bad_bookmarks_refused_with_line "exit $rc: $(cat "$TMP/bad.err")"; fi

# ---- --beside: a second run beside the first; a run that does not open is refused -----------
"$V" "$RUN" --beside synth:srm:12:6:1 --size ${W}x${H} --panels none \
     --script "pgdn pgdn pgdn wait:3 s q" --screenshot "$TMP/bs.png" >/dev/null 2>"$TMP/bs.err"; rc=$?
if [ "$rc" = 0 ] && [ -s "$TMP/bs.png" ]; then ok beside_opens_and_steps; else fail beside_opens_and_steps "exit $rc: $(cat "$TMP/bs.err")"; fi
# a click goes to the half it falls in: near the right end of the left half's
# timeline is near the end of the run (the whole window's timeline would put
# it near the middle); on the right half's timeline, the left run follows to
# that phase; on the right picture, it does not move
"$V" "$RUN" --beside synth:srm:12:6:1 --size ${W}x${H} --panels timeline --screenshot "$TMP/bc.png" \
     --script "end wait:2 s home wait:2 click:$((W / 2 - 30)),$((H - 40)) wait:2 s click:$((W - 30)),$((H - 40)) wait:2 s click:$((W * 3 / 4)),$((H / 3)) wait:2 s q" \
     >/dev/null 2>"$TMP/bc.err"
set -- $(events "$TMP/bc.err")
if [ $# -ge 4 ] && [ "$2" -ge $(($1 * 7 / 10)) ] && [ "$2" -lt "$1" ] && [ "$3" -gt 0 ] && [ "$4" = "$3" ]
then ok beside_click_in_its_half
else fail beside_click_in_its_half "events: $* (end, left timeline, right timeline, right picture)"; fi
"$V" "$RUN" --beside "$TMP/no-such-run" --script q >/dev/null 2>"$TMP/bs2.err"; rc=$?
if [ "$rc" = 2 ] && grep -q "no-such-run" "$TMP/bs2.err"; then ok beside_bad_run_refused
else fail beside_bad_run_refused "exit $rc: $(cat "$TMP/bs2.err")"; fi

# ---- a projector at font scale 2: the panels with no room named, Tab shows them ------------
for tabs in 0 1 2; do
    keys=$(for i in $(seq $tabs); do printf 'key:Tab wait:2 '; done)
    "$V" "$RUN" --size ${W}x${H} --panels all --font-scale 2 --layout-report "$TMP/tab$tabs.json" \
         --script "wait:2 ${keys}wait:2 q" >/dev/null 2>"$TMP/tab$tabs.err"
done
if python3 - "$TMP"/tab0.json "$TMP"/tab1.json "$TMP"/tab2.json >"$TMP/tab.out" 2>&1 <<'EOF2'
import json, sys
d0, d1, d2 = (json.load(open(f)) for f in sys.argv[1:])
hid = set(d0["hidden"])
assert hid and not d0["covered"], d0["hidden"]
more = " ".join(t["text"] for t in d0["texts"] if t["panel"] == "more")
assert "Tab" in more, more
shown = set()
for d in (d1, d2):
    assert d["covered"] and "picture" not in d["panels"], d["panels"]
    shown |= {p for p in d["panels"] if p in hid}
    assert any(t["panel"] in hid for t in d["texts"]), "no text of a hidden panel"
assert shown == hid, (shown, hid)
EOF2
then ok tab_shows_the_panels_with_no_room
else fail tab_shows_the_panels_with_no_room "$(tail -2 "$TMP/tab.out") $(cat "$TMP"/tab*.err | head -3)"; fi
if python3 "$ROOT/scripts/layout-check.py" --min-px 16 --min-big 18 --status "$TMP"/tab[012].json >"$TMP/tabc.out"
then ok tab_pages_readable; else fail tab_pages_readable "$(grep -v '^ok' "$TMP/tabc.out" | head -3)"; fi

# ---- notes pane, pen, pointer, erase: what the screen shows ---------------------------------
"$V" "$RUN" --size ${W}x${H} --bookmarks "$TMP/bm.tsv" --script "wait:1000000" >/dev/null 2>"$TMP/w.err" &
VPID=$!
wid=""
for i in $(seq 100); do wid=$(pdtview_window pdtview) && [ -n "$wid" ] && break; sleep 0.1; done
# the share of pixels of X capture $1 that differ from $2 by more than 10 %, in per mille
differ() {
    local ae
    ae=$(compare -metric AE -fuzz 10% "$1" "$2" "$TMP/d.png" 2>&1 >/dev/null | sed 's/[^0-9.e+].*//')
    python3 -c "print(int(float('${ae:-1e9}') * 1000 / ($W * $H)))"
}
shot() { sleep 0.6; import -window root "$TMP/$1.png" 2>/dev/null; }
if [ -n "$wid" ]; then
    xdotool key --window "$wid" b; shot plain
    xdotool key --window "$wid" n; shot notes
    n=$(differ "$TMP/plain.png" "$TMP/notes.png")
    if [ "$n" -ge 5 ]; then ok notes_pane_shown; else fail notes_pane_shown "$n per mille differ"; fi
    xdotool key --window "$wid" n; shot plain2
    xdotool key --window "$wid" d
    xdotool mousemove --window "$wid" 100 200 mousedown 1
    for x in 140 180 220 260 300; do xdotool mousemove --window "$wid" $x 240; sleep 0.05; done
    xdotool mouseup 1; shot pen
    p=$(differ "$TMP/plain2.png" "$TMP/pen.png")
    if [ "$p" -ge 1 ]; then ok pen_draws; else fail pen_draws "$p per mille differ"; fi
    xdotool key --window "$wid" e d; shot erased
    xdotool key --window "$wid" p; xdotool mousemove --window "$wid" 300 300; shot pointer
    e=$(differ "$TMP/plain2.png" "$TMP/erased.png") q=$(differ "$TMP/erased.png" "$TMP/pointer.png")
    # the key line at the top reads differently ("e: drawing erased"), the picture is the same
    if [ "$e" -lt "$p" ]; then ok erase_clears_the_drawing; else fail erase_clears_the_drawing "$e vs $p per mille"; fi
    if [ "$q" -ge 1 ]; then ok pointer_ring_shown; else fail pointer_ring_shown "$q per mille differ"; fi
    xdotool key --window "$wid" q
else
    fail lecture_window "no window named pdtview"
fi
for i in $(seq 50); do kill -0 "$VPID" 2>/dev/null || break; sleep 0.1; done
VPID=

# ---- a click's zoom lasts until the cursor moves ----------------------------------------------
# the long thin triangle 0 1 2 has a circle far larger than the picture: a
# click on it zooms out; End then shows what f (fit) shows
printf '0 0\n100 0\n50 2\n50 60\n' >"$TMP/thin.txt"
"$BIN/pdt" triangulate "$TMP/thin.txt" --trace "$TMP/thin" >/dev/null 2>&1
zoom() { # NAME SCRIPT
    "$V" "$TMP/thin" --end --size ${W}x${H} --panels none --screenshot "$TMP/$1.png" \
         --script "wait:2 click:300,637 wait:3 $2 wait:3 s q" >/dev/null 2>&1
}
zoom clicked ""
zoom end "end"
zoom fit "end f"
c=$(differ "$TMP/clicked.png" "$TMP/fit.png") z=$(differ "$TMP/end.png" "$TMP/fit.png")
if [ -s "$TMP/end.png" ] && [ "$c" -ge 20 ] && [ "$z" -lt 5 ]; then ok click_zoom_given_back_at_the_next_move
else fail click_zoom_given_back_at_the_next_move "clicked vs fit: $c per mille differ (the click must zoom out); End vs fit: $z"; fi
summary
