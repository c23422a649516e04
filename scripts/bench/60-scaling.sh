#!/bin/bash
# make bench, section "scaling": the sequential pipeline's cost per point as n
# grows (issue 11).  For each input, `pdt triangulate --stats -o OUT.tri`
# gives the seconds of every phase (read, sort, kernel, canonical, write);
# the table shows them as seconds and as nanoseconds per input point, the
# peak resident memory in bytes per point and the process's CPU seconds
# (user + system, both threads: a plain run faults its working memory in on
# a second thread, PDT_TRI_PREFAULT in docs/geometry.md) (/usr/bin/time), and CGAL's
# Delaunay_triangulation_2 range insert on the same file in the same run
# (tools/cgal_dt.cpp, exact predicates, spatial sort included) with the ratio
# (pdt sort + kernel) / (CGAL insert).  Medians of SCALING_RUNS runs (default 1).
#
# Sizes (override for a quick run, e.g. SCALING_UNIFORM="1e5 1e6" SCALING_OTHER="1e6"):
#   SCALING_UNIFORM  uniform points in [0, 2^20)^2   (default 1e5 1e6 4e6 1e7 3e7)
#   SCALING_OTHER    grid (k x k) and clusters        (default 1e6 1e7)
#   SCALING_QUICK=1  the same as SCALING_UNIFORM="1e5 1e6" SCALING_OTHER="1e6"
# This section alone: make bench BENCH_ONLY=scaling (3*10^7 points need about
# 1.9 GB for pdt (62 bytes per point; 84 with PDT_PLAIN_STRIPS=0), more for CGAL, and 0.5 GB of input text in build/bench).
# MEMSTATE=warm|cold|asis: the memory state each timed run (pdt's and CGAL's)
# starts in (scripts/bench/tools/memstate.sh; default warm).
# Inputs are cached in build/bench/scaling/.  The load average is printed
# before and after: on a loaded machine the seconds measure the contention.
set -u
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
B=$ROOT/build/bench
W=$B/scaling
PDT=$ROOT/bin/pdt
mkdir -p "$W"
if [ "${SCALING_QUICK:-0}" = 1 ]; then
    UNI=${SCALING_UNIFORM:-"1e5 1e6"}
    OTH=${SCALING_OTHER:-"1e6"}
else
    UNI=${SCALING_UNIFORM:-"1e5 1e6 4e6 1e7 3e7"}
    OTH=${SCALING_OTHER:-"1e6 1e7"}
fi
RUNS=${SCALING_RUNS:-1}
. scripts/bench/tools/memstate.sh
memstate_build "$B"
[ -x "$PDT" ] || { echo "bin/pdt is missing: run make first"; exit 1; }
TIME=/usr/bin/time
[ -x "$TIME" ] || { echo "scaling: /usr/bin/time missing (Debian package 'time'), skipped"; exit 0; }

HAVE_CGAL=0
if [ -d /usr/include/CGAL ] && command -v g++ > /dev/null; then
    if [ ! -x "$B/cgal_dt" ] || [ scripts/bench/tools/cgal_dt.cpp -nt "$B/cgal_dt" ]; then
        echo "compiling build/bench/cgal_dt (CGAL) ..."
        g++ -O2 -DNDEBUG -o "$B/cgal_dt" scripts/bench/tools/cgal_dt.cpp -lgmp -lmpfr 2> "$B/cgal_dt.log" \
            || echo "skip CGAL: compilation failed (see build/bench/cgal_dt.log)"
    fi
    [ -x "$B/cgal_dt" ] && HAVE_CGAL=1
else
    echo "skip CGAL: libcgal-dev or g++ not installed"
fi

num() { python3 -c "print(int(float('$1')))"; }

RES=$W/results.tsv
: > "$RES"
echo "memory state before each run: MEMSTATE=$MEMSTATE (scripts/bench/tools/memstate.sh)"
echo "load before: $(uptime)"
inputs=()
for s in $UNI; do inputs+=("uniform:$s"); done
for s in $OTH; do inputs+=("grid:$s" "clusters:$s"); done
for spec in "${inputs[@]}"; do
    kind=${spec%%:*}
    n=$(num "${spec#*:}")
    in=$W/$kind-$n.txt
    [ -s "$in" ] || "$PDT" gen "$kind" "$n" --seed 1 -o "$in" || exit 1
    echo "measuring $kind $n ..."
    for ((r = 1; r <= RUNS; r++)); do
        # a new output each run: replacing the last one would add its unlink to
        # the write phase (0.2 s for the 1.5 GB of 3*10^7 points here)
        rm -f "$W/out.tri"
        warm_mb=$((n * 150 / 1000000 + 64)) # pdt's 62-84 bytes per point, the output's pages, room
        memstate_prepare "$warm_mb"
        s0=$(steal_now)
        "$TIME" -f '%M %U %S' -o "$W/time.out" "$PDT" triangulate "$in" -o "$W/out.tri" --stats \
            2> "$W/run.err" > /dev/null || { echo "  pdt failed: $(tail -2 "$W/run.err")"; exit 1; }
        steal=$(awk "BEGIN { print $(steal_now) - $s0 }")
        stats=$(grep '^{' "$W/run.err" | tail -1)
        kib=$(tail -1 "$W/time.out" | awk '{print $1}')
        cpu=$(tail -1 "$W/time.out" | awk '{print $2 + $3}')
        cg=-
        if [ $HAVE_CGAL = 1 ]; then
            memstate_prepare $((warm_mb * 2)) # CGAL holds more per point
            cg=$("$B/cgal_dt" "$in" | python3 -c 'import json,sys; print(json.load(sys.stdin)["build"])') || cg=-
        fi
        printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$kind" "$n" "$kib" "$cpu" "$cg" "$steal" "$stats" >> "$RES"
    done
