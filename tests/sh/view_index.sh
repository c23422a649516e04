#!/bin/bash
# pdtview's kept index and memory budget (issue 12): a run larger than a
# quarter of --mem opens through RUN/.pdtview-index (or the cache folder when
# RUN is read-only); the index is kept, rebuilt when the run changed or the
# index is damaged, and gives the same replay as the run held in memory.
# san: yes
. "$(dirname "$0")/lib.sh"
V=$BIN/pdtview
R=$TMP/run
"$PDT" gen uniform 1500 --seed 7 > "$TMP/u.txt"
"$PDT" triangulate "$TMP/u.txt" -o "$TMP/u.tri" --trace "$R" || { fail record; summary; exit 1; }
IDX=$R/.pdtview-index
inode() { stat -c %i "$1" 2>/dev/null; }
# same_pictures RUN BUDGET CURSOR...: the frames at each cursor (an --at number, or
# end) drawn from the run held in memory and through the index under --mem
# BUDGET are byte-identical
same_pictures() {
    local run=$1 budget=$2 at a; shift 2
    for at in "$@"; do
        a="--at $at"; [ "$at" = end ] && a=--end
        "$V" --headless "$run" $a -o "$TMP/sp_mem.png" --size 640x400 --quiet --index off
        "$V" --headless "$run" $a -o "$TMP/sp_idx.png" --size 640x400 --quiet --mem "$budget"
        cmp -s "$TMP/sp_mem.png" "$TMP/sp_idx.png" || return 1
    done
}

# in memory (the default budget on a small run): no index is written
mem=$("$V" "$R" --counts --end)
if [ -n "$mem" ] && [ ! -e "$IDX" ]; then ok small_run_in_memory
else fail small_run_in_memory "index written for a small run, or no counts: $mem"; fi

# a tiny budget: the index is built beside the run, and the replay is the same
got=$("$V" "$R" --counts --end --mem 1M 2>"$TMP/e1")
if [ "$got" = "$mem" ] && [ -s "$IDX" ] && [ ! -s "$TMP/e1" ]; then ok index_built_same_counts
else fail index_built_same_counts "got '$got' want '$mem'; $(cat "$TMP/e1")"; fi
ls "$R"/.pdtview-index.tmp* >/dev/null 2>&1 && fail no_temp_left "a temporary index is left" || ok no_temp_left

# the index holds no events: it refers to the rank files' blocks, and checks
# each block as it decodes it.  A rank file changed behind it (same size and
# time) is found: at the opening when the index is checked whole (rebuilt,
# saying why), or when the block is first decoded when it is checked lazily
# (the index removed, with a message naming it)
flip_rank() { # DIR: flip a bit inside rank 0's last block (200 bytes before the end), keep its time
    python3 -c 'import sys, os; p = sys.argv[1]; o = os.path.getsize(p) - 200; f = open(p, "r+b"); f.seek(o); b = f.read(1); f.seek(o); f.write(bytes([b[0] ^ 0x01]))' "$1/rank-0000.trace"
    touch -r "$R/rank-0000.trace" "$1/rank-0000.trace"
}
"$V" "$R" --counts --end --mem 1M >/dev/null 2>&1
cp -a "$R" "$TMP/rund1"; cp -a "$R" "$TMP/rund2"
flip_rank "$TMP/rund1"; flip_rank "$TMP/rund2"
"$V" "$TMP/rund1" --counts --end --mem 1M 2>&1 >/dev/null | grep -q "rebuilt the index (stale: rank-0000.trace does not match it" &&
    ok rank_file_changed_rebuilt || fail rank_file_changed_rebuilt "$("$V" "$TMP/rund1" --counts --end --mem 1M 2>&1)"
PDTVIEW_VERIFY=lazy "$V" "$TMP/rund2" --describe --mem 1M >/dev/null 2>"$TMP/ed1"; rc=$?
if [ $rc -ne 0 ] && grep -q "refers to rank-0000.trace, which no longer matches it" "$TMP/ed1" &&
   [ ! -e "$TMP/rund2/.pdtview-index" ]; then ok rank_file_changed_lazy
