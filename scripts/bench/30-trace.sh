#!/bin/bash
# Benchmark section: the cost of tracing and of reading traces.
#  * `pdt triangulate` on 10^6 uniform points with tracing off, level 1 and
#    level 2: median wall time of REPS runs, ratio level1/off (goal <= 1.5),
#    events, bytes and bytes per event;
#  * time to open and iterate a trace of >= 10^7 events (`pdt trace info`
#    reads every event of every rank through the cursor API), and the time of
#    `pdt trace check` on it.
# Prints figures only; fails only if a program fails.
set -u
cd "$(dirname "$0")/../.."
PDT=${PDT:-bin/pdt}
REPS=${REPS:-5}
N=${N:-1000000}
W=build/bench/trace
rm -rf "$W"
mkdir -p "$W"
pts=$W/uniform-$N.txt
"$PDT" gen uniform "$N" -o "$pts" || exit 1

calc() { awk "BEGIN {printf \"%.6f\\n\", $1}"; }
# median of the numbers on stdin
median() { sort -g | awk '{a[NR]=$1} END {if (NR%2) print a[(NR+1)/2]; else printf "%.6f\n", (a[NR/2]+a[NR/2+1])/2}'; }
# wall seconds of one run of the command
seconds() {
    local t0 t1
    t0=$(date +%s.%N)
    "$@" >/dev/null 2>"$W/stderr" || { echo "failed: $*" >&2; cat "$W/stderr" >&2; return 1; }
    t1=$(date +%s.%N)
    awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.6f\n", b - a}'
}

declare -A med
for level in off 1 2; do
    : >"$W/times-$level"
    for ((i = 0; i < REPS; i++)); do
        if [ "$level" = off ]; then
            s=$(seconds "$PDT" triangulate "$pts" -o "$W/out.tri") || exit 1
        else
            s=$(seconds "$PDT" triangulate "$pts" -o "$W/out.tri" --trace "$W/run-$level" \
                --trace-level "$level") || exit 1
        fi
        echo "$s" >>"$W/times-$level"
    done
    med[$level]=$(median <"$W/times-$level")
done

printf 'triangulate %d uniform points, median of %d runs:\n' "$N" "$REPS"
printf '  %-9s %9s %12s %14s %11s\n' tracing seconds events bytes bytes/event
printf '  %-9s %9.3f\n' off "${med[off]}"
for level in 1 2; do
    ev=$("$PDT" trace info "$W/run-$level" | awk '$1 == "0" && NF >= 5 {print $2; exit}')
    by=$(du -cb "$W/run-$level"/rank-*.trace | tail -1 | cut -f1)
    printf '  %-9s %9.3f %12s %14s %11.2f\n' "level $level" "${med[$level]}" "$ev" "$by" \
        "$(calc "$by / $ev")"
done
printf '  ratio level 1 / off = %.2f (goal <= 1.5), level 2 / off = %.2f\n' \
    "$(calc "${med[1]} / ${med[off]}")" "$(calc "${med[2]} / ${med[off]}")"

# A trace of >= 10^7 events: level 1 on 2*10^6 points gives about 5 events per point.
big=$W/uniform-2000000.txt
"$PDT" gen uniform 2000000 -o "$big" || exit 1
"$PDT" triangulate "$big" -o "$W/big.tri" --trace "$W/run-big" --trace-level 1 2>/dev/null || exit 1
rm -f "$big" "$W/big.tri"
ev=$("$PDT" trace info "$W/run-big" | awk '$1 == "0" && NF >= 5 {print $2; exit}')
: >"$W/times-read"
for ((i = 0; i < 3; i++)); do seconds "$PDT" trace info "$W/run-big" >>"$W/times-read" || exit 1; done
rd=$(median <"$W/times-read")
ck=$(seconds "$PDT" trace check "$W/run-big") || exit 1
printf 'open + iterate a trace of %s events (pdt trace info, median of 3): %.3f s = %.1f ns/event\n' \
    "$ev" "$rd" "$(calc "$rd * 1000000000 / $ev")"
printf 'pdt trace check on it (recomputes T* of 2*10^6 points): %.3f s\n' "$ck"
rm -rf "$W"
