#!/bin/bash
# pdt triangulate under mpirun when things go wrong: a rank killed with
# SIGKILL in the middle of the run, bad input, an output that would replace
# the input.  Each time: non-zero exit, a message, no output file.
# Also the quiet cases: empty and collinear input give 0 triangles and say so.
# san: yes
source "$(dirname "$0")/lib.sh"
PDT=$PDT_HOOKED  # injects faults (PDT_TEST_*)
cd "$TMP"
export OMPI_MCA_rmaps_base_oversubscribe=1
# Open MPI's own allocations in MPI_Init/Finalize are suppressed in
# tests/lsan.supp; those suppressions need full stacks and named plugins.
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
export OMPI_MCA_mca_base_component_disable_dlclose=1 PMIX_MCA_mca_base_component_disable_dlclose=1
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi

"$PDT" gen uniform 3000 --seed 3 -o u.txt

# --- a rank dies: rank 1 sleeps at a given place (test-only variable), we kill
# exactly that process.  Non-zero exit, no output file and no temporary left,
# and rank 0 (ended by mpirun's SIGTERM) names the step the job was in.
# kill_rank NAME VAR=RANK:SECONDS "STEP" (as rank 0 names it)
kill_rank() {
    local name=$1 hook=$2 step=$3
    env "$hook" PDT_TEST_MARK="mark-$name" timeout 120 mpirun -np 2 "$PDT" triangulate u.txt -o "$name.tri" \
        > "log-$name.out" 2> "log-$name.err" &
    local MPID=$!   # timeout, whose child is mpirun, whose children are the ranks
    local victim=
    for _ in $(seq 1 100); do
        for c in $(for m in $(pgrep -P "$MPID"); do pgrep -P "$m"; done 2> /dev/null); do
            if tr '\0' '\n' < "/proc/$c/environ" 2> /dev/null | grep -qx 'OMPI_COMM_WORLD_RANK=1'; then
                victim=$c
            fi
        done
        [ -n "$victim" ] && break
        sleep 0.1
    done
    if [ -z "$victim" ]; then
        fail "$name" "could not find rank 1 of mpirun $MPID"
        kill "$MPID" 2> /dev/null
        wait 2> /dev/null
        return
    fi
    # let it reach its sleep (the hook creates the mark file then)
    for _ in $(seq 1 600); do [ -e "mark-$name" ] && break; sleep 0.1; done
    sleep 0.2
    local t0=$SECONDS rc
    kill -KILL "$victim"
    wait "$MPID"; rc=$?
    local left
    left=$(ls -A | grep -v '^log-\|^mark-' | grep -c "$name")
    if [ $rc -ne 0 ] && [ $rc -ne 124 ] && [ "$left" -eq 0 ] && [ $((SECONDS - t0)) -lt 30 ] &&
        grep -qF "while rank 0 was in its $step:" "log-$name.err"; then
        ok "$name"
    else
        fail "$name" "rc=$rc files=$(ls -A | grep -v '^log-\|^mark-' | grep "$name") after $((SECONDS - t0)) s: $(cat "log-$name.err")"
    fi
    wait 2> /dev/null
}
kill_rank rank_killed_mid_run PDT_TEST_SLEEP_BEFORE_MERGE=1:60 "triangulate step (merge phase)"
kill_rank rank_killed_in_write PDT_TEST_SLEEP_IN_WRITE=1:60 "write step"

# --- bad input: file:line message, exit 2, no output
printf '0 0\n1 1\n2 x\n' > bad.txt
mpirun -np 3 "$PDT" triangulate bad.txt -o bad.tri > /dev/null 2> bad.err; rc=$?
if [ $rc -eq 2 ] && grep -q 'bad.txt:3' bad.err && [ ! -e bad.tri ]; then ok bad_input_exit_2
else fail bad_input_exit_2 "rc=$rc $(cat bad.err)"; fi

mpirun -np 2 "$PDT" triangulate missing.txt -o m.tri > /dev/null 2> m.err; rc=$?
if [ $rc -eq 2 ] && grep -q 'missing.txt' m.err && [ ! -e m.tri ]; then ok missing_input_exit_2
else fail missing_input_exit_2 "rc=$rc $(cat m.err)"; fi

cp u.txt same.txt
mpirun -np 2 "$PDT" triangulate same.txt -o same.txt > /dev/null 2> s.err; rc=$?
if [ $rc -eq 2 ] && cmp -s u.txt same.txt && grep -q 'replace the input' s.err; then
    ok output_would_replace_input
else fail output_would_replace_input "rc=$rc $(cat s.err)"; fi

# --- rank 0 cannot write: non-zero exit, message, nothing left behind
mpirun -np 2 "$PDT" triangulate u.txt -o nodir/out.tri > /dev/null 2> w.err; rc=$?
if [ $rc -ne 0 ] && grep -q 'nodir/out.tri' w.err && [ ! -e nodir ]; then ok write_error_nonzero_exit
else fail write_error_nonzero_exit "rc=$rc $(head -3 w.err)"; fi

