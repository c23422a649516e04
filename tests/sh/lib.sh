# pdt — helpers for shell tests (source this file).
#   ok NAME / fail NAME MSG / check NAME CMD... / summary / par_same (an MPI run = the plain one)
# BIN (the programs' folder) and ROOT (the repository) come from tests/run.sh.
: "${ROOT:=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)}"
: "${BIN:=$ROOT/bin}"
PDT=$BIN/pdt
# the same program built to read the PDT_TEST_* fault-injection variables
# (src/base/testhook.c): for the scripts that inject faults
PDT_HOOKED=$BIN/test/pdt
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
T_PASS=0; T_FAIL=0
TMP=$(mktemp -d "${TMPDIR:-/tmp}/pdt-test.XXXXXX")
trap 'rm -rf "$TMP"' EXIT
ok()   { echo "ok - $1"; T_PASS=$((T_PASS + 1)); }
fail() { echo "not ok - $1"; shift; [ $# -gt 0 ] && echo "#   $*"; T_FAIL=$((T_FAIL + 1)); }
# check NAME COMMAND... : passes when the command exits 0
check() { local n=$1; shift; if "$@"; then ok "$n"; else fail "$n" "command failed: $*"; fi; }
summary() { echo "# $T_PASS passed, $T_FAIL failed"; [ "$T_FAIL" -eq 0 ]; }
# par_same NAME REF NP INPUT [VAR=VALUE...]: `mpirun -np NP pdt triangulate INPUT`, with the
# variables given passed to every rank (-x), exits 0 and writes the bytes of the plain run's REF
par_same() {
    local name=$1 ref=$2 np=$3 in=$4 out=$1.tri x=() e
    shift 4
    for e in "$@"; do x+=(-x "$e"); done
    timeout 120 mpirun -np "$np" "${x[@]}" "$PDT" triangulate "$in" -o "$out" > mpi.out 2> mpi.err
    local rc=$?
    if [ "$rc" -ne 0 ]; then
        fail "$name" "exit $rc $(head -3 mpi.err)"
    elif ! cmp -s "$ref" "$out"; then
        fail "$name" "output differs from the plain run ($(wc -l < "$out") vs $(wc -l < "$ref") lines)"
    else
        ok "$name"
    fi
}

# pdtview_window PATTERN: the id of a pdtview window whose title matches the
# extended regex PATTERN (empty if none).  Found by class, then by title:
# pdtview's title is UTF-8 (WM_NAME of type UTF8_STRING), which
# `xdotool search --name` does not match.
pdtview_window() {
    local w
    for w in $(xdotool search --class pdtview 2>/dev/null); do
        if xdotool getwindowname "$w" 2>/dev/null | grep -qE "$1"; then echo "$w"; return 0; fi
    done
    return 1
}

# xvfb_start WxH: a fresh Xvfb screen of that size on a display it picks free
# (-displayfd: no race with a test beside); sets DISPLAY and XPID (its pid).
# xvfb_cleanup (for `trap xvfb_cleanup EXIT`) ends VPID (a pdtview the test
# left running) and the Xvfb, and removes TMP.
xvfb_start() {
    rm -f "$TMP/xvfb.num"
    Xvfb -displayfd 3 -screen 0 "$1"x24 -nolisten tcp 3>"$TMP/xvfb.num" >"$TMP/xvfb.log" 2>&1 &
    XPID=$!
    for _ in $(seq 100); do [ -s "$TMP/xvfb.num" ] && break; sleep 0.1; done
    export DISPLAY=:$(head -1 "$TMP/xvfb.num")
    for _ in $(seq 50); do xdotool getdisplaygeometry >/dev/null 2>&1 && break; sleep 0.1; done
}
xvfb_cleanup() {
    [ -n "${VPID:-}" ] && stop_pid "$VPID"
    [ -n "${XPID:-}" ] && kill "$XPID" 2>/dev/null
    rm -rf "$TMP"
}

# stop_pid PID: SIGTERM, then SIGKILL if it is still there 3 s later (a
# viewer stuck in a call never reads the quit event SDL makes of SIGTERM).
stop_pid() {
    kill "$1" 2>/dev/null || return 0
    for _ in $(seq 30); do kill -0 "$1" 2>/dev/null || return 0; sleep 0.1; done
    kill -KILL "$1" 2>/dev/null
}

# stuck_report PID: where a process that should have shown a window is
# (its threads' stacks when gdb is there, their kernel wait channels
# otherwise) and which windows the X server has, for a failure's message.
stuck_report() {
    echo "process $1: $(ps -o stat=,etime=,time= -p "$1" 2>/dev/null || echo gone)"
    if command -v gdb >/dev/null; then
        timeout 20 gdb -batch -p "$1" -ex 'thread 1' -ex 'bt 30' -ex 'info threads' 2>/dev/null |
            grep -E '^(\[Switching|#|[ *] +[0-9])' | head -60
    else
        for t in /proc/"$1"/task/*; do echo "task ${t##*/}: $(cat "$t/wchan" 2>/dev/null) $(cut -d' ' -f3 "$t/stat" 2>/dev/null)"; done
    fi
    xwininfo -root -tree 2>&1 | head -20
}