done
rm -f "$W/out.tri" "$W/time.out" "$W/run.err"
echo "load after:  $(uptime)"

python3 - "$RES" "$RUNS" <<'PY'
import json, statistics, sys
from collections import OrderedDict
rows = OrderedDict()
for line in open(sys.argv[1]):
    kind, n, kib, cpu, cg, steal, st = line.rstrip("\n").split("\t", 6)
    rows.setdefault((kind, int(n)), []).append((int(kib), None if cg == "-" else float(cg), json.loads(st), float(cpu), float(steal)))
ph = ["read", "sort", "kernel", "canonical", "write", "total"]
print()
print(f"pdt triangulate IN -o OUT.tri --stats, per phase (medians of {sys.argv[2]} run(s)); CGAL insert in the same run")
hdr = f"{'input':<9} {'n':>10} " + " ".join(f"{p:>9}" for p in ph) + f" {'cpu s':>7} {'CGAL':>8} {'(s+k)/CGAL':>10} {'peak B/pt':>9} {'steal s':>7}"
print(hdr)
print("-" * len(hdr))
for (kind, n), r in rows.items():
    sec = {p: statistics.median(x[2]["seconds"][p] for x in r) for p in ph}
    kib = max(x[0] for x in r)
    cgs = [x[1] for x in r if x[1] is not None]
    cg = statistics.median(cgs) if cgs else None
    ratio = (sec["sort"] + sec["kernel"]) / cg if cg else None
    cpu = statistics.median(x[3] for x in r)
    print(f"{kind:<9} {n:>10} " + " ".join(f"{sec[p]:>9.3f}" for p in ph) + f" {cpu:>7.2f}" +
          (f" {cg:>8.3f} {ratio:>10.2f}" if cg else f" {'-':>8} {'-':>10}") + f" {kib * 1024 / n:>9.1f}" +
          f" {max(x[4] for x in r):>7.2f}")
    print(f"{'  ns/pt':<20} " + " ".join(f"{sec[p] * 1e9 / n:>9.1f}" for p in ph) + f" {'':>7}" +
          (f" {cg * 1e9 / n:>8.1f}" if cg else f" {'-':>8}"))
STEAL_OK = 0.05  # seconds the host may take from a run that still counts as undisturbed
def per_point(r, n):
    """Each phase's median ns per point over the runs r (None when r is empty)."""
    return {p: statistics.median(x[2]["seconds"][p] for x in r) * 1e9 / n for p in ph} if r else None
def sci(n):
    """10^6, 3*10^7, ..."""
    e = len(str(n)) - 1
    m = n // 10 ** e
    return (f"{m}*" if m != 1 else "") + f"10^{e}" if n == m * 10 ** e else str(n)
uni = sorted(n for (kind, n) in rows if kind == "uniform")
pairs = [(a, b) for a, b in ((1000000, 10000000), (10000000, 30000000)) if a in uni and b in uni]
if pairs:
    print()
    print("growth of the cost per point (issue 11's goal: every phase within 1.15x), uniform points:")
    for a, b in pairs:
        for label, keep in (("all runs", lambda x: True),
                            (f"runs that lost at most {STEAL_OK} s to the host", lambda x: x[4] <= STEAL_OK)):
            ra = [x for x in rows[("uniform", a)] if keep(x)]
            rb = [x for x in rows[("uniform", b)] if keep(x)]
            pa, pb = per_point(ra, a), per_point(rb, b)
            head = f"  {sci(a)} -> {sci(b)}, {label} ({len(ra)} and {len(rb)}):"
            if not pa or not pb:
                print(head + " none")
                continue
            worst = max((p for p in ph if p != "total"), key=lambda p: pb[p] / pa[p])
            print(head + " " + ", ".join(f"{p} {pb[p] / pa[p]:.2f}x" for p in ph if p != "total") +
                  f"; the largest: {worst}")
print()
print("seconds per phase from --stats (wall; read: text parse; write: the .tri file, a new one each run);")
print("ns/pt: the same per")
print("input point; cpu s: the process's user + system seconds (both threads: the prefault thread's")
print("included); CGAL: Delaunay_triangulation_2::insert of the range (s, then ns/pt); (s+k)/CGAL:")
print("pdt sort + kernel over CGAL's insert (below 1: pdt faster); peak: max RSS / n (time -f %M);")
print("steal s: the most CPU seconds the host took from this VM during one of the row's pdt runs;")
print("growth: median ns per point at the larger n over the same at the smaller (all runs, then")
print("only the runs the host took at most 0.05 s from: a run it took from loses up to twice that).")
PY