# --- a rank fails its share of the parallel write (test-only variable): the
# message names that rank and the write, nothing is left (not even the temporary)
mkdir -p wdir
PDT_TEST_FAIL_WRITE=1 mpirun -np 3 -x PDT_TEST_FAIL_WRITE "$PDT" triangulate u.txt -o wdir/fw.tri \
    > /dev/null 2> fw.err; rc=$?
if [ $rc -eq 2 ] && grep -q 'rank 1, write: wdir/fw.tri' fw.err && [ -z "$(ls -A wdir)" ]; then
    ok write_fails_on_one_rank
else fail write_fails_on_one_rank "rc=$rc files=$(ls -A wdir) $(grep pdt fw.err | head -3)"; fi

# --- a rank without room for the table of every rank's part of the input
# (test-only variable): every rank stops before the allgather that fills the
# table, whichever rank it is; the message names that rank, nothing is written
mkdir -p rdir
for r in 0 2; do
    PDT_TEST_READ_NOMEM=$r mpirun -np 3 -x PDT_TEST_READ_NOMEM "$PDT" triangulate u.txt \
        -o rdir/nm.tri > /dev/null 2> nm$r.err; rc=$?
    if [ $rc -eq 2 ] && grep -q "rank $r: read: out of memory" nm$r.err && [ -z "$(ls -A rdir)" ]; then
        ok read_table_nomem_rank$r
    else fail read_table_nomem_rank$r "rc=$rc files=$(ls -A rdir) $(grep pdt nm$r.err | head -3)"; fi
done

# --- the parallel write gives the plain run's bytes
"$PDT" triangulate u.txt -o u.plain.tri
mpirun -np 3 "$PDT" triangulate u.txt -o u.par.tri > /dev/null 2> pw.err; rc=$?
if [ $rc -eq 0 ] && cmp -s u.plain.tri u.par.tri; then ok parallel_write_same_bytes
else fail parallel_write_same_bytes "rc=$rc $(head -3 pw.err)"; fi

# --- standard input is read by rank 0
"$PDT" triangulate u.txt -o u.ref
mpirun -np 3 "$PDT" triangulate - -o u.stdin.tri < u.txt > /dev/null 2> in.err; rc=$?
if [ $rc -eq 0 ] && cmp -s u.ref u.stdin.tri; then ok stdin_input
else fail stdin_input "rc=$rc $(head -3 in.err)"; fi

# --- no triangles: exit 0, empty output, the reason on stderr
: > empty.txt
mpirun -np 3 "$PDT" triangulate empty.txt -o empty.tri > /dev/null 2> e.err; rc=$?
if [ $rc -eq 0 ] && [ -e empty.tri ] && [ ! -s empty.tri ] && grep -q '0 triangles' e.err; then
    ok empty_input_zero_triangles
else fail empty_input_zero_triangles "rc=$rc $(cat e.err)"; fi
seq 0 499 | awk '{print 3 * $1, 2 * $1 + 1}' > col.txt   # one line
mpirun -np 4 "$PDT" triangulate col.txt -o col.tri --stats > /dev/null 2> c.err; rc=$?
if [ $rc -eq 0 ] && [ ! -s col.tri ] && grep -q 'collinear' c.err && grep -q '"collinear": true' c.err; then
    ok collinear_input_zero_triangles
else fail collinear_input_zero_triangles "rc=$rc $(head -3 c.err)"; fi

# --- a small run with --stats under the sanitizer build too
"$PDT" gen clusters 1500 --seed 5 -o cl.txt
"$PDT" triangulate cl.txt -o cl.ref
mpirun -np 3 "$PDT" triangulate cl.txt -o cl.tri --stats > /dev/null 2> cl.err; rc=$?
if [ $rc -eq 0 ] && cmp -s cl.ref cl.tri && grep -q '"per_rank"' cl.err; then ok stats_run_3_ranks
else fail stats_run_3_ranks "rc=$rc $(head -5 cl.err)"; fi
# --- the partition balances by count even when every point has the same x
seq 0 7999 | awk '{ print 5, ($1 * 7919) % 100003 }' > col8k.txt   # one vertical line, shuffled
mpirun -np 4 "$PDT" triangulate col8k.txt -o col8k.tri --stats > /dev/null 2> col8k.err; rc=$?
pts=$(grep -o '"points": [0-9]*' col8k.err | head -4 | awk '{print $2}' | tr '\n' ' ')
uniq=$(grep -o '"unique": [0-9]*' col8k.err | head -1 | awk '{print $2}')
if [ $rc -eq 0 ] && [ -n "$uniq" ] && echo "$pts" | awk -v u="$uniq" '
    { for (i = 1; i <= NF; i++) if ($i < 0.8 * u / NF || $i > 1.2 * u / NF) bad = 1; n = NF }
    END { exit !(n == 4 && !bad) }'; then ok column_strips_balanced
else fail column_strips_balanced "rc=$rc points per rank: $pts of $uniq"; fi
summary
