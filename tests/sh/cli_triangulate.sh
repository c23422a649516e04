#!/bin/bash
# pdt triangulate end to end: the canonical format byte for byte, the output
# formats, messages, --stats, --scale, and bad inputs (exit 2, the message
# names file and line, no output file left behind).
# san: yes
source "$(dirname "$0")/lib.sh"
cd "$TMP"

# A square with one point inside: T* joins the inner point to every corner.
printf '0 0\n10 0\n0 10\n10 10\n3 4\n' > sq.txt
printf '0 1 4\n0 4 2\n1 3 4\n2 4 3\n' > sq.want
"$PDT" triangulate sq.txt > sq.out 2> sq.err; rc=$?
if [ $rc -eq 0 ] && cmp -s sq.out sq.want && [ ! -s sq.err ]; then ok canonical_stdout_byte_for_byte
else fail canonical_stdout_byte_for_byte "rc=$rc out=$(tr '\n' ' ' < sq.out) err=$(cat sq.err)"; fi

"$PDT" triangulate sq.txt -o sq.tri && cmp -s sq.tri sq.want && ok output_tri_file || fail output_tri_file
"$PDT" triangulate - < sq.txt | cmp -s - sq.want && ok input_from_stdin || fail input_from_stdin

# The same points in other spellings: comments, blank lines, CRLF, .node.
printf '# a square\r\n\r\n0 0 \r\n10\t0\r\n0 10   # left top\r\n10 10\r\n3 4' > sq_crlf.txt
"$PDT" triangulate sq_crlf.txt | cmp -s - sq.want && ok crlf_comments_blank_lines || fail crlf_comments_blank_lines
printf '5 2 0 1\n1 0 0 1\n2 10 0 1\n3 0 10 1\n4 10 10 1\n5 3 4 0\n' > sq.node
"$PDT" triangulate sq.node | cmp -s - sq.want && ok node_input_1_based || fail node_input_1_based

"$PDT" triangulate sq.txt -o sq.off
printf 'OFF\n5 4 0\n0 0 0\n10 0 0\n0 10 0\n10 10 0\n3 4 0\n3 0 1 4\n3 0 4 2\n3 1 3 4\n3 2 4 3\n' | cmp -s - sq.off \
    && ok output_off || fail output_off "$(cat sq.off)"
mkdir ele && "$PDT" triangulate sq.txt -o ele/sq.ele && [ -f ele/sq.node ] \
    && grep -v '^#' ele/sq.ele | cmp -s - <(printf '4 3 0\n0 0 1 4\n1 0 4 2\n2 1 3 4\n3 2 4 3\n') \
    && ok output_ele_with_node || fail output_ele_with_node
# The .ele/.node pair is read back by pdt itself.
"$PDT" triangulate ele/sq.node | cmp -s - sq.want && ok ele_node_roundtrip || fail ele_node_roundtrip

# Duplicates: dropped, counted, represented by the first copy.
printf '0 0\n10 0\n0 10\n10 0\n10 10\n3 4\n0 0\n' > dup.txt
"$PDT" triangulate dup.txt > dup.out 2> dup.err
if grep -q '2 duplicate points dropped' dup.err && ! grep -qE '(^| )(3|6)( |$)' dup.out && [ "$(wc -l < dup.out)" -eq 4 ]; then
    ok duplicate_points; else fail duplicate_points "$(cat dup.err) / $(cat dup.out)"; fi

# Degenerate inputs: no triangles and a message saying why.
printf '0 0\n1 1\n2 2\n5 5\n' > col.txt
"$PDT" triangulate col.txt > col.out 2> col.err; rc=$?
[ $rc -eq 0 ] && [ ! -s col.out ] && grep -q '0 triangles: all 4 distinct points are collinear' col.err \
    && ok all_collinear || fail all_collinear "rc=$rc $(cat col.err)"
printf '7 7\n7 7\n8 9\n' > two.txt
"$PDT" triangulate two.txt > two.out 2> two.err; rc=$?
[ $rc -eq 0 ] && [ ! -s two.out ] && grep -q 'only 2 distinct points' two.err \
    && ok fewer_than_three_points || fail fewer_than_three_points "rc=$rc $(cat two.err)"
: > empty.txt
"$PDT" triangulate empty.txt > e.out 2> e.err; rc=$?
[ $rc -eq 0 ] && [ ! -s e.out ] && grep -q 'only 0 distinct points' e.err && ok empty_file || fail empty_file

# --stats: one JSON object with the figures.
"$PDT" triangulate dup.txt --stats > /dev/null 2> st.err
if python3 - st.err <<'PY'
import json, sys
line = [l for l in open(sys.argv[1]) if l.startswith('{')][0]
s = json.loads(line)
assert s["n"] == 7 and s["duplicates"] == 2 and s["unique"] == 5, s
assert s["triangles"] == 4 and s["hull"] == 4, s
for k in ("read", "sort", "kernel", "canonical", "write", "total"):
    assert s["seconds"][k] >= 0, k
sec = s["seconds"]
phases = sum(sec[k] for k in ("read", "sort", "kernel", "canonical", "write"))
assert phases <= sec["total"] + 1e-6, sec
assert s["peak_rss_kib"] > 0
PY
then ok stats_json; else fail stats_json "$(cat st.err)"; fi

# --scale: decimals multiplied and rounded; collisions reported.
printf '0 0\n1.0 0\n0 0.999\n1.04 1.0\n0.3 0.4\n1.001 -0.0004\n' > dec.txt
"$PDT" triangulate dec.txt --scale 10 > dec.out 2> dec.err; rc=$?
[ $rc -eq 0 ] && grep -q '1 point became equal to a different point after rounding with --scale 10' dec.err \
    && [ "$(wc -l < dec.out)" -eq 4 ] && cmp -s dec.out sq.want && ok scale_rounding_and_collisions \
    || fail scale_rounding_and_collisions "rc=$rc $(cat dec.err) $(cat dec.out)"

