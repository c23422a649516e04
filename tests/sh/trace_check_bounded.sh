#!/bin/bash
# pdt trace check in bounded memory: over its budget (--mem) it finds the
# distinct points by a sort on disk and certifies T* side by side on disk
# instead of recomputing it, so its own memory (RssAnon, sampled from /proc)
# stays about the budget whatever the run's size (at most twice it here, for
# a run of 50000 points and one of four times as many, where the check in
# memory takes ten times that).  The same verdict as the check in memory.
# (Release build only: the sanitizers' shadow memory would be measured.)
source "$(dirname "$0")/lib.sh"

# peak_anon CMD...: the largest RssAnon (KiB) of CMD; its output goes to
# $TMP/peak.out, its status to $TMP/peak.rc
peak_anon() {
    "$ROOT/scripts/bench/tools/anon_peak.sh" "$TMP/peak.out" "$@"
    echo $? >"$TMP/peak.rc"
}

for n in 50000 200000; do
    "$PDT" gen uniform $n -o "$TMP/u$n.txt" &&
        "$PDT" triangulate "$TMP/u$n.txt" -o "$TMP/u$n.tri" --trace "$TMP/run$n" >/dev/null ||
        fail "record_$n"
done

small=$(peak_anon "$PDT" trace check "$TMP/run50000" --mem 2M)
[ "$(cat "$TMP/peak.rc")" = 0 ] && grep -q "= T\*.*certified side by side on disk" "$TMP/peak.out" &&
    ok certified_small || fail certified_small "$(cat "$TMP/peak.out")"
big=$(peak_anon "$PDT" trace check "$TMP/run200000" --mem 2M)
[ "$(cat "$TMP/peak.rc")" = 0 ] && grep -q "= T\*.*certified side by side on disk" "$TMP/peak.out" &&
    ok certified_big || fail certified_big "$(cat "$TMP/peak.out")"
# the budget, a few fixed buffers (the sorted runs' stdio buffers, a decoded
# block of events) and the C library's own
echo "# peak RssAnon: $small KiB (50000 points), $big KiB (200000 points), --mem 2M"
if [ "$small" -le $((4 * 1024)) ] && [ "$big" -le $((4 * 1024)) ]; then
    ok check_memory_bounded
else
    fail check_memory_bounded "peak RssAnon $small KiB (50000 points), $big KiB (200000 points), --mem 2M"
fi
# the same run checked in memory (recomputing T*) takes far more: the
# measure sees the difference
whole=$(peak_anon "$PDT" trace check "$TMP/run200000")
[ "$(cat "$TMP/peak.rc")" = 0 ] && grep -q "= T\*" "$TMP/peak.out" && ! grep -q certified "$TMP/peak.out" &&
    echo "# in memory: $whole KiB" && [ "$whole" -ge $((3 * big)) ] && ok in_memory_takes_more ||
    fail in_memory_takes_more "peak $whole KiB in memory, $big KiB bounded: $(cat "$TMP/peak.out")"

# a parallel run: merge steps, border lift-ups, several ranks' finals
if command -v mpirun >/dev/null; then
    mpirun -np 3 "$PDT" triangulate "$TMP/u50000.txt" -o "$TMP/p.tri" --trace "$TMP/par" >/dev/null 2>&1 ||
        fail mpi_traced_run
    out=$("$PDT" trace check "$TMP/par" --mem 1M 2>&1) && [[ "$out" == *"= T*"*"certified side by side"* ]] &&
        ok certified_mpi_run || fail certified_mpi_run "$out"
fi

# wrong finals (a hole, a flipped side, a point too few, a copy as a corner) are
# named by the certificate: tests/unit/test_trace_check.c, certified_tstar
summary
