#!/bin/bash
# valgrind (memcheck, --leak-check=full) on the release build:
#   * a traced 4-rank run: mpirun -np 4 valgrind ... pdt triangulate --trace;
#   * the sequential traced run, pdt trace check on both folders;
#   * pdtview --headless rendering the 4-rank run (PNG) and a damaged copy.
# Each must report no invalid access, no use of uninitialised memory and no
# definitely lost block (valgrind exits 99 on any of them).  Library noise
# is suppressed by tests/valgrind/libs.supp (Open MPI / PMIx / fontconfig;
# every rule is explained there) plus Debian's Open MPI and PMIx files; two
# canaries prove that the suppressions do not hide a leak or an invalid read
# in our own code, with and without MPI.  Skipped only if valgrind is absent.
# Takes about a minute (valgrind runs the 4 ranks 20-50 times slower).
source "$(dirname "$0")/lib.sh"
cd "$TMP"
if ! command -v valgrind >/dev/null; then
    echo "# valgrind not installed: skipped"; ok valgrind_skipped; summary; exit
fi
SUPP=(--suppressions="$ROOT/tests/valgrind/libs.supp")
for f in /usr/share/openmpi/openmpi-valgrind.supp \
         /usr/lib/x86_64-linux-gnu/pmix2/share/pmix/pmix-valgrind.supp; do
    [ -f "$f" ] && SUPP+=(--suppressions="$f")
done
VG=(valgrind -q --num-callers=40 --leak-check=full --show-leak-kinds=definite
    --errors-for-leak-kinds=definite --error-exitcode=99 "${SUPP[@]}")
# Open MPI plugins must stay loaded so that their frames have names
export OMPI_MCA_mca_base_component_disable_dlclose=1 PMIX_MCA_mca_base_component_disable_dlclose=1

# vg_case NAME LOG_PATTERN CMD...: passes when CMD exits 0 and the logs are empty
vg_case() {
    local name=$1 logs=$2; shift 2
    rm -f $logs
    "$@" >"$name.out" 2>&1
    local rc=$? report
    report=$(cat $logs 2>/dev/null | grep -v '^==[0-9]*== *$' | head -30)
    if [ "$rc" -eq 0 ] && [ -z "$report" ]; then ok "$name"
    else fail "$name" "exit $rc; $(tail -3 "$name.out" | tr '\n' ' ') ${report}"; fi
}

# ---- canaries: a leak and an invalid read in a program of ours are reported
cat >canary.c <<'C'
#include <stdio.h>
#include <stdlib.h>
#ifdef WITH_MPI
#include <mpi.h>
#endif
int main(int argc, char **argv)
{
#ifdef WITH_MPI
    MPI_Init(&argc, &argv);
#endif
    int *p = malloc(10 * sizeof *p);
    for (int i = 0; i < 10; i++) p[i] = i;
    int bad = argc > 5 ? 0 : p[10];      /* reads one past the end */
    printf("%d\n", bad & 1);
    p = malloc(64);                      /* lost */
    p[0] = 1;
#ifdef WITH_MPI
    MPI_Finalize();
#endif
    (void)argv;
    return 0;
}
C
canary() { # NAME LOG CMD...
    local name=$1 log=$2; shift 2
    "$@" >"$name.out" 2>&1
    local rc=$?
    if [ "$rc" -ne 0 ] && grep -q 'Invalid read of size 4' $log && grep -q 'definitely lost' $log
    then ok "$name"; else fail "$name" "exit $rc, log: $(head -5 $log 2>/dev/null)"; fi
}
if gcc -g -O0 -o canary canary.c; then
    canary valgrind_canary_plain canary.log "${VG[@]}" --log-file=canary.log ./canary
else fail valgrind_canary_plain "cannot compile the canary"; fi
if command -v mpicc >/dev/null && mpicc -g -O0 -DWITH_MPI -o canary_mpi canary.c; then
    canary valgrind_canary_mpi "canary_mpi.*.log" mpirun -np 2 "${VG[@]}" \
        --log-file='canary_mpi.%q{OMPI_COMM_WORLD_RANK}.log' ./canary_mpi
else fail valgrind_canary_mpi "mpicc missing or cannot compile the canary"; fi

# ---- our programs
"$PDT" gen uniform 2000 --seed 3 -o u.txt
vg_case valgrind_traced_4_rank_run "vg4.*.log" mpirun -np 4 "${VG[@]}" \
    --log-file='vg4.%q{OMPI_COMM_WORLD_RANK}.log' "$PDT" triangulate u.txt -o u4.tri --trace run4
vg_case valgrind_traced_sequential_run vg1.log "${VG[@]}" --log-file=vg1.log \
    "$PDT" triangulate u.txt -o u1.tri --trace run1 --trace-level 2
cmp -s u1.tri u4.tri && ok valgrind_runs_agree || fail valgrind_runs_agree "4-rank output differs"
vg_case valgrind_trace_check vgc.log "${VG[@]}" --log-file=vgc.log "$PDT" trace check run4
vg_case valgrind_headless_render vgv.log "${VG[@]}" --log-file=vgv.log \
    "$BIN/pdtview" --headless run4 --end -o v.png --size 640x400
[ -s v.png ] && ok valgrind_render_wrote_png || fail valgrind_render_wrote_png
cp -r run4 cut && truncate -s 3000 cut/rank-0002.trace
vg_case valgrind_headless_render_damaged vgd.log "${VG[@]}" --log-file=vgd.log \
    "$BIN/pdtview" --headless cut --end -o d.png --size 320x200
summary