else fail rank_file_changed_lazy "exit $rc: $(cat "$TMP/ed1")"; fi

# what the window shows (event lines, lit code lines) is the same at every event
"$V" "$R" --describe --index off > "$TMP/d_mem.txt"
"$V" "$R" --describe --mem 1M > "$TMP/d_idx.txt"
if [ -s "$TMP/d_mem.txt" ] && cmp -s "$TMP/d_mem.txt" "$TMP/d_idx.txt"; then ok describe_same
else fail describe_same "$(diff "$TMP/d_mem.txt" "$TMP/d_idx.txt" | head -3)"; fi

# seek == stepping == direct seek, with checkpoints (1M) and without (64K)
for b in 1M 64K; do
    out=$("$V" "$R" --check --mem $b)
    case "$out" in *", 0 differ"*) ok "check_mem_$b" ;; *) fail "check_mem_$b" "$out" ;; esac
done
# a state over a quarter of the budget lives in a temporary file's mapping
# (paged, its pages given back after each seek and frame): the same replay
# and the same pictures as in memory
case "$("$V" "$R" --check --mem 16K)" in *", 0 differ"*"(states paged"*) ok paged_state_check ;;
    *) fail paged_state_check "$("$V" "$R" --check --mem 16K)" ;; esac
case "$("$V" "$R" --check --mem 1M)" in *"paged"*) fail small_state_not_paged ;; *) ok small_state_not_paged ;; esac
same_pictures "$R" 16K 0 2345 end && ok paged_state_same_pictures || fail paged_state_same_pictures
case "$("$V" "$R" --check --mem 1M)" in *"checkpoints every"*) ok checkpoints_made ;;
    *) fail checkpoints_made "no checkpoints under --mem 1M" ;; esac

# a build that crashed left its temporary file (pdt/safefile.h's name): the
# next build removes it (its process is gone), and leaves alone the one of a
# process still alive, and a file of the user's that only looks alike
dead=$(sh -c 'echo $$')
echo junk > "$R/.${IDX##*/}.pdt-tmp.$dead.0badf00d"
echo junk > "$R/.${IDX##*/}.pdt-tmp.$$.0badf00d"
echo junk > "$IDX.tmp$dead"
mv "$IDX" "$TMP/idx.keep"
"$V" "$R" --counts --end --mem 1M >/dev/null 2>&1
if [ ! -e "$R/.${IDX##*/}.pdt-tmp.$dead.0badf00d" ] && [ -e "$R/.${IDX##*/}.pdt-tmp.$$.0badf00d" ] &&
    [ -e "$IDX.tmp$dead" ] && [ -s "$IDX" ]; then ok stale_temp_removed
else fail stale_temp_removed "$(ls -a "$R")"; fi
rm -f "$R/.${IDX##*/}.pdt-tmp.$$.0badf00d" "$IDX.tmp$dead"
rm -f "$IDX.tmp$$"

# lazy verification (what a big index gets; PDTVIEW_VERIFY=lazy forces it):
# the same replay and picture; a damaged chunk is found when it is first
# read (a part never read is never checked: --describe reads the events):
# the index is removed with a message naming it, the next opening rebuilds it
lz=$(PDTVIEW_VERIFY=lazy "$V" "$R" --counts --end --mem 1M 2>"$TMP/el")
if [ "$lz" = "$mem" ] && [ ! -s "$TMP/el" ]; then ok lazy_verify_same_counts
else fail lazy_verify_same_counts "got '$lz' want '$mem'; $(cat "$TMP/el")"; fi
PDTVIEW_VERIFY=lazy "$V" --headless "$R" --end -o "$TMP/lazy.png" --size 640x400 --quiet --mem 1M
"$V" --headless "$R" --end -o "$TMP/mem0.png" --size 640x400 --quiet --index off
if [ -s "$TMP/lazy.png" ] && cmp -s "$TMP/lazy.png" "$TMP/mem0.png"; then ok lazy_verify_same_picture
else fail lazy_verify_same_picture "the end frame differs with lazy verification"; fi
python3 -c 'import sys; f = open(sys.argv[1], "r+b"); f.seek(5000); b = f.read(1); f.seek(5000); f.write(bytes([b[0] ^ 0xFF]))' "$IDX"
PDTVIEW_VERIFY=lazy "$V" "$R" --describe --mem 1M >/dev/null 2>"$TMP/el2"; rc=$?  # reads every event
if [ $rc -ne 0 ] && grep -q "kept index $IDX is damaged" "$TMP/el2" && [ ! -e "$IDX" ]; then
    ok lazy_verify_damage_found
