#!/bin/bash
# Damaged run folders through the programs: a real traced 4-rank run
# (mpirun -np 4 pdt triangulate --trace) whose files are then truncated
# (at every block boundary and its neighbours, and at evenly spaced offsets),
# given one flipped bit in every block, robbed of a rank file, or given a
# manifest of another format version.  Each time `pdt trace check` and
# `pdtview --headless` must end (timeout 60 s: a hang fails), must not crash
# (no signal, no sanitizer report), must say which file and which byte/block
# is damaged, and must still show the intact prefix: `pdt trace dump` prints
# exactly the events of the complete blocks before the damage, a number that
# never decreases as the cut moves later, and pdtview renders them.
# (Every single byte offset is covered by tests/unit/test_damage.c.)
# san: yes
source "$(dirname "$0")/lib.sh"
cd "$TMP"
V=$BIN/pdtview
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
export OMPI_MCA_mca_base_component_disable_dlclose=1 PMIX_MCA_mca_base_component_disable_dlclose=1
if ! command -v mpirun >/dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi

"$PDT" gen uniform 2000 --seed 5 -o u.txt
if mpirun -np 4 "$PDT" triangulate u.txt -o u.tri --trace run >mpi.out 2>&1 &&
   [ -f run/rank-0003.trace ]; then ok traced_4_rank_run
else fail traced_4_rank_run "$(tail -3 mpi.out)"; summary; exit; fi
if timeout 60 "$PDT" trace check run >chk.out 2>&1; then ok intact_run_checks
else fail intact_run_checks "$(head -3 chk.out)"; fi

# blocks FILE: "OFFSET EVENTS LENGTH" per event block, then "OFFSET end LENGTH"
# for the end marker (LENGTH: of the payload)
blocks() {
    python3 - "$1" <<'PY'
import struct, sys
d = open(sys.argv[1], "rb").read()
off = struct.unpack_from("<I", d, 12)[0]
while off + 32 <= len(d):
    magic, ln = struct.unpack_from("<II", d, off)
    cnt = struct.unpack_from("<I", d, off + 24)[0]
    if magic == 0x45544450:
        print(off, "end", ln); break
    print(off, cnt, ln)
    off += 32 + ln
PY
}

# run_tools DIR NAME: run check, dump and pdtview on DIR; sets RC_CHECK,
# DUMPED (events of the given rank), RC_VIEW and the outputs *.out
run_tools() { # DIR RANK
    timeout 60 "$PDT" trace check "$1" >check.out 2>&1; RC_CHECK=$?
    DUMPED=$(timeout 60 "$PDT" trace dump "$1" --rank "$2" 2>dump.err | wc -l); RC_DUMP=${PIPESTATUS[0]}
    rm -f view.png
    timeout 60 "$V" --headless "$1" --end -o view.png --size 320x200 >view.out 2>&1; RC_VIEW=$?
}

# sane NAME: no hang (124), no signal (>=128), no sanitizer report, in any tool
sane() {
    local f
    for f in check.out dump.err view.out; do
        if grep -qE 'AddressSanitizer|LeakSanitizer|runtime error:' "$f"; then
            fail "$1" "sanitizer report in $f: $(grep -m1 -E 'Sanitizer|runtime error' "$f")"; return 1
        fi
    done
    if [ "$RC_CHECK" -ge 124 ] || [ "$RC_DUMP" -ge 124 ] || [ "$RC_VIEW" -ge 124 ]; then
        fail "$1" "hang or crash: check $RC_CHECK, dump $RC_DUMP, view $RC_VIEW"; return 1
    fi
    return 0
}

# ---- (a) truncation ------------------------------------------------------------------
F=rank-0001.trace
SIZE=$(stat -c %s run/$F)
blocks run/$F >layout.txt
offs=$(awk '{print $1}' layout.txt)   # block starts and the end marker
cuts=$( { echo 0; echo 31; echo 32; echo 33
          for o in $offs; do echo $((o - 1)); echo "$o"; echo $((o + 1)); echo $((o + 31)); echo $((o + 32)); done
          for i in $(seq 1 23); do echo $((SIZE * i / 24)); done; echo $((SIZE - 1)); } |
        awk -v s="$SIZE" '$1 >= 0 && $1 < s' | sort -n | uniq)
