#!/bin/bash
# pdt trace: traced runs of pdt hull / pdt triangulate, read back with
# pdt trace dump / info / check / export, and traces altered on purpose.
# san: yes
source "$(dirname "$0")/lib.sh"

# ---- Graham's exact sequence, through the command line -------------------------
# The square with points sprinkled on its boundary (thesis, Hull Collinearities).
printf '0 0\n2 0\n4 0\n4 2\n4 4\n2 4\n0 4\n0 2\n2 2\n' >"$TMP/square.txt"
"$PDT" hull "$TMP/square.txt" -o "$TMP/square.hull" --trace "$TMP/sq" || fail hull_trace_runs
got=$("$PDT" trace dump "$TMP/sq" --rank 0 | grep -E ' (push|pop|delete) ' | sed 's/^r0 #[0-9]* t=[0-9.]*ms //')
want="delete angular-tie pt=3 kept=4
delete angular-tie pt=8 kept=6
delete angular-tie pt=1 kept=0
push graham pt=2 depth=1
push graham pt=4 depth=2
push graham pt=5 depth=3
pop graham pt=5 depth=2 cause=6
push graham pt=6 depth=3
push graham pt=7 depth=4
pop graham pt=7 depth=3 cause=0
push graham pt=0 depth=4"
if [ "$got" = "$want" ]; then ok graham_square_sequence; else fail graham_square_sequence "got: $got"; fi

# Angular ties and duplicates (p0 has a copy; (0,5) has a copy; 3 points on one ray).
printf '0 0\n5 0\n5 0\n5 5\n0 5\n0 5\n1 4\n3 2\n2 1\n' >"$TMP/ties.txt"
"$PDT" hull "$TMP/ties.txt" -o "$TMP/ties.hull" --trace "$TMP/ties" || fail hull_trace_ties
got=$("$PDT" trace dump "$TMP/ties" --kind pop; "$PDT" trace dump "$TMP/ties" --kind delete)
got=$(echo "$got" | sed 's/^r0 #[0-9]* t=[0-9.]*ms //')
want="pop graham pt=8 depth=3 cause=0
delete coincident pt=2 kept=1
delete angular-tie pt=7 kept=5
delete angular-tie pt=6 kept=5
delete coincident pt=4 kept=5"
if [ "$got" = "$want" ]; then ok graham_ties_sequence; else fail graham_ties_sequence "got: $got"; fi

# --from / --count select by event index
line=$("$PDT" trace dump "$TMP/sq" --rank 0 --from 3 --count 1)
case "$line" in "r0 #3 t="*"ms sort pt=3 pos=1") ok dump_from_count ;; *) fail dump_from_count "$line" ;; esac

# ---- counts of each kind for a known run ------------------------------------------
# A 4x4 grid plus one duplicate: 16 distinct points, 12 on the hull boundary,
# so 2*16 - 12 - 2 = 18 triangles; every distinct point lifted once.
: >"$TMP/grid.txt"
for y in 0 1 2 3; do for x in 0 1 2 3; do echo "$x $y" >>"$TMP/grid.txt"; done; done
echo "2 2" >>"$TMP/grid.txt"
"$PDT" triangulate "$TMP/grid.txt" -o "$TMP/grid.tri" --trace "$TMP/grid" || fail grid_trace
info=$("$PDT" trace info "$TMP/grid")
count() { echo "$info" | awk -v k="$1" '$1 == k {print $2; exit}'; }
c="lift=$(count lift) tri-new=$(count tri-new) tri-final=$(count tri-final) push=$(count push)"
if [ "$c" = "lift=16 tri-new=18 tri-final=18 push=" ]; then ok grid_event_counts; else fail grid_event_counts "$c"; fi
[ "$(count tri-final)" = "$(wc -l <"$TMP/grid.tri")" ] && ok finals_equal_output || fail finals_equal_output
echo "$info" | grep -q "bytes/event" && echo "$info" | grep -qE "r0 +kernel +start" &&
    ok info_shows_bytes_and_phases || fail info_shows_bytes_and_phases "$info"