else fail lazy_verify_damage_found "exit $rc: $(cat "$TMP/el2"); $(ls -a "$R")"; fi
lz=$(PDTVIEW_VERIFY=lazy "$V" "$R" --counts --end --mem 1M 2>/dev/null)
[ "$lz" = "$mem" ] && [ -s "$IDX" ] && ok lazy_verify_rebuilt || fail lazy_verify_rebuilt "got '$lz'"
# a byte of the triangles' table changed (section 2 of the header's table,
# at its middle; ihdr in src/view/model/index_int.h): the end frame draws the
# triangles, so it checks that chunk
python3 - "$IDX" <<'PY'
import struct, sys
f = open(sys.argv[1], 'r+b')
head = f.read(4096)
off, size = struct.unpack_from('<QQ', head, 8 + 4 + 4 + 8 + 8 + 48 + 32 + 26 * 8 + 64 * 8 + 24 * 2)
f.seek(off + size // 2); b = f.read(1); f.seek(off + size // 2); f.write(bytes([b[0] ^ 0xFF]))
PY
PDTVIEW_VERIFY=lazy "$V" --headless "$R" --end -o "$TMP/lz3.png" --size 320x200 --quiet --mem 1M 2>"$TMP/el3"; rc=$?
if [ $rc -ne 0 ] && grep -q "kept index $IDX is damaged" "$TMP/el3" && [ ! -e "$IDX" ]; then
    ok lazy_verify_damaged_triangles_found
else fail lazy_verify_damaged_triangles_found "exit $rc: $(cat "$TMP/el3")"; fi
"$V" "$R" --counts --end --mem 1M >/dev/null 2>&1  # (rebuilt for what follows)

# the second opening maps the kept index (same file, not rewritten)
i1=$(inode "$IDX")
"$V" "$R" --counts --end --mem 1M >/dev/null 2>"$TMP/e2"
if [ "$(inode "$IDX")" = "$i1" ] && [ ! -s "$TMP/e2" ]; then ok index_kept
else fail index_kept "the index was rewritten: $(cat "$TMP/e2")"; fi

# the same picture from the index as from memory
"$V" --headless "$R" --end -o "$TMP/mem.png" --size 640x400 --quiet --index off
"$V" --headless "$R" --end -o "$TMP/idx.png" --size 640x400 --quiet --mem 1M
if [ -s "$TMP/mem.png" ] && cmp -s "$TMP/mem.png" "$TMP/idx.png"; then ok same_picture
else fail same_picture "the end frame differs through the index"; fi

# stale: a run file changed (size and time) -> rebuilt, never trusted
"$PDT" gen uniform 1400 --seed 8 > "$TMP/v.txt"
# (a new --trace into R would replace the folder whole, index and all: copy the files in)
"$PDT" triangulate "$TMP/v.txt" -o "$TMP/v.tri" --trace "$TMP/vrun" >/dev/null
cp "$TMP/vrun/manifest" "$TMP/vrun/points.bin" "$TMP/vrun/rank-0000.trace" "$R/"
want=$("$V" "$R" --counts --end --index off)
got=$("$V" "$R" --counts --end --mem 1M 2>"$TMP/e3")
if [ "$got" = "$want" ] && grep -q "rebuilt the index (stale" "$TMP/e3"; then ok stale_rebuilt
else fail stale_rebuilt "got '$got' want '$want'; $(cat "$TMP/e3")"; fi
# only the modification time changed
touch -d '2001-01-01' "$R/rank-0000.trace"
"$V" "$R" --counts --end --mem 1M >/dev/null 2>"$TMP/e4"
grep -q "stale" "$TMP/e4" && ok stale_mtime_rebuilt || fail stale_mtime_rebuilt "$(cat "$TMP/e4")"

# damaged: a byte changed in the middle, or cut short -> rebuilt
size=$(stat -c %s "$IDX")
python3 -c 'import sys; f = open(sys.argv[1], "r+b"); f.seek(5000); b = f.read(1); f.seek(5000); f.write(bytes([b[0] ^ 0xFF]))' "$IDX"  # a byte of the events
got=$("$V" "$R" --counts --end --mem 1M 2>"$TMP/e5")
if [ "$got" = "$want" ] && grep -q "damaged: checksum" "$TMP/e5"; then ok damaged_rebuilt
else fail damaged_rebuilt "got '$got'; $(cat "$TMP/e5")"; fi
truncate -s $((size / 3)) "$IDX"
got=$("$V" "$R" --counts --end --mem 1M 2>"$TMP/e6")
if [ "$got" = "$want" ] && grep -q "damaged" "$TMP/e6" && [ "$(stat -c %s "$IDX")" = "$size" ]; then
    ok truncated_rebuilt
else fail truncated_rebuilt "got '$got'; $(cat "$TMP/e6")"; fi
# an index of another run copied over this one's
cp "$IDX" "$TMP/idx.bak"
"$V" synth:srm:8:4:2 --counts --end >/dev/null
mkdir "$TMP/other" && "$V" --write-run "$TMP/other" synth:srm:8:4:2 --quiet &&
    "$V" "$TMP/other" --counts --end --mem 1M --index on >/dev/null 2>&1 &&
    cp "$TMP/other/.pdtview-index" "$IDX"
got=$("$V" "$R" --counts --end --mem 1M 2>"$TMP/e7")
if [ "$got" = "$want" ] && grep -q "rebuilt the index" "$TMP/e7"; then ok foreign_index_rebuilt
else fail foreign_index_rebuilt "got '$got'; $(cat "$TMP/e7")"; fi

# a read-only run folder: the index goes to $XDG_CACHE_HOME/pdt, the folder is untouched
RO=$TMP/ro
mkdir -p "$RO/run" "$TMP/cache" "$TMP/rbin"
cp "$R"/manifest "$R"/points.bin "$R"/rank-*.trace "$RO/run/"
cp "$V" "$TMP/rbin/pdtview"
chmod 755 "$TMP" "$RO" "$TMP/rbin"
chmod 555 "$RO/run"
chmod 777 "$TMP/cache"
as_user() {  # root ignores folder permissions: read-only is tested as nobody
    if [ "$(id -u)" = 0 ]; then
        setpriv --reuid=65534 --regid=65534 --clear-groups env HOME=/nonexistent XDG_CACHE_HOME="$TMP/cache" "$@"
    else
        env XDG_CACHE_HOME="$TMP/cache" "$@"
    fi
}
got=$(as_user "$TMP/rbin/pdtview" "$RO/run" --counts --end --mem 1M 2>"$TMP/e8")
cached=$(ls "$TMP/cache/pdt/"run-*.pdtview-index 2>/dev/null | head -1)
if [ "$got" = "$want" ] && [ -n "$cached" ] && [ ! -e "$RO/run/.pdtview-index" ]; then ok readonly_cache
else fail readonly_cache "got '$got'; cache '$cached'; $(cat "$TMP/e8")"; fi
i2=$(inode "$cached")
as_user "$TMP/rbin/pdtview" "$RO/run" --counts --end --mem 1M >/dev/null 2>&1
[ -n "$i2" ] && [ "$(inode "$cached")" = "$i2" ] && ok readonly_cache_kept || fail readonly_cache_kept
chmod 755 "$RO/run"

# a run of 3 ranks (candidates deferred, shipped, discarded): the index built
# under a tiny budget (the triangle events grouped in several runs, streamed
# to the file) shows the same pictures and the same events as memory (the
# plain build records it: mpirun with the sanitized one is not what is tested)
R3=$TMP/run3
"$PDT" gen uniform 3000 --seed 11 > "$TMP/u3.txt"
if mpirun -np 3 "$ROOT/bin/pdt" triangulate "$TMP/u3.txt" -o "$TMP/u3.tri" --trace "$R3" >/dev/null 2>&1; then
    same3=1
    same_pictures "$R3" 256K 9000 20000 end || same3=0
    "$V" "$R3" --describe --index off > "$TMP/d3m.txt"
    "$V" "$R3" --describe --mem 256K > "$TMP/d3i.txt"
    if [ $same3 = 1 ] && [ -s "$R3/.pdtview-index" ] && [ -s "$TMP/d3m.txt" ] && cmp -s "$TMP/d3m.txt" "$TMP/d3i.txt"
    then ok ranks3_tiny_budget_same
    else fail ranks3_tiny_budget_same "pictures same: $same3; $(diff "$TMP/d3m.txt" "$TMP/d3i.txt" | head -3)"; fi
    case "$("$V" "$R3" --check --mem 256K)" in *", 0 differ"*) ok ranks3_check ;;
        *) fail ranks3_check "$("$V" "$R3" --check --mem 256K)" ;; esac
