#!/bin/bash
# Regenerate the pictures in docs/img from real runs of the real programs:
#   viewer-graham.png   Graham's scan of 30 points (pdt hull --trace), headless
#   viewer-merge.png    lesson 07's 40 points on 4 ranks, in the first merge step
#   viewer-final.png    the same run at its end: clean view with the Voronoi diagram
#   viewer-window.png   the SDL2 window under Xvfb (1024x768), lesson 07 mid-merge
# Usage: scripts/screenshots.sh   (needs bin/pdt, bin/pdtview, mpirun; Xvfb and
# ImageMagick's import for the window shot, skipped with a note when missing)
set -eu
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
OUT=docs/img
mkdir -p "$OUT"

bin/pdt gen uniform 30 --seed 11 | bin/pdt hull - --trace "$TMP/hull30" > /dev/null
bin/pdtview --headless "$TMP/hull30" --at 66 --size 1200x750 -o "$OUT/viewer-graham.png"

mpirun -np 4 bin/pdt triangulate lessons/07-strips/points.txt -o "$TMP/l07.tri" \
    --trace "$TMP/l07" > /dev/null
# 25 events into the first merge step (its border kernel at work)
first_merge=$(bin/pdtview "$TMP/l07" --describe |
    awk -F'\t' '$1 == "event" && $5 ~ /: merge level/ { print $2 + 25; exit }')
bin/pdtview --headless "$TMP/l07" --at "${first_merge:-300}" --size 1200x750 -o "$OUT/viewer-merge.png"
bin/pdtview --headless "$TMP/l07" --end --clean --voronoi --panels none --size 1200x750 \
    -o "$OUT/viewer-final.png"

if command -v Xvfb > /dev/null && command -v import > /dev/null; then
    d=$((200 + $$ % 500))
    Xvfb ":$d" -screen 0 1024x768x24 -nolisten tcp > "$TMP/xvfb.log" 2>&1 &
    xpid=$!
    sleep 1
    DISPLAY=":$d" bin/pdtview "$TMP/l07" --at "${first_merge:-300}" --size 1024x768 \
        --script "wait:1500 q" > /dev/null 2>&1 &
    vpid=$!
    sleep 1.2
    DISPLAY=":$d" import -window root "$OUT/viewer-window.png"
    wait "$vpid" || true
    kill "$xpid" 2> /dev/null || true
else
    echo "screenshots: Xvfb or import missing: viewer-window.png not regenerated" >&2
fi
ls -l "$OUT"