"$PDT" triangulate "$TMP/grid.txt" -o "$TMP/grid2.tri" --trace "$TMP/grid2" --trace-level 2 &&
    [ "$("$PDT" trace dump "$TMP/grid2" --kind edge-add | wc -l)" -gt 18 ] &&
    ok level2_records_edges || fail level2_records_edges
[ -z "$("$PDT" trace dump "$TMP/grid" --kind edge-add)" ] && ok level1_has_no_edges ||
    fail level1_has_no_edges

# ---- pdt trace check passes on every gen family ------------------------------------
for kind in $("$PDT" gen --help | awk '/^kinds:/ {for (i = 2; i <= NF; i++) print $i}'); do
    "$PDT" gen "$kind" 200 -o "$TMP/$kind.txt" || { fail "gen_$kind"; continue; }
    "$PDT" triangulate "$TMP/$kind.txt" -o "$TMP/$kind.tri" --trace "$TMP/t-$kind" &&
        "$PDT" trace check "$TMP/t-$kind" >"$TMP/check.out" 2>&1 &&
        "$PDT" hull "$TMP/$kind.txt" -o "$TMP/$kind.hull" --trace "$TMP/h-$kind" &&
        "$PDT" trace check "$TMP/h-$kind" >>"$TMP/check.out" 2>&1 &&
        ok "trace_check_$kind" || fail "trace_check_$kind" "$(cat "$TMP/check.out")"
done

# ---- altered traces fail, naming the problem ------------------------------------------
"$PDT" gen uniform 3000 -o "$TMP/u.txt"
"$PDT" triangulate "$TMP/u.txt" -o "$TMP/u.tri" --trace "$TMP/u" || fail uniform_trace
"$PDT" trace check "$TMP/u" >/dev/null && ok check_passes_unaltered || fail check_passes_unaltered

cp -r "$TMP/u" "$TMP/trunc"
truncate -s 70000 "$TMP/trunc/rank-0000.trace"
out=$("$PDT" trace check "$TMP/trunc" 2>&1); rc=$?
[[ $rc -eq 1 && "$out" == *"rank-0000.trace: block 1 at byte "*": truncated"* ]] &&
    ok check_fails_truncated_block || fail check_fails_truncated_block "rc=$rc $out"

cp -r "$TMP/u" "$TMP/flip"
printf '\x55' | dd of="$TMP/flip/rank-0000.trace" bs=1 seek=1000 conv=notrunc status=none
out=$("$PDT" trace check "$TMP/flip" 2>&1); rc=$?
[[ $rc -eq 1 && "$out" == *"rank-0000.trace: block 0 at byte 32: checksum mismatch"* ]] &&
    ok check_fails_flipped_checksum || fail check_fails_flipped_checksum "rc=$rc $out"

# Remove one event and write the block back with a correct checksum (an
# independent encoder in Python, following docs/trace-format.md), so only the
# missing event can give it away.
cat >"$TMP/drop.py" <<'EOF'
import struct, sys
def crc32c(data, c=0xFFFFFFFF):
    for b in data:
        c ^= b
        for _ in range(8): c = (c >> 1) ^ (0x82F63B78 & -(c & 1))
    return c
def varint(b, i):
    r = s = 0
    while True:
        x = b[i]; i += 1; r |= (x & 0x7f) << s; s += 7
        if x < 0x80: return r, i
def put(v):
    out = bytearray()
    while v >= 0x80: out.append((v & 0x7f) | 0x80); v >>= 7
    out.append(v); return bytes(out)