else
    fail ranks3_record "mpirun -np 3 failed"
fi

# a hull run (Graham's sort: the per-point sort tables, which a triangulation's
# index leaves out) gives the same event lines and seeks through the index
RH=$TMP/runh
"$PDT" gen uniform 2000 --seed 5 > "$TMP/uh.txt"
"$PDT" hull "$TMP/uh.txt" -o "$TMP/uh.out" --trace "$RH" >/dev/null 2>&1 || fail hull_record
"$V" "$RH" --describe --index off > "$TMP/dhm.txt"
"$V" "$RH" --describe --mem 64K > "$TMP/dhi.txt"
if [ -s "$RH/.pdtview-index" ] && [ -s "$TMP/dhm.txt" ] && cmp -s "$TMP/dhm.txt" "$TMP/dhi.txt"
then ok hull_run_same_events
else fail hull_run_same_events "$(diff "$TMP/dhm.txt" "$TMP/dhi.txt" | head -3)"; fi
case "$("$V" "$RH" --check --mem 64K)" in *", 0 differ"*) ok hull_run_check ;;
    *) fail hull_run_check "$("$V" "$RH" --check --mem 64K)" ;; esac

# a level-2 run (the kernel's edges: the edge table and its map) whose
# tables outgrow a tiny budget's share: they live in temporary files'
# mappings while the index is built (replay.c, tab_grow), and the replay is
# the same as the one held in memory
R2=$TMP/run2
"$PDT" gen uniform 3000 --seed 21 > "$TMP/u2.txt"
"$PDT" triangulate "$TMP/u2.txt" -o "$TMP/u2.tri" --trace "$R2" --trace-level 2 >/dev/null 2>&1 ||
    fail level2_record
