#!/bin/bash
# Traced MPI runs: `pdt trace check` accepts them (final triangles = T*,
# merges pair up, sends match receives); the trace shows lift-ups at every
# rank and at the merge ranks, deferrals, discards, and exactly one merge step
# per pair of groups per level.  A traced run whose rank is killed leaves
# trace files that can still be read.
source "$(dirname "$0")/lib.sh"
PDT=$PDT_HOOKED  # injects faults (PDT_TEST_*)
cd "$TMP"
export OMPI_MCA_rmaps_base_oversubscribe=1
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi

"$PDT" gen uniform 400 --seed 2 -o u.txt
"$PDT" triangulate u.txt -o ref.tri
mpirun -np 4 "$PDT" triangulate u.txt -o p4.tri --trace run4 2> run4.err; rc=$?
if [ $rc -eq 0 ] && cmp -s ref.tri p4.tri; then ok traced_4_ranks_same_output
else fail traced_4_ranks_same_output "rc=$rc $(head -3 run4.err)"; fi

"$PDT" trace check run4 > check.out 2>&1; rc=$?
if [ $rc -eq 0 ]; then ok trace_check_4_ranks; else fail trace_check_4_ranks "$(cat check.out)"; fi

# lift-ups at each rank (local) ...
bad=
for r in 0 1 2 3; do
    k=$("$PDT" trace dump run4 --rank $r --kind lift | wc -l)
    [ "$k" -gt 0 ] || bad="$bad rank$r:$k"
done
[ -z "$bad" ] && ok lift_ups_at_every_rank || fail lift_ups_at_every_rank "no lift-ups at$bad"
# ... and at the merge ranks, for the border sets
if grep -Eq '[0-9]+ local \+ [1-9][0-9]* merge lift-ups' check.out; then ok lift_ups_at_merge_ranks
else fail lift_ups_at_merge_ranks "$(cat check.out)"; fi

nd=$("$PDT" trace dump run4 --kind ra-defer | wc -l)
nx=$("$PDT" trace dump run4 --kind discard | wc -l)
nw=$("$PDT" trace dump run4 --kind discard | grep -c 'witness=[0-9]')
if [ "$nd" -gt 0 ] && [ "$nx" -gt 0 ] && [ "$nw" -gt 0 ]; then ok deferrals_and_discards
else fail deferrals_and_discards "ra-defer=$nd discard=$nx with witness=$nw"; fi

# an untraced merge counts its discards without looking them up: every
# rank's kept and discarded are the traced run's, on families that defer
# little or nearly everything, strips (4 ranks) and bisection (16)
counts() { sed -n 's/.*"per_rank": //p' "$1" | grep -o '"kept": [0-9]*, "discarded": [0-9]*'; }
bad=
for kind in uniform grid circle clusters; do
    "$PDT" gen $kind 600 --seed 3 -o k.txt
    for np in 4 16; do
        mpirun -np $np "$PDT" triangulate k.txt -o k1.tri --stats 2> k1.err
        mpirun -np $np "$PDT" triangulate k.txt -o k2.tri --stats --trace runk 2> k2.err
        a=$(counts k1.err) b=$(counts k2.err)
        nx=$("$PDT" trace dump runk --kind discard | wc -l)
        sum=$(echo "$a" | awk '{s += $4} END {print s + 0}')
        if [ -z "$a" ] || [ "$a" != "$b" ] || [ "$nx" != "$sum" ] || ! cmp -s k1.tri k2.tri; then
            bad="$bad $kind/$np(discards traced $nx, counted $sum)"
        fi
        rm -rf runk
    done
done
[ -z "$bad" ] && ok untraced_discards_counted || fail untraced_discards_counted "differ:$bad"

# one merge step per pair per level: P = 4 -> (0|1) at 1, (2|3) at 3, (01|23) at 2
"$PDT" trace dump run4 --kind merge-begin | sed 's/.*merge-begin //' | sort > merges.txt
printf '%s\n' 'level=0 left=0 right=1 end=2 at=1' 'level=0 left=2 right=3 end=4 at=3' \
    'level=1 left=0 right=2 end=4 at=2' | sort > want.txt
if cmp -s merges.txt want.txt; then ok one_merge_per_pair_per_level
else fail one_merge_per_pair_per_level "$(cat merges.txt)"; fi

# P = 5 (a lone group passes level 0 and 1), P > n, and a collinear input
mpirun -np 5 "$PDT" triangulate u.txt -o p5.tri --trace run5 2> /dev/null
nm=$("$PDT" trace dump run5 --kind merge-begin | wc -l)
if cmp -s ref.tri p5.tri && "$PDT" trace check run5 > /dev/null 2>&1 && [ "$nm" -eq 4 ]; then
    ok trace_check_5_ranks
else fail trace_check_5_ranks "merges=$nm $("$PDT" trace check run5 2>&1)"; fi
printf '0 0\n5 1\n2 7\n' > three.txt
mpirun -np 6 "$PDT" triangulate three.txt -o three.tri --trace run6 2> /dev/null
if [ "$(wc -l < three.tri)" -eq 1 ] && "$PDT" trace check run6 > /dev/null 2>&1; then
    ok trace_check_more_ranks_than_points
else fail trace_check_more_ranks_than_points "$("$PDT" trace check run6 2>&1)"; fi
seq 0 59 | awk '{print $1, 3 * $1}' > line.txt
mpirun -np 3 "$PDT" triangulate line.txt -o line.tri --trace run3 2> /dev/null
if [ ! -s line.tri ] && "$PDT" trace check run3 > /dev/null 2>&1; then ok trace_check_collinear
else fail trace_check_collinear "$("$PDT" trace check run3 2>&1)"; fi

# level 2: the kernel's edges too
mpirun -np 2 "$PDT" triangulate u.txt -o l2.tri --trace runl2 --trace-level 2 2> /dev/null
ne=$("$PDT" trace dump runl2 --kind edge-add | wc -l)
if cmp -s ref.tri l2.tri && [ "$ne" -gt 0 ] && "$PDT" trace check runl2 > /dev/null 2>&1; then
    ok trace_level_2
else fail trace_level_2 "edge-add=$ne"; fi

# a rank killed in a traced run: no output; the trace files that exist open
"$PDT" gen uniform 3000 --seed 3 -o big.txt
PDT_TEST_SLEEP_BEFORE_MERGE=1:60 mpirun -np 2 "$PDT" triangulate big.txt -o killed.tri \
    --trace runk > /dev/null 2>&1 &
MPID=$!
victim=
for _ in $(seq 1 100); do
    for c in $(pgrep -P "$MPID" 2> /dev/null); do
        tr '\0' '\n' < "/proc/$c/environ" 2> /dev/null | grep -qx 'OMPI_COMM_WORLD_RANK=1' && victim=$c
    done
    [ -n "$victim" ] && break
    sleep 0.1
done
if [ -n "$victim" ]; then
    sleep 1
    kill -KILL "$victim"
    wait "$MPID"; rc=$?
    "$PDT" trace info runk > info.out 2>&1; irc=$?
    "$PDT" trace check runk > kcheck.out 2>&1; krc=$?
    if [ $rc -ne 0 ] && [ ! -e killed.tri ] && grep -q 'rank' info.out && [ $krc -ne 0 ]; then
        ok killed_traced_run_readable
    else fail killed_traced_run_readable "rc=$rc info=$irc check=$krc $(head -3 info.out)"; fi
else
    kill "$MPID" 2> /dev/null
    fail killed_traced_run_readable "rank 1 not found"
fi
summary
