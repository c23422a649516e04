#!/bin/bash
# pdt — run libFuzzer targets (called by `make fuzz`, which builds bin/fuzz/).
#
#   FUZZ_SECONDS=60 FUZZ_JOBS=1 tests/fuzz/run.sh [TARGET...]
#
# Each target starts from its seed corpus tests/fuzz/corpus/TARGET/ plus the
# corpus grown by earlier runs (build/fuzz/corpus/TARGET/, where new inputs
# go) and runs for FUZZ_SECONDS under nice.  A crash, leak, timeout or
# out-of-memory input is written to tests/fuzz/crashes/TARGET/ (commit it
# with the fix: `make test` replays that folder) and fuzzing of that target
# goes on until the time is up (-fork=1 -ignore_crashes=1 ...).  Logs:
# build/fuzz/log-TARGET.txt.  Prints one line per target: executions,
# coverage (cov = edges, ft = features), corpus size, new crash files.
# Exit status 1 if any target produced a crash file.
set -u
cd "$(dirname "$0")/../.."
SECS=${FUZZ_SECONDS:-60}
JOBS=${FUZZ_JOBS:-1}
[ $# -gt 0 ] || set -- points_text points_node tris manifest trace_rank trace_run
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
mkdir -p build/fuzz

one() {
    local t=$1 bin=bin/fuzz/fuzz_$1
    [ -x "$bin" ] || { echo "$t: $bin missing (make fuzz-build)"; return 1; }
    mkdir -p "build/fuzz/corpus/$t" "tests/fuzz/crashes/$t"
    local before after
    before=$(ls "tests/fuzz/crashes/$t" | wc -l)
    # -fork=1 keeps going after a crash (each crash saved once);
    # -timeout: one input taking more than 10 s counts as a hang.
    nice -n 10 "$bin" -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
        -max_total_time="$SECS" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
        -artifact_prefix="tests/fuzz/crashes/$t/" -print_final_stats=1 \
        "build/fuzz/corpus/$t" "tests/fuzz/corpus/$t" >"build/fuzz/log-$t.txt" 2>&1
    after=$(ls "tests/fuzz/crashes/$t" | wc -l)
    # fork mode prints "#N: cov: C ft: F corp: K exec/s: E oom/timeout/crash: a/b/c time: T"
    local last
    last=$(grep -E '^#[0-9]+: cov:' "build/fuzz/log-$t.txt" | tail -1)
    printf '%-12s %ss  %s  new crash files: %d\n' "$t" "$SECS" "${last:-no stats (see log)}" \
        $((after - before))
    [ "$after" -eq "$before" ]
}

rc=0
running=0
pids=()
for t in "$@"; do
    one "$t" &
    pids+=($!)
    running=$((running + 1))
    if [ "$running" -ge "$JOBS" ]; then
        wait "${pids[0]}" || rc=1
        pids=("${pids[@]:1}")
        running=$((running - 1))
    fi
done
for p in "${pids[@]}"; do wait "$p" || rc=1; done
exit $rc
