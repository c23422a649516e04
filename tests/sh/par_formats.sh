#!/bin/bash
# pdt triangulate under mpirun writes every output format in parallel (each
# rank its block at its offset): .tri, .ele with its .node, and .off are the
# plain run's bytes at P = 1..4, with the default and a tiny PDT_COMM_CHUNK
# (every transfer in many pieces), on inputs with negative coordinates,
# duplicates, and too few points for a triangle; standard output is gathered
# at rank 0; a rank that fails its share of an .ele write leaves neither the
# .ele nor the .node (nor a temporary).
source "$(dirname "$0")/lib.sh"
PDT=$PDT_HOOKED  # injects faults (PDT_TEST_*)
cd "$TMP"
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi

"$PDT" gen uniform 3000 --seed 5 -o u.txt
"$PDT" gen duplicates 500 --seed 5 -o d.txt
awk '{print $1 - 1073741824, $2 - 1073741824}' u.txt > neg.txt   # negative coordinates
printf '1 2\n3 4\n' > two.txt

# same NAME INPUT EXT P [CHUNK] : the mpirun output (and the .node of an .ele)
# is the plain run's
same() {
    local name=$1 in=$2 ext=$3 p=$4 chunk=${5:-}
    rm -f ref.* par.*
    "$PDT" triangulate "$in" -o "ref.$ext" 2> /dev/null
    if [ -n "$chunk" ]; then
        PDT_COMM_CHUNK=$chunk mpirun -np "$p" -x PDT_COMM_CHUNK "$PDT" triangulate "$in" \
            -o "par.$ext" > /dev/null 2> par.err
    else
        mpirun -np "$p" "$PDT" triangulate "$in" -o "par.$ext" > /dev/null 2> par.err
    fi
    local rc=$?
    if [ $rc -ne 0 ]; then fail "$name" "exit $rc $(head -3 par.err)"; return; fi
    if ! cmp -s "ref.$ext" "par.$ext"; then fail "$name" ".$ext differs from the plain run"; return; fi
    if [ "$ext" = ele ] && ! cmp -s ref.node par.node; then
        fail "$name" ".node differs from the plain run"; return
    fi
    if [ -n "$(ls -A | grep '\.tmp\.')" ]; then fail "$name" "temporary left: $(ls -A)"; return; fi
    ok "$name"
}

for ext in tri ele off; do
    for p in 1 2 3 4; do
        same "${ext}_uniform_p$p" u.txt "$ext" "$p"
        same "${ext}_negative_p$p" neg.txt "$ext" "$p"
    done
    same "${ext}_duplicates_p3" d.txt "$ext" 3
    same "${ext}_duplicates_p4_chunk7" d.txt "$ext" 4 7
    same "${ext}_uniform_p3_chunk13" u.txt "$ext" 3 13
    same "${ext}_two_points_p3" two.txt "$ext" 3
done

# standard output: gathered at rank 0, same bytes
"$PDT" triangulate neg.txt -o ref.tri 2> /dev/null
mpirun -np 3 "$PDT" triangulate neg.txt > so.tri 2> so.err; rc=$?
if [ $rc -eq 0 ] && cmp -s ref.tri so.tri; then ok stdout_gathered
else fail stdout_gathered "rc=$rc $(head -3 so.err)"; fi

# a rank fails its share of an .ele write: nothing is left
mkdir -p wdir
PDT_TEST_FAIL_WRITE=2 mpirun -np 3 -x PDT_TEST_FAIL_WRITE "$PDT" triangulate u.txt -o wdir/f.ele \
    > /dev/null 2> fw.err; rc=$?
if [ $rc -eq 2 ] && grep -q 'rank 2, write: wdir/f.ele' fw.err && [ -z "$(ls -A wdir)" ]; then
    ok ele_write_fails_on_one_rank
else fail ele_write_fails_on_one_rank "rc=$rc files=$(ls -A wdir) $(grep pdt fw.err | head -3)"; fi
summary