"$V" "$R2" --describe --index off > "$TMP/d2m.txt"
"$V" "$R2" --describe --mem 32K > "$TMP/d2i.txt"
if [ -s "$R2/.pdtview-index" ] && [ -s "$TMP/d2m.txt" ] && cmp -s "$TMP/d2m.txt" "$TMP/d2i.txt"
then ok level2_paged_tables_same_events
else fail level2_paged_tables_same_events "$(diff "$TMP/d2m.txt" "$TMP/d2i.txt" | head -3)"; fi
same_pictures "$R2" 32K 4000 20000 end && ok level2_paged_tables_same_pictures ||
    fail level2_paged_tables_same_pictures
case "$("$V" "$R2" --check --mem 32K)" in *", 0 differ"*) ok level2_paged_tables_check ;;
    *) fail level2_paged_tables_check "$("$V" "$R2" --check --mem 32K)" ;; esac

# the kept index is the same bytes at every build: no padding or other
# unset bytes go into it (the 3-rank run's messages and hulls had some)
same_index() { # RUN
    rm -f "$1/.pdtview-index"
    "$V" "$1" --counts --end --index on >/dev/null && cp "$1/.pdtview-index" "$TMP/ix.a" &&
        rm -f "$1/.pdtview-index" && "$V" "$1" --counts --end --index on >/dev/null &&
        cmp -s "$TMP/ix.a" "$1/.pdtview-index"
}
for run in "$R3" "$RH" "$R2"; do
    [ -d "$run" ] || continue
    if same_index "$run"; then ok "index_same_bytes_$(basename "$run")"
    else fail "index_same_bytes_$(basename "$run")" "$(cmp "$TMP/ix.a" "$run/.pdtview-index" 2>&1)"; fi
