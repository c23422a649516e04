#!/bin/bash
# Record the run kept in assets/runs/uniform-300-p8/ (lesson 9): 300 uniform
# points (assets/points/uniform-300.txt = `pdt gen uniform 300`) triangulated
# by 8 MPI ranks, trace level 1.  It was recorded on the 2-core development
# machine, so 8 ranks share 2 cores (--oversubscribe).  Run from anywhere
# after `make`; the old recording is replaced.
set -eu
cd "$(dirname "$0")/../.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
PDT=${PDT:-bin/pdt}
[ -s assets/points/uniform-300.txt ] || {
    { echo "# pdt gen uniform 300 --seed 1"; "$PDT" gen uniform 300 --seed 1; } > assets/points/uniform-300.txt; }
rm -rf assets/runs/uniform-300-p8
mpirun -np 8 --oversubscribe "$PDT" triangulate assets/points/uniform-300.txt \
    --trace assets/runs/uniform-300-p8 -o /dev/null
"$PDT" trace check assets/runs/uniform-300-p8
du -sh assets/runs/uniform-300-p8
