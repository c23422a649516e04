#!/bin/bash
# --partition bisect under mpirun: the regions are boxes by recursive
# bisection across the longer side and the merge tree follows it.  A traced
# run passes `pdt trace check` (its manifest says partition = bisect, and the
# checker asks one cut to separate the two groups of every merge), with the
# merges of the bisection tree (P = 5: [0,3)|[3,5) at the top, [0,2)|[2,3)
# below it); a trace whose regions overlap is refused; the seams shrink
# (--stats: border sets per level; at P = 8 the level-0 seams span half the
# input's side, the strips' all of it); merges shared along their seams
# give the same bytes, and so do cuts moved by counts; a bad value is a
# usage error.
source "$(dirname "$0")/lib.sh"
cd "$TMP"
export OMPI_MCA_rmaps_base_oversubscribe=1
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi

"$PDT" gen uniform 3000 --seed 5 -o u.txt
"$PDT" triangulate u.txt -o ref.tri
mpirun -np 5 "$PDT" triangulate u.txt -o b5.tri --partition bisect --trace run5 2> run5.err; rc=$?
if [ $rc -eq 0 ] && cmp -s ref.tri b5.tri; then ok traced_bisect_5_ranks_same_output
else fail traced_bisect_5_ranks_same_output "rc=$rc $(head -3 run5.err)"; fi
grep -q '^partition = bisect$' run5/manifest && ok manifest_names_bisect \
    || fail manifest_names_bisect "$(cat run5/manifest)"
"$PDT" trace check run5 > check.out 2>&1; rc=$?
if [ $rc -eq 0 ]; then ok trace_check_bisect_5_ranks; else fail trace_check_bisect_5_ranks "$(cat check.out)"; fi

# the merges of the bisection tree of 5 ranks: 3|2, then 2|1 and 1|1
"$PDT" trace dump run5 --kind merge-begin | sed 's/.*merge-begin //' | sort > merges.txt
printf '%s\n' 'level=0 left=0 right=1 end=2 at=1' 'level=1 left=0 right=2 end=3 at=2' \
    'level=1 left=3 right=4 end=5 at=4' 'level=2 left=0 right=3 end=5 at=3' | sort > want.txt
if cmp -s merges.txt want.txt; then ok merges_follow_the_bisection_tree
else fail merges_follow_the_bisection_tree "$(cat merges.txt)"; fi

# the same trace read as strips: rank 1's points are not after rank 0's
sed 's/^partition = bisect$/partition = strips/' run5/manifest > m && cp m run5/manifest
if "$PDT" trace check run5 > bad.out 2>&1; then fail strips_check_refuses_boxes "$(cat bad.out)"
else ok strips_check_refuses_boxes; fi

# a strips trace whose merges are renumbered so that a merge joins regions
# no cut separates: ranks 0 and 2 of a strip run (rank 1 in between)
mpirun -np 4 "$PDT" triangulate u.txt -o s4.tri --trace run4 2> /dev/null
echo 'partition = bisect' >> run4/manifest
if "$PDT" trace check run4 > ok4.out 2>&1; then ok strips_regions_are_bisect_regions_too
else fail strips_regions_are_bisect_regions_too "$(cat ok4.out)"; fi

# P = 16 and P > n, traced
mpirun -np 16 "$PDT" triangulate u.txt -o b16.tri --partition bisect --trace run16 2> /dev/null
if cmp -s ref.tri b16.tri && "$PDT" trace check run16 > /dev/null 2>&1; then ok trace_check_bisect_16_ranks
else fail trace_check_bisect_16_ranks "$("$PDT" trace check run16 2>&1 | head -3)"; fi
# no --partition: 16 ranks are bisected, traced or not, and the manifest says so
mpirun -np 16 "$PDT" triangulate u.txt -o a16.tri --trace runa16 --stats 2> a16.json > /dev/null
if cmp -s ref.tri a16.tri && grep -qx 'partition = bisect' runa16/manifest &&
   grep -q '"partition": "bisect"' a16.json && "$PDT" trace check runa16 > /dev/null 2>&1; then
    ok default_16_ranks_bisected_and_traced_as_such
else fail default_16_ranks_bisected_and_traced_as_such "$(grep partition runa16/manifest a16.json | head -3)"; fi
"$PDT" gen uniform 6 --seed 1 -o six.txt
"$PDT" triangulate six.txt -o six.tri
mpirun -np 9 "$PDT" triangulate six.txt -o six9.tri --partition bisect --trace run9 2> /dev/null
if cmp -s six.tri six9.tri && "$PDT" trace check run9 > /dev/null 2>&1; then ok trace_check_bisect_more_ranks_than_points
else fail trace_check_bisect_more_ranks_than_points "$("$PDT" trace check run9 2>&1 | head -3)"; fi