done

# the build holds no table per event or per point (they go to the index
# and to scratch files a window at a time): its working memory, as it
# counts it, stays within --mem and does not grow with the run (a run four
# times the events, the same budget); and what it builds is what memory gives
build_mem() { # RUN: the build's working memory in KiB, under --mem 16M
    rm -f "$1/.pdtview-index"
    "$V" "$1" --bench --mem 16M | sed -n 's/^index build: working memory \([0-9.]*\) MiB.*/\1/p' |
        awk '{ printf "%d", $1 * 1024 }'
}
for np in 10000 40000; do
    "$PDT" gen uniform $np --seed 13 > "$TMP/ub$np.txt"
    "$PDT" triangulate "$TMP/ub$np.txt" -o "$TMP/ub.tri" --trace "$TMP/runb$np" >/dev/null 2>&1 ||
        fail "record_$np"
done
small=$(build_mem "$TMP/runb10000"); big=$(build_mem "$TMP/runb40000")
if [ -n "$small" ] && [ -n "$big" ] && [ "$big" -le $((16 * 1024)) ] && [ "$big" -le $((small + small / 10)) ]
then ok build_memory_bounded
else fail build_memory_bounded "working memory ${small:-?} KiB (10000 points), ${big:-?} KiB (40000 points), budget 16384 KiB"; fi
RB=$TMP/runb40000
same_pictures "$RB" 16M 123457 end && ok build_bounded_same_pictures || fail build_bounded_same_pictures

# the build's scratch tables (src/view/model/scratch_int.h) held in memory
# (half of the default budget takes them all), in files (no memory), or
# split between the two (a 2 MiB share: the spill's first part in memory,
# the rest in its file, the next tables in files until it is dropped):
# the same index, and the working memory counts what memory held.  Only a
# test build (the sanitizer's) reads $PDT_TEST_SCRATCH_MEM.
scratch_build() { # POOL (bytes, or default): RB's index to $TMP/ixs.POOL; prints the working memory
    rm -f "$RB/.pdtview-index"
    if [ "$1" = default ]; then "$V" "$RB" --bench --index on
    else PDT_TEST_SCRATCH_MEM=$1 "$V" "$RB" --bench --index on; fi |
        sed -n 's/^index build: working memory \([0-9.]*\) MiB.*/\1/p'
    cp "$RB/.pdtview-index" "$TMP/ixs.$1"
}
if [ "$(basename "$BIN")" = san ]; then
    w0=$(scratch_build 0); w2=$(scratch_build 2097152); wd=$(scratch_build default)
    if cmp -s "$TMP/ixs.0" "$TMP/ixs.2097152" && cmp -s "$TMP/ixs.0" "$TMP/ixs.default"
    then ok scratch_in_memory_same_index
    else fail scratch_in_memory_same_index "$(cmp "$TMP/ixs.0" "$TMP/ixs.2097152"; cmp "$TMP/ixs.0" "$TMP/ixs.default")"; fi
    if awk -v a="$w0" -v b="$w2" -v c="$wd" 'BEGIN { exit !(a > 0 && b >= a + 1.9 && b <= a + 2.1 && c > b + 2) }'
    then ok scratch_memory_counted
    else fail scratch_memory_counted "working memory ${w0:-?} MiB (none), ${w2:-?} MiB (2 MiB), ${wd:-?} MiB (default)"; fi
fi

