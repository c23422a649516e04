#!/bin/bash
# The plain writer on several threads (src/io/write.c, "long sections on
# several threads"): a long section of a regular file is printed in chunks by
# T threads that take turns and write each chunk at its offset.  The bytes must
# be the one-thread loop's for every output format (.tri, .ele with its .node,
# .off, points as text and .node from `pdt gen`), every thread count and every
# chunk size (PDT_TEST_WRITE_CHUNK=items: many chunks, every thread's turn
# taken, a last chunk shorter than the others).  A write that fails on a
# helper's chunk (file size limit: EFBIG) must end the run with the file's name
# and the reason, exit 2, and leave neither the output nor a temporary file.
# Standard output keeps the same bytes: through a pipe and appending to a
# file (>>) with the one-thread loop, redirected to a file (>) on threads.
# san: yes
source "$(dirname "$0")/lib.sh"
PDT=$PDT_HOOKED  # injects faults (PDT_TEST_*)
cd "$TMP"

"$PDT" gen uniform 3000 --seed 5 -o in.txt 2> /dev/null
"$PDT" gen clusters 2000 --seed 2 -o in2.txt 2> /dev/null

# run T CHUNK ARGS...: pdt with PDT_WRITE_THREADS=T and the test chunk size
run() {
    local t=$1 c=$2
    shift 2
    PDT_WRITE_THREADS=$t PDT_TEST_WRITE_CHUNK=$c "$PDT" "$@" 2> err.txt
}

for in in in.txt in2.txt; do
    for ext in tri ele off; do
        run 1 "" triangulate $in -o ref.$ext || fail "ref $in $ext" "$(cat err.txt)"
        [ $ext = ele ] && cp ref.node refnode.node
        for t in 2 3 5; do
            for c in 1 7 1000; do
                name="$in .$ext, $t threads, chunks of $c"
                if ! run $t $c triangulate $in -o out.$ext; then
                    fail "$name" "exit non-zero: $(cat err.txt)"
                elif ! cmp -s ref.$ext out.$ext; then
                    fail "$name" "bytes differ from the one-thread writer"
                elif [ $ext = ele ] && ! cmp -s refnode.node out.node; then
                    fail "$name" "the .node differs from the one-thread writer's"
                else
                    ok "$name"
                fi
            done
        done
    done
done

# points: `pdt gen` writes text and .node through the same writer
for ext in txt node; do
    run 1 "" gen grid 2500 --seed 1 -o ref.$ext
    for t in 2 4; do
        run $t 3 gen grid 2500 --seed 1 -o out.$ext
        if cmp -s ref.$ext out.$ext; then ok "gen .$ext, $t threads"
        else fail "gen .$ext, $t threads" "bytes differ from the one-thread writer"; fi
    done
done

# the default (threads = CPUs online, chunks of 16384) on 2^18 + 5 points'
# worth of lines: the threaded path's own threshold
"$PDT" gen uniform 140000 --seed 9 -o big.txt 2> /dev/null
run 1 "" triangulate big.txt -o refbig.tri
"$PDT" triangulate big.txt -o out.tri 2> err.txt
if cmp -s refbig.tri out.tri; then ok "default threads and chunks: same bytes"
else fail "default threads and chunks: same bytes" "$(cat err.txt)"; fi

# standard output is a pipe: same bytes
run 1 "" triangulate in.txt -o ref.tri
run 3 5 triangulate in.txt -o - | cat > pipe.tri
if cmp -s ref.tri pipe.tri; then ok "standard output through a pipe: same bytes"
else fail "standard output through a pipe: same bytes"; fi

# standard output redirected to a regular file: threads when it is opened
# plainly (>), the one-thread loop when it appends (>>: pwrite would append
# whatever its offset, and the chunks would land in the order they were done)
run 3 5 triangulate in.txt -o - > redir.tri
if cmp -s ref.tri redir.tri; then ok "standard output to a file (>): same bytes"
else fail "standard output to a file (>): same bytes"; fi
echo "first line" > app.tri
run 3 5 triangulate in.txt -o - >> app.tri
{ echo "first line"; cat ref.tri; } > app-want.tri
if cmp -s app-want.tri app.tri; then ok "standard output appending to a file (>>): same bytes after the old ones"
else fail "standard output appending to a file (>>): same bytes after the old ones"; fi

# a helper that cannot be started (PDT_TEST_WRITE_HELPERS=K: only K start):
# those started are stopped before any chunk is written, and the one-thread
# loop writes the same bytes
for k in 0 1; do
    if PDT_TEST_WRITE_HELPERS=$k run 3 5 triangulate in.txt -o nohelp.tri && cmp -s ref.tri nohelp.tri
    then ok "only $k of 2 helpers start: the one-thread loop, same bytes"
    else fail "only $k of 2 helpers start: the one-thread loop, same bytes" "$(cat err.txt)"; fi
done

# a failed write: the file size limit (bytes in 512-byte blocks) is met by some
# chunk after the first one, on whichever thread printed it
rm -f out.tri
size=$(stat -c %s ref.tri)
limit=$((size / 512 / 2))
(
    trap '' XFSZ
    ulimit -f $limit
    PDT_WRITE_THREADS=3 PDT_TEST_WRITE_CHUNK=50 exec "$PDT" triangulate in.txt -o out.tri
) 2> err.txt
rc=$?
left=$(ls -A | grep -c '^\.\?out\.tri')
if [ $rc -ne 2 ]; then
    fail "write fails on a helper's chunk: exit 2" "exit $rc: $(cat err.txt)"
elif ! grep -q "out.tri: write error: File too large" err.txt; then
    fail "write fails on a helper's chunk: the message" "$(cat err.txt)"
elif [ "$left" -ne 0 ]; then
    fail "write fails on a helper's chunk: nothing left" "$(ls -A)"
else
    ok "write fails on a helper's chunk: exit 2, the file and the reason named, nothing left"
fi

summary
