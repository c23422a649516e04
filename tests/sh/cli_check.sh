#!/bin/bash
# pdt check end to end: exit 0 only for T*, 1 with the first violation
# otherwise, 2 for unreadable input.
# san: yes
source "$(dirname "$0")/lib.sh"
cd "$TMP"

printf '0 0\n10 0\n0 10\n10 10\n3 4\n' > sq.txt
printf '0 1 4\n0 4 2\n1 3 4\n2 4 3\n' > good.tri
"$PDT" check sq.txt good.tri > ok.out 2> ok.err; rc=$?
[ $rc -eq 0 ] && grep -q '^ok: ' ok.out && ok accepts_delaunay || fail accepts_delaunay "rc=$rc $(cat ok.err)"
# Any rotation and order of the same triangles is fine.
printf '4 2 0\n3 4 1\n# comment\n4 0 1\n\n4 3 2\n' > rot.tri
"$PDT" check sq.txt rot.tri > /dev/null 2>&1; rc=$?
[ $rc -eq 0 ] && ok accepts_any_rotation_and_order || fail accepts_any_rotation_and_order "rc=$rc"
# The .ele written by pdt triangulate checks too.
"$PDT" triangulate sq.txt -o sq.ele && "$PDT" check sq.txt sq.ele > /dev/null && ok accepts_ele || fail accepts_ele

# Not Delaunay: the other diagonal, a missing triangle, a clockwise one.
printf '0 0\n10 0\n10 10\n0 10\n' > q.txt     # a square: cocircular, the tie rule picks one diagonal
printf '0 1 4\n0 4 2\n1 3 4\n' > missing.tri
"$PDT" check sq.txt missing.tri > /dev/null 2> m.err; rc=$?
[ $rc -eq 1 ] && grep -q 'NOT the Delaunay triangulation' m.err && ok rejects_missing_triangle \
    || fail rejects_missing_triangle "rc=$rc $(cat m.err)"
printf '0 1 4\n0 4 2\n1 3 4\n2 3 4\n' > cw.tri
"$PDT" check sq.txt cw.tri > /dev/null 2> cw.err; rc=$?
[ $rc -eq 1 ] && ok rejects_clockwise_triangle || fail rejects_clockwise_triangle "rc=$rc $(cat cw.err)"
printf '0 1 3\n1 2 3\n' > flip0.tri
printf '0 1 2\n0 2 3\n' > flip1.tri
"$PDT" check q.txt flip0.tri > /dev/null 2>&1; r0=$?
"$PDT" check q.txt flip1.tri > /dev/null 2>&1; r1=$?
# q.txt is 0=(0,0) 1=(10,0) 2=(10,10) 3=(0,10): exactly one diagonal is T*.
if [ $((r0 + r1)) -eq 1 ] && { [ $r0 -eq 0 ] || [ $r0 -eq 1 ]; }; then ok cocircular_square_one_diagonal_only
else fail cocircular_square_one_diagonal_only "r0=$r0 r1=$r1"; fi

# Input errors: exit 2.
printf '0 1 4\n0 4 9\n' > range.tri
"$PDT" check sq.txt range.tri 2> r.err; rc=$?
[ $rc -eq 2 ] && grep -q 'range.tri:2: point index 9 out of range (5 points)' r.err && ok index_out_of_range \
    || fail index_out_of_range "rc=$rc $(cat r.err)"
printf '0 1\n' > short.tri
"$PDT" check sq.txt short.tri 2> s.err; rc=$?
[ $rc -eq 2 ] && grep -q 'short.tri:1: missing point index' s.err && ok malformed_triangles || fail malformed_triangles
"$PDT" check nosuch.txt good.tri 2> /dev/null; [ $? -eq 2 ] && ok missing_points_file || fail missing_points_file
"$PDT" check sq.txt 2> /dev/null; [ $? -eq 2 ] && ok usage_one_argument || fail usage_one_argument
"$PDT" check --help | grep -q '^usage: pdt check POINTS TRIANGLES' && ok help || fail help
summary
