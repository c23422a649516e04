#!/bin/bash
# The reader on real MPI traces: the merged order (pdt trace dump without
# --rank) keeps each rank's order and never puts a receive before its send,
# even though every rank has its own clock; the Chrome export has one row
# per rank and a flow arrow per message.
source "$(dirname "$0")/lib.sh"
if ! command -v mpirun >/dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi
"$PDT" gen clusters 1500 -o "$TMP/c.txt"
mpirun -np 5 "$PDT" triangulate "$TMP/c.txt" -o "$TMP/c.tri" --trace "$TMP/run" 2>"$TMP/err" ||
    fail mpi_traced_run "$(head -3 "$TMP/err")"
"$PDT" trace dump "$TMP/run" >"$TMP/merged.txt"
total=$("$PDT" trace info "$TMP/run" | awk '$1 == "all" {print $2}')
[ "$(wc -l <"$TMP/merged.txt")" = "$total" ] && [ "$total" -gt 1000 ] && ok merged_has_every_event ||
    fail merged_has_every_event "$(wc -l <"$TMP/merged.txt") lines, info says $total"
# r2 #17 t=...ms send tag=1 to=3 bytes=64 seq=0
causal() {
    awk '
    { r = substr($1, 2); k = substr($2, 2) + 0
      if ((r in last) ? k != last[r] + 1 : k != 0) { print "order broken at line " NR ": " $0; bad = 1 }
      last[r] = k }
    $4 == "send" { split($6, to, "="); sent[r "," to[2] "," $5 "," $8] = 1; nsend++ }
    $4 == "recv" { split($6, fr, "="); key = fr[2] "," r "," $5 "," $8
                   if (!(key in sent)) { print "recv before its send at line " NR ": " $0; bad = 1 }
                   nrecv++ }
    END { if (nsend == 0 || nsend != nrecv) { print "sends " nsend " recvs " nrecv; bad = 1 }
          exit bad }' "$1"
}
causal "$TMP/merged.txt" >"$TMP/order.out" && ok merged_order_causal_and_per_rank ||
    fail merged_order_causal_and_per_rank "$(head -3 "$TMP/order.out")"
# Skew the clocks on purpose: higher ranks look up to 4 s early, so ordering by
# time alone would put receives before their sends.
cp -r "$TMP/run" "$TMP/skew"
sed -i 's/^clock_offset_ns = .*/clock_offset_ns = 0 -1000000000 -2000000000 -3000000000 -4000000000/' \
    "$TMP/skew/manifest"
"$PDT" trace dump "$TMP/skew" >"$TMP/skew.txt"
head -1 "$TMP/skew.txt" | grep -q '^r4 ' && causal "$TMP/skew.txt" >"$TMP/order2.out" &&
    ok merged_order_causal_with_skewed_clocks ||
    fail merged_order_causal_with_skewed_clocks "$(head -1 "$TMP/skew.txt"; head -3 "$TMP/order2.out")"
"$PDT" trace export --chrome "$TMP/run" -o "$TMP/run.json" && python3 - "$TMP/run.json" <<'PY' && ok chrome_rows_and_flows || fail chrome_rows_and_flows
import json, sys
d = json.load(open(sys.argv[1]))
ev = d["traceEvents"]
rows = {e["tid"] for e in ev if e.get("name") == "thread_name"}
starts = {e["id"] for e in ev if e["ph"] == "s"}
ends = {e["id"] for e in ev if e["ph"] == "f"}
assert rows == set(range(5)), rows
assert starts and starts == ends, (len(starts), len(ends))
assert any(e["ph"] == "B" and e["name"].startswith("merge level") for e in ev)
PY
summary
