#!/bin/bash
# pdt — the whole test suite.  Run by `make test` after building bin/ (release)
# and bin/san/ (ASan + UBSan).
#
#  * every unit-test program, in both builds (bin/tests/*, bin/san/tests/*);
#  * every shell test tests/sh/*.sh, with the release build, and again with the
#    sanitizer build when the script says "# san: yes".
#
# Each test case prints "ok - NAME" or "not ok - NAME"; a program or script
# that exits non-zero without a "not ok" line counts as one failed case.
# The last line is "N passed, N failed".
set -u
cd "$(dirname "$0")/.."
ROOT=$(pwd)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export LSAN_OPTIONS=suppressions=$ROOT/tests/lsan.supp:print_suppressions=0
export UBSAN_OPTIONS=print_stacktrace=1
FILTER=${1:-}
passed=0; failed=0; failures=()
LOGDIR=$ROOT/build/test-logs
mkdir -p "$LOGDIR"

run_one() { # label command...
    local label=$1; shift
    local log="$LOGDIR/$(echo "$label" | tr '/ ' '__').log"
    local t0=$SECONDS
    "$@" >"$log" 2>&1
    local rc=$?
    local ok nok
    ok=$(grep -c '^ok - ' "$log")
    nok=$(grep -c '^not ok - ' "$log")
    if [ "$rc" -ne 0 ] && [ "$nok" -eq 0 ]; then nok=1; echo "not ok - $label exited $rc" >>"$log"; fi
    passed=$((passed + ok)); failed=$((failed + nok))
    printf '%-46s %4d ok %3d failed  (%ds)\n' "$label" "$ok" "$nok" $((SECONDS - t0))
    if [ "$nok" -ne 0 ]; then
        failures+=("$label")
        grep -E '^(not ok|#)' "$log" | head -20 | sed 's/^/    /'
        tail -5 "$log" | sed 's/^/    | /'
    fi
}

for build in bin bin/san; do
    for t in "$build"/tests/*; do
        [ -x "$t" ] || continue
        case "$t" in *"$FILTER"*) ;; *) continue ;; esac
        run_one "${t#bin/}" "$t"
    done
done

for s in tests/sh/*.sh; do
    [ -f "$s" ] || continue
    [ "$(basename "$s")" = lib.sh ] && continue
    case "$s" in *"$FILTER"*) ;; *) continue ;; esac
    run_one "rel/$(basename "$s" .sh)" env BIN="$ROOT/bin" ROOT="$ROOT" bash "$s"
    if grep -q '^# san: yes' "$s"; then
        run_one "san/$(basename "$s" .sh)" env BIN="$ROOT/bin/san" ROOT="$ROOT" bash "$s"
    fi
done

echo
if [ "${#failures[@]}" -ne 0 ]; then
    echo "failed: ${failures[*]}"
    echo "logs: $LOGDIR"
fi
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ] && [ "$passed" -gt 0 ]
