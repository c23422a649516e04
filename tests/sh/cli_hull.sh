#!/bin/bash
# pdt hull end to end: Graham's scan Version B on the thesis' cases.
# san: yes
source "$(dirname "$0")/lib.sh"
cd "$TMP"

# The square with points along its sides (and one inside, and a copy of a
# corner): only the four corners, counter-clockwise from the rightmost lowest.
printf '0 0\n5 0\n10 0\n10 5\n10 10\n5 10\n0 10\n0 5\n5 5\n10 0\n' > sq.txt
"$PDT" hull sq.txt > h.out 2> h.err; rc=$?
[ $rc -eq 0 ] && [ "$(tr '\n' ' ' < h.out)" = "2 4 6 0 " ] && ok square_with_side_points_gives_corners \
    || fail square_with_side_points_gives_corners "rc=$rc got: $(tr '\n' ' ' < h.out) $(cat h.err)"

# Angular ties around the origin (10,0): of (10,5) and (10,10), and of (5,0)
# and (0,0), only the farther point is kept.
printf '10 0\n10 5\n10 10\n0 10\n5 0\n0 0\n5 5\n' > tie.txt
"$PDT" hull tie.txt > t.out; rc=$?
[ $rc -eq 0 ] && [ "$(tr '\n' ' ' < t.out)" = "0 2 3 5 " ] && ok angular_tie_keeps_farther \
    || fail angular_tie_keeps_farther "got: $(tr '\n' ' ' < t.out)"

# Hull of a triangle written to a file, atomically.
printf '0 0\n4 0\n0 4\n1 1\n' > tri.txt
"$PDT" hull tri.txt -o tri.hull && [ "$(tr '\n' ' ' < tri.hull)" = "1 2 0 " ] && ok output_file || fail output_file
"$PDT" hull tri.txt --stats 2> st.err > /dev/null && grep -q '"hull": 3' st.err && ok stats || fail stats "$(cat st.err)"

# Bad input: exit 2, file and line named, no output file.
printf '0 0\n4 zero\n' > bad.txt
"$PDT" hull bad.txt -o bad.hull 2> bad.err; rc=$?
[ $rc -eq 2 ] && grep -q "bad.txt:2: 'zero' is not a number" bad.err && [ ! -e bad.hull ] \
    && ok bad_input || fail bad_input "rc=$rc $(cat bad.err)"
cp tri.txt self.txt
"$PDT" hull self.txt -o self.txt 2> self.err; rc=$?
[ $rc -eq 2 ] && cmp -s self.txt tri.txt && grep -q 'would replace the input' self.err \
    && ok output_would_replace_input || fail output_would_replace_input "rc=$rc"
"$PDT" hull --help | grep -q '^usage: pdt hull INPUT' && ok help || fail help
"$PDT" hull 2> /dev/null; [ $? -eq 2 ] && ok usage_no_input || fail usage_no_input
summary
