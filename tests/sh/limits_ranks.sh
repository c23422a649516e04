#!/bin/bash
# More points per rank than the kernel takes (PDT_KERNEL_MAX_POINTS, 2^29 - 1):
# refused before computing, naming the input, the limit and how many ranks
# would do; exit 2, no output, no trace points.bin.  The limit is lowered
# with the test hook PDT_TEST_KERNEL_LIMIT (2^29 points do not fit here);
# test_kernel_limit checks that the real constant is the kernel's.
source "$(dirname "$0")/lib.sh"
PDT=$PDT_HOOKED  # injects faults (PDT_TEST_*)
cd "$TMP"
"$PDT" gen uniform 100 --seed 4 -o in.txt
"$PDT" triangulate in.txt -o ref.tri

PDT_TEST_KERNEL_LIMIT=40 "$PDT" triangulate in.txt -o p1.tri --trace run1 2> p1.err; rc=$?
if [ $rc -eq 2 ] && grep -q '^pdt: in.txt: 100 points on 1 rank: more than 40 points per rank' p1.err &&
   grep -q 'at least 3 ranks (mpirun -np 3' p1.err && [ ! -e p1.tri ] && [ ! -e run1/points.bin ]; then
    ok plain_run_over_limit_refused
else fail plain_run_over_limit_refused "rc=$rc $(cat p1.err)"; fi

# the release program never reads the test hooks (only test builds do:
# bin/test/pdt, the sanitizer build): the same run goes through
if [ "$(basename "$BIN")" != san ]; then
    PDT_TEST_KERNEL_LIMIT=40 "$BIN/pdt" triangulate in.txt -o prod.tri 2> prod.err; rc=$?
    if [ $rc -eq 0 ] && cmp -s ref.tri prod.tri; then ok release_build_ignores_test_hooks
    else fail release_build_ignores_test_hooks "rc=$rc $(cat prod.err)"; fi
fi

if command -v mpirun > /dev/null; then
    PDT_TEST_KERNEL_LIMIT=40 mpirun -np 2 "$PDT" triangulate in.txt -o p2.tri 2> p2.err; rc=$?
    n=$(grep -c 'more than 40 points per rank' p2.err)
    if [ $rc -ne 0 ] && [ "$n" -eq 1 ] && grep -q 'in.txt: 100 points on 2 ranks' p2.err &&
       grep -q 'at least 3 ranks' p2.err && [ ! -e p2.tri ]; then
        ok two_ranks_over_limit_refused_once
    else fail two_ranks_over_limit_refused_once "rc=$rc $(cat p2.err)"; fi
    PDT_TEST_KERNEL_LIMIT=40 mpirun -np 3 "$PDT" triangulate in.txt -o p3.tri 2> p3.err; rc=$?
    [ $rc -eq 0 ] && cmp -s ref.tri p3.tri && ok enough_ranks_run || fail enough_ranks_run "rc=$rc $(cat p3.err)"
fi
summary
