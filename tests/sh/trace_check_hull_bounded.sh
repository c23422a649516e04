#!/bin/bash
# pdt trace check of hull runs (pdt hull --trace) in bounded memory: over its
# budget (--mem) the check certifies the final Graham stack in one pass over
# the points instead of recomputing the hull (docs/trace-format.md, "The hull
# in bounded memory"), and its stacks grow in temporary files beyond an
# eighth of the budget.  Every family, degenerate inputs and a set whose
# points are all extreme (the stack as deep as the points) get the same
# verdict and summary at the default budget, --mem 1K and --mem 1 (but for
# the words saying the hull was certified); a run whose points.bin no longer
# matches its trace is rejected at every budget, naming why; and the check of
# 3*10^6 uniform points under --mem 16M stays near its budget (RssAnon,
# printed; release build only: the sanitizers' shadow memory would count).
# san: yes
source "$(dirname "$0")/lib.sh"
cd "$TMP" || exit 1
SAID=" (the hull certified point by point: recomputing it would not fit the memory budget)"

# move.py RUN I X Y: point I of RUN's points.bin moved to (X, Y), its CRC-32C
# checksums and the manifest's CRC-64 rewritten to match (docs/trace-format.md
# §2, §5): the folder reads as intact, only the points differ from the trace.
cat >move.py <<'EOF'
import struct, sys
def table(poly):
    t = []
    for i in range(256):
        c = i
        for _ in range(8): c = (c >> 1) ^ (poly if c & 1 else 0)
        t.append(c)
    return t
T32, T64 = table(0x82F63B78), table(0xC96C5795D7870F42)
def crc(data, t, ones):
    c = ones
    for b in data: c = t[(c ^ b) & 0xff] ^ (c >> 8)
    return c ^ ones
run, i, x, y = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
b = bytearray(open(run + '/points.bin', 'rb').read())
struct.pack_into('<ii', b, 24 + 8 * i, x, y)
struct.pack_into('<I', b, 16, crc(b[24:], T32, 0xFFFFFFFF))
struct.pack_into('<I', b, 20, crc(b[:20], T32, 0xFFFFFFFF))
open(run + '/points.bin', 'wb').write(b)
c64 = crc(b[24:], T64, 0xFFFFFFFFFFFFFFFF)
m = open(run + '/manifest').read().split('\n')
m = ['input_checksum = crc64:%016x' % c64 if l.startswith('input_checksum =') else l for l in m]
open(run + '/manifest', 'w').write('\n'.join(m))
EOF

# convex.py R: the corners of a convex polygon whose sides are the primitive
# vectors of length <= R, each direction once (about 1.9 R^2 points, every one
# extreme), shuffled
cat >convex.py <<'EOF'
import math, random, sys
R = int(sys.argv[1])
q = sorted(((a, b) for a in range(1, R + 1) for b in range(0, R + 1)
            if a * a + b * b <= R * R and math.gcd(a, b) == 1), key=lambda v: math.atan2(v[1], v[0]))
x = y = 0
pts = []
for dx, dy in q + [(-b, a) for a, b in q] + [(-a, -b) for a, b in q] + [(b, -a) for a, b in q]:
    pts.append((x, y)); x += dx; y += dy
random.Random(7).shuffle(pts)
sys.stdout.write(''.join('%d %d\n' % p for p in pts))
EOF

# same_verdicts NAME N: the run NAME (N points) passes at every budget with the
# same summary; the small budgets say they certified the hull when 12 bytes a
# point do not fit them
same_verdicts() {
    local name=$1 n=$2 whole tiny one
    whole=$("$PDT" trace check "$name.run" 2>&1) || { fail "${name}_same_verdicts" "$whole"; return; }
    tiny=$("$PDT" trace check "$name.run" --mem 1K 2>&1) || { fail "${name}_same_verdicts" "1K: $tiny"; return; }
    one=$("$PDT" trace check "$name.run" --mem 1 2>&1) || { fail "${name}_same_verdicts" "1: $one"; return; }
    local want1K=$whole want1=$whole
    [ $((12 * n)) -gt 1024 ] && want1K=$whole$SAID
    [ "$n" -gt 0 ] && want1=$whole$SAID
    if [[ "$whole" == ok:* && "$whole" != *certified* && "$tiny" == "$want1K" && "$one" == "$want1" ]]; then
        ok "${name}_same_verdicts"
    else
        fail "${name}_same_verdicts" "default: $whole | 1K: $tiny | 1: $one"
    fi
}

# record NAME: pdt hull NAME.txt --trace NAME.run
record() { "$PDT" hull "$1.txt" -o "$1.hull" --trace "$1.run" >/dev/null || fail "record_$1"; }

# ---- every family, two sizes ---------------------------------------------------------
for kind in uniform circle circle-round grid collinear duplicates clusters parabola; do
    for n in 300 3000; do
        "$PDT" gen "$kind" $n -o "$kind$n.txt" || { fail "gen_$kind$n"; continue; }
        record "$kind$n"
        same_verdicts "$kind$n" $n
    done
done

# ---- degenerate inputs, written by hand ---------------------------------------------
: >n0.txt
echo "5 -3" >n1.txt
printf '5 -3\n-2 7\n' >n2.txt
printf '5 -3\n-2 7\n9 9\n' >n3.txt
printf '4 4\n4 4\n' >twice.txt
for i in $(seq 200); do echo "-7 11"; done >coincident.txt
for i in $(seq 200); do echo "$((3 * (i % 61) - 90)) $((-2 * (i % 61) + 40))"; done >collinear.txt
for i in $(seq 100); do echo "$i 0"; echo "$((100 - i)) 0"; done >level.txt  # on the origin's level
for f in n0:0 n1:1 n2:2 n3:3 twice:2 coincident:200 collinear:200 level:200; do
    record "${f%:*}"
    same_verdicts "${f%:*}" "${f#*:}"
