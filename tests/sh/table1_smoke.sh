#!/bin/bash
# make table1 still runs end to end (tiny sizes, one run each): the table
# has its rows, phase columns and system and stolen seconds, and the
# merge-traffic and peak-memory lines are there.  No figure is asserted.
source "$(dirname "$0")/lib.sh"
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi
out=$TMP/table1.txt
if ! TABLE1_DIR=$TMP/t1 SIZES=3000 PS="1 2" RUNS=1 timeout 300 "$ROOT/scripts/table1.sh" > "$out" 2>&1; then
    fail table1_runs "$(tail -5 "$out")"; summary; exit
fi
ok table1_runs
check table1_header grep -q '| n | run | wall s | speedup | read s | partition s | local s | merge s | order s | write s | sys s | steal s |' "$out"
# every row has its system and stolen seconds (numbers: the host's steal counter was read)
check table1_steal_cells test "$(grep -cE '^\| 3,000 \| .* \| [0-9]+\.[0-9]{2} \| [0-9]+\.[0-9]{2}( \([0-9]+ of [0-9]+\))? \| [^|]*\|$' "$out")" -eq \
    "$(grep -c '^| 3,000 |' "$out")"
check table1_rows test "$(grep -cE '^\| 3,000 \| (plain|mpirun -np [12]) \|' "$out")" -eq 3
if [ "$(getconf _NPROCESSORS_ONLN)" -ge 2 ]; then
    check table1_ceiling_row grep -qE '^\| 3,000 \| ceiling: 2 plain runs on n/2 at once \| [0-9.]+ \| [0-9.]+ \|' "$out"
fi
check table1_merge_and_memory grep -qE 'merge traffic at P = 2: .*% of the input; peak memory, largest rank at P = 2' "$out"
check table1_uptime grep -q '^uptime after:' "$out"
summary
