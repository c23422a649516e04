#!/bin/bash
# The all-to-all exchanges in two hops (src/par/comm_hops.c): a run of 64
# ranks or more sends the partition's records and the order's triangles
# through relays in a grid of ceil(sqrt(P)) columns.  PDT_TEST_COMM_HOPS=2
# makes a run of a few ranks take that path under mpirun (a full grid at
# P = 4, short last rows at P = 3, 5 and 7), with strips and with the
# bisection; the output must stay byte-identical to the plain run.
# san: yes
source "$(dirname "$0")/lib.sh"
PDT=$PDT_HOOKED  # reads PDT_TEST_COMM_HOPS
cd "$TMP"
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
export OMPI_MCA_mca_base_component_disable_dlclose=1 PMIX_MCA_mca_base_component_disable_dlclose=1
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi

for kind in uniform duplicates collinear; do
    in=$kind.txt ref=$kind.ref.tri
    "$PDT" gen "$kind" 2000 --seed 3 -o "$in" || { fail "gen_$kind"; continue; }
    "$PDT" triangulate "$in" -o "$ref" 2>/dev/null || { fail "plain_$kind"; continue; }
    for np in 3 4 5 7; do
        for part in strips bisect; do
            name=${kind}_np${np}_${part}_two_hops
            timeout 120 mpirun -np "$np" -x PDT_TEST_COMM_HOPS=2 "$PDT" triangulate "$in" \
                --partition "$part" -o "$name.tri" > mpi.out 2> mpi.err
            rc=$?
            if [ "$rc" -ne 0 ]; then fail "$name" "exit $rc $(head -3 mpi.err)"
            elif ! cmp -s "$ref" "$name.tri"; then fail "$name" "output differs from the plain run"
            else ok "$name"; fi
        done
    done
done
summary
