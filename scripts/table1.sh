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
#   speedup    plain wall / wall, the plain run being the faster of the
#              default (from 2^21 points: two strips one after the other, to
#              save memory) and the whole kernel at once (PDT_PLAIN_STRIPS=0),
#              both shown;
#   phases     read, partition, local, merge, order, write: seconds, the
#              largest over the ranks (from `--stats` per_rank[].seconds;
#              older builds without it: rank 0's read and write, and
#              partition_s, local_s, merge_s, gather_s as "order");
# then, for each P of PS from 2 to the number of cores, the "ceiling": P
# plain runs at once, each on n/P of the points (the best P processes can do
# here, with no communication, merge or order at all), the runs of a size in
# rounds (plain, each P, each ceiling, then again), with each command's system
# CPU seconds ("sys": on this project's VMs memory new to the machine costs
# about 2 s per GiB of system time, 0.3 s when it was in use just before, and
# the wall follows); then, per size, the merge traffic at the largest P (merge-step bytes / input
# bytes, 8 per point) and peak memory: the largest rank's peak RSS at P = 2
# against the plain run's.  Load (uptime) is printed before and after: on a
# busy machine the wall figures mean little (the phases and bytes still do).
#
# Environment: SIZES="100000 1000000 4000000 10000000" PS="1 2 4 8" RUNS=3
#              QUICK=1 (SIZES="20000 100000" PS="1 2 8" RUNS=3: a minute)
#              NICE=0 KEEP=0 (KEEP=1 keeps build/table1/*.txt inputs)
#              MEMSTATE=warm|cold|asis: the memory state each timed command
#              starts in (scripts/bench/tools/memstate.sh; default warm)
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
. scripts/bench/tools/memstate.sh
memstate_build build/bench
command -v mpirun > /dev/null || { echo "table1: mpirun not found" >&2; exit 1; }
command -v python3 > /dev/null || { echo "table1: python3 not found" >&2; exit 1; }
[ -x "$PDT" ] || { echo "table1: $PDT not built (make)" >&2; exit 1; }

# run_once LABEL I CMD... : run I of LABEL; appends "wall_seconds stats_json_file
# system_seconds steal_seconds" to $W/LABEL.runs (system seconds of the whole
# command, its children included: on this project's VMs memory new to the
# machine makes them jump, 0.3 s -> 2 s at 10^7 points, and the wall with them)
run_once() {
    local label=$1 i=$2; shift 2
    local t0 t1 s0
    # a new output each run (replacing the last one would add the unlink of
    # its page cache to the write phase)
    rm -f "$W/out.tri"
    memstate_prepare "$WARM_MB"
    s0=$(steal_now)
    t0=$(date +%s.%N)
    /usr/bin/time -f "%S" -o "$W/$label.$i.sys" nice -n "$NICE" "$@" -o "$W/out.tri" --stats \
        2> "$W/$label.$i.json" > /dev/null || {
        echo "table1: $label run $i failed:" >&2; tail -3 "$W/$label.$i.json" >&2; exit 1; }
    t1=$(date +%s.%N)
    echo "$(awk "BEGIN { print $t1 - $t0 }") $W/$label.$i.json $(tail -1 "$W/$label.$i.sys")" \
        "$(awk "BEGIN { print $(steal_now) - $s0 }")" >> "$W/$label.runs"
}

# pieces K IN: K consecutive K-ths of the input's lines (same kind of points,
# n/K of them) in $W/pieceK-I.txt, for the ceiling
pieces() {
    local k=$1 in=$2 lines
    lines=$(wc -l < "$in")
    for i in $(seq 0 $((k - 1))); do
        sed -n "$((lines * i / k + 1)),$((lines * (i + 1) / k))p" "$in" > "$W/piece$k-$i.txt"
    done
}

# ceiling_once LABEL K: K plain runs at once, one per piece: the wall until all
# are done, in $W/LABEL.runs ("wall - system_seconds").  What K processes on
# this machine can do with no communication, merge or order at all: the best
# a K-rank run could reach here (each with the whole kernel, the faster way).
ceiling_once() {
    local label=$1 k=$2
    local t0 t1 s0
    rm -f "$W"/piece*.tri
    memstate_prepare "$WARM_MB"
    s0=$(steal_now)
    t0=$(date +%s.%N)
    /usr/bin/time -f "%S" -o "$W/$label.sys" bash -c '
        for i in $(seq 0 $(($2 - 1))); do
            PDT_PLAIN_STRIPS=0 nice -n "$3" "$4" triangulate "$1/piece$2-$i.txt" \
                -o "$1/piece$2-$i.tri" 2> /dev/null &
        done
        wait' _ "$W" "$k" "$NICE" "$PDT"
    t1=$(date +%s.%N)
    echo "$(awk "BEGIN { print $t1 - $t0 }") - $(tail -1 "$W/$label.sys")" \
        "$(awk "BEGIN { print $(steal_now) - $s0 }")" >> "$W/$label.runs"
}

echo "pdt Table 1 — wall time against the plain run, uniform points, median of $RUNS runs"
echo "machine: $CORES cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
echo "memory state before each run: MEMSTATE=$MEMSTATE (scripts/bench/tools/memstate.sh)"
echo "uptime before: $(uptime)"
echo
# The runs of one size go in rounds (plain, each P, each ceiling, then again),
# so that a change in the machine's state in the middle touches every row.
for n in $SIZES; do
    in=$W/uniform-$n.txt
    WARM_MB=$((n * 150 / 1000000 + 64)) # what a run of n points touches, with room
    [ -s "$in" ] || "$PDT" gen uniform "$n" --seed 1 -o "$in"
    ceil_ps=""
    for p in $PS; do [ "$p" -gt 1 ] && [ "$p" -le "$CORES" ] && ceil_ps="$ceil_ps $p"; done
    for p in $ceil_ps; do pieces "$p" "$in"; done
    : > "$W/seq-$n.runs"
    : > "$W/whole-$n.runs"
    for p in $PS; do : > "$W/p$p-$n.runs"; done
    for p in $ceil_ps; do : > "$W/ceil$p-$n.runs"; done
    for i in $(seq 1 "$RUNS"); do
        run_once "seq-$n" "$i" "$PDT" triangulate "$in"
        run_once "whole-$n" "$i" env PDT_PLAIN_STRIPS=0 "$PDT" triangulate "$in"
        for p in $PS; do run_once "p$p-$n" "$i" mpirun -np "$p" "$PDT" triangulate "$in"; done
        for p in $ceil_ps; do ceiling_once "ceil$p-$n" "$p"; done
    done
    rm -f "$W"/piece*.txt "$W"/piece*.tri
    [ "${KEEP:-0}" = 1 ] || rm -f "$in"
done

python3 scripts/table1_report.py "$W" "$CORES" "$SIZES" "$PS"
echo
echo "uptime after: $(uptime)"
