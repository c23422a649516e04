#!/bin/bash
# make bench: run every benchmark section in scripts/bench/*.sh in order.
# Each section prints its own figures (medians of several runs) and ratios
# against other tools measured in the same run.  Benchmarks never fail the
# build on a time; they exit non-zero only if a program itself fails.
# BENCH_ONLY=WORD runs only the sections whose file name contains WORD
# (e.g. make bench BENCH_ONLY=scaling SCALING_UNIFORM="1e6 1e7 3e7").
set -u
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
mkdir -p build/bench
rc=0
for s in scripts/bench/*.sh; do
    [ -f "$s" ] || continue
    case "$(basename "$s")" in *"${BENCH_ONLY:-}"*) ;; *) continue ;; esac
    echo "== $(basename "$s" .sh) =="
    bash "$s" || rc=1
    echo
done
exit $rc
