#!/bin/bash
# pdt on a simulated cluster (scripts/simulate.sh: bin/smpi/pdt under
# SimGrid's smpirun, docs/simulation.md): 256 simulated ranks on a small
# input write the plain run's bytes (every rank pwrites its block into the
# one process's file), on every family of pdt gen and with either
# partition, without PDT_MPI=1 (pdt sees smpirun by itself), with
# --stats saying "simulated": true and 256 ranks; more ranks than points
# work; 64 ranks, whose exchanges go direct, and merges shared along
# their seams give the same bytes; --trace
# writes one file per rank (256 of them) that `pdt trace check` accepts;
# `make simulate`'s first row of a table is the median of three runs.
# Builds bin/smpi/pdt if it is missing.
source "$(dirname "$0")/lib.sh"
SIM=$ROOT/scripts/simulate.sh
if ! command -v smpirun > /dev/null; then
    fail smpirun_available "smpirun not found (make deps installs libsimgrid-dev)"
    summary; exit
fi
if [ ! -f "$ROOT/bin/smpi/pdt" ]; then
    make -C "$ROOT" -s smpi-build > "$TMP/make.log" 2>&1 ||
        { fail smpi_build "$(tail -3 "$TMP/make.log")"; summary; exit; }
fi
cd "$TMP"
unset PDT_MPI

# sim NAME P OUT-FILE ARGS...: simulate.sh -np P -- triangulate ARGS (3 minutes at most)
sim() {
    local name=$1 np=$2
    shift 2
    timeout 300 "$SIM" -np "$np" -- triangulate "$@" > "$name.out" 2> "$name.err"
}

"$PDT" gen uniform 1200 -o u.txt
"$PDT" triangulate u.txt -o plain.ele
if sim p256 256 u.txt -o sim.ele --stats; then
    if cmp -s plain.ele sim.ele; then ok smpi_256_ranks_same_bytes_as_plain
    else fail smpi_256_ranks_same_bytes_as_plain "output differs from the plain run"; fi
    if grep -q '"ranks": 256,' p256.err && grep -q '"simulated": true' p256.err; then
        ok smpi_stats_say_simulated_256_ranks
    else
        fail smpi_stats_say_simulated_256_ranks "$(head -c 300 p256.err)"
    fi
    if ! grep -q '"write": 0.000000' p256.err && grep -q '"merge_bytes"' p256.err; then
        ok smpi_stats_have_parallel_figures
    else
        fail smpi_stats_have_parallel_figures "$(head -c 300 p256.err)"
    fi
    # total: the slowest rank's start to the output in place, so at least
    # every rank's phases one after the other (the figures' gathering after
    # that is not in it)
    if python3 - p256.err <<'PY'
import json, sys
t = open(sys.argv[1]).read()
s = json.JSONDecoder().raw_decode(t[t.index('{"command"'):])[0]
tot = s["seconds"]["total"]
most = max(sum(r["seconds"].values()) for r in s["per_rank"])
assert most > 0 and most <= tot + 1e-6, (most, tot)
PY
    then ok smpi_total_covers_every_rank_phases
    else fail smpi_total_covers_every_rank_phases "$(head -c 300 p256.err)"; fi
else
    fail smpi_256_ranks_same_bytes_as_plain "exit $?: $(head -3 p256.err)"
fi

# every family of pdt gen at 256 ranks, both partitions in turn: the plain
# run's bytes (ties, duplicates, collinear and cocircular points at scale)
part=strips
for fam in uniform grid circle circle-round parabola clusters collinear duplicates column; do
    "$PDT" gen "$fam" 300 --seed 3 -o "f-$fam.txt"
    "$PDT" triangulate "f-$fam.txt" -o "f-$fam.ele"
    if sim "f-$fam" 256 "f-$fam.txt" -o "f-$fam-sim.ele" --partition "$part" &&
        cmp -s "f-$fam.ele" "f-$fam-sim.ele"; then
        ok "smpi_256_ranks_${fam}_${part}_same_bytes"
    else
        fail "smpi_256_ranks_${fam}_${part}_same_bytes" "$(head -3 "f-$fam.err")"
    fi
    if [ "$part" = strips ]; then part=bisect; else part=strips; fi
done

