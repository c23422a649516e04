#!/bin/bash
# Points from a spreadsheet: "x,y" / "x;y" / "x<TAB>y" with an optional header
# line naming the columns give the same triangles as "x y"; what is still
# malformed is reported with file:line and exit 2.
# san: yes
source "$(dirname "$0")/lib.sh"
"$PDT" gen uniform 200 --seed 7 -o "$TMP/p.txt" || fail gen
"$PDT" triangulate "$TMP/p.txt" -o "$TMP/ref.tri"
{ echo 'x,y'; tr ' ' ',' < "$TMP/p.txt"; } > "$TMP/p.csv"
{ printf 'X;Y\r\n'; tr ' ' ';' < "$TMP/p.txt" | sed 's/$/\r/'; } > "$TMP/semi.txt"
{ printf 'x\ty\n'; tr ' ' '\t' < "$TMP/p.txt"; } > "$TMP/p.tsv"
for f in p.csv semi.txt p.tsv; do
    "$PDT" triangulate "$TMP/$f" -o "$TMP/$f.tri" 2> "$TMP/e"; rc=$?
    [ $rc -eq 0 ] && cmp -s "$TMP/ref.tri" "$TMP/$f.tri" && ok "same_triangles_$f" \
        || fail "same_triangles_$f" "rc=$rc $(cat "$TMP/e")"
done
out=$("$PDT" triangulate - < "$TMP/p.csv") && [ "$out" = "$(cat "$TMP/ref.tri")" ] \
    && ok csv_on_standard_input || fail csv_on_standard_input
"$PDT" check "$TMP/p.csv" "$TMP/ref.tri" > /dev/null && ok check_reads_csv || fail check_reads_csv
h1=$("$PDT" hull "$TMP/p.txt"); h2=$("$PDT" hull "$TMP/p.csv")
[ -n "$h1" ] && [ "$h1" = "$h2" ] && ok hull_reads_csv || fail hull_reads_csv
printf 'x,y\n1.5,2.25\n0,0\n3,0.5\n' > "$TMP/d.csv"
out=$("$PDT" triangulate "$TMP/d.csv" --scale 100); rc=$?
[ $rc -eq 0 ] && [ "$out" = "0 1 2" ] && ok scale_decimals_csv || fail scale_decimals_csv "rc=$rc [$out]"
printf 'x,y\n1,2\n3,,4\n' > "$TMP/bad.csv"
"$PDT" triangulate "$TMP/bad.csv" -o "$TMP/bad.tri" 2> "$TMP/e"; rc=$?
[ $rc -eq 2 ] && grep -q "bad.csv:3: missing y coordinate" "$TMP/e" && [ ! -e "$TMP/bad.tri" ] \
    && ok empty_field_file_line || fail empty_field_file_line "rc=$rc $(cat "$TMP/e")"
printf 'x,y\n1,2\n3,4,5\n' > "$TMP/bad.csv"
"$PDT" triangulate "$TMP/bad.csv" 2> "$TMP/e"; rc=$?
[ $rc -eq 2 ] && grep -q "bad.csv:3: unexpected ',5'" "$TMP/e" \
    && ok third_column_file_line || fail third_column_file_line "rc=$rc $(cat "$TMP/e")"
printf 'name,x,y\n' > "$TMP/bad.csv"
"$PDT" triangulate "$TMP/bad.csv" 2> "$TMP/e"; rc=$?
[ $rc -eq 2 ] && grep -q "bad.csv:1: 'name' is not a number" "$TMP/e" \
    && ok three_name_header_refused || fail three_name_header_refused "rc=$rc $(cat "$TMP/e")"
summary
