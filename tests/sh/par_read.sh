#!/bin/bash
# pdt triangulate under mpirun, where every rank reads and parses its own
# part of the input file: for text, CSV with a header, TSV with CRLF and
# comments, .node with attributes and markers, --scale decimals, duplicates
# across the parts, a file with fewer lines than ranks, and with tiny
# PDT_COMM_CHUNK messages, the output and the messages are the plain run's
# for P in {2,3,8}; a bad line in the middle or in the last part is reported
# with the plain run's message (file and line), exit 2, no output, for P in
# {2,8}.  (P = 1 is the plain pipeline; tests/unit/test_par_read.c compares
# P = 1..8 with the plain reader on many more files.)
source "$(dirname "$0")/lib.sh"
cd "$TMP"
export OMPI_MCA_rmaps_base_oversubscribe=1
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi

# same NAME INPUT [OPTIONS...]: every P gives the plain run's bytes and messages
same() {
    local name=$1 in=$2; shift 2
    if ! "$PDT" triangulate "$in" -o "$name.ref.tri" "$@" 2> ref.err; then
        fail "plain_$name" "$(cat ref.err)"; return
    fi
    local p
    for p in 2 3 8; do
        rm -f "$name.p$p.tri"
        if ! timeout 120 mpirun -np "$p" -x PDT_COMM_CHUNK="${CHUNK:-}" "$PDT" triangulate "$in" \
            -o "$name.p$p.tri" "$@" > mpi.out 2> mpi.err; then
            fail "${name}_p$p" "exit $? $(head -3 mpi.err)"
        elif ! cmp -s "$name.ref.tri" "$name.p$p.tri"; then
            fail "${name}_p$p" "output differs from the plain run"
        elif ! diff -q ref.err mpi.err > /dev/null; then
            fail "${name}_p$p" "messages differ: $(head -2 mpi.err) / $(head -2 ref.err)"
        else
            ok "${name}_p$p"
        fi
    done
}

# bad NAME INPUT: every P reports the plain run's one message, exit 2, no file
bad() {
    local name=$1 in=$2
    "$PDT" triangulate "$in" -o "$name.tri" 2> ref.err
    local rc=$?
    if [ "$rc" -ne 2 ] || [ -e "$name.tri" ]; then fail "plain_$name" "exit $rc"; return; fi
    local p
    for p in 2 8; do
        timeout 120 mpirun -np "$p" "$PDT" triangulate "$in" -o "$name.tri" > mpi.out 2> mpi.err
        rc=$?
        if [ "$rc" -ne 2 ]; then
            fail "${name}_p$p" "exit $rc, want 2"
        elif [ -e "$name.tri" ]; then
            fail "${name}_p$p" "an output file was left"
        elif ! diff -q ref.err <(grep '^pdt:' mpi.err) > /dev/null; then
            fail "${name}_p$p" "message '$(head -2 mpi.err)', plain '$(cat ref.err)'"
        else
            ok "${name}_p$p"
        fi
    done
}

"$PDT" gen uniform 3000 --seed 5 -o u.txt || fail gen_uniform
"$PDT" gen duplicates 3000 --seed 5 -o d.txt || fail gen_duplicates
same text u.txt
same duplicates d.txt
CHUNK=64 same text_chunk64 u.txt
CHUNK=64 same duplicates_chunk64 d.txt

{ echo "x,y"; sed 's/ /,/' u.txt; } > h.csv
same csv_header h.csv
{ echo "# points"; echo; printf 'x\ty\r\n'; sed 's/ /\t/; s/$/\r/' d.txt | sed '100a # a comment\r'; } > t.tsv
same tsv_crlf_comments t.tsv
awk 'BEGIN { print "# a node file"; print "3000 2 1 1" } { print NR - 1, $1, $2, "0.5", NR % 2 }' \
    u.txt > n.node
same node n.node
awk '{ printf "%d.%d %d.25\n", $1 / 1000, $1 % 1000, $2 / 1000 }' d.txt > s.txt
same scale s.txt --scale 10
printf '1 2\n3 4\n5 7\n' > few.txt
same fewer_lines_than_ranks few.txt

# bad lines: in the middle, in the last part, several (the first wins)
awk 'NR == 1500 { print "12 x"; next } { print }' u.txt > bad_mid.txt
bad bad_middle bad_mid.txt
awk 'NR == 2990 { print "12 13 14"; next } { print }' u.txt > bad_last.txt
bad bad_last_part bad_last.txt
awk 'NR == 1600 || NR == 2800 || NR == 2000 { print "oops"; next } { print }' u.txt > bad3.txt
bad bad_several bad3.txt
sed '2000s/^[0-9]*/7777/' n.node > bad_idx.node
bad node_index_out_of_order bad_idx.node
sed '2s/^3000/3001/' n.node > short.node
bad node_file_ends short.node
sed '2s/^3000/2000/' n.node > long.node
bad node_more_points long.node
summary
