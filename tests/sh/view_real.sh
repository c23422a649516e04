#!/bin/bash
# pdtview on real run folders: pdt triangulate --trace (sequential and under
# mpirun with several ranks, every gen family) and pdt hull --trace.  At the
# end of a triangulation run the viewer's final triangles are exactly the
# output; seeking equals stepping both ways at every cursor; pictures render.
. "$(dirname "$0")/lib.sh"
V=$BIN/pdtview

final_of() { "$V" "$1" --counts | sed -n 's/.* final \([0-9]*\) .*/\1/p'; }

# sequential, trace level 2 (kernel edges)
$PDT gen uniform 300 --seed 7 -o "$TMP/u.txt"
if $PDT triangulate "$TMP/u.txt" -o "$TMP/u.tri" --trace "$TMP/seq" --trace-level 2 &&
   [ "$(final_of "$TMP/seq")" = "$(wc -l < "$TMP/u.tri")" ]; then ok seq_final_equals_output
else fail seq_final_equals_output "viewer $(final_of "$TMP/seq"), output $(wc -l < "$TMP/u.tri")"; fi
if "$V" "$TMP/seq" --check | grep -q ' 0 differ'; then ok seq_seek_equals_step; else fail seq_seek_equals_step; fi
if "$V" --headless "$TMP/seq" --phase kernel --size 800x500 -o "$TMP/seq.png" --quiet && [ -s "$TMP/seq.png" ]; then
    ok seq_render; else fail seq_render; fi

# pdt hull: Graham Version B
if $PDT hull "$TMP/u.txt" --trace "$TMP/hull" >/dev/null && "$V" "$TMP/hull" --check | grep -q ' 0 differ' &&
   "$V" --headless "$TMP/hull" --phase graham-scan --size 800x500 -o "$TMP/hull.svg" --quiet &&
   xmllint --noout "$TMP/hull.svg"; then ok hull_run
else fail hull_run; fi

# several ranks, every family
if command -v mpirun >/dev/null; then
    for kind in uniform grid circle circle-round parabola clusters collinear duplicates column; do
        $PDT gen $kind 120 --seed 3 -o "$TMP/$kind.txt"
        if ! mpirun -np 3 $PDT triangulate "$TMP/$kind.txt" -o "$TMP/$kind.tri" --trace "$TMP/$kind" \
                >"$TMP/$kind.log" 2>&1; then
            fail "mpi_$kind" "$(tail -2 "$TMP/$kind.log")"; continue
        fi
        f=$(final_of "$TMP/$kind"); want=$(wc -l < "$TMP/$kind.tri")
        c=$("$V" "$TMP/$kind" --check)
        if [ "$f" = "$want" ] && echo "$c" | grep -q ' 0 differ' &&
           "$V" --headless "$TMP/$kind" --end --size 640x400 -o "$TMP/$kind.png" --quiet; then ok "mpi_$kind"
        else fail "mpi_$kind" "final $f, output $want; $c"; fi
    done
    # 4 ranks: the merge phases are there and render
    if mpirun -np 4 $PDT triangulate "$TMP/u.txt" -o "$TMP/u4.tri" --trace "$TMP/p4" >/dev/null 2>&1 &&
       "$V" --headless "$TMP/p4" --phase merge:1 --size 800x500 -o "$TMP/p4.pdf" --quiet &&
       pdftoppm -r 20 -png "$TMP/p4.pdf" "$TMP/p4page" && [ "$(final_of "$TMP/p4")" = "$(wc -l < "$TMP/u4.tri")" ]; then
        ok mpi4_merge_levels
    else fail mpi4_merge_levels; fi
    # a damaged run (one rank file cut short): warned about, still replayed
    cp -r "$TMP/p4" "$TMP/dmg" && truncate -s 3000 "$TMP/dmg/rank-0002.trace"
    if "$V" --headless "$TMP/dmg" --end --size 640x400 -o "$TMP/dmg.png" 2>"$TMP/dmg.err" >/dev/null &&
       grep -q 'rank-0002.trace' "$TMP/dmg.err" && "$V" "$TMP/dmg" --check 2>/dev/null | grep -q ' 0 differ'; then
        ok damaged_run
    else fail damaged_run "$(head -3 "$TMP/dmg.err")"; fi
else
    fail mpi "mpirun not installed"
fi
summary
