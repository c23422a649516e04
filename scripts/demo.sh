#!/bin/bash
# make demo (until the viewer's demo replaces it): triangulate the bundled
# example assets/points/demo.txt with pdt, verify the result with the
# independent checker, compute its hull, then do the same on 10^5 generated
# points, printing each command and what it did.
set -eu
cd "$(dirname "$0")/.."
PDT=bin/pdt
IN=assets/points/demo.txt
OUT=build/demo
mkdir -p "$OUT"
run() { echo; echo "\$ $*"; "$@"; }

run "$PDT" triangulate "$IN" -o "$OUT/demo.tri" --stats
echo "($(wc -l < "$OUT/demo.tri") triangles in $OUT/demo.tri; the first ones:)"
head -5 "$OUT/demo.tri"
run "$PDT" check "$IN" "$OUT/demo.tri"
run "$PDT" hull "$IN"
run "$PDT" triangulate "$IN" -o "$OUT/demo.off"
echo "(Geomview OFF written to $OUT/demo.off)"

run "$PDT" gen uniform 100000 --seed 1 -o "$OUT/uniform-1e5.txt"
run "$PDT" triangulate "$OUT/uniform-1e5.txt" -o "$OUT/uniform-1e5.tri" --stats
run "$PDT" check "$OUT/uniform-1e5.txt" "$OUT/uniform-1e5.tri"
echo
echo "demo: done (outputs in $OUT/)"
