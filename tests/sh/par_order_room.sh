#!/bin/bash
# The order phase's room (src/par/driver.c, order_room_*): the grouped
# triangles, the received ones and the ordered output go into the rank's
# block when they fit, else into arrays of their own.  On real inputs the
# block nearly always has room, so PDT_TEST_ORDER_ROOM=N makes the phase see
# at most N triangles of it: 0 (everything apart), and sizes at which some
# parts fit and others do not, on some ranks and not others.  The output must
# stay byte-identical to the plain run.
# san: yes
source "$(dirname "$0")/lib.sh"
PDT=$PDT_HOOKED  # injects faults (PDT_TEST_*)
cd "$TMP"
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
export OMPI_MCA_mca_base_component_disable_dlclose=1 PMIX_MCA_mca_base_component_disable_dlclose=1
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi

# 3000 uniform points: about 2000 final triangles per rank at P = 3, 1500 at
# P = 4; a circle: every triangle final in the last merge, on one rank
for kind in uniform circle; do
    in=$kind.txt ref=$kind.ref.tri
    "$PDT" gen "$kind" 3000 --seed 5 -o "$in" || { fail "gen_$kind"; continue; }
    "$PDT" triangulate "$in" -o "$ref" || { fail "plain_$kind"; continue; }
    for np in 3 4; do
        for room in 0 1500 3000 4500 6000; do
            par_same "${kind}_np${np}_room${room}" "$ref" "$np" "$in" PDT_TEST_ORDER_ROOM="$room"
        done
    done
done
summary
