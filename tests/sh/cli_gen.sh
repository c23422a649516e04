#!/bin/bash
# pdt gen end to end: every kind, determinism, seeds, output files; and
# every kind triangulated and checked.
# san: yes
source "$(dirname "$0")/lib.sh"
cd "$TMP"

kinds=$("$PDT" gen --help | sed -n 's/^kinds: *//p')
[ -n "$kinds" ] && ok help_lists_kinds || fail help_lists_kinds
for k in uniform grid circle circle-round parabola clusters collinear; do
    case " $kinds " in *" $k "*) ok "kind_listed_$k" ;; *) fail "kind_listed_$k" "kinds: $kinds" ;; esac
done
for k in $kinds; do
    "$PDT" gen "$k" 300 --seed 7 > "$k.txt" 2> "$k.err"; rc=$?
    if [ $rc -ne 0 ] || [ "$(wc -l < "$k.txt")" -ne 300 ]; then fail "gen_$k" "rc=$rc $(cat "$k.err")"; continue; fi
    "$PDT" gen "$k" 300 --seed 7 | cmp -s - "$k.txt" || { fail "gen_${k}_deterministic"; continue; }
    "$PDT" triangulate "$k.txt" -o "$k.tri" 2> /dev/null && "$PDT" check "$k.txt" "$k.tri" > /dev/null 2> "$k.chk"
    rc=$?
    [ $rc -eq 0 ] && ok "gen_${k}_triangulate_check" || fail "gen_${k}_triangulate_check" "rc=$rc $(cat "$k.chk")"
done
"$PDT" gen uniform 100 --seed 1 > s1.txt; "$PDT" gen uniform 100 --seed 2 > s2.txt
cmp -s s1.txt s2.txt && fail seed_changes_points || ok seed_changes_points
"$PDT" gen uniform 50 -o u.node && "$PDT" triangulate u.node > /dev/null 2>&1 && head -1 u.node | grep -q '^#' \
    && ok node_output || fail node_output
"$PDT" gen uniform 0 | wc -c | grep -qx 0 && ok zero_points || fail zero_points
"$PDT" gen nosuchkind 5 2> k.err; [ $? -eq 2 ] && [ -s k.err ] && ok unknown_kind || fail unknown_kind
"$PDT" gen uniform -5 2> /dev/null; [ $? -eq 2 ] && ok negative_count || fail negative_count
"$PDT" gen uniform 5x 2> /dev/null; [ $? -eq 2 ] && ok bad_count || fail bad_count
"$PDT" gen uniform 5 --seed abc 2> /dev/null; [ $? -eq 2 ] && ok bad_seed || fail bad_seed
summary
