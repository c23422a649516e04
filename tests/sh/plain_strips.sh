#!/bin/bash
# The plain run on strips (src/par/plain.c): an untraced run with a .tri
# output of at least 2^21 points (unless a sample of them says the merge
# would redo most of the work) sorts its points, cuts them into 2 strips
# and runs SRM on one strip after the other in one block, to hold the edges
# of half the points instead of all.  The triangles must be the bytes of the
# whole kernel's, on every generator family (grids, circles, collinear runs,
# duplicates) and every size down to 1 point; PDT_PLAIN_STRIPS=K forces
# K strips (0: the whole kernel) at any size.  --stats says which way a run
# went (per_rank[].strips) and has the same figures both ways; the peak
# memory of a 2.2*10^6-point run is measured, not timed (the default's cases
# in the plain build only: the sanitizer build would take minutes on them).
# san: yes
source "$(dirname "$0")/lib.sh"
cd "$TMP"

# same NAME IN K: `pdt triangulate IN` with K strips writes ref.tri's bytes and
# the same figures (and says it worked on K strips)
same() {
    local name=$1 in=$2 k=$3
    if ! PDT_PLAIN_STRIPS=$k "$PDT" triangulate "$in" -o out.tri --stats > /dev/null \
        2> out.json; then
        fail "$name" "exit non-zero: $(head -3 out.json)"
    elif ! cmp -s ref.tri out.tri; then
        fail "$name" "output differs from the whole kernel's ($(wc -l < out.tri) vs $(wc -l < ref.tri) lines)"
    elif [ "$(figures out.json)" != "$(figures ref.json)" ]; then
        fail "$name" "figures differ: $(figures out.json) vs $(figures ref.json)"
    elif ! grep -q "\"strips\": $k}" out.json; then
        fail "$name" "per_rank[].strips is not $k: $(grep -o '"strips": [0-9]*' out.json)"
    else
        ok "$name"
    fi
}
figures() { grep -o '"\(n\|unique\|duplicates\|triangles\|hull\|collinear\)": [a-z0-9]*' "$1" | tr '\n' ' '; }

for kind in uniform grid circle circle-round parabola clusters collinear duplicates column; do
    for n in 1 2 3 4 7 40 1000; do
        in=$kind-$n.txt
        "$PDT" gen "$kind" "$n" --seed 3 -o "$in" 2> /dev/null || continue
        PDT_PLAIN_STRIPS=0 "$PDT" triangulate "$in" -o ref.tri --stats > /dev/null \
            2> ref.json || { fail "whole_${kind}_$n" "$(head -3 ref.json)"; continue; }
        for k in 2 3 5 16; do same "${kind}_${n}_k$k" "$in" "$k"; done
    done
done

# by default: 2 strips from 2^21 points on, the whole kernel below, traced or
# with points to write (.ele needs the points back in input order)
if [ "$BIN" != "$ROOT/bin" ]; then summary; exit; fi
"$PDT" gen clusters 2200000 --seed 7 -o big.txt || fail gen_big
PDT_PLAIN_STRIPS=0 /usr/bin/time -f "%M" -o whole.kib "$PDT" triangulate big.txt -o ref.tri \
    --stats > /dev/null 2> ref.json || fail whole_big "$(head -3 ref.json)"
/usr/bin/time -f "%M" -o strips.kib "$PDT" triangulate big.txt -o out.tri --stats > /dev/null \
    2> out.json || fail strips_big "$(head -3 out.json)"
if cmp -s ref.tri out.tri && grep -q '"strips": 2}' out.json; then
    ok default_big_two_strips
else
    fail default_big_two_strips "$(grep -o '"strips": [0-9]*' out.json), cmp $(cmp ref.tri out.tri 2>&1)"
fi
# (the whole kernel holds 72 bytes of edges per point, two strips 36 + 12:
# about 84 against 62 bytes per point, plus the program)
whole=$(tail -1 whole.kib) strips=$(tail -1 strips.kib)
if [ "$strips" -lt $((whole * 85 / 100)) ]; then
    ok "peak_memory_smaller # $strips KiB against $whole KiB"
else
    fail peak_memory_smaller "$strips KiB against $whole KiB (want below 85 %)"
fi
# where the merge would redo most of the work (points in convex position, a
# narrow column: 6x the time and 3.5x the memory on 2.2*10^6 points of a
# parabola), a sample of the points says so and the whole kernel runs
for kind in parabola column; do
    "$PDT" gen "$kind" 2200000 --seed 4 -o hostile.txt || fail "gen_$kind"
    if "$PDT" triangulate hostile.txt -o hostile.tri --stats > /dev/null 2> h.json &&
        grep -q '"strips": 0}' h.json; then
        ok "default_${kind}_whole_kernel"
    else
        fail "default_${kind}_whole_kernel" "$(grep -o '"strips": [0-9]*' h.json) $(head -2 h.json)"
    fi
done
for case in "below:2000000:0:tri" "traced:2200000:0:tri" "ele:2200000:0:ele"; do
    IFS=: read -r name n want ext <<< "$case"
    head -"$n" big.txt > c.txt
    extra=()
    [ "$name" = traced ] && extra=(--trace run)
    rm -rf run
    if "$PDT" triangulate c.txt -o "c.$ext" "${extra[@]}" --stats > /dev/null 2> c.json &&
        grep -q "\"strips\": $want}" c.json; then
        ok "default_${name}_whole_kernel"
    else
        fail "default_${name}_whole_kernel" "$(grep -o '"strips": [0-9]*' c.json) $(head -2 c.json)"
    fi
done
# what the memory buys: under an address-space limit that the whole kernel
# cannot run in (it needs about 198 MB here for 2.2*10^6 points, two strips
# about 152 MB), the default run succeeds; under a lower one both fail with
# the plain run's message (no rank named), exit 2 and no output
limited() { (ulimit -v "$1"; env $2 "$PDT" triangulate big.txt -o lim.tri > /dev/null 2> lim.err); }
rm -f lim.tri
if limited 175000 PDT_PLAIN_STRIPS=0; then
    fail whole_kernel_over_limit "ran in 175000 KiB of address space (the limit says nothing here)"
elif limited 175000 PDT_PLAIN_STRIPS=2 && cmp -s ref.tri lim.tri; then
    ok "two_strips_under_limit_whole_kernel_cannot"
else
    fail two_strips_under_limit_whole_kernel_cannot "$(head -2 lim.err)"
fi
rm -f lim.tri
for v in 150000 120000; do
    limited "$v" PDT_PLAIN_STRIPS=2
    rc=$?
    if [ "$rc" -eq 2 ] && [ ! -e lim.tri ] && grep -q '^pdt: triangulation failed: .*out of memory' lim.err &&
        ! grep -q 'rank' lim.err; then
        ok "out_of_memory_message_$v # $(grep -v duplicate lim.err)"
    else
        fail "out_of_memory_message_$v" "exit $rc, $(head -2 lim.err)"
    fi
    rm -f lim.tri
done
summary