# --stats: the border sets per level; the bisection's below the top are smaller
"$PDT" gen uniform 40000 --seed 9 -o big.txt
for part in strips bisect; do
    mpirun -np 8 "$PDT" triangulate big.txt -o $part.tri --partition $part --stats 2> $part.json > /dev/null
done
read -r s0 b0 < <(python3 - <<'PY'
import json
s = json.load(open("strips.json"))["parallel"]; b = json.load(open("bisect.json"))["parallel"]
assert s["partition"] == "strips" and b["partition"] == "bisect"
print(s["largest_border_set_by_level"][0], b["largest_border_set_by_level"][0])
PY
)
if [ -n "$b0" ] && [ $((3 * b0)) -lt $((2 * s0)) ]; then ok stats_border_sets_by_level_shrink
else fail stats_border_sets_by_level_shrink "level 0: strips $s0, bisect $b0"; fi
cmp -s strips.tri bisect.tri && ok strips_and_bisect_same_bytes || fail strips_and_bisect_same_bytes "differ"

# the samples reach rank 0 by one gather below 64 ranks and up a binomial
# tree from there (PDT_TEST_BIS_GATHER=1 or 2 forces either in the test
# build): both must give rank 0 every rank's sample once, so the same cuts
# and every rank the same number of points (a sample lost or taken twice
# moves the cuts; P = 5, 6 and 7: trees with short branches)
for np in 5 6 7; do
    for g in 1 2; do
        mpirun -np $np -x PDT_TEST_BIS_GATHER=$g "$PDT_HOOKED" triangulate big.txt -o g$g.tri \
            --partition bisect --stats 2> g$g.json > /dev/null
    done
    pts=$(python3 - <<'PY'
import json
a, b = (json.load(open(f"g{g}.json"))["per_rank"] for g in (1, 2))
pa, pb = [r["points"] for r in a], [r["points"] for r in b]
print("same" if pa == pb else f"gather {pa} tree {pb}")
PY
)
    if [ "$pts" = same ] && cmp -s strips.tri g1.tri && cmp -s strips.tri g2.tri; then
        ok "samples_by_tree_same_cuts_np$np"
    else fail "samples_by_tree_same_cuts_np$np" "$pts"; fi
done

# merges shared along their seams (algorithm.md §3.13), forced on a small
# input with pieces of 20 points (PDT_SHARE_PIECE): the same bytes at
# P = 8 and 13, --stats counts the shared merges, and on uniform points no
# merge rank has to finish one alone; PDT_SHARE_PIECE=0 shares none
for np in 8 13; do
    mpirun -np $np -x PDT_SHARE_PIECE=20 "$PDT" triangulate big.txt -o sh$np.tri \
        --partition bisect --stats 2> sh$np.json > /dev/null
    got=$(python3 -c 'import json,sys; p=json.load(open(sys.argv[1]))["parallel"]
print(p["shared_merges"], p["shared_merges_done_alone"])' sh$np.json 2> /dev/null)
    if cmp -s strips.tri sh$np.tri && [ "${got% *}" -ge $((np - 1)) ] 2> /dev/null &&
       [ "${got#* }" = 0 ]; then ok "shared_merges_same_bytes_np$np"
    else fail "shared_merges_same_bytes_np$np" "shared, alone: $got"; fi
done
mpirun -np 8 -x PDT_SHARE_PIECE=0 "$PDT" triangulate big.txt -o sh0.tri --stats 2> sh0.json > /dev/null
if cmp -s strips.tri sh0.tri && grep -q '"shared_merges": 0,' sh0.json; then ok share_piece_0_shares_none
else fail share_piece_0_shares_none "$(grep -o '"shared_merges[^,]*' sh0.json)"; fi

# from 2^15 points a rank the sample's cuts are moved by counts of the
# points (docs/parallel.md, "Cuts moved by counts"): at P = 16 the same
# bytes, and every region within 3 % of n / P
"$PDT" gen uniform 540000 --seed 9 -o many.txt
"$PDT" triangulate many.txt -o many.tri
mpirun -np 16 "$PDT" triangulate many.txt -o many16.tri --partition bisect --stats \
    2> many16.json > /dev/null
spread=$(python3 -c 'import json,sys; d=json.load(open(sys.argv[1]))
p=[r["points"] for r in d["parallel"]["per_rank"]]; s=d["n"]/len(p)
print("ok" if max(p) < 1.03*s and min(p) > 0.97*s else f"{min(p)}..{max(p)}")' many16.json 2>&1)
if cmp -s many.tri many16.tri && [ "$spread" = ok ]; then ok counted_cuts_same_bytes_np16
else fail counted_cuts_same_bytes_np16 "regions: $spread"; fi

# a bad value
"$PDT" triangulate u.txt -o x.tri --partition boxes 2> bad.err; rc=$?
if [ $rc -eq 2 ] && grep -q "strips or bisect" bad.err; then ok partition_bad_value_usage
else fail partition_bad_value_usage "rc=$rc $(cat bad.err)"; fi
summary
