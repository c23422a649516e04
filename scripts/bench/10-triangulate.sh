#!/bin/bash
# make bench, section 10: sequential `pdt triangulate` against other tools,
# all measured in the same run on the same inputs:
#   uniform 10^5 and 10^6 points in [0, 2^20)^2 and a 1000 x 1000 grid
#   (`pdt gen uniform|grid`), each run RUNS times (default 5; the other tools
#   OTHER_RUNS times, default 3) and the median taken.  BENCH_INPUTS="uniform-1e5"
#   picks a subset.
# Tools: pdt; qdelaunay (Qhull, "Qt i"); CGAL's Delaunay_triangulation_2
# (a small program of ours, tools/cgal_dt.cpp, compiled here into
# build/bench/); delaunator (npm package, installed here into build/bench/,
# run by tools/delaunator_run.mjs).  A tool that cannot be set up is skipped
# with a message.
# Columns: "compute" excludes reading the input (pdt: sort + kernel +
# canonical order from --stats; CGAL and delaunator: building the
# triangulation, timed inside the program); "wall" is the whole process
# (start, read, compute, and for pdt and qdelaunay writing the triangles to
# a file); "peak" is the maximum resident memory (/usr/bin/time).
# Ratios are tool / pdt: above 1 means pdt is faster.
set -u
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
B=$ROOT/build/bench
PDT=$ROOT/bin/pdt
RUNS=${RUNS:-5}
OTHER_RUNS=${OTHER_RUNS:-3}
mkdir -p "$B"
RES=$B/10-triangulate.tsv
: > "$RES"

[ -x "$PDT" ] || { echo "bin/pdt is missing: run make first"; exit 1; }
TIME=/usr/bin/time
[ -x "$TIME" ] || { echo "/usr/bin/time is missing (Debian package time)"; exit 1; }

# ---- inputs -------------------------------------------------------------------
declare -A GEN=( [uniform-1e5]="uniform 100000" [uniform-1e6]="uniform 1000000" [grid-1000x1000]="grid 1000000" )
INPUTS=${BENCH_INPUTS:-"uniform-1e5 uniform-1e6 grid-1000x1000"}
for name in $INPUTS; do
    if [ ! -s "$B/$name.txt" ]; then
        # shellcheck disable=SC2086
        "$PDT" gen ${GEN[$name]} --seed 1 -o "$B/$name.txt" || exit 1
    fi
    if [ ! -s "$B/$name.qh" ]; then
        { echo 2; wc -l < "$B/$name.txt"; cat "$B/$name.txt"; } > "$B/$name.qh"
    fi
done

# ---- tools --------------------------------------------------------------------
HAVE_QHULL=0; HAVE_CGAL=0; HAVE_DELAUNATOR=0
command -v qdelaunay > /dev/null && HAVE_QHULL=1 || echo "skip qdelaunay: not installed (qhull-bin)"
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
if command -v node > /dev/null && command -v npm > /dev/null; then
    if [ ! -f "$B/node_modules/delaunator/package.json" ]; then
        echo "installing delaunator into build/bench (npm) ..."
        [ -f "$B/package.json" ] || echo '{"name": "pdt-bench", "private": true}' > "$B/package.json"
        (cd "$B" && npm install --no-audit --no-fund delaunator > npm.log 2>&1) \
            || echo "skip delaunator: npm install failed (see build/bench/npm.log)"
    fi
    cp scripts/bench/tools/delaunator_run.mjs "$B/"
    [ -f "$B/node_modules/delaunator/package.json" ] && HAVE_DELAUNATOR=1
else
    echo "skip delaunator: node or npm not installed"
fi