# expected events for a cut at T: block k is complete iff the next block's start <= T
expect_at() {
    awk -v t="$1" '{ off[NR] = $1; cnt[NR] = $2 == "end" ? 0 : $2; n = NR }
        END { s = 0; for (k = 1; k < n; k++) if (off[k + 1] <= t) s += cnt[k]; print s }' layout.txt
}
bad=0; prev=-1; ncut=0
for t in $cuts; do
    rm -rf cut; cp -r run cut; truncate -s "$t" cut/$F
    run_tools cut 1
    sane "truncate_at_$t" || { bad=1; continue; }
    ncut=$((ncut + 1))
    want=$(expect_at "$t")
    # where: the cut block's offset, the header, or a clean cut at a block start
    start=$(awk -v t="$t" '$1 <= t { o = $1 } END { print o + 0 }' layout.txt)
    if [ "$t" -lt 32 ]; then where="$F: not a pdt trace file"
    elif [ "$t" -eq "$start" ]; then where="$F: no end marker"
    else where="$F: block [0-9]* at byte $start"; fi
    if [ "$RC_CHECK" -ne 1 ] || ! grep -q "$where" check.out; then
        fail "truncate_at_$t" "check rc $RC_CHECK, want 1 and '$where': $(head -2 check.out)"; bad=1
    elif [ "$DUMPED" -ne "$want" ]; then
        fail "truncate_at_$t" "dump shows $DUMPED events of rank 1, want $want"; bad=1
    elif [ "$DUMPED" -lt "$prev" ]; then
        fail "truncate_at_$t" "events went down: $DUMPED after $prev"; bad=1
    elif [ "$RC_VIEW" -ne 0 ] || [ ! -s view.png ] || ! grep -q "$F" view.out; then
        fail "truncate_at_$t" "pdtview rc $RC_VIEW, no picture or no notice: $(head -2 view.out)"; bad=1
    fi
    prev=$DUMPED
done
[ "$bad" -eq 0 ] && ok "truncate_rank_file_at_${ncut}_offsets"

# ---- (b) one flipped bit in every block (and in the file header) --------------------------
F=rank-0002.trace
blocks run/$F >layout2.txt
flip() { # FILE BYTE
    python3 -c 'import sys
p, i = sys.argv[1], int(sys.argv[2])
d = bytearray(open(p, "rb").read()); d[i] ^= 1 << (i % 8); open(p, "wb").write(d)' "$1" "$2"
}
bad=0; nflip=0
while read -r off cnt len; do
    # the block's header (its length field) and the middle of its payload
    for b in $((off + 5)) $((off + 32 + len / 2)); do
        rm -rf flip; cp -r run flip; flip flip/$F "$b"
        run_tools flip 2
        sane "bitflip_at_$b" || { bad=1; continue; }
        nflip=$((nflip + 1))
        want=$(awk -v o="$off" '$2 != "end" && $1 < o { s += $2 } END { print s + 0 }' layout2.txt)
        if [ "$RC_CHECK" -ne 1 ] || ! grep -q "$F: .*byte $off" check.out; then
            fail "bitflip_at_$b" "check rc $RC_CHECK, want 1 naming byte $off: $(head -2 check.out)"; bad=1
        elif [ "$DUMPED" -ne "$want" ]; then
            fail "bitflip_at_$b" "dump shows $DUMPED events of rank 2, want $want"; bad=1
        elif [ "$RC_VIEW" -ne 0 ] || [ ! -s view.png ] || ! grep -q "$F" view.out; then
            fail "bitflip_at_$b" "pdtview rc $RC_VIEW: $(head -2 view.out)"; bad=1
        fi
    done
done <layout2.txt
rm -rf flip; cp -r run flip; flip flip/$F 20
run_tools flip 2
if sane bitflip_file_header && [ "$RC_CHECK" -eq 1 ] && grep -q "$F: file header checksum mismatch" check.out &&
   [ "$DUMPED" -eq 0 ] && [ "$RC_VIEW" -eq 0 ]; then nflip=$((nflip + 1))
else fail bitflip_file_header "check rc $RC_CHECK, dump $DUMPED: $(head -2 check.out)"; bad=1; fi
[ "$bad" -eq 0 ] && ok "bitflip_in_every_block_${nflip}_cases"

# ---- (c) a rank file is missing ----------------------------------------------------------
rm -rf miss; cp -r run miss; rm miss/rank-0003.trace
run_tools miss 0
full0=$("$PDT" trace dump run --rank 0 | wc -l)
if sane missing_rank_file && [ "$RC_CHECK" -eq 1 ] && grep -q "rank-0003.trace: missing" check.out &&
   [ "$DUMPED" -eq "$full0" ] && [ "$RC_VIEW" -eq 0 ] && [ -s view.png ] &&
   grep -q "rank-0003.trace: missing" view.out; then ok missing_rank_file
else fail missing_rank_file "check rc $RC_CHECK, view rc $RC_VIEW, rank 0 $DUMPED/$full0: $(head -2 check.out)"; fi

# ---- (d) a manifest from another format version ---------------------------------------------
rm -rf ver; cp -r run ver; sed -i 's/^format = .*/format = 3.0/' ver/manifest
run_tools ver 0
if sane other_major_version && [ "$RC_CHECK" -ne 0 ] && grep -q "manifest:2: run folder format 3.0; this pdt reads formats 1.x to 2.x" check.out &&
   [ "$RC_VIEW" -ne 0 ] && grep -q "format 3.0" view.out; then ok other_major_version_refused
else fail other_major_version_refused "check rc $RC_CHECK, view rc $RC_VIEW: $(head -2 check.out)"; fi
sed -i 's/^format = .*/format = 2.9/' ver/manifest
run_tools ver 0
if sane newer_minor_version && [ "$RC_CHECK" -eq 0 ] && [ "$DUMPED" -eq "$full0" ]; then ok newer_minor_version_read
else fail newer_minor_version_read "check rc $RC_CHECK: $(head -2 check.out)"; fi
summary