# an index that cannot be written whole: the file size limit falls inside
# the checkpoints (the last section, header bytes 1432..1447 its place and
# length), so the thread writing them fails while another steps through the
# run.  The opening still gives the replay (from memory), says in one line
# that no index was kept, and leaves no index or temporary file behind.
rm -f "$RB/.pdtview-index"
want=$("$V" "$RB" --counts --end --index on)
read -r ck_at ck_len < <(od -An -t u8 -j 1432 -N 16 "$RB/.pdtview-index")
rm -f "$RB/.pdtview-index"
if [ "${ck_len:-0}" -gt 4096 ]; then
    got=$(trap '' XFSZ; ulimit -f $(((ck_at + ck_len / 2) / 1024))
          timeout 120 "$V" "$RB" --counts --end --index on 2>"$TMP/efb")
    rc=$?
    left=$(ls -A "$RB" | grep -c pdtview-index)
    if [ "$rc" = 0 ] && [ "$got" = "$want" ] && [ "$left" = 0 ] &&
        grep -q "no index kept (writing the index: File too large)" "$TMP/efb"
    then ok index_write_fails_in_checkpoints
    else fail index_write_fails_in_checkpoints "exit $rc, $left index files left, $(head -2 "$TMP/efb")"; fi
else
    fail index_write_fails_in_checkpoints "no checkpoints found in the index (${ck_at:-?} ${ck_len:-?})"
fi

# the triangle events grouped in more buckets (what a run of more than
# 10^9 events gets at the default budget, forced here): the same replay
RS=$TMP/runb10000
rm -f "$RS/.pdtview-index"
nb=$(PDTVIEW_BUCKETS=4096 "$V" "$RS" --bench --mem 1M | sed -n 's/.*grouped in \([0-9]*\) buckets.*/\1/p')
if [ "$nb" = 4096 ] && [ "$("$V" "$RS" --counts --end --mem 1M)" = "$("$V" "$RS" --counts --end --index off)" ]
then ok many_buckets_same_counts
else fail many_buckets_same_counts "buckets '${nb}'"; fi
case "$("$V" "$RS" --check --mem 1M)" in *", 0 differ"*) ok many_buckets_check ;;
    *) fail many_buckets_check "$("$V" "$RS" --check --mem 1M)" ;; esac
rm -f "$RS/.pdtview-index"
PDTVIEW_BUCKETS=4096 "$V" "$RS" --counts --mem 1M >/dev/null
same_pictures "$RS" 1M 27777 end && ok many_buckets_same_pictures || fail many_buckets_same_pictures

# a run of 16 ranks (its timeline in time, the merge tree with each step's
# time): the times the index keeps for the phases, merge steps and messages
# draw the same timeline and tree as the events' own times held in memory
R16=$TMP/run16
"$V" --write-run "$R16" synth:srm:40:12:16 --quiet
for at in 900 end; do
    a="--at $at"; [ "$at" = end ] && a=--end
    "$V" --headless "$R16" $a -o "$TMP/t16m.png" --size 1024x768 --panels timeline,tree --quiet --index off \
        --layout-report "$TMP/t16m.json"
    "$V" --headless "$R16" $a -o "$TMP/t16i.png" --size 1024x768 --panels timeline,tree --quiet --mem 1M \
        --layout-report "$TMP/t16i.json"
    if [ -s "$R16/.pdtview-index" ] && cmp -s "$TMP/t16m.png" "$TMP/t16i.png" &&
        cmp -s "$TMP/t16m.json" "$TMP/t16i.json" && grep -q '"panel": *"tree"' "$TMP/t16i.json"
    then ok "ranks16_times_kept_same_frame_$at"
    else fail "ranks16_times_kept_same_frame_$at" "frames or texts differ, or no tree drawn"; fi
done

# bad budgets
for bad in 0 12Q -5 ''; do
    "$V" "$R" --counts --mem "$bad" >/dev/null 2>"$TMP/eb"; rc=$?
    if [ $rc -eq 2 ] && grep -q -- "--mem" "$TMP/eb"; then ok "bad_mem_'$bad'"
    else fail "bad_mem_'$bad'" "exit $rc: $(cat "$TMP/eb")"; fi
done
PDTVIEW_MEM=1M "$V" "$R" --check >/dev/null && ok env_budget || fail env_budget
summary
