#!/bin/bash
# pdtview --edit FILE in a real window under Xvfb: real X clicks (xdotool)
# add points, a right click deletes one, Ctrl+Z brings it back; the file is
# rewritten after every change and `pdt` reads it as is (the triangles the
# editor's replay ends with are `pdt triangulate`'s); a file that does not
# parse is refused (exit 2, file:line) and left as it was.  Live runs on P
# simulated ranks record, rank by rank, the events `mpirun -np P pdt
# triangulate --trace` records (times aside); keys switch ranks and hull.
. "$(dirname "$0")/lib.sh"
V=$BIN/pdtview
for t in Xvfb xdotool import; do
    command -v $t >/dev/null || { fail "have_$t" "$t is not installed (DEB_TEST)"; summary; exit 1; }
done

# refused: a file that does not parse is never overwritten
printf '0 0\n1 2\n3 4294967296\n' >"$TMP/bad.txt"
cp "$TMP/bad.txt" "$TMP/bad.orig"
"$V" --edit "$TMP/bad.txt" 2>"$TMP/bad.err"; rc=$?
if [ "$rc" -eq 2 ] && grep -q 'bad.txt:3' "$TMP/bad.err" && cmp -s "$TMP/bad.txt" "$TMP/bad.orig"; then
    ok edit_refuses_bad_file; else fail edit_refuses_bad_file "exit $rc: $(cat "$TMP/bad.err")"; fi

# the live run is the real run: rank by rank the same events (kinds and
# operands: `pdt trace dump` without the time column) as mpirun -np P, and as
# the plain `pdt triangulate --trace` / `pdt hull --trace` on one rank
same_events() { # NAME DIR_A DIR_B RANKS
    local r a b bad=
    for r in $(seq 0 $(($4 - 1))); do
        a=$("$PDT" trace dump "$2" --rank "$r" | sed 's/ t=[^ ]*//')
        b=$("$PDT" trace dump "$3" --rank "$r" | sed 's/ t=[^ ]*//')
        if [ -z "$a" ] || [ "$a" != "$b" ]; then bad="rank $r: $(diff <(echo "$a") <(echo "$b") | head -4)"; break; fi
    done
    if [ -z "$bad" ] && "$PDT" trace check "$3" >/dev/null; then ok "$1"; else fail "$1" "$bad"; fi
}
"$PDT" gen clusters 300 --seed 3 -o "$TMP/c300.txt"
(head -40 "$TMP/c300.txt"; head -15 "$TMP/c300.txt"; printf '0 0\n0 0\n1 1\n2 2\n3 3\n') >"$TMP/dup.txt"
for P in 4 3; do
    for f in c300 dup; do
        mpirun -np $P "$PDT" triangulate "$TMP/$f.txt" -o "$TMP/mpi.ele" --trace "$TMP/mpi-$f-$P" >/dev/null 2>"$TMP/mpi.err" ||
            fail "mpirun_${f}_$P" "$(cat "$TMP/mpi.err")"
        "$V" --edit "$TMP/$f.txt" --ranks $P --write-run "$TMP/live-$f-$P" --quiet 2>"$TMP/live.err" ||
            fail "live_write_run_${f}_$P" "$(cat "$TMP/live.err")"
        same_events "live_${P}_ranks_records_what_mpirun_records_$f" "$TMP/mpi-$f-$P" "$TMP/live-$f-$P" $P
    done
done
"$PDT" triangulate "$TMP/c300.txt" -o "$TMP/one.ele" --trace "$TMP/one" 2>/dev/null
"$V" --edit "$TMP/c300.txt" --write-run "$TMP/live-one" --quiet
same_events live_1_rank_records_what_pdt_triangulate_records "$TMP/one" "$TMP/live-one" 1
"$PDT" hull "$TMP/c300.txt" -o "$TMP/hull.txt" --trace "$TMP/hull" 2>/dev/null
"$V" --edit "$TMP/c300.txt" --hull --ranks 4 --write-run "$TMP/live-hull" --quiet
same_events live_hull_records_what_pdt_hull_records "$TMP/hull" "$TMP/live-hull" 1

