#!/bin/bash
# make simulate: strong and weak scaling of pdt on a simulated cluster
# (scripts/simulate.sh; docs/simulation.md explains the figures).
#
#   scripts/simulate-scaling.sh [--platform NAME|FILE] [--sizes "1e6 1e7 1e8"]
#       [--ps "1 2 4 ... 1024"] [--weak-ps "1 2 4 ... 1024"] [--per-rank 1e5]
#       [--partition strips|bisect] [--base-runs 3] [--no-strong] [--no-weak]
#       [--keep DIR]
#
# Strong scaling: for each n of --sizes uniform points (`pdt gen uniform`),
# one simulated run per P of --ps; weak scaling: --per-rank points per rank
# (n = P * per-rank) for each P of --weak-ps.  Each run is
#   scripts/simulate.sh -np P --platform PLATFORM -- triangulate IN -o OUT.tri --stats
# and prints one row of a Markdown table (what docs/simulation.md shows):
#   P, simulated seconds of each phase (read, partition, local, merge, order,
#   write: the largest over the ranks), total (simulated, start to figures),
#   speedup (total at the table's first P, normally 1, / total; weak: the
#   efficiency total(first P) / total), efficiency (speedup / P), critical
#   path (the longest chain of one rank's compute and waits from the
#   partition to the order, simulated), merge bytes (all merge steps), the
#   largest border set (points in the largest merge), and the simulation's
#   own wall seconds, CPU seconds (user + system: what the wall would be on
#   an idle core) and peak memory (GNU time: the one process of all ranks).
# The first P of a table (normally 1) is the base of its speedups: it runs
# --base-runs times and its row is the run with the median total (a one-rank
# run of 10^7 points took from 5.0 to 6.7 simulated seconds from one
# `make simulate` to the next on one host); the line under the table gives
# all their totals.  --partition is passed to pdt as is.  Inputs and outputs
# live in a temporary folder (--keep DIR keeps them there).  The platform and
# the load of the machine (uptime) head the output.
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
platform=cluster-10g sizes="1e6 1e7 1e8" per_rank=1e5 partition="" keep="" base_runs=3
ps="1 2 4 8 16 32 64 128 256 512 1024" weak_ps=$ps strong=1 weak=1
while [ $# -gt 0 ]; do
    case "$1" in
        --platform) platform=$2; shift 2 ;;
        --sizes) sizes=$2; shift 2 ;;
        --ps) ps=$2; shift 2 ;;
        --weak-ps) weak_ps=$2; shift 2 ;;
        --per-rank) per_rank=$2; shift 2 ;;
        --partition) partition=$2; shift 2 ;;
        --base-runs) base_runs=$2; shift 2 ;;
        --no-strong) strong=0; shift ;;
        --no-weak) weak=0; shift ;;
        --keep) keep=$2; shift 2 ;;
        -h|--help) sed -n '2,/^set -u/s/^# \{0,1\}//p' "$0" | sed '$d'; exit 0 ;;
        *) echo "simulate-scaling.sh: unknown option '$1'" >&2; exit 2 ;;
    esac
done
PDT=$ROOT/bin/pdt
[ -x "$PDT" ] && [ -f "$ROOT/bin/smpi/pdt" ] || { echo "simulate-scaling.sh: make rel-all smpi first" >&2; exit 2; }
if [ -n "$keep" ]; then W=$keep; mkdir -p "$W"; else
    W=$(mktemp -d "${TMPDIR:-/tmp}/pdt-scaling.XXXXXX"); trap 'rm -rf "$W"' EXIT
fi
int() { awk -v x="$1" -v y="${2:-1}" 'BEGIN { printf "%.0f", x * y }'; }
popt=()
[ -n "$partition" ] && popt=(--partition "$partition")