# merges shared along their seams on 256 simulated ranks (pieces of 10
# points forced): the plain run's bytes, shared merges counted; and the
# circle, where a shared merge's pieces never hold the whole selection and
# the merge rank finishes it alone
for fam in uniform circle; do
    "$PDT" gen "$fam" 1200 --seed 4 -o "s-$fam.txt"
    "$PDT" triangulate "s-$fam.txt" -o "s-$fam.ele"
    if PDT_SHARE_PIECE=10 sim "s-$fam" 256 "s-$fam.txt" -o "s-$fam-sim.ele" --stats &&
        cmp -s "s-$fam.ele" "s-$fam-sim.ele" &&
        ! grep -q '"shared_merges": 0,' "s-$fam.err"; then
        ok "smpi_256_ranks_shared_merges_${fam}_same_bytes"
    else
        fail "smpi_256_ranks_shared_merges_${fam}_same_bytes" \
            "$(grep -o '"shared_merges[^,]*, "shared_merges_done_alone": [0-9]*' "s-$fam.err"; head -3 "s-$fam.err")"
    fi
done

# uniform NAME P N SEED EXT: N uniform points, the plain run and P simulated
# ranks; true when they wrote the same bytes
uniform() {
    local name=$1 np=$2 n=$3 seed=$4 ext=$5
    "$PDT" gen uniform "$n" --seed "$seed" -o "$name.txt"
    "$PDT" triangulate "$name.txt" -o "$name.$ext"
    sim "$name" "$np" "$name.txt" -o "$name-sim.$ext" && cmp -s "$name.$ext" "$name-sim.$ext"
}

# 64 ranks, below PDT_COMM_HOPS_MIN: every exchange direct, in windows of
# the pairwise schedule (src/par/comm_mpi.c)
if uniform mid 64 30000 5 tri; then ok smpi_64_ranks_direct_exchanges_same_bytes
else fail smpi_64_ranks_direct_exchanges_same_bytes "$(head -3 mid.err)"; fi

# more ranks than points: 64 ranks, 20 points (most ranks get none)
if uniform few 64 20 7 ele; then ok smpi_more_ranks_than_points
else fail smpi_more_ranks_than_points "$(head -3 few.err)"; fi

# a simulated trace: one file per rank, simulated clock, accepted by the checker
"$PDT" gen clusters 600 -o c.txt
"$PDT" triangulate c.txt -o c.ele
if sim tr 256 c.txt -o c-sim.ele --partition strips --trace run && cmp -s c.ele c-sim.ele &&
    [ "$(ls run/rank-*.trace | wc -l)" = 256 ] && "$PDT" trace check run > check.out 2>&1; then
    ok smpi_trace_256_ranks_checks
else
    fail smpi_trace_256_ranks_checks "$(head -3 tr.err) $(tail -3 check.out 2>/dev/null)"
fi

# make simulate's tables (scripts/simulate-scaling.sh) on tiny sizes: the
# first row of each is the run with the median total of its --base-runs
# runs, and the line under the table lists them
"$ROOT/scripts/simulate-scaling.sh" --sizes 2e3 --ps "1 4" --weak-ps "1 2" --per-rank 500 \
    --base-runs 3 > scaling.out 2> scaling.err
if python3 - scaling.out <<'EOF'
import re, sys
text = open(sys.argv[1]).read()
tables = re.findall(r"\n\| 1 \| \d+ \|(?:[^|\n]*\|){6}([^|\n]*)\|.*?\n\n"
                    r"The first row is the run with the median total of 3 \(totals ([^)]*) s\)",
                    text, re.S)
assert len(tables) == 2, text
for row_total, totals in tables:
    t = sorted(float(x) for x in totals.split(","))
    assert len(t) == 3 and abs(float(row_total) - t[1]) < 1e-9, (row_total, totals)
EOF
then ok simulate_scaling_base_row_is_median_of_three
else fail simulate_scaling_base_row_is_median_of_three "$(tail -5 scaling.err) $(tail -12 scaling.out)"; fi

# a wrong platform is a usage error
"$SIM" -np 2 --platform no-such-platform -- triangulate u.txt -o x.ele 2> bad.err
rc=$?
if [ "$rc" = 2 ] && grep -q "no such platform" bad.err; then ok smpi_unknown_platform_usage_error
else fail smpi_unknown_platform_usage_error "exit $rc: $(cat bad.err)"; fi
summary
