#!/bin/bash
# Hostile inputs and stops (issue 30, items 6, 9, 11, 12): every reader of
# point files, triangle files and run folders refuses a FIFO, a device or a
# link to /dev/zero by name instead of blocking or spinning; a stream with no
# end of line is refused at its first line instead of read without bound;
# extreme clock offsets in a manifest are not applied (no overflow: the
# sanitizer build must stay silent); a job stopped by SIGINT to mpirun or by
# SIGKILL of mpirun leaves no new output and exits non-zero.  Every command
# runs under `timeout`, so that a reader that blocks fails instead of hanging.
# san: yes
source "$(dirname "$0")/lib.sh"
cd "$TMP"
V=$BIN/pdtview
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
export OMPI_MCA_mca_base_component_disable_dlclose=1 PMIX_MCA_mca_base_component_disable_dlclose=1

"$PDT" gen uniform 3000 --seed 3 -o u.txt
"$PDT" triangulate u.txt -o u.tri --trace run 2> /dev/null || { fail record_run; summary; exit 1; }
mkfifo fifo
ln -s /dev/zero zero.txt

# refused NAME PATTERN CMD...: CMD ends within the timeout, non-zero (or with a
# warning), and its stderr matches PATTERN (names the file and what it is)
refused() {
    local name=$1 pat=$2 rc; shift 2
    timeout 120 "$@" > out.txt 2> err.txt; rc=$?
    if [ $rc -eq 124 ] || [ $rc -eq 137 ]; then fail "$name" "hung (killed by timeout): $*"
    elif grep -qE "$pat" err.txt && ! grep -q 'runtime error' err.txt; then ok "$name"
    else fail "$name" "rc=$rc $(head -c 400 err.txt)"; fi
}
FIFO_MSG='is a FIFO \(named pipe\), not a regular file'
DEV_MSG='is a character device, not a regular file'

# --- point and triangle files
refused triangulate_fifo_input "fifo: $FIFO_MSG" "$PDT" triangulate fifo -o f.tri
refused hull_fifo_input "fifo: $FIFO_MSG" "$PDT" hull fifo
refused check_fifo_points "fifo: $FIFO_MSG" "$PDT" check fifo u.tri
refused check_fifo_triangles "fifo: $FIFO_MSG" "$PDT" check u.txt fifo
refused triangulate_dev_zero "/dev/zero: $DEV_MSG" "$PDT" triangulate /dev/zero -o z.tri
refused triangulate_link_to_dev_zero "zero.txt: $DEV_MSG" "$PDT" triangulate zero.txt -o z.tri
refused edit_fifo "fifo: $FIFO_MSG" "$V" --edit fifo --write-run wr
if [ ! -e f.tri ] && [ ! -e z.tri ]; then ok refused_inputs_write_nothing
else fail refused_inputs_write_nothing "$(ls)"; fi

# --- streams with no end of line: refused at line 1, memory bounded
# (the address-space limit proves the bound in the release build; ASan needs
# terabytes of address space, so the sanitizer build runs with the timeout alone)
lim() {
    if [[ $BIN == */san ]]; then timeout 20 "$@"; else (ulimit -v 600000; timeout 20 "$@"); fi
}
lim "$PDT" triangulate - -o s.tri < /dev/zero > /dev/null 2> err.txt; rc=$?
if [ $rc -eq 2 ] && grep -q 'standard input:1: no end of line' err.txt; then ok stdin_dev_zero_refused
else fail stdin_dev_zero_refused "rc=$rc $(head -c 300 err.txt)"; fi
head -c 3000000 /dev/zero | tr '\0' 'x' > long.txt
{ printf '0 0\n1 0\n'; cat long.txt; } | lim "$PDT" triangulate - -o s.tri > /dev/null 2> err.txt; rc=$?
if [ $rc -eq 2 ] && grep -q 'standard input:3: no end of line' err.txt; then ok stdin_long_garbage_line_names_line
else fail stdin_long_garbage_line_names_line "rc=$rc $(head -c 300 err.txt)"; fi
printf '0 0\n10 0\n0 10\n' | timeout 20 "$PDT" triangulate - -o s.tri 2> err.txt; rc=$?
if [ $rc -eq 0 ] && [ "$(cat s.tri)" = "0 1 2" ]; then ok stdin_normal_input_still_read
else fail stdin_normal_input_still_read "rc=$rc $(cat err.txt)"; fi
timeout 20 "$PDT" triangulate long.txt -o s2.tri > /dev/null 2> err.txt; rc=$?
if [ $rc -eq 2 ] && grep -q 'long.txt:1' err.txt && [ "$(wc -c < err.txt)" -lt 400 ]; then
    ok regular_file_garbage_line_short_message
