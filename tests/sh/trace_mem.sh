#!/bin/bash
# The trace tools in bounded memory and their exit statuses: pdt trace check
# with a tiny --mem (or $PDT_TRACE_MEM) sorts the final triangles on disk and
# gives the same verdict; the streamed merged dump has every event in a
# causal order; exit 2 for a folder that is no readable run (bad manifest),
# 1 for a violated invariant.
# san: yes
source "$(dirname "$0")/lib.sh"
"$PDT" gen uniform 2500 -o "$TMP/u.txt"
"$PDT" triangulate "$TMP/u.txt" -o "$TMP/u.tri" --trace "$TMP/run" || fail traced_run

out=$("$PDT" trace check "$TMP/run" 2>&1) && [[ "$out" == "ok: "*"= T*"* && "$out" != *"on disk"* ]] &&
    ok check_in_memory || fail check_in_memory "$out"
# the ~5000 finals are sorted in memory by buckets of their smallest corner
# (4096 or more: sort_fins' bucket pass, then an introsort per bucket); a
# wrong order would not match T*
nfin=$(echo "$out" | grep -o '[0-9]* final triangles' | cut -d' ' -f1)
[ "${nfin:-0}" -ge 4096 ] && ok check_sorts_finals_in_buckets ||
    fail check_sorts_finals_in_buckets "only '${nfin:-}' finals: the bucket pass is not run"
out=$("$PDT" trace check "$TMP/run" --mem 2K 2>&1) && [[ "$out" == *"= T*"*"sorted on disk in"* ]] &&
    ok check_tiny_mem_spills || fail check_tiny_mem_spills "$out"
# 300K: the ~5000 finals fit the pass's buffer (half the budget), but not
# beside what recomputing T* of 2500 points takes: they go to disk first
out=$("$PDT" trace check "$TMP/run" --mem 300K 2>&1) && [[ "$out" == *"= T*"*"sorted on disk in 1 runs"* ]] &&
    ok check_finals_leave_room_for_tstar || fail check_finals_leave_room_for_tstar "$out"
out=$(PDT_TRACE_MEM=1K "$PDT" trace check "$TMP/run" 2>&1) && [[ "$out" == *"sorted on disk in"* ]] &&
    ok check_mem_from_environment || fail check_mem_from_environment "$out"
TMPDIR=/nonexistent-dir "$PDT" trace check "$TMP/run" --mem 1K >"$TMP/o" 2>&1; rc=$?
[ $rc = 2 ] && grep -q "temporary file for .* in /nonexistent-dir: cannot create" "$TMP/o" && ok check_spill_failure_is_named ||
    fail check_spill_failure_is_named "rc $rc: $(cat "$TMP/o")"
for bad in 0 -5 12Q K; do
    "$PDT" trace check "$TMP/run" --mem "$bad" 2>/dev/null
    [ $? = 2 ] || fail "mem_$bad" "accepted --mem $bad"
done
ok bad_mem_values_refused

# exit statuses: 2 = not a readable run folder, 1 = an invariant violated
cp -r "$TMP/run" "$TMP/badman"
sed -i 's/^n = .*/n = lots/' "$TMP/badman/manifest"
"$PDT" trace check "$TMP/badman" >"$TMP/o" 2>&1; rc=$?
[ $rc = 2 ] && grep -q "manifest" "$TMP/o" && ok check_malformed_manifest_exit_2 ||
    fail check_malformed_manifest_exit_2 "rc $rc: $(cat "$TMP/o")"
chmod 000 "$TMP/badman/manifest"
if [ -r "$TMP/badman/manifest" ]; then
    echo "ok - check_unreadable_manifest_exit_2 # skip: root reads any file"
else
    "$PDT" trace check "$TMP/badman" >/dev/null 2>&1
    [ $? = 2 ] && ok check_unreadable_manifest_exit_2 || fail check_unreadable_manifest_exit_2
fi
"$PDT" trace check "$TMP/nothing-here" >/dev/null 2>&1; rc=$?
[ $rc = 2 ] && ok check_missing_folder_exit_2 || fail check_missing_folder_exit_2 "rc $rc"
cp -r "$TMP/run" "$TMP/skewed"
sed -i 's/^input_checksum = .*/input_checksum = fnv1a64:0000000000000001/' "$TMP/skewed/manifest"
"$PDT" trace check "$TMP/skewed" >"$TMP/o" 2>&1; rc=$?
[ $rc = 1 ] && ok check_violation_exit_1 || fail check_violation_exit_1 "rc $rc: $(cat "$TMP/o")"

# the streamed merged order: every event once, each rank in order, recv after send
if command -v mpirun >/dev/null; then
    mpirun -np 3 "$ROOT/bin/pdt" triangulate "$TMP/u.txt" -o "$TMP/p.tri" --trace "$TMP/par" 2>/dev/null ||
        fail mpi_traced_run
    "$PDT" trace dump "$TMP/par" >"$TMP/merged.txt"
    total=$("$PDT" trace info "$TMP/par" | awk '$1 == "all" {print $2}')
    awk '{ r = substr($1, 2); k = substr($2, 2) + 0
           if ((r in last) ? k != last[r] + 1 : k != 0) bad = 1; last[r] = k }
         $4 == "send" { split($6, to, "="); sent[r "," to[2] "," $5 "," $8] = 1 }
         $4 == "recv" { split($6, fr, "="); if (!((fr[2] "," r "," $5 "," $8) in sent)) bad = 1 }
         END { exit bad }' "$TMP/merged.txt" && [ "$(wc -l <"$TMP/merged.txt")" = "$total" ] &&
        ok streamed_merge_complete_and_causal || fail streamed_merge_complete_and_causal
    out=$("$PDT" trace check "$TMP/par" --mem 1K 2>&1) && [[ "$out" == *"= T*"*"on disk"* ]] &&
        ok check_tiny_mem_mpi_run || fail check_tiny_mem_mpi_run "$out"
    # --from/--count on the merged stream
    [ "$("$PDT" trace dump "$TMP/par" --from 100 --count 5)" = "$(sed -n 101,105p "$TMP/merged.txt")" ] &&
        ok streamed_merge_from_count || fail streamed_merge_from_count
fi
summary
