#!/bin/bash
# The chunked transfer path of the comm layer (src/par/comm_mpi.c): with
# PDT_COMM_CHUNK forcing tiny messages, every collective and every
# point-to-point message of a parallel triangulation is cut into many pieces
# (and the large-transfer code runs on a small input); the output must stay
# byte-identical to the plain run.  Also: a bad PDT_COMM_CHUNK is ignored.
source "$(dirname "$0")/lib.sh"
cd "$TMP"
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
export OMPI_MCA_mca_base_component_disable_dlclose=1 PMIX_MCA_mca_base_component_disable_dlclose=1
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi

run_case() { # NAME CHUNK NP INPUT REF
    local name=$1 chunk=$2 np=$3 in=$4 ref=$5 out=$1.tri
    timeout 120 mpirun -np "$np" -x PDT_COMM_CHUNK="$chunk" "$PDT" triangulate "$in" -o "$out" \
        > mpi.out 2> mpi.err
    local rc=$?
    if [ "$rc" -ne 0 ]; then
        fail "$name" "exit $rc $(head -3 mpi.err)"
    elif ! cmp -s "$ref" "$out"; then
        fail "$name" "output differs from the plain run ($(wc -l < "$out") vs $(wc -l < "$ref") lines)"
    else
        ok "$name"
    fi
}

for kind in uniform duplicates; do
    in=$kind.txt ref=$kind.ref.tri
    "$PDT" gen "$kind" 2000 --seed 11 -o "$in" || { fail "gen_$kind"; continue; }
    "$PDT" triangulate "$in" -o "$ref" || { fail "plain_$kind"; continue; }
    for np in 2 3; do
        run_case "${kind}_np${np}_chunk1000" 1000 "$np" "$in" "$ref"
        run_case "${kind}_np${np}_chunk7" 7 "$np" "$in" "$ref"
    done
done
run_case uniform_np2_chunk_bad nonsense 2 uniform.txt uniform.ref.tri
summary