def zz(d, w): d %= 1 << w; return ((d << 1) ^ (-(d >> (w - 1)))) % (1 << w)
def unzz(z): return (z >> 1) ^ -(z & 1)
path, kind, nth = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
b = bytearray(open(path, 'rb').read())
off = struct.unpack_from('<I', b, 12)[0]
magic, ln, first, base, cnt, crc = struct.unpack_from('<IIQQII', b, off)
assert magic == 0x42544450 and first == 0
i, t, prev, evs = off + 32, base, [0, 0, 0, 0], []
for _ in range(cnt):                       # decode block 0
    k, mask = b[i], b[i + 1]; i += 2
    z, i = varint(b, i); t += unzz(z); sub = 0
    if mask & 1: sub = b[i]; i += 1
    f = [0, 0, 0, 0]
    for j, bit in enumerate((2, 4, 8, 16)):
        if mask & bit:
            z, i = varint(b, i); w = 32 if j < 3 else 64
            prev[j] = (prev[j] + unzz(z)) % (1 << w); f[j] = prev[j]
    evs.append((k, sub, f, t))
drop = [n for n, e in enumerate(evs) if e[0] == kind][nth]
del evs[drop]
pay, t, prev = bytearray(), base, [0, 0, 0, 0]
for k, sub, f, te in evs:                  # encode again
    mask = (1 if sub else 0) | sum(bit for j, bit in enumerate((2, 4, 8, 16)) if f[j])
    pay += bytes([k, mask]) + put(zz(te - t, 64)); t = te
    if sub: pay.append(sub)
    for j, bit in enumerate((2, 4, 8, 16)):
        if f[j]:
            w = 32 if j < 3 else 64
            pay += put(zz(f[j] - prev[j], w)); prev[j] = f[j]
rest = b[off + 32 + ln:]
# later blocks start one event earlier now
o = 0
while o + 32 <= len(rest):
    m2, l2, f2, b2, c2, _ = struct.unpack_from('<IIQQII', rest, o)
    if m2 == 0x45544450: struct.pack_into('<Q', rest, o + 32, struct.unpack_from('<Q', rest, o + 32)[0] - 1)
    struct.pack_into('<Q', rest, o + 8, f2 - 1)
    struct.pack_into('<I', rest, o + 28, crc32c(bytes(rest[o:o + 28]) + bytes(rest[o + 32:o + 32 + l2])) ^ 0xFFFFFFFF)
    o += 32 + l2
hdr = bytearray(struct.pack('<IIQQI', magic, len(pay), 0, base, cnt - 1))
hdr += struct.pack('<I', crc32c(bytes(hdr) + bytes(pay)) ^ 0xFFFFFFFF)
open(path, 'wb').write(bytes(b[:off]) + bytes(hdr) + bytes(pay) + bytes(rest))
print(drop)
EOF
"$PDT" hull "$TMP/u.txt" -o "$TMP/u.hull" --trace "$TMP/uh" || fail uniform_hull_trace
cp -r "$TMP/uh" "$TMP/nopop"
python3 "$TMP/drop.py" "$TMP/nopop/rank-0000.trace" 4 5 >/dev/null || fail drop_script
out=$("$PDT" trace check "$TMP/nopop" 2>&1); rc=$?
[[ $rc -eq 1 && "$out" == *"rank 0 event #"*"graham"* ]] &&
    ok check_fails_removed_pop || fail check_fails_removed_pop "rc=$rc $out"
# the re-encoded file is intact: the reader reports no damage
"$PDT" trace info "$TMP/nopop" | grep -q '^warning' && fail reencoded_file_intact ||
    ok reencoded_file_intact
cp -r "$TMP/u" "$TMP/nolift"
python3 "$TMP/drop.py" "$TMP/nolift/rank-0000.trace" 5 100 >/dev/null || fail drop_script_lift
out=$("$PDT" trace check "$TMP/nolift" 2>&1); rc=$?
[[ $rc -eq 1 && "$out" == *"was never lifted"* ]] &&
    ok check_fails_removed_lift || fail check_fails_removed_lift "rc=$rc $out"