# no display: a message and exit 1, not a viewer running unseen (SDL's
# offscreen driver), and the missing file it was to edit is not made
rc=0; env -u WAYLAND_DISPLAY DISPLAY=:1999 timeout 60 "$V" --edit "$TMP/nodisplay.txt" 2>"$TMP/nod.err" || rc=$?
if [ "$rc" -eq 1 ] && grep -q 'cannot open a window.*DISPLAY=:1999' "$TMP/nod.err" && [ ! -e "$TMP/nodisplay.txt" ]
then ok no_display_is_an_error_and_makes_no_file
else fail no_display_is_an_error_and_makes_no_file "exit $rc: $(cat "$TMP/nod.err"; ls "$TMP/nodisplay.txt" 2>&1)"; fi

W=900; H=600
xvfb_start ${W}x${H}
trap xvfb_cleanup EXIT

F=$TMP/mine.txt
# start_viewer TITLE OUT ERR ARGS...: pdtview ARGS in the background (VPID)
# and the id of its window whose title matches TITLE in wid (empty if none
# came).  A viewer that finds no display (it exits saying so) is started
# once more: the X server's answer, not the editor, is what failed (seen
# under load).
start_viewer() {
    local title=$1 out=$2 err=$3 try
    shift 3
    for try in 1 2; do
        "$V" "$@" >"$out" 2>"$err" &
        VPID=$!
        wid=
        for i in $(seq 300); do
            wid=$(pdtview_window "$title"); [ -n "$wid" ] && return 0
            kill -0 "$VPID" 2>/dev/null || break
            sleep 0.1
        done
        grep -q 'no display answers' "$err" || return 1
        echo "# note: the viewer found no display (try $try): $(cat "$err"; cat "$TMP/xvfb.log"; ls -la /tmp/.X11-unix)"
        sleep 1
    done
    return 1
}
# start_editor: the editor on $F (its window's id in wid)
start_editor() {
    start_viewer 'pdtview' "$TMP/out.log" "$TMP/err.log" --edit "$F" --size ${W}x${H} --screenshot "$TMP/edit.png"
}
start_editor
if [ -n "$wid" ] && [ -f "$F" ] && [ ! -s "$F" ]; then ok edit_creates_missing_file
else fail edit_creates_missing_file "window '$wid', file: $(ls -l "$F" 2>&1); $(stuck_report "$VPID"; cat "$TMP/err.log")"; fi
sleep 1.5
npts() { grep -cE '^-?[0-9]' "$F" 2>/dev/null || echo 0; }
# wait until the file has $1 points
wait_pts() { for i in $(seq 100); do [ "$(npts)" = "$1" ] && return 0; sleep 0.1; done; return 1; }
clicks=("120 120" "400 110" "260 380" "330 230" "150 420" "480 400")
for c in "${clicks[@]}"; do
    read -r x y <<<"$c"
    xdotool mousemove --window "$wid" "$x" "$y" click 1
    sleep 0.3
done
if wait_pts 6; then ok edit_clicks_add_points; else fail edit_clicks_add_points "$(npts) points: $(cat "$F")"; fi
cp "$F" "$TMP/six.txt"
xdotool mousemove --window "$wid" 330 230 click 3
if wait_pts 5; then ok edit_right_click_deletes; else fail edit_right_click_deletes "$(npts) points"; fi
xdotool key --window "$wid" ctrl+z
if wait_pts 6 && cmp -s "$F" "$TMP/six.txt"; then ok edit_undo; else fail edit_undo "$(cat "$F")"; fi
xdotool key --window "$wid" ctrl+y
if wait_pts 5; then ok edit_redo; else fail edit_redo "$(npts) points"; fi
xdotool key --window "$wid" ctrl+z
wait_pts 6
# pdt reads the file as it is
if "$PDT" triangulate "$F" -o "$TMP/mine.tri" 2>"$TMP/tri.err"; then ok pdt_reads_saved_file
else fail pdt_reads_saved_file "$(cat "$TMP/tri.err")"; fi
sleep 0.3
import -window root "$TMP/x11.png" 2>/dev/null
xdotool key --window "$wid" s
for i in $(seq 50); do grep -q screenshot "$TMP/err.log" && break; sleep 0.1; done
xdotool key --window "$wid" q
for i in $(seq 50); do kill -0 "$VPID" 2>/dev/null || break; sleep 0.1; done
if ! kill -0 "$VPID" 2>/dev/null; then wait "$VPID"; rc=$?; VPID=
    if [ "$rc" -eq 0 ]; then ok edit_quit; else fail edit_quit "exit $rc: $(cat "$TMP/err.log")"; fi