else fail regular_file_garbage_line_short_message "rc=$rc $(head -c 300 err.txt)"; fi

# --- run folders: a FIFO or /dev/zero in place of each file, for every reader
# damaged_copy NAME FILE fifo|zero: a copy of run with FILE replaced
damaged_copy() {
    rm -rf "$1"; cp -r run "$1"; rm -f "$1/$2"
    if [ "$3" = fifo ]; then mkfifo "$1/$2"; else ln -s /dev/zero "$1/$2"; fi
}
damaged_copy r_rank rank-0000.trace fifo
damaged_copy r_manifest manifest fifo
damaged_copy r_points points.bin fifo
damaged_copy r_manifest_zero manifest zero
damaged_copy r_rank_zero rank-0000.trace zero
for c in r_rank:rank-0000.trace:"$FIFO_MSG" r_manifest:manifest:"$FIFO_MSG" \
         r_points:points.bin:"$FIFO_MSG" r_manifest_zero:manifest:"$DEV_MSG" \
         r_rank_zero:rank-0000.trace:"$DEV_MSG"; do
    IFS=: read -r d f msg <<< "$c"
    refused "trace_check_$d" "$f: $msg" "$PDT" trace check "$d"
    refused "trace_dump_$d" "$f: $msg" "$PDT" trace dump "$d"
    refused "trace_export_$d" "$f: $msg" "$PDT" trace export --chrome "$d" -o "$d.json"
    refused "view_headless_$d" "$f: $msg" "$V" --headless "$d" --end -o "$d.png"
    refused "view_index_$d" "$f: $msg" "$V" "$d" --index on --counts
done
# the kept index itself a FIFO: not waited on (rebuilt in its place)
rm -rf r_index; cp -r run r_index; mkfifo r_index/.pdtview-index
refused view_index_file_fifo "rebuilt the index \(is a FIFO" "$V" r_index --index on --counts

# --- extreme clock offsets: not applied, a warning, no overflow (UBSan)
if command -v mpirun > /dev/null; then
    mpirun -np 2 "$PDT" triangulate u.txt -o u2.tri --trace run2 > /dev/null 2>&1
else
    cp -r run run2
    sed -i 's/^ranks = .*/ranks = 2/' run2/manifest
fi
for offs in "9223372036854775807 -9223372036854775808" "-9223372036854775808 9223372036854775807" \
            "1000000000000000000 -1000000000000000000"; do
    rm -rf run3; cp -r run2 run3
    sed -i "s/^clock_offset_ns = .*/clock_offset_ns = $offs/" run3/manifest
    tag=$(echo "$offs" | cut -c1-3 | tr -- '-' 'm')
    for cmd in "trace check" "trace dump" "trace export --chrome" "trace export --otf2"; do
        case $cmd in *chrome) extra=(-o c.json) ;; *otf2) rm -rf o2; extra=(-o o2) ;; *) extra=() ;; esac
        # shellcheck disable=SC2086
        timeout 60 "$PDT" $cmd run3 "${extra[@]}" > out.txt 2> err.txt; rc=$?
        name="clock_offset_${tag}_$(echo "$cmd" | tr ' -' '_' | tr -s _)"
        if [ $rc -ne 124 ] && [ $rc -lt 128 ] && ! grep -qE 'runtime error|Sanitizer' err.txt; then
            ok "$name"
        else fail "$name" "rc=$rc $(grep -m3 -E 'runtime error|ERROR' err.txt)"; fi
    done
    timeout 60 "$V" --headless run3 --end -o o.png > /dev/null 2> err.txt; rc=$?
    if [ $rc -eq 0 ] && ! grep -qE 'runtime error|Sanitizer' err.txt; then ok "clock_offset_${tag}_view"
    else fail "clock_offset_${tag}_view" "rc=$rc $(grep -m3 -E 'runtime error|ERROR' err.txt)"; fi