# ---- a run killed with SIGKILL leaves a readable trace ------------------------------------
# (in the temporary folder beside DIR: a killed run leaves DIR as it was, here absent)
"$PDT" gen uniform 400000 -o "$TMP/big.txt"
"$PDT" triangulate "$TMP/big.txt" -o "$TMP/big.tri" --trace "$TMP/killed" 2>/dev/null &
pid=$!
for ((i = 0; i < 400; i++)); do  # until a few blocks are on disk (or the run ended)
    sz=$(cat "$TMP"/.killed.pdt-tmp.*/rank-0000.trace 2>/dev/null | wc -c)
    [ "$sz" -ge 150000 ] && break
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.02
done
if kill -9 "$pid" 2>/dev/null; then
    wait "$pid" 2>/dev/null
    kdir=$(ls -d "$TMP"/.killed.pdt-tmp.* 2>/dev/null | head -1)
    info=$("$PDT" trace info "$kdir")
    ev=$(echo "$info" | awk '$1 == "0" && NF >= 5 {print $2; exit}')
    if [[ "$info" == *"warning: rank-0000.trace: "*"run killed?"* || "$info" == *"warning: rank-0000.trace: block"* ]] &&
        [ "${ev:-0}" -gt 4000 ] && [ ! -e "$TMP/killed" ]; then ok killed_run_readable; else fail killed_run_readable "$info"; fi
    out=$("$PDT" trace check "$kdir" 2>&1); rc=$?
    [[ $rc -eq 1 && "$out" == *"damaged run folder"* ]] && ok killed_run_fails_check ||
        fail killed_run_fails_check "rc=$rc $out"
    rm -rf "$kdir"
else
    wait "$pid"
    echo "ok - killed_run_readable # skip: the run finished before it could be killed"
fi
rm -f "$TMP/big.txt" "$TMP/big.tri"

# ---- the documented Python reader agrees with pdt trace dump ------------------------
awk '/^```python/ {f = 1; next} /^```/ {f = 0} f' "$ROOT/docs/trace-format.md" >"$TMP/reader.py"
python3 "$TMP/reader.py" "$TMP/grid2/rank-0000.trace" | awk '{print $1}' >"$TMP/py.kinds"
"$PDT" trace dump "$TMP/grid2" --rank 0 | awk '{print $4}' >"$TMP/dump.kinds"
python3 "$TMP/reader.py" "$TMP/grid2/rank-0000.trace" | awk '$1 == 5 {print $3, $6}' >"$TMP/py.lift"
"$PDT" trace dump "$TMP/grid2" --kind lift | sed 's/.*pt=\([0-9]*\) z=\([0-9]*\)/\1 \2/' >"$TMP/dump.lift"
n1=$(wc -l <"$TMP/py.kinds")
[ "$n1" -gt 50 ] && [ "$n1" = "$(wc -l <"$TMP/dump.kinds")" ] && cmp -s "$TMP/py.lift" "$TMP/dump.lift" &&
    ok python_reader_matches_dump || fail python_reader_matches_dump "python $n1 events"

# ---- Chrome export ---------------------------------------------------------------------
"$PDT" trace export --chrome "$TMP/grid" -o "$TMP/run.json" &&
    python3 -m json.tool "$TMP/run.json" >/dev/null &&
    grep -q '"thread_name"' "$TMP/run.json" && grep -q '"name":"kernel"' "$TMP/run.json" &&
    ok chrome_export_valid_json || fail chrome_export_valid_json
"$PDT" trace export --chrome "$TMP/trunc" -o "$TMP/trunc.json" 2>/dev/null &&
    python3 -m json.tool "$TMP/trunc.json" >/dev/null && ok chrome_export_damaged_valid ||
    fail chrome_export_damaged_valid

# ---- usage errors ------------------------------------------------------------------------
"$PDT" trace dump "$TMP/grid" --kind nosuch 2>/dev/null; [ $? -eq 2 ] && ok dump_unknown_kind ||
    fail dump_unknown_kind
"$PDT" trace info "$TMP/nonexistent" 2>/dev/null; [ $? -eq 2 ] && ok info_missing_folder ||
    fail info_missing_folder
summary
