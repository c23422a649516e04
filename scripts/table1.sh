#!/bin/bash
# make table1: the thesis' Table 1 (speedup of the parallel algorithm),
# reproduced with pdt, by WALL TIME of the whole command against the plain
# run (`pdt triangulate`, no MPI), with each rank's phases so a reader sees
# where the time goes.
#
# For n in SIZES uniform points (`pdt gen uniform`) and P in PS ranks, the
# median of RUNS runs of
#   wall       the whole `mpirun -np P pdt triangulate IN -o OUT` (MPI
#              start-up, read, compute, write) and of the plain run;
#   speedup    plain wall / wall;
#   phases     read, partition, local, merge, order, write: seconds, the
#              largest over the ranks (from `--stats` per_rank[].seconds;
#              older builds without it: rank 0's read and write, and
#              partition_s, local_s, merge_s, gather_s as "order");
# then, for each P of PS from 2 to the number of cores, the "ceiling": P
# plain runs at once, each on n/P of the points (the best P processes can do
# here, with no communication, merge or order at all); then, per size, the merge traffic at the largest P (merge-step bytes / input
# bytes, 8 per point) and peak memory: the largest rank's peak RSS at P = 2
# against the plain run's.  Load (uptime) is printed before and after: on a
# busy machine the wall figures mean little (the phases and bytes still do).
#
# Environment: SIZES="100000 1000000 4000000 10000000" PS="1 2 4 8" RUNS=3
#              QUICK=1 (SIZES="20000 100000" PS="1 2 8" RUNS=3: a minute)
#              NICE=0 KEEP=0 (KEEP=1 keeps build/table1/*.txt inputs)
set -u
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
if [ "${QUICK:-0}" = 1 ]; then
    SIZES=${SIZES:-"20000 100000"}; PS=${PS:-"1 2 8"}
fi
SIZES=${SIZES:-"100000 1000000 4000000 10000000"}
PS=${PS:-"1 2 4 8"}
RUNS=${RUNS:-3}
NICE=${NICE:-0}
PDT=$PWD/bin/pdt
CORES=$(nproc)
W=${TABLE1_DIR:-build/table1}
mkdir -p "$W"
command -v mpirun > /dev/null || { echo "table1: mpirun not found" >&2; exit 1; }
command -v python3 > /dev/null || { echo "table1: python3 not found" >&2; exit 1; }
[ -x "$PDT" ] || { echo "table1: $PDT not built (make)" >&2; exit 1; }

# run LABEL CMD... : RUNS times; appends "wall_seconds stats_json_file" lines to $W/LABEL.runs
run() {
    local label=$1; shift
    : > "$W/$label.runs"
    for i in $(seq 1 "$RUNS"); do
        local t0 t1
        t0=$(date +%s.%N)
        nice -n "$NICE" "$@" -o "$W/out.tri" --stats 2> "$W/$label.$i.json" > /dev/null || {
            echo "table1: $label run $i failed:" >&2; tail -3 "$W/$label.$i.json" >&2; exit 1; }
        t1=$(date +%s.%N)
        echo "$(awk "BEGIN { print $t1 - $t0 }") $W/$label.$i.json" >> "$W/$label.runs"
    done
}

# ceiling LABEL K IN: RUNS times, K plain runs at once, each on a consecutive
# K-th of the input's lines (same kind of points, n/K of them): the wall
# until all are done, in $W/LABEL.runs ("wall -").  What K processes on this
# machine can do with no communication, merge or order at all: the best a
# K-rank run could reach here.
ceiling() {
    local label=$1 k=$2 in=$3 lines
    lines=$(wc -l < "$in")
    for i in $(seq 0 $((k - 1))); do
        sed -n "$((lines * i / k + 1)),$((lines * (i + 1) / k))p" "$in" > "$W/piece$i.txt"
    done
    : > "$W/$label.runs"
    for r in $(seq 1 "$RUNS"); do
        local t0 t1
        t0=$(date +%s.%N)
        for i in $(seq 0 $((k - 1))); do
            nice -n "$NICE" "$PDT" triangulate "$W/piece$i.txt" -o "$W/piece$i.tri" 2> /dev/null &
        done
        wait
        t1=$(date +%s.%N)
        echo "$(awk "BEGIN { print $t1 - $t0 }") -" >> "$W/$label.runs"
    done
    rm -f "$W"/piece*.txt "$W"/piece*.tri
}

echo "pdt Table 1 — wall time against the plain run, uniform points, median of $RUNS runs"
echo "machine: $CORES cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
echo "uptime before: $(uptime)"
echo
for n in $SIZES; do
    in=$W/uniform-$n.txt
    [ -s "$in" ] || "$PDT" gen uniform "$n" --seed 1 -o "$in"
    run "seq-$n" "$PDT" triangulate "$in"
    for p in $PS; do run "p$p-$n" mpirun -np "$p" "$PDT" triangulate "$in"; done
    for p in $PS; do [ "$p" -gt 1 ] && [ "$p" -le "$CORES" ] && ceiling "ceil$p-$n" "$p" "$in"; done
    [ "${KEEP:-0}" = 1 ] || rm -f "$in"
done

python3 scripts/table1_report.py "$W" "$CORES" "$SIZES" "$PS"
echo
echo "uptime after: $(uptime)"
