#!/bin/bash
# pdtview's first opening of a run in bounded memory (issue 12): the build
# of the kept index holds its tables of objects (Graham's stacks and slot
# changes, the per-point sort tables, a level-2 run's edges) in memory only
# up to a share of --mem, and beyond it in temporary files' mappings whose
# pages it gives back as it goes, so its own memory (RssAnon, sampled by
# scripts/bench/tools/anon_peak.sh) does not grow with the run.  Figures are
# printed; the one assert is on memory, with a wide margin.
. "$(dirname "$0")/lib.sh"
V=$BIN/pdtview
own() { # RUN: peak RssAnon (KiB) of a first opening under --mem 1M
    rm -f "$1/.pdtview-index"
    "$ROOT/scripts/bench/tools/anon_peak.sh" "$TMP/own.out" "$V" "$1" --counts --end --mem 1M
}
for np in 50000 400000; do
    "$PDT" gen uniform $np --seed 3 > "$TMP/h$np.txt"
    "$PDT" hull "$TMP/h$np.txt" -o "$TMP/h$np.hull" --trace "$TMP/runh$np" >/dev/null 2>&1 ||
        fail "hull_record_$np"
done
small=$(own "$TMP/runh50000"); big=$(own "$TMP/runh400000")
echo "# first opening under --mem 1M, own memory: hull run of 50000 points ${small:-?} KiB," \
     "of 400000 points ${big:-?} KiB (its tables in memory would take some 27 MB)"
if [ -n "$small" ] && [ -n "$big" ] && [ "$big" -le $((small + 6144)) ]
then ok hull_build_own_memory_flat
else fail hull_build_own_memory_flat "${small:-?} KiB, then ${big:-?} KiB"; fi
# and the index it built under that budget gives the replay held in memory
"$V" "$TMP/runh400000" --counts --end --index off > "$TMP/cm.txt"
"$V" "$TMP/runh400000" --counts --end --mem 1M > "$TMP/ci.txt"
if [ -s "$TMP/cm.txt" ] && cmp -s "$TMP/cm.txt" "$TMP/ci.txt"; then ok hull_build_paged_same_counts
else fail hull_build_paged_same_counts "$(diff "$TMP/cm.txt" "$TMP/ci.txt" | head -3)"; fi
summary
