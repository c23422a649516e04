#!/bin/bash
# The prefault thread (a second thread faulting a rank's working memory in
# ahead of use): on for a plain run and for `mpirun -np 1` when the machine
# has another CPU, on for every rank when the machine has a CPU per rank,
# off when ranks share CPUs (more ranks than CPUs) and with PDT_PREFAULT=0.
# `--stats` per_rank[].prefault says which; the output is the same bytes
# every way.  (The kernel's block must be at least 8 MiB for the thread:
# 200 000 points.)
source "$(dirname "$0")/lib.sh"
cd "$TMP"
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi
CPUS=$(getconf _NPROCESSORS_ONLN)

"$PDT" gen uniform 200000 --seed 5 -o in.txt || fail gen
PDT_PREFAULT=0 "$PDT" triangulate in.txt -o ref.tri || fail plain_without_thread

# case NAME WANT(true|false) ENV CMD... : every rank's "prefault" is WANT, output = ref.tri
case_() {
    local name=$1 want=$2 env=$3; shift 3
    if ! env $env timeout 120 "$@" in.txt -o out.tri --stats > /dev/null 2> stats.json; then
        fail "$name" "exit non-zero: $(head -3 stats.json)"; return
    fi
    local got
    got=$(grep -o '"prefault": [a-z]*' stats.json | sort -u | sed 's/"prefault": //' | tr '\n' ' ')
    if [ "$got" != "$want " ]; then
        fail "$name" "prefault: '$got', want '$want'"
    elif ! cmp -s ref.tri out.tri; then
        fail "$name" "output differs from the plain run without the thread"
    else
        ok "$name"
    fi
}

if [ "$CPUS" -ge 2 ]; then
    case_ plain_has_thread true "" "$PDT" triangulate
    case_ np1_has_thread true "" mpirun -np 1 "$PDT" triangulate
    case_ np2_has_threads true "" mpirun -np 2 "$PDT" triangulate
fi
case_ plain_turned_off false "PDT_PREFAULT=0" "$PDT" triangulate
case_ np2_turned_off false "" mpirun -np 2 -x PDT_PREFAULT=0 "$PDT" triangulate
case_ ranks_sharing_cpus_have_none false "" mpirun --oversubscribe -np $((CPUS + 1)) "$PDT" triangulate
summary