done
rm -rf run3; cp -r run2 run3
sed -i 's/^clock_offset_ns = .*/clock_offset_ns = 9223372036854775807 -9223372036854775808/' run3/manifest
timeout 60 "$PDT" trace dump run3 > /dev/null 2> err.txt
if grep -q 'clock_offset_ns of rank 0 is 9223372036854775807 ns, beyond' err.txt; then
    ok clock_offset_out_of_range_warns
else fail clock_offset_out_of_range_warns "$(head -c 300 err.txt)"; fi

# --- stopping the launcher: no new output, non-zero status ---------------------
if ! command -v mpirun > /dev/null; then summary; exit; fi
# stop_job NAME SIGNAL: mpirun -np 2 with rank 0 asleep in its write (the
# test hook; a caught signal ends the sleep early) gets SIGNAL once the sleep
# has begun.  mpirun's first word to the ranks is SIGCONT, its SIGTERM
# follows a second later: the SIGCONT ends rank 0's sleep, and without the
# commit check rank 0 would finish and rename in that second; with it, it
# waits at the commit until the SIGTERM ends it.  (The sleep is long, so
# that the result does not depend on how fast a loaded machine delivers the
# SIGCONT: a rank that commits before its launcher has said anything is
# beyond any check.)
stop_job() {
    local name=$1 sig=$2 sleep=$3 rc kids alive
    rm -f "mark-$name"
    PDT_TEST_SLEEP_IN_WRITE=0:$sleep PDT_TEST_MARK="$TMP/mark-$name" \
        mpirun -np 2 -x PDT_TEST_SLEEP_IN_WRITE -x PDT_TEST_MARK \
        "$PDT_HOOKED" triangulate u.txt -o "out-$name.tri" > "log-$name.out" 2> "log-$name.err" &
    local mp=$!
    for _ in $(seq 1 600); do [ -e "mark-$name" ] && break; sleep 0.05; done
    kids=$(pgrep -P "$mp")
    kill "-$sig" "$mp"
    wait "$mp"; rc=$?
    # the ranks (orphans after a SIGKILL) must end, and not commit on the way
    for _ in $(seq 1 300); do
        alive=0
        for k in $kids; do kill -0 "$k" 2> /dev/null && alive=1; done
        [ $alive -eq 0 ] && break
        sleep 0.1
    done
    local left
    left=$(ls -A | grep -c "out-$name")
    if [ $rc -ne 0 ] && [ $alive -eq 0 ] && [ "$left" -eq 0 ]; then ok "$name"
    else fail "$name" "rc=$rc ranks alive=$alive files=$(ls -A | grep "out-$name") $(grep pdt "log-$name.err" | head -3)"; fi
}
stop_job sigint_to_mpirun_leaves_no_output INT 20
stop_job sigterm_to_mpirun_leaves_no_output TERM 20
stop_job sigkill_to_mpirun_orphans_do_not_commit KILL 3
# a run that is not stopped still writes (the stop check costs nothing then)
mpirun -np 2 "$PDT" triangulate u.txt -o whole.tri > /dev/null 2> w.err; rc=$?
if [ $rc -eq 0 ] && cmp -s u.tri whole.tri; then ok unstopped_mpi_run_writes
else fail unstopped_mpi_run_writes "rc=$rc $(head -3 w.err)"; fi
summary
