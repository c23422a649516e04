# Sourced by the benchmarks that time whole runs (table1.sh, bench/60-scaling.sh).
#
# The memory state a timed run starts in, MEMSTATE:
#   warm (default)  just before the run (after a sync), build/bench/warm touches and frees
#                   enough memory for it: the run meets memory the machine
#                   has backed, as on a machine without free page reporting;
#   cold            3 s of pause before the run: the VM has handed its free
#                   memory back to the host, and every page the run touches
#                   first costs about 1.25 s per GiB (this project's VMs);
#   asis            neither (the state the previous commands left).
# See warm.c beside this file and docs/geometry.md, "Fresh memory".
MEMSTATE=${MEMSTATE:-warm}
case "$MEMSTATE" in
    warm|cold|asis) ;;
    *) echo "MEMSTATE=$MEMSTATE: expected warm, cold or asis" >&2; exit 2 ;;
esac

# memstate_build BUILD_DIR: compile the warm tool into BUILD_DIR/warm
memstate_build() {
    local b=$1 src
    src=$(dirname "${BASH_SOURCE[0]}")/warm.c
    [ "$MEMSTATE" = warm ] || return 0
    if [ ! -x "$b/warm" ] || [ "$src" -nt "$b/warm" ]; then
        mkdir -p "$b"
        cc -O2 -pthread -o "$b/warm" "$src" || { echo "memstate: cannot compile $src" >&2; exit 1; }
    fi
    MEMSTATE_WARM=$b/warm
}

# memstate_prepare MB: put the machine in MEMSTATE before a timed run that
# touches up to MB megabytes.  warm and cold first wait for the files written
# so far to reach the disk (sync): a run at 3*10^7 points writes 1.5 GB, and
# the next run's write phase met that file's writeback (0.97-1.07 s after a
# sync, up to 1.49 s without).
memstate_prepare() {
    case "$MEMSTATE" in
        warm) sync; "$MEMSTATE_WARM" "$1" ;;
        cold) sync; sleep 3 ;;
    esac
}

# steal_now: the CPU seconds the host has taken from this VM's CPUs so far
# (steal, /proc/stat; 0 on a machine that is not a VM).  A run during which
# the host ran something else on one of our CPUs takes up to twice as long (a
# two-rank run more than a plain one, which mostly uses one CPU): the
# benchmarks print each run's share.
MEMSTATE_TICK=$(getconf CLK_TCK 2> /dev/null || echo 100)
steal_now() { awk -v t="$MEMSTATE_TICK" '/^cpu /{ printf "%.2f", $9 / t }' /proc/stat; }