pfile=$platform
case "$pfile" in */*|*.xml) ;; *) pfile=$ROOT/assets/platforms/$pfile.xml ;; esac
echo "Platform: $platform: $(tr '\n' ' ' < "$pfile" | grep -o '<cluster[^>]*' |
    grep -o ' \(radical\|speed\|bw\|lat\)="[^"]*"' | tr -d '\n')"
echo "Host speed: smpi/host-speed = the platform's node speed (a CPU second here is a simulated second)"
[ -n "$partition" ] && echo "Partition: $partition"
echo "Load before: $(uptime | sed 's/.*load/load/')"

# run N P NAME: one simulated run; prints the JSON line and "wall rss" to NAME.{json,time}
run() {
    local n=$1 p=$2 name=$3 in="$W/uniform-$1.txt"
    [ -s "$in" ] || "$PDT" gen uniform "$n" -o "$in" || return 1
    /usr/bin/time -f "%e %M %U %S" -o "$W/$name.time" "$ROOT/scripts/simulate.sh" -np "$p" \
        --platform "$platform" -- triangulate "$in" -o "$W/$name.tri" --stats "${popt[@]}" \
        2> "$W/$name.err" > /dev/null
    local rc=$?
    grep '^{"command"' "$W/$name.err" | tail -1 > "$W/$name.json"
    rm -f "$W/$name.tri"
    [ $rc = 0 ] && [ -s "$W/$name.json" ]
}

# run_base N P NAME: run N P NAME.1 ... NAME.$base_runs, NAME the one with the
# median total; their totals to NAME.totals
run_base() {
    local n=$1 p=$2 name=$3 k ok=()
    for k in $(seq "$base_runs"); do run "$n" "$p" "$name.$k" && ok+=("$name.$k"); done
    [ ${#ok[@]} -gt 0 ] || return 1
    python3 - "$W" "$name" "${ok[@]}" <<'EOF'
import json, shutil, sys
w, name, runs = sys.argv[1], sys.argv[2], sys.argv[3:]
tot = {r: json.load(open(f"{w}/{r}.json"))["seconds"]["total"] for r in runs}
order = sorted(runs, key=tot.get)
mid = order[(len(order) - 1) // 2]
for ext in ("json", "time", "err"):
    shutil.copy(f"{w}/{mid}.{ext}", f"{w}/{name}.{ext}")
with open(f"{w}/{name}.totals", "w") as f:
    f.write(", ".join(f"{tot[r]:.4f}" for r in runs) + "\n")
EOF
}

# table TITLE KIND NAMES...: the Markdown table of the named runs (KIND strong|weak)
table() {
    python3 - "$W" "$@" <<'EOF'
import json, sys
w, title, kind, names = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
print(f"\n{title}\n")
print("| P | n | read | partition | local | merge | order | write | total | "
      + ("speedup | efficiency" if kind == "strong" else "weak efficiency | time / time(P=first)")
      + " | critical path | merge bytes | largest border set | sim wall s | sim CPU s | sim MiB |")
print("|" + "---|" * 17)
base = None
for name in names:
    try:
        j = json.load(open(f"{w}/{name}.json"))
        t = open(f"{w}/{name}.time").read().split()
        wall, rss = t[0], t[1]
        cpu = float(t[2]) + float(t[3]) if len(t) >= 4 else float("nan")
    except Exception:
        print(f"| {name} | failed |" + " |" * 16)
        continue
    s, par = j["seconds"], j.get("parallel", {})
    tot = s["total"]
    base = base or tot
    p = j["ranks"]
    crit = par.get("critical_path_s", s["partition"] + s["local"] + s["order"])
    if kind == "strong":
        a, b = f"{base / tot:.2f}", f"{base / tot / p:.2f}"
    else:
        a, b = f"{base / tot:.2f}", f"{tot / base:.2f}"
    print(f"| {p} | {j['n']} | " + " | ".join(f"{s[k]:.4f}" for k in
          ("read", "partition", "local", "merge", "order", "write"))
          + f" | {tot:.4f} | {a} | {b} | {crit:.4f} | {par.get('merge_bytes', 0)} | "
          f"{par.get('largest_border_set', 0)} | {float(wall):.1f} | {cpu:.1f} | {int(rss) // 1024} |")
try:
    runs = open(f"{w}/{names[0]}.totals").read().strip()
    print(f"\nThe first row is the run with the median total of {len(runs.split(','))} "
          f"(totals {runs} s).")
except OSError:
    pass
EOF
}

if [ "$strong" = 1 ]; then
    for n in $sizes; do
        N=$(int "$n"); names=()
        first=1
        for p in $ps; do
            r=run; [ $first = 1 ] && r=run_base; first=0
            $r "$N" "$p" "strong-$N-$p" || echo "simulate-scaling.sh: n=$N P=$p failed (see $W/strong-$N-$p.err)" >&2
            names+=("strong-$N-$p")
        done
        table "Strong scaling, n = $N uniform points (simulated seconds)" strong "${names[@]}"
        rm -f "$W/uniform-$N.txt"
    done
fi
if [ "$weak" = 1 ]; then
    names=() first=1
    for p in $weak_ps; do
        N=$(int "$per_rank" "$p")
        r=run; [ $first = 1 ] && r=run_base; first=0
        $r "$N" "$p" "weak-$p" || echo "simulate-scaling.sh: weak P=$p failed (see $W/weak-$p.err)" >&2
        names+=("weak-$p")
        rm -f "$W/uniform-$N.txt"
    done
    table "Weak scaling, $(int "$per_rank") uniform points per rank (simulated seconds)" weak "${names[@]}"
fi
echo
echo "Load after: $(uptime | sed 's/.*load/load/')"
