#!/bin/bash
# points.bin and the manifest's input_checksum of traced runs, written by
# every rank at its place (no rank holds the whole input): the same bytes and
# checksum for a plain run and for P = 1..8 ranks (tiny message chunks
# too, more ranks than points, no points); the checksum is CRC-64/XZ of the
# data bytes as docs/trace-format.md defines it (recomputed here in Python
# from the page's definition); a rank failing its block leaves no points.bin,
# no temporary, no manifest and names the rank; format 1 runs still read.
source "$(dirname "$0")/lib.sh"
PDT=$PDT_HOOKED  # injects faults (PDT_TEST_*)
cd "$TMP"
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi

"$PDT" gen clusters 700 --seed 11 -o in.txt
"$PDT" triangulate in.txt -o plain.tri --trace plain 2> plain.err || fail plain_traced_run "$(cat plain.err)"
sum() { sed -n 's/^input_checksum = //p' "$1/manifest"; }
want=$(sum plain)

bad=
for p in 1 2 3 4 5 6 7 8; do
    mpirun -np $p "$PDT" triangulate in.txt -o p$p.tri --trace run$p 2> run$p.err ||
        bad="$bad P=$p:rc"
    cmp -s plain/points.bin run$p/points.bin || bad="$bad P=$p:points.bin"
    [ "$(sum run$p)" = "$want" ] || bad="$bad P=$p:checksum($(sum run$p))"
    cmp -s plain.tri p$p.tri || bad="$bad P=$p:output"
done
[ -z "$bad" ] && ok points_bin_same_for_plain_and_P_1_to_8 ||
    fail points_bin_same_for_plain_and_P_1_to_8 "$bad"
"$PDT" trace check run5 > check5.out 2>&1 && ok trace_check_P5 || fail trace_check_P5 "$(cat check5.out)"
ls -a run8 | grep -q '\.tmp\.' && fail no_temporary_left "$(ls -a run8)" || ok no_temporary_left

# the bytes, as the format page defines them (independent of our code)
python3 - "$want" plain/points.bin in.txt > py.out 2>&1 <<'PY'
import struct, sys
want, path, inp = sys.argv[1], sys.argv[2], sys.argv[3]
b = open(path, 'rb').read()
def crc(data, poly, width):
    top = (1 << width) - 1
    c = top
    for x in data:
        c ^= x
        for _ in range(8):
            c = (c >> 1) ^ (poly if c & 1 else 0)
    return c ^ top
assert b[:8] == b'PDTPNTS1', b[:8]
n, dcrc, hcrc = struct.unpack_from('<QII', b, 8)
pts = [tuple(map(int, l.split())) for l in open(inp) if l.strip() and not l.startswith('#')]
assert n == len(pts) and len(b) == 24 + 8 * n, (n, len(pts), len(b))
assert b[24:] == b''.join(struct.pack('<ii', x, y) for x, y in pts), 'point bytes'
assert hcrc == crc(b[:20], 0x82F63B78, 32), 'header crc'
assert dcrc == crc(b[24:], 0x82F63B78, 32), 'data crc'
got = 'crc64:%016x' % crc(b[24:], 0xC96C5795D7870F42, 64)
assert got == want, (got, want)
print('bytes ok')
PY
grep -q 'bytes ok' py.out && ok points_bin_and_checksum_as_documented || fail points_bin_and_checksum_as_documented "$(cat py.out)"

# messages of 16 bytes (the gather of the blocks' checksums is chunked too)
PDT_COMM_CHUNK=16 mpirun -np 3 "$PDT" triangulate in.txt -o c3.tri --trace chunk3 2> chunk3.err
cmp -s plain/points.bin chunk3/points.bin && [ "$(sum chunk3)" = "$want" ] && ok tiny_chunks_same_points_bin ||
    fail tiny_chunks_same_points_bin "$(cat chunk3.err)"

# more ranks than points (empty blocks), and no points at all
printf '0 0\n5 1\n2 7\n' > three.txt
"$PDT" triangulate three.txt -o t.tri --trace three1 2> /dev/null
mpirun -np 6 "$PDT" triangulate three.txt -o t6.tri --trace three6 2> three6.err
: > empty.txt
"$PDT" triangulate empty.txt -o e.tri --trace empty1 2> /dev/null
mpirun -np 3 "$PDT" triangulate empty.txt -o e3.tri --trace empty3 2> empty3.err
if cmp -s three1/points.bin three6/points.bin && [ "$(sum three1)" = "$(sum three6)" ] &&
   cmp -s empty1/points.bin empty3/points.bin && [ "$(stat -c %s empty3/points.bin)" = 24 ] &&
   [ "$(sum empty3)" = "crc64:0000000000000000" ] && "$PDT" trace check three6 > /dev/null 2>&1; then
    ok empty_blocks_and_no_points
else fail empty_blocks_and_no_points "$(cat three6.err empty3.err)"; fi

# a rank that cannot write its block: no points.bin, no temporary, no manifest, no output
PDT_TEST_FAIL_TRACE_POINTS=1 mpirun -np 3 "$PDT" triangulate in.txt -o f.tri --trace fail3 2> fail3.err; rc=$?
if [ $rc -ne 0 ] && grep -q 'rank 1' fail3.err && grep -q 'trace' fail3.err &&
   grep -q 'points.bin' fail3.err && [ ! -e fail3/points.bin ] && [ ! -e fail3/manifest ] &&
   ! ls -a fail3 | grep -q '\.tmp\.' && [ ! -e f.tri ]; then
    ok failed_block_leaves_nothing
else fail failed_block_leaves_nothing "rc=$rc $(cat fail3.err) $(ls -a fail3)"; fi

# format 1 (before this change: FNV-1a 64, written by rank 0): still read and checked
OLD=$ROOT/assets/runs/uniform-300-p8
if grep -q '^format = 1\.' "$OLD/manifest" && "$PDT" trace check "$OLD" > old.out 2>&1 &&
   "$PDT" trace info "$OLD" | grep -q 'format 1.0' && "$PDT" trace info "$OLD" | grep -q 'checksum fnv1a64:'; then
    ok format_1_run_still_checks
else fail format_1_run_still_checks "$(cat old.out)"; fi
cp -r "$OLD" old && sed -i 's/^input_checksum = .*/input_checksum = fnv1a64:0000000000000001/' old/manifest
"$PDT" trace check old > old2.out 2>&1; rc=$?
[ $rc -eq 1 ] && grep -q "input_checksum" old2.out && ok format_1_wrong_checksum_reported ||
    fail format_1_wrong_checksum_reported "rc=$rc $(cat old2.out)"
summary
