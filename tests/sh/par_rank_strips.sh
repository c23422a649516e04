#!/bin/bash
# Two strips per rank (src/par/driver.c, rank_strips): a rank of a large
# untraced .tri run triangulates its strip as two strips one after the other
# and merges them first, at level 0, with no message; the order phase then
# exchanges in two rounds.  Real inputs reach it from 2^21 points; here
# PDT_RANK_STRIPS=2 makes small inputs take it.  The output must stay
# byte-identical to the plain run for every family and P, --stats must say
# so, and a run that cannot take it (traced) must not.
# san: yes
source "$(dirname "$0")/lib.sh"
cd "$TMP"
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
export OMPI_MCA_mca_base_component_disable_dlclose=1 PMIX_MCA_mca_base_component_disable_dlclose=1
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi

for kind in uniform grid circle clusters collinear duplicates column; do
    in=$kind.txt ref=$kind.ref.tri
    "$PDT" gen "$kind" 4000 --seed 9 -o "$in" || { fail "gen_$kind"; continue; }
    "$PDT" triangulate "$in" -o "$ref" 2>/dev/null || { fail "plain_$kind"; continue; }
    for np in 2 3 5; do
        par_same "${kind}_np${np}_two_strips" "$ref" "$np" "$in" PDT_RANK_STRIPS=2
    done
done
# tiny inputs: strips with no point, or one
for n in 1 2 3 5 9; do
    "$PDT" gen uniform $n --seed 4 -o tiny$n.txt && "$PDT" triangulate tiny$n.txt -o tiny$n.ref.tri 2>/dev/null
    par_same "tiny${n}_np3_two_strips" tiny$n.ref.tri 3 tiny$n.txt PDT_RANK_STRIPS=2
done
# --stats says how many strips each rank held
mpirun -np 2 -x PDT_RANK_STRIPS=2 "$PDT" triangulate uniform.txt -o s.tri --stats 2> stats.err > /dev/null
case "$(grep '^{' stats.err)" in *'"strips": 2'*'"strips": 2'*) ok stats_say_two_strips ;;
    *) fail stats_say_two_strips "$(grep '^{' stats.err | head -c 300)" ;; esac
# a traced run keeps one strip per rank (its events are the lessons'), even
# when asked for two
mpirun -np 2 -x PDT_RANK_STRIPS=2 "$PDT" triangulate uniform.txt -o t.tri --trace trun --stats \
    2> tstats.err > /dev/null
case "$(grep '^{' tstats.err)" in *'"strips": 2'*) fail traced_one_strip ;; *) ok traced_one_strip ;; esac
cmp -s t.tri uniform.ref.tri && ok traced_same_output || fail traced_same_output
"$PDT" trace check trun > tcheck.out 2>&1 && ok traced_run_checks || fail traced_run_checks "$(tail -2 tcheck.out)"
# the other formats (the points written from each rank's input block)
for fmt in ele off; do
    "$PDT" triangulate uniform.txt -o ref.$fmt 2>/dev/null
    mpirun -np 3 -x PDT_RANK_STRIPS=2 "$PDT" triangulate uniform.txt -o two.$fmt > /dev/null 2>&1
    same=1
    cmp -s ref.$fmt two.$fmt || same=0
    [ $fmt = ele ] && { cmp -s ref.node two.node || same=0; }
    [ $same = 1 ] && ok "format_${fmt}_two_strips" || fail "format_${fmt}_two_strips"
done
summary
