#!/bin/bash
# Opening a run checks every block of a rank file (its checksum and a decode
# of its events) on several threads, a window of the file at a time.  A rank
# file of some 22 MB (two windows) damaged in a block of its second window:
# the warnings name that block and its byte, and keep exactly the blocks
# before it, as a block-by-block scan would.  The blocks are found and
# counted here by an independent reader in Python (docs/trace-format.md).
# san: yes
source "$(dirname "$0")/lib.sh"
cd "$TMP" || exit 1

"$PDT" gen uniform 400000 -o u.txt >/dev/null 2>&1 &&
    "$PDT" triangulate u.txt -o u.tri --trace run >/dev/null 2>&1 || fail traced_run_made

cat >blocks.py <<'EOF'
import struct, sys
def crc32c(data, c=0xFFFFFFFF):
    for b in data:
        c ^= b
        for _ in range(8): c = (c >> 1) ^ (0x82F63B78 & -(c & 1))
    return c ^ 0xFFFFFFFF
path, how = sys.argv[1], sys.argv[2]
b = bytearray(open(path, 'rb').read())
off, blocks = struct.unpack_from('<I', b, 12)[0], []
while off + 32 <= len(b):
    magic, ln, first, base, cnt, crc = struct.unpack_from('<IIQQII', b, off)
    if magic != 0x42544450: break
    blocks.append((off, ln, cnt))
    off += 32 + ln
k = len(blocks) * 3 // 4                 # a block of the second window (16 MiB on)
at, ln, cnt = blocks[k]
if how == 'flip':                        # a payload byte changed: the checksum fails
    b[at + 32 + ln // 2] ^= 0x55
elif how == 'malformed':                 # events that cannot be decoded, under a valid checksum
    b[at + 32:at + 32 + ln] = b'\xff' * ln
    struct.pack_into('<I', b, at + 28, crc32c(bytes(b[at:at + 28]) + bytes(b[at + 32:at + 32 + ln])))
if how != 'count':
    open(path, 'wb').write(bytes(b))
print(len(blocks), k, at, sum(c for _, _, c in blocks[:k]), sum(c for _, _, c in blocks))
EOF

# the intact run: every block and event read
read -r nblk _ _ _ nev < <(python3 blocks.py run/rank-0000.trace count)
info=$("$PDT" trace info run 2>&1)
if echo "$info" | grep -Eq "^ +0 +$nev +$nblk +[0-9]+ +[0-9.]+ +yes$" && [ "$nblk" -gt 400 ]; then
    ok intact_run_every_block
else
    fail intact_run_every_block "python: $nblk blocks, $nev events; pdt: $(echo "$info" | grep -E '^ +0 ')"
fi

# damaged_case NAME HOW WHAT: the run with block k damaged (HOW); `pdt trace
# check` fails saying WHAT of block k at its byte, and `pdt trace info` keeps
# the k blocks before it and their events
damaged_case() {
    local name=$1 how=$2 what=$3
    cp -r run "$how"
    read -r _ k at before _ < <(python3 blocks.py "$how/rank-0000.trace" "$how")
    local out rc info
    out=$("$PDT" trace check "$how" 2>&1); rc=$?
    info=$("$PDT" trace info "$how" 2>&1)
    if [ "$rc" -eq 1 ] && [[ "$out" == *"rank-0000.trace: block $k at byte $at: $what"* ]] &&
        echo "$info" | grep -Eq "^ +0 +$before +$k +[0-9]+ +[0-9.]+ +NO$" &&
        [[ "$info" == *"read $before events in $k intact blocks before the damage"* ]]; then
        ok "$name"
    else
        fail "$name" "rc=$rc, want block $k at byte $at: $what, $before events: $(echo "$out" | head -2)" \
            "$(echo "$info" | grep -E '^ +0 |warning')"
    fi
}
damaged_case flipped_block_second_window flip "checksum mismatch"
damaged_case malformed_block_second_window malformed "malformed event data"

# The points' checksum is made while the rank files are scanned; its
# warning still comes first, before the rank files' (as the reading goes).
cp -r run both
python3 blocks.py both/rank-0000.trace flip >/dev/null
sed -i 's/^input_checksum = crc64:.*/input_checksum = crc64:0000000000000001/' both/manifest
w=$("$PDT" trace info both 2>&1 | grep '^warning')
first=$(echo "$w" | head -1); n=$(echo "$w" | wc -l)
if [[ "$first" == *"points.bin: points do not match the manifest's input_checksum"* ]] && [ "$n" -ge 3 ] &&
    echo "$w" | sed -n 2p | grep -q "checksum mismatch"; then
    ok points_warning_before_rank_warnings
else
    fail points_warning_before_rank_warnings "$w"
fi

summary
