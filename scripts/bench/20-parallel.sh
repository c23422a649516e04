#!/bin/bash
# make bench, section "parallel": the SRM driver against the plain sequential
# run on 10^6 uniform points (P = 1, 2), and on inputs where the merge becomes
# sequential (a rounded circle: every triangle's circumdisk spans the set).
# Median of RUNS runs (default 3); compute = the driver at rank 0 without MPI
# start-up, reading and writing.  The full speedup table is `make table1`.
set -u
cd "$(dirname "$0")/../.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
PDT=$PWD/bin/pdt
RUNS=${RUNS:-3}
W=build/bench/parallel
mkdir -p "$W"
command -v mpirun > /dev/null || { echo "parallel: mpirun not found, skipped"; exit 0; }

# one KIND N : prints a line per configuration
one() {
    local kind=$1 n=$2 in=$W/$1-$2.txt
    [ -s "$in" ] || "$PDT" gen "$kind" "$n" --seed 1 -o "$in" || exit 1
    for cfg in seq 1 2 4; do
        for i in $(seq 1 "$RUNS"); do
            if [ "$cfg" = seq ]; then
                "$PDT" triangulate "$in" -o "$W/out.tri" --stats 2> "$W/$cfg.$i.json" || exit 1
            else
                mpirun -np "$cfg" "$PDT" triangulate "$in" -o "$W/out.tri" --stats \
                    2> "$W/$cfg.$i.json" || exit 1
            fi
        done
    done
    python3 - "$W" "$RUNS" "$kind" "$n" << 'EOF'
import json, statistics, sys
w, runs, kind, n = sys.argv[1], int(sys.argv[2]), sys.argv[3], int(sys.argv[4])
def js(cfg):
    out = []
    for i in range(1, runs + 1):
        t = open(f"{w}/{cfg}.{i}.json").read()
        out.append(json.loads(t[t.index("{"):]))
    return out
seq = statistics.median(j["seconds"]["sort"] + j["seconds"]["kernel"] + j["seconds"]["canonical"]
                        for j in js("seq"))
print(f"{kind} n={n:,}: sequential compute {seq:.3f} s")
for p in (1, 2, 4):
    r = js(p)
    t = statistics.median(j["parallel"]["time_s"] for j in r)
    par = r[0]["parallel"]
    print(f"  P={p}: compute {t:.3f} s  ({seq / t:.2f}x the sequential run)  "
          f"largest border set {par['largest_border_set']:,} ({100 * par['largest_border_set_rel_n']:.1f}% of n)"
          f"{'  -> merge became sequential' if par['sequential_merge'] else ''}  "
          f"merge bytes {par['merge_bytes']:,}")
EOF
}
one uniform 1000000
one circle-round 100000