else fail edit_quit "still running"; fi
if [ -s "$TMP/edit.png" ] && [ -s "$TMP/x11.png" ]; then ok edit_screenshots; else fail edit_screenshots; fi
[ -n "${KEEP_SHOTS:-}" ] && cp "$TMP/edit.png" "$TMP/x11.png" "$F" "$KEEP_SHOTS"/

# --ranks 4 and the keys: 1 … 8 switch ranks, x Graham only (the title says
# which); clicks on 4 ranks; the file's live run is mpirun's
G=$TMP/four.txt
cp "$TMP/c300.txt" "$G"
[ -n "${VPID:-}" ] && stop_pid "$VPID"  # (an editor that did not quit: not left behind)
start_viewer 'editing.*four' "$TMP/out4.log" "$TMP/err4.log" --edit "$G" --ranks 4 --size ${W}x${H} \
    --screenshot "$TMP/four.png"
# wait until the window title matches $1
wait_title() { for i in $(seq 100); do xdotool getwindowname "$wid" 2>/dev/null | grep -q "$1" && return 0; sleep 0.1; done; return 1; }
if [ -n "$wid" ] && wait_title 'triangulate, 4 ranks'; then ok edit_ranks_4_window
else fail edit_ranks_4_window "'$(xdotool getwindowname "$wid" 2>&1)' $(cat "$TMP/err4.log")"; fi
sleep 1
npts4() { grep -cE '^-?[0-9]' "$G" 2>/dev/null || echo 0; }
xdotool mousemove --window "$wid" 200 200 click 1
sleep 0.3
xdotool mousemove --window "$wid" 330 330 click 1
for i in $(seq 100); do [ "$(npts4)" = 302 ] && break; sleep 0.1; done
if [ "$(npts4)" = 302 ]; then ok edit_ranks_4_clicks_add; else fail edit_ranks_4_clicks_add "$(npts4) points"; fi
xdotool key --window "$wid" 2
if wait_title 'triangulate, 2 ranks'; then ok edit_key_2_ranks; else fail edit_key_2_ranks "$(xdotool getwindowname "$wid")"; fi
xdotool key --window "$wid" x
if wait_title 'hull (Graham), 1 rank'; then ok edit_key_x_hull; else fail edit_key_x_hull "$(xdotool getwindowname "$wid")"; fi
xdotool key --window "$wid" x
xdotool key --window "$wid" 4
if wait_title 'triangulate, 4 ranks'; then ok edit_key_4_ranks; else fail edit_key_4_ranks "$(xdotool getwindowname "$wid")"; fi
xdotool key --window "$wid" q
for i in $(seq 50); do kill -0 "$VPID" 2>/dev/null || break; sleep 0.1; done
if ! kill -0 "$VPID" 2>/dev/null; then wait "$VPID"; rc=$?; VPID=
    if [ "$rc" -eq 0 ] && [ -s "$TMP/four.png" ]; then ok edit_ranks_quit; else fail edit_ranks_quit "exit $rc: $(cat "$TMP/err4.log")"; fi
else fail edit_ranks_quit "still running"; fi
[ -n "${KEEP_SHOTS:-}" ] && cp "$TMP/four.png" "$KEEP_SHOTS"/
mpirun -np 4 "$PDT" triangulate "$G" -o "$TMP/mpi4.ele" --trace "$TMP/mpi-four" >/dev/null 2>&1
"$V" --edit "$G" --ranks 4 --write-run "$TMP/live-four" --quiet
same_events edit_file_live_4_ranks_is_mpiruns "$TMP/mpi-four" "$TMP/live-four" 4

# the same points, the same triangles: the editor's replay ends where pdt does
"$PDT" triangulate "$F" -o "$TMP/a.tri" --trace "$TMP/run" 2>/dev/null
c1=$("$V" "$TMP/run" --end --counts | sed -n 's/.* final \([0-9]*\).*/\1/p')
if [ -n "$c1" ] && [ "$c1" -eq "$(grep -c . "$TMP/a.tri")" ] && [ "$c1" -gt 0 ]; then ok edit_file_triangulates
else fail edit_file_triangulates "final $c1"; fi
summary