# ---- measuring ------------------------------------------------------------------
# measure INPUT TOOL RUNS CMD... : run CMD RUNS times; record per run the
# wall seconds, the peak KiB and the in-program compute seconds (from the JSON
# line the tool prints on stdout or stderr, or "-").
measure() {
    local input=$1 tool=$2 runs=$3; shift 3
    local i
    for ((i = 1; i <= runs; i++)); do
        local t0 t1 rc
        t0=$(date +%s%N)
        "$TIME" -f '%M' -o "$B/time.out" "$@" > "$B/run.out" 2> "$B/run.err"
        rc=$?
        t1=$(date +%s%N)
        if [ $rc -ne 0 ]; then
            echo "  $tool on $input failed (exit $rc): $(tail -2 "$B/run.err")"
            return 1
        fi
        local compute
        compute=$(python3 - "$B/run.out" "$B/run.err" <<'PY'
import json, sys
for f in sys.argv[1:]:
    for line in open(f, errors="replace"):
        line = line.strip()
        if line.startswith("{"):
            d = json.loads(line)
            if "seconds" in d:
                s = d["seconds"]
                print("%.6f" % (s["sort"] + s["kernel"] + s["canonical"]))
            else:
                print("%.6f" % d["build"])
            sys.exit()
print("-")
PY
)
        printf '%s\t%s\t%s\t%s\t%s\n' "$input" "$tool" \
            "$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.6f", (b - a) / 1e9 }')" \
            "$(tail -1 "$B/time.out")" "$compute" >> "$RES"
    done
}

for name in $INPUTS; do
    echo "measuring $name ..."
    measure "$name" pdt "$RUNS" "$PDT" triangulate "$B/$name.txt" --stats
    [ $HAVE_CGAL = 1 ] && measure "$name" cgal "$OTHER_RUNS" "$B/cgal_dt" "$B/$name.txt"
    [ $HAVE_DELAUNATOR = 1 ] && measure "$name" delaunator "$OTHER_RUNS" \
        node --max-old-space-size=8192 "$B/delaunator_run.mjs" "$B/$name.txt"
    [ $HAVE_QHULL = 1 ] && measure "$name" qdelaunay "$OTHER_RUNS" sh -c 'qdelaunay Qt i < "$1"' sh "$B/$name.qh"
done
rm -f "$B/run.out" "$B/run.err" "$B/time.out"

# ---- the table ------------------------------------------------------------------
python3 - "$RES" "$RUNS" "$OTHER_RUNS" <<'PY'
import statistics, sys
from collections import defaultdict
rows = defaultdict(list)
order = []
for line in open(sys.argv[1]):
    inp, tool, wall, kib, comp = line.rstrip("\n").split("\t")
    if (inp, tool) not in rows:
        order.append((inp, tool))
    rows[(inp, tool)].append((float(wall), int(kib), None if comp == "-" else float(comp)))
def med(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None
print()
print(f"pdt triangulate vs other tools (medians: pdt of {sys.argv[2]} runs, others of {sys.argv[3]})")
hdr = f"{'input':<16} {'tool':<11} {'compute s':>10} {'wall s':>8} {'peak MiB':>9} {'compute/pdt':>12} {'wall/pdt':>9}"
print(hdr)
print("-" * len(hdr))
for inp, tool in order:
    r = rows[(inp, tool)]
    c, w, m = med([x[2] for x in r]), med([x[0] for x in r]), max(x[1] for x in r) / 1024
    p = rows.get((inp, "pdt"))
    pc, pw = (med([x[2] for x in p]), med([x[0] for x in p])) if p else (None, None)
    fmt = lambda v, f: (f % v) if v is not None else "-"
    rc = c / pc if (c is not None and pc) else None
    rw = w / pw if pw else None
    print(f"{inp:<16} {tool:<11} {fmt(c, '%.3f'):>10} {w:>8.3f} {m:>9.1f} {fmt(rc, '%.2f'):>12} {fmt(rw, '%.2f'):>9}")
print()
print("compute: without reading the input (pdt: sort + kernel + canonical order; CGAL,")
print("delaunator: building the triangulation); qdelaunay reports no split.  wall: the whole")
print("process, including reading the text input (and, for pdt and qdelaunay, writing the")
print("triangles to a file).  peak: maximum resident memory.  ratio > 1: pdt is faster.")
PY
