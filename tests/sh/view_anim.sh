#!/bin/bash
# pdtview animation export: --gif / --video (mp4, webm) read back with the
# tools users have (ImageMagick's identify and compare, FFmpeg's ffprobe):
# frame count, size, duration, the picture itself; ranges (--from/--to,
# --phase, --every, --hold and its 2 s default for a GIF); bad output paths (exit 2, a message, nothing
# left behind); the window's m / r keys under Xvfb.
# san: yes
. "$(dirname "$0")/lib.sh"
V=$BIN/pdtview
for t in identify compare ffprobe; do
    command -v $t >/dev/null || { fail "have_$t" "$t is not installed (DEB_TEST)"; summary; exit 1; }
done
RUN=synth:srm:12:6:4
m=$("$V" --headless "$RUN" --end -o "$TMP/x.png" --size 320x200 | sed -n 's/.*event \([0-9]*\) of.*/\1/p')

# ---- GIF: every 100 events at 8 frames/s -------------------------------------------------
if "$V" --headless "$RUN" --gif "$TMP/a.gif" --every 100 --fps 8 --size 640x400 --quiet; then
    ok gif_written; else fail gif_written; fi
# a GIF rests 2 s on its last frame unless told (--hold): 16 more frames at 8/s
want=$(( (m + 99) / 100 + 1 + 16 ))
got=$(identify "$TMP/a.gif" 2>/dev/null | wc -l)
if [ "$got" -eq "$want" ]; then ok gif_frame_count_holds_2s; else fail gif_frame_count_holds_2s "want $want, got $got (m=$m)"; fi
size=$(identify -format '%W %H\n' "$TMP/a.gif" | sort -u)
if [ "$size" = "640 400" ]; then ok gif_size; else fail gif_size "page sizes: $size"; fi
# delays in 1/100 s add up to frames / fps
cs=$(identify -format '%T\n' "$TMP/a.gif" | awk '{s += $1} END {print s}')
wantcs=$(python3 -c "print(round(100 * $want / 8))")
if [ "$cs" -eq "$wantcs" ]; then ok gif_duration; else fail gif_duration "delays add to $cs/100 s, want $wantcs"; fi
# later frames store only what changed
small=$(identify -format '%w %h\n' "$TMP/a.gif" | awk '$1 * $2 < 640 * 400' | wc -l)
if [ "$small" -gt 0 ]; then ok gif_frame_differencing; else fail gif_frame_differencing "every frame is full size"; fi
# the last frame, composed, looks like the headless picture of the end
convert "$TMP/a.gif" -coalesce "$TMP/co-%03d.png" 2>/dev/null
last=$(ls "$TMP"/co-*.png | tail -1)
"$V" --headless "$RUN" --end -o "$TMP/end.png" --size 640x400 --quiet
ae=$(compare -metric AE -fuzz 10% "$last" "$TMP/end.png" "$TMP/diff.png" 2>&1 >/dev/null | sed 's/[^0-9.e+].*//')
share=$(python3 -c "print(f'{float(\"${ae:-1e9}\") / (640 * 400) * 100:.3f}')")
echo "# last GIF frame vs headless PNG: $share % of the pixels differ by more than 10 %"
if python3 -c "import sys; sys.exit(0 if float('$share') < 1.0 else 1)"; then ok gif_last_frame_equals_png
else fail gif_last_frame_equals_png "$share % differ"; fi

# ---- --hold 0, --from/--to, --hold, --phase -------------------------------------------------
"$V" --headless "$RUN" --gif "$TMP/h0.gif" --every 100 --fps 8 --size 320x200 --hold 0 --quiet
got=$(identify "$TMP/h0.gif" 2>/dev/null | wc -l)
if [ "$got" -eq $(( (m + 99) / 100 + 1 )) ]; then ok gif_hold_0_no_rest
else fail gif_hold_0_no_rest "got $got frames"; fi
"$V" --headless "$RUN" --gif "$TMP/r.gif" --from 100 --to 130 --every 10 --hold 0.5 --fps 10 \
     --size 320x200 --quiet
got=$(identify "$TMP/r.gif" 2>/dev/null | wc -l)
if [ "$got" -eq 9 ]; then ok gif_from_to_hold; else fail gif_from_to_hold "want 4 + 5 frames, got $got"; fi
out=$("$V" --headless "$RUN" --gif "$TMP/p.gif" --phase merge:1 --every 50 --size 320x200 --hold 0)
from=$(echo "$out" | sed -n 's/.*events \([0-9]*\) to \([0-9]*\).*/\1/p')
to=$(echo "$out" | sed -n 's/.*events \([0-9]*\) to \([0-9]*\).*/\2/p')
if [ -n "$from" ] && [ "$from" -gt 0 ] && [ "$to" -gt "$from" ] && [ "$to" -le "$m" ] &&
   [ "$(identify "$TMP/p.gif" | wc -l)" -eq $(( (to - from + 49) / 50 + 1 )) ]; then ok gif_phase
else fail gif_phase "$out"; fi

# ---- videos --------------------------------------------------------------------------------
probe() { ffprobe -v error -count_frames -select_streams v:0 \
          -show_entries stream=codec_name,width,height,nb_read_frames:format=duration -of default=nw=1 "$1"; }