# Bad inputs: exit 2, "FILE:LINE: what", nothing written.
bad_input() { # NAME CONTENT EXPECTED-MESSAGE [extra args]
    local name=$1 content=$2 want=$3; shift 3
    mkdir -p "bad_$name"; printf "$content" > "bad_$name/in.txt"
    (cd "bad_$name" && "$PDT" triangulate in.txt -o out.tri "$@" > /dev/null 2> err); local rc=$?
    if [ $rc -eq 2 ] && grep -qF -- "$want" "bad_$name/err" && [ "$(ls -A "bad_$name")" = "$(printf 'err\nin.txt')" ]; then
        ok "bad_input_$name"
    else fail "bad_input_$name" "rc=$rc files=$(ls -A "bad_$name" | tr '\n' ' ') err=$(cat "bad_$name/err")"; fi
}
bad_input out_of_range '1 2\n3 4\n5 4294967296\n' 'in.txt:3: coordinate 4294967296 does not fit in 32 bits'
bad_input not_a_number '1 2\n\nx 4\n' "in.txt:3: 'x' is not a number"
bad_input decimal_without_scale '1 2\n1.5 4\n' 'in.txt:2: coordinate 1.5 is not an integer (decimal coordinates need --scale K)'
bad_input missing_coordinate '1 2\n3\n' 'in.txt:2: missing y coordinate'
bad_input extra_junk '1 2\n3 4 5\n' "in.txt:2: unexpected '5' after the coordinates"
bad_input scaled_out_of_range '1 2\n3 4e9\n' 'in.txt:2: coordinate 4e9 times scale 1 does not fit in 32 bits' --scale 1
mkdir -p bad_node && printf '3 3 0 0\n1 0 0\n2 1 0\n3 0 1\n' > bad_node/in.node
(cd bad_node && "$PDT" triangulate in.node -o out.tri 2> err); rc=$?
[ $rc -eq 2 ] && grep -qF 'in.node:1: .node header says dimension 3' bad_node/err && [ ! -e bad_node/out.tri ] \
    && ok bad_node_header || fail bad_node_header "rc=$rc $(cat bad_node/err)"
mkdir -p bad_count && printf '4 2 0 0\n1 0 0\n2 1 0\n3 0 1\n' > bad_count/in.node
(cd bad_count && "$PDT" triangulate in.node -o out.tri 2> err); rc=$?
[ $rc -eq 2 ] && grep -qF 'in.node:4: file ends after 3 of the 4 points' bad_count/err && [ ! -e bad_count/out.tri ] \
    && ok bad_node_count || fail bad_node_count "rc=$rc $(cat bad_count/err)"
"$PDT" triangulate "$TMP" -o d.tri 2> dir.err; rc=$?
[ $rc -eq 2 ] && grep -q 'is a directory' dir.err && [ ! -e d.tri ] && ok input_is_directory || fail input_is_directory
"$PDT" triangulate nosuch.txt -o n.tri 2> ns.err; rc=$?
[ $rc -eq 2 ] && grep -q 'nosuch.txt: cannot open: No such file or directory' ns.err && [ ! -e n.tri ] \
    && ok input_missing || fail input_missing
"$PDT" triangulate /proc/self/mem -o m.tri 2> mem.err; rc=$?
[ $rc -eq 2 ] && grep -q '/proc/self/mem: read error' mem.err && [ ! -e m.tri ] \
    && ok input_unreadable || fail input_unreadable "rc=$rc $(cat mem.err)"
"$PDT" triangulate sq.txt -o nodir/x.tri 2> nd.err; rc=$?
[ $rc -eq 2 ] && grep -q 'nodir/x.tri: cannot create' nd.err && ok output_dir_missing || fail output_dir_missing
cp sq.txt self.tri
"$PDT" triangulate self.tri -o self.tri 2> self.err; rc=$?
[ $rc -eq 2 ] && cmp -s self.tri sq.txt && ok output_would_replace_input || fail output_would_replace_input
cp sq.node same.node
"$PDT" triangulate same.node -o same.ele 2> same.err; rc=$?
[ $rc -eq 2 ] && cmp -s same.node sq.node && [ ! -e same.ele ] && ok ele_node_would_replace_input || fail ele_node_would_replace_input
# A previous output survives a failed run untouched.
printf 'keep\n' > keep.tri
printf '1 2\nbad\n' > bad2.txt
"$PDT" triangulate bad2.txt -o keep.tri 2> /dev/null
[ "$(cat keep.tri)" = keep ] && ok failed_run_keeps_old_output || fail failed_run_keeps_old_output

# Usage.
"$PDT" triangulate --help > h.out; rc=$?
[ $rc -eq 0 ] && grep -q '^usage: pdt triangulate INPUT' h.out && ok help || fail help
"$PDT" triangulate > /dev/null 2>&1; [ $? -eq 2 ] && ok usage_no_input || fail usage_no_input
"$PDT" triangulate sq.txt --frobnicate 2> u.err; [ $? -eq 2 ] && grep -q "unknown option '--frobnicate'" u.err \
    && ok usage_unknown_option || fail usage_unknown_option
"$PDT" triangulate sq.txt --scale 0 2> /dev/null; [ $? -eq 2 ] && ok usage_bad_scale || fail usage_bad_scale
"$PDT" triangulate sq.txt --trace-level 7 2> /dev/null; [ $? -eq 2 ] && ok usage_bad_trace_level || fail usage_bad_trace_level
summary
