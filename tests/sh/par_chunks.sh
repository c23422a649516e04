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

for kind in uniform duplicates; do
    in=$kind.txt ref=$kind.ref.tri
    "$PDT" gen "$kind" 2000 --seed 11 -o "$in" || { fail "gen_$kind"; continue; }
    "$PDT" triangulate "$in" -o "$ref" || { fail "plain_$kind"; continue; }
    for np in 2 3; do
        par_same "${kind}_np${np}_chunk1000" "$ref" "$np" "$in" PDT_COMM_CHUNK=1000
        par_same "${kind}_np${np}_chunk7" "$ref" "$np" "$in" PDT_COMM_CHUNK=7
    done
done
par_same uniform_np2_chunk_bad uniform.ref.tri 2 uniform.txt PDT_COMM_CHUNK=nonsense
summary