for ext in mp4 webm; do
    if "$V" --headless "$RUN" --video "$TMP/v.$ext" --every 50 --fps 12 --size 640x400 --quiet; then
        ok "${ext}_written"; else fail "${ext}_written"; fi
    p=$(probe "$TMP/v.$ext")
    echo "$p" | sed 's/^/# '"$ext"': /'
    want=$(( (m + 49) / 50 + 1 ))
    codec=$(echo "$p" | sed -n 's/^codec_name=//p')
    case $ext:$codec in mp4:h264|mp4:mpeg4|webm:vp9|webm:vp8) ok "${ext}_codec" ;; *) fail "${ext}_codec" "$codec" ;; esac
    if echo "$p" | grep -qx 'width=640' && echo "$p" | grep -qx 'height=400'; then ok "${ext}_size"
    else fail "${ext}_size" "$p"; fi
    if echo "$p" | grep -qx "nb_read_frames=$want"; then ok "${ext}_frame_count"
    else fail "${ext}_frame_count" "want $want"; fi
    dur=$(echo "$p" | sed -n 's/^duration=//p')
    if python3 -c "import sys; sys.exit(0 if abs(float('${dur:-0}') - $want / 12) < 0.09 else 1)"; then
        ok "${ext}_duration"; else fail "${ext}_duration" "$dur s, want $want/12 s"; fi
done

# ---- bad output: exit 2, a message, nothing written ------------------------------------------
mkdir -p "$TMP/outdir"
"$V" --headless "$RUN" --gif "$TMP/nodir/a.gif" --size 320x200 2>"$TMP/e1"; rc=$?
if [ "$rc" -eq 2 ] && grep -q 'nodir/a.gif' "$TMP/e1" && [ ! -e "$TMP/nodir" ]; then ok error_gif_no_dir
else fail error_gif_no_dir "exit $rc: $(cat "$TMP/e1")"; fi
mkdir -p "$TMP/isdir.mp4"
"$V" --headless "$RUN" --video "$TMP/isdir.mp4" --size 320x200 2>"$TMP/e2"; rc=$?
if [ "$rc" -eq 2 ] && grep -q 'is a directory' "$TMP/e2"; then ok error_video_is_dir
else fail error_video_is_dir "exit $rc: $(cat "$TMP/e2")"; fi
"$V" --headless "$RUN" --video "$TMP/outdir/odd.mp4" --size 321x200 2>"$TMP/e3"; rc=$?
if [ "$rc" -eq 2 ] && grep -q 'even width' "$TMP/e3" && [ -z "$(ls -A "$TMP/outdir")" ]; then ok error_video_odd_size
else fail error_video_odd_size "exit $rc: $(cat "$TMP/e3"); left: $(ls -A "$TMP/outdir")"; fi
"$V" --headless "$RUN" --gif "$TMP/outdir/a.gif" --from 20 --to 10 2>"$TMP/e4"; rc=$?
if [ "$rc" -eq 2 ] && grep -q 'from <= to' "$TMP/e4" && [ -z "$(ls -A "$TMP/outdir")" ]; then ok error_range
else fail error_range "exit $rc: $(cat "$TMP/e4")"; fi
"$V" --headless "$RUN" --video "$TMP/outdir/a.avi" 2>"$TMP/e5"; rc=$?
if [ "$rc" -eq 2 ] && grep -q '.mp4 or .webm' "$TMP/e5"; then ok error_video_ext; else fail error_video_ext "exit $rc"; fi
"$V" --headless "$RUN" --gif "$TMP/outdir/a.gif" --fps 100 2>"$TMP/e6"; rc=$?
if [ "$rc" -eq 2 ] && grep -q 'at most 50' "$TMP/e6" && [ -z "$(ls -A "$TMP/outdir")" ]; then ok error_gif_fps
else fail error_gif_fps "exit $rc: $(cat "$TMP/e6")"; fi

# ---- the window: m marks, r records (under Xvfb) ----------------------------------------------
if command -v Xvfb >/dev/null && [ -z "${SKIP_WINDOW:-}" ]; then
    d=110
    while [ -e /tmp/.X$d-lock ] || [ -e /tmp/.X11-unix/X$d ]; do d=$((d + 1)); done
    Xvfb :$d -screen 0 800x600x24 -nolisten tcp >"$TMP/xvfb.log" 2>&1 &
    XPID=$!
    for i in $(seq 50); do DISPLAY=:$d xdotool getdisplaygeometry >/dev/null 2>&1 && break; sleep 0.1; done
    DISPLAY=:$d timeout 60 "$V" "$RUN" --size 640x400 --record "$TMP/win.gif" --fps 5 \
        --script "right right m right right right right right r wait:2 q" 2>"$TMP/win.err"
    kill "$XPID" 2>/dev/null; wait "$XPID" 2>/dev/null
    got=$(identify "$TMP/win.gif" 2>/dev/null | wc -l)
    # 6 frames, then 2 s (10 frames at 5/s) on the last: a GIF rests on its end
    if grep -q 'recorded .*win.gif (16 frames, events 2 to 7)' "$TMP/win.err" && [ "$got" -eq 16 ]; then
        ok window_record_key; else fail window_record_key "$got frames; $(cat "$TMP/win.err")"; fi
fi
summary