done
# Graham's scan writes the first copy of coincident points, and the two ends of
# collinear ones (the first copy of the origin, the last copy of the far end)
hulls=$(for f in coincident collinear level; do tr '\n' ' ' <$f.hull; echo; done)
[ "$hulls" = "$(printf '0 \n59 182 \n198 199 ')" ] && ok degenerate_hulls || fail degenerate_hulls "$hulls"

# ---- every point extreme: the stack holds them all ------------------------------------
python3 convex.py 100 >convex.txt && record convex
n=$(wc -l <convex.txt)
[ "$(wc -l <convex.hull)" = "$n" ] && [ "$n" -gt 15000 ] && ok convex_all_extreme ||
    fail convex_all_extreme "$n points, $(wc -l <convex.hull) on the hull"
same_verdicts convex "$n"

# ---- points.bin no longer the points scanned: the final stack is not their hull -------
"$PDT" gen uniform 3000 -o u.txt && record u
# a point inside (the last one not on the hull), a corner before it, the first corners
inside=$(awk 'NR == FNR {h[$1] = 1; next} !((FNR - 1) in h) {i = FNR - 1} END {print i}' u.hull u.txt)
corner=$(awk -v i="$inside" 'NR > 1 && $1 < i && $1 > c {c = $1} END {print c + 0}' u.hull)
c1=$(sed -n 2p u.hull) c2=$(sed -n 3p u.hull)
read -r _ y1 < <(sed -n "$((c1 + 1))p" u.txt)
read -r xc yc < <(sed -n "$((corner + 1))p" u.txt)
# the corner after c2, and the middle of the origin, c1 and it: a point inside
read -r xm ym < <(for k in 1 2 4; do sed -n "$(($(sed -n ${k}p u.hull) + 1))p" u.txt; done |
                  awk '{x += $1; y += $2} END {print int(x / 3), int(y / 3)}')
# damaged NAME I X Y IN_MEMORY CERTIFIED: the run u with point I at (X, Y) fails at
# every budget (exit 1), the messages saying IN_MEMORY and CERTIFIED
damaged() {
    local name=$1 i=$2 x=$3 y=$4 want_mem=$5 want_cert=$6 whole tiny one rc1 rc2 rc3
    cp -r u.run "$name.run" && python3 move.py "$name.run" "$i" "$x" "$y" || { fail "$name"; return; }
    whole=$("$PDT" trace check "$name.run" 2>&1); rc1=$?
    tiny=$("$PDT" trace check "$name.run" --mem 1K 2>&1); rc2=$?
    one=$("$PDT" trace check "$name.run" --mem 1 2>&1); rc3=$?
    local pre="pdt trace check: $name.run: the final Graham stack ("
    if [ "$rc1$rc2$rc3" = 111 ] && [[ "$whole" == "$pre"*"$want_mem"* && "$tiny" == "$pre"*"$want_cert"* &&
        "$one" == "$tiny" ]]; then
        ok "$name"
    else
        fail "$name" "exit $rc1 $rc2 $rc3: $whole | $tiny | $one"
    fi
}
damaged moved_below "$inside" 5 -1000000000 "is not the hull of the run's points (" \
    "is not the rightmost lowest point: pt $inside is lower"
damaged moved_outside "$inside" 1000000000 $((y1 + 1)) "first difference at position" \
    "pt $inside (1000000000, $((y1 + 1))) lies outside it"
damaged later_copy "$inside" "$xc" "$yc" "first difference at position" \
    "pt $inside is a later copy of its point pt $corner"
damaged corner_inside "$c2" "$xm" "$ym" "first difference at position" \
    "no strict left turn at position 2 (pts $c1 $c2 $(sed -n 4p u.hull))"
# points on a line, the origin moved off it
cp -r collinear.run off.run && python3 move.py off.run "$(sed -n 1p collinear.hull)" 1000 -1000 &&
    out=$("$PDT" trace check off.run --mem 1 2>&1); rc=$?
[ "$rc" = 1 ] && [[ "$out" == *"the final Graham stack (2 points) is not the hull of the run's points: "* ]] &&
    ok collinear_damaged || fail collinear_damaged "exit $rc: $out"

# ---- memory: 3*10^6 uniform points under --mem 16M ---------------------------------------
if [[ "$BIN" == */san ]]; then
    echo "# memory not measured in the sanitizer build"
else
    "$PDT" gen uniform 3000000 -o big.txt && record big && rm -f big.txt
    peak() { "$ROOT/scripts/bench/tools/anon_peak.sh" peak.out "$@"; }
    t0=$EPOCHREALTIME
    bounded=$(peak "$PDT" trace check big.run --mem 16M); rc=$?
    t1=$EPOCHREALTIME
    out=$(cat peak.out)
    whole=$(peak "$PDT" trace check big.run); rc2=$?
    t2=$EPOCHREALTIME
    awk -v b="$bounded" -v w="$whole" -v t0="$t0" -v t1="$t1" -v t2="$t2" 'BEGIN {
        printf "# 3*10^6 uniform points: --mem 16M peak RssAnon %d KiB (%.2f s), default budget %d KiB (%.2f s)\n",
               b, t1 - t0, w, t2 - t1 }'
    [ "$rc" = 0 ] && [[ "$out" == *"$SAID" ]] && [ "$bounded" -lt $((64 * 1024)) ] &&
        ok bounded_memory || fail bounded_memory "exit $rc, $bounded KiB: $out"
    [ "$rc2" = 0 ] && [ "$whole" -gt "$bounded" ] && ok default_takes_more ||
        fail default_takes_more "exit $rc2, $whole KiB in memory, $bounded KiB bounded"
fi
summary
