#!/bin/bash
# make table1: the thesis' Table 1 (speedup of the parallel algorithm),
# reproduced with pdt's SRM driver.
#
# For n in {10^5, 10^6, 4*10^6} uniform points and P in {1, 2, 4, 8} ranks:
# median of RUNS runs (default 3) of
#   wall     the whole `mpirun -np P pdt triangulate` (MPI start-up, read,
#            compute, write),
#   compute  the parallel driver alone (partition .. gather at rank 0),
# speedup and efficiency of `compute` against P = 1 of the same program and
# against the sequential pipeline (plain `pdt triangulate`, no MPI: sort +
# kernel + canonical order), bytes sent by all ranks, merge-step bytes
# relative to the input's size (8 bytes per point), and the largest border
# set |B|, and the critical path in CPU seconds (local kernel, classification
# and the merges on the way up, which never wait for messages) with its
# speedup: the part of the figures the machine's load does not distort.
# Rows with P above the number of cores are marked '*'.
#
# Environment: SIZES="100000 1000000 4000000" PS="1 2 4 8" RUNS=3 NICE=10
set -u
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
SIZES=${SIZES:-"100000 1000000 4000000"}
PS=${PS:-"1 2 4 8"}
RUNS=${RUNS:-3}
NICE=${NICE:-10}
PDT=$PWD/bin/pdt
CORES=$(nproc)
W=build/table1
mkdir -p "$W"
command -v mpirun > /dev/null || { echo "table1: mpirun not found" >&2; exit 1; }
command -v python3 > /dev/null || { echo "table1: python3 not found" >&2; exit 1; }

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

echo "pdt Table 1 — SRM parallel Delaunay triangulation, uniform points, median of $RUNS runs"
echo "machine: $CORES cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'),"\
     "load before start: $(cut -d' ' -f1-3 /proc/loadavg)"
echo
for n in $SIZES; do
    in=$W/uniform-$n.txt
    [ -s "$in" ] || "$PDT" gen uniform "$n" --seed 1 -o "$in"
    run "seq-$n" "$PDT" triangulate "$in"
    for p in $PS; do run "p$p-$n" mpirun -np "$p" "$PDT" triangulate "$in"; done
done

python3 - "$W" "$CORES" "$SIZES" "$PS" << 'EOF'
import json, statistics, sys
w, cores, sizes, ps = sys.argv[1], int(sys.argv[2]), sys.argv[3].split(), sys.argv[4].split()

def load(label):
    rows = []
    for line in open(f"{w}/{label}.runs"):
        wall, path = line.split()
        text = open(path).read()
        j = json.loads(text[text.index("{"):])
        rows.append((float(wall), j))
    return rows

def med(xs):
    return statistics.median(xs)

hdr = ("n", "P", "wall s", "compute s", "speedup P=1", "eff P=1", "speedup seq", "eff seq",
       "cp CPU s", "cp speedup", "bytes sent", "merge bytes", "merge/input", "largest B", "")
print("| " + " | ".join(hdr) + " |")
print("|" + "|".join("---" for _ in hdr) + "|")
for n in sizes:
    seq = load(f"seq-{n}")
    s = [j["seconds"] for _, j in seq]
    seq_compute = med([x["sort"] + x["kernel"] + x["canonical"] for x in s])
    seq_wall = med([wall for wall, _ in seq])
    print(f"| {int(n):,} | seq | {seq_wall:.3f} | {seq_compute:.3f} | | | 1.00 | | | | 0 | 0 | | | plain run |")
    base = cbase = None
    for p in ps:
        runs = load(f"p{p}-{n}")
        comp = med([j["parallel"]["time_s"] for _, j in runs])
        wall = med([wall for wall, _ in runs])
        par = runs[0][1]["parallel"]
        cpu = med([j["parallel"]["critical_path_cpu_s"] for _, j in runs])
        if base is None:
            base, cbase = comp, cpu
        sp1, sps = base / comp, seq_compute / comp
        mark = "* P > cores" if int(p) > cores else ""
        print(f"| {int(n):,} | {p} | {wall:.3f} | {comp:.3f} | {sp1:.2f} | {sp1 / int(p):.2f} | "
              f"{sps:.2f} | {sps / int(p):.2f} | {cpu:.3f} | {cbase / cpu:.2f} | "
              f"{par['bytes_total']:,} | {par['merge_bytes']:,} | "
              f"{100 * par['merge_bytes_rel_input']:.3f}% | {par['largest_border_set']:,} | {mark} |")
print()
print("compute = the parallel driver at rank 0 (partition, local kernels, merges, gather and")
print("canonical order); wall adds MPI start-up, reading and writing.  seq = the plain")
print("sequential run (sort + kernel + canonical).  merge/input = merge-step bytes / (8 n).")
print("cp CPU = CPU seconds along the critical path (local kernel + classification + the")
print("merges on the way up; no partition, gather or waiting): what the ranks compute, whatever")
print("the machine's load; cp speedup = cp CPU at P=1 / cp CPU at P.")
EOF
