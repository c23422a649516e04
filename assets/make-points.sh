#!/bin/bash
# Regenerate the classroom point sets in assets/points/ with `pdt gen`:
# every generator family at a few small sizes (seed 1).  Run after `make`.
#   assets/make-points.sh [PDT]
set -eu
cd "$(dirname "$0")/.."
PDT=${1:-bin/pdt}
mkdir -p assets/points
for kind in $("$PDT" gen --help | sed -n 's/^kinds: //p'); do
    for n in 12 40 200; do
        f=assets/points/$kind-$n.txt
        { echo "# pdt gen $kind $n --seed 1"; "$PDT" gen "$kind" "$n" --seed 1; } >"$f"
    done
done
ls assets/points | wc -l
