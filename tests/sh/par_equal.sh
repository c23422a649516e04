#!/bin/bash
# pdt triangulate under mpirun: for every `pdt gen` family, sizes from 0 to
# 10^4 and P in {1,2,3,4,5,7,8,13,16,32} (oversubscribed), with both
# partitions (--partition strips and bisect), the output is byte-identical to
# the plain (sequential, no MPI) run, and `pdt check` accepts the plain run's
# output.  The matrix is chosen to fit in a few minutes: every family x every
# P up to 16 at n = 100, fewer P at n = 2000 and 10^4, P = 32 on two
# families, and the tiny sizes (0..5 points, P > n, empty regions) on the
# families where they differ.  (tests/unit/test_par_bisect.c runs the same
# comparison on the thread backend for more P.)
source "$(dirname "$0")/lib.sh"
cd "$TMP"
export OMPI_MCA_rmaps_base_oversubscribe=1
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi

KINDS="uniform grid circle circle-round parabola clusters collinear duplicates column"

# same_for KIND N P... : one case per P
same_for() {
    local kind=$1 n=$2; shift 2
    local in=$kind-$n.txt ref=$kind-$n.ref.tri
    if ! "$PDT" gen "$kind" "$n" --seed 7 -o "$in" 2> gen.err; then
        fail "gen_${kind}_$n" "$(cat gen.err)"; return
    fi
    if ! "$PDT" triangulate "$in" -o "$ref" 2> ref.err; then
        fail "plain_${kind}_$n" "$(cat ref.err)"; return
    fi
    if "$PDT" check "$in" "$ref" > /dev/null 2> chk.err; then ok "check_plain_${kind}_$n"
    else fail "check_plain_${kind}_$n" "$(cat chk.err)"; fi
    local p out part
    for p in "$@"; do
        for part in strips bisect; do
            out=$kind-$n-p$p-$part.tri
            if ! mpirun -np "$p" "$PDT" triangulate "$in" -o "$out" --partition "$part" > mpi.out 2> mpi.err; then
                fail "mpi_${part}_${kind}_n${n}_p$p" "exit $? $(head -3 mpi.err)"
            elif ! cmp -s "$ref" "$out"; then
                fail "mpi_${part}_${kind}_n${n}_p$p" "output differs from the plain run ($(wc -l < "$out") vs $(wc -l < "$ref") lines)"
            else
                ok "mpi_${part}_${kind}_n${n}_p$p"
            fi
        done
    done
}

for n in 0 1 2 3 5; do
    for kind in uniform collinear duplicates; do same_for "$kind" "$n" 2 3 16; done
done
for kind in $KINDS; do same_for "$kind" 100 1 2 3 4 5 7 8 13 16; done
for kind in $KINDS; do same_for "$kind" 2000 2 4 7; done
for kind in uniform grid; do same_for "$kind" 2000 32; done
for kind in $KINDS; do same_for "$kind" 10000 3 8; done
summary
