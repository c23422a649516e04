#!/bin/bash
# The editor and the animation export (issue 14).  Goals: a live re-run of
# 500 points, click to redrawn frame, under 30 ms (median and worst of 101
# changes); GIF and video export speed in frames per second for a 1600x1000
# replay.  Prints figures with the load average; never fails on a time.
set -u
cd "$(dirname "$0")/../.."
V=bin/pdtview
OUT=build/bench/live
mkdir -p "$OUT"
echo "-- load: $(cut -d' ' -f1-3 /proc/loadavg) (wall times grow with it; CPU times less)"
echo "-- live edit: save + re-run + replay index + seek + one frame drawn"
"$V" --bench-live 500 --size 1600x1000
"$V" --bench-live 500 --size 1600x1000 --hull
"$V" --bench-live 500 --ranks 4 --size 1600x1000 2>&1 | sed 's/^/   4 ranks: /'
echo "-- export of synth:srm:24:12:4 at 1600x1000 (every 40 events)"
for f in anim.gif anim.mp4 anim.webm; do
    case $f in *.gif) opt=--gif ;; *) opt=--video ;; esac
    t0=$(date +%s.%N)
    line=$( { /usr/bin/time -f 'cpu %U %S' "$V" --headless synth:srm:24:12:4 $opt "$OUT/$f" \
              --every 40 --size 1600x1000 --fps 10; } 2>"$OUT/time.txt") || { echo "$f: failed"; cat "$OUT/time.txt"; continue; }
    t1=$(date +%s.%N)
    frames=$(echo "$line" | sed -n 's/.*(\([0-9]*\) frames.*/\1/p')
    cpu=$(awk '/^cpu/ {print $2 + $3}' "$OUT/time.txt")
    python3 -c "
f, w, c = $frames, $t1 - $t0, float('${cpu:-0}')
print(f'$f: {f} frames, {w:.2f} s wall = {f / w:.1f} frames/s; {c:.2f} s CPU = {f / c if c else 0:.1f} frames/s of CPU (drawing included); {$(stat -c %s "$OUT/$f")} bytes')"
done
