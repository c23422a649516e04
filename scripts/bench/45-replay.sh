#!/bin/bash
# Replaying cluster-sized runs (issue 12): a 10^7-point level-1 run on 1 rank
# (about 5*10^7 events) and a 10^6-point run on 8 ranks.  For each: the trace
# tools (check, dump of the merged order, OTF2 export) and the viewer (first
# and second opening, seek, frame time), each with its wall time and peak
# resident memory (GNU time's maxrss).  Smaller sizes: REPLAY_N1=... and
# REPLAY_N8=... (points).  The runs are kept in build/bench/replay/ and
# re-used.  Prints figures; never fails on a time.
set -u
cd "$(dirname "$0")/../.."
N1=${REPLAY_N1:-10000000}
N8=${REPLAY_N8:-1000000}
OUT=build/bench/replay
mkdir -p "$OUT"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
if [ ! -x /usr/bin/time ]; then echo "GNU time (/usr/bin/time) missing: make deps-bench"; exit 1; fi

# measure LABEL CMD...: one line "LABEL  wall s  peak MiB" (output of CMD dropped)
measure() {
    local label=$1; shift
    /usr/bin/time -f "%e %M" -o "$OUT/time.txt" "$@" >"$OUT/cmd.out" 2>"$OUT/cmd.err" ||
        { echo "$label: failed: $(tail -2 "$OUT/cmd.err")"; return 1; }
    read -r wall kib <"$OUT/time.txt"
    printf '  %-37s %8.2f s  %8.1f MiB peak\n' "$label" "$wall" "$(echo "$kib / 1024" | bc -l)"
}

# anon LABEL CMD...: the command's own memory, its largest RssAnon sampled
# (GNU time's peak above counts the mapped file pages too)
anon() {
    local label=$1 kib; shift
    kib=$(scripts/bench/tools/anon_peak.sh "$OUT/cmd.out" "$@") ||
        { echo "$label: failed: $(tail -2 "$OUT/cmd.out")"; return 1; }
    printf '  %-37s %8.1f MiB RssAnon peak\n' "$label" "$(echo "$kib / 1024" | bc -l)"
}

# record N RANKS DIR: a level-1 traced uniform run (once)
record() {
    local n=$1 p=$2 dir=$3
    [ -f "$dir/manifest" ] && return 0
    echo "recording $dir ($n points, $p rank(s)) ..."
    bin/pdt gen uniform "$n" -o "$OUT/pts-$n.txt" || return 1
    if [ "$p" = 1 ]; then
        bin/pdt triangulate "$OUT/pts-$n.txt" -o "$OUT/out.tri" --trace "$dir" || return 1
    else
        mpirun -np "$p" bin/pdt triangulate "$OUT/pts-$n.txt" -o "$OUT/out.tri" --trace "$dir" || return 1
    fi
    rm -f "$OUT/pts-$n.txt" "$OUT/out.tri"
}

one_run() {
    local dir=$1
    local ev
    ev=$(bin/pdt trace info "$dir" | awk '$1 == "all" {print $2; f = 1} $1 == "0" && NF >= 5 && !f {e = $2} END {if (!f) print e}')
    echo "-- $dir: $ev events, $(du -sh --exclude=.pdtview-index "$dir" | cut -f1) on disk, its kept index aside (load: $(cut -d' ' -f1-3 /proc/loadavg))"
    measure "pdt trace check" bin/pdt trace check "$dir"
    measure "pdt trace check --mem 64M" bin/pdt trace check "$dir" --mem 64M
    grep -o 'sorted on disk in [0-9]* runs\|T\* certified[^)]*' "$OUT/cmd.out" | sed 's/^/    /'
    anon "pdt trace check (own memory)" bin/pdt trace check "$dir"
    anon "pdt trace check --mem 64M (own memory)" bin/pdt trace check "$dir" --mem 64M
    measure "pdt trace dump (merged) >/dev/null" bin/pdt trace dump "$dir"
    rm -rf "$OUT/otf2"
    measure "pdt trace export --otf2" bin/pdt trace export --otf2 "$dir" -o "$OUT/otf2"
    rm -rf "$OUT/otf2"
    # the viewer: the kept index is removed first, so the first opening builds it
    rm -f "$dir/.pdtview-index"
    measure "pdtview first opening (first frame)" bin/pdtview --headless "$dir" --at 0 -o "$OUT/first.png" --size 1280x800
    [ -f "$dir/.pdtview-index" ] && echo "    kept index: $(du -h "$dir/.pdtview-index" | cut -f1)" ||
        echo "    (no kept index: the run fits a quarter of the budget, held in memory)"
    measure "pdtview second opening (first frame)" bin/pdtview --headless "$dir" --at 0 -o "$OUT/first.png" --size 1280x800
    # the build within a smaller budget (the same index, triangles grouped in more runs)
    mv "$dir/.pdtview-index" "$OUT/index.keep"
    measure "pdtview first opening, --mem 256M" bin/pdtview --headless "$dir" --at 0 -o "$OUT/first.png" --size 1280x800 --mem 256M
    mv "$OUT/index.keep" "$dir/.pdtview-index"
    PDTVIEW_VERIFY=eager measure "pdtview second opening, whole check" bin/pdtview --headless "$dir" --at 0 -o "$OUT/first.png" --size 1280x800
    measure "pdtview second opening (--end frame)" bin/pdtview --headless "$dir" --end -o "$OUT/end.png" --size 1280x800
    measure "pdtview --end, --mem 256M" bin/pdtview --headless "$dir" --end -o "$OUT/end.png" --size 1280x800 --mem 256M
    # a state over a quarter of the budget is paged (a temporary file's mapping)
    measure "pdtview --end, --mem 64M" bin/pdtview --headless "$dir" --end -o "$OUT/end64.png" --size 1280x800 --mem 64M
    anon "pdtview --end (own memory)" bin/pdtview --headless "$dir" --end -o "$OUT/end.png" --size 1280x800
    anon "pdtview --end, --mem 64M (own memory)" bin/pdtview --headless "$dir" --end -o "$OUT/end64.png" --size 1280x800 --mem 64M
    cmp -s "$OUT/end.png" "$OUT/end64.png" && echo "    (the same picture)" || echo "    (THE PICTURE DIFFERS)"
    bin/pdtview --bench "$dir" --size 1280x800 | sed 's/^/    /'
    echo "  pdtview --bench --mem 64M:"
    bin/pdtview --bench "$dir" --size 1280x800 --mem 64M | grep -E "^seek|^memory after" | sed 's/^/    /'
}

record "$N1" 1 "$OUT/run-$N1-p1" && one_run "$OUT/run-$N1-p1"
record "$N8" 8 "$OUT/run-$N8-p8" && one_run "$OUT/run-$N8-p8"
echo "(first opening: builds RUN/.pdtview-index; later openings map it and check each 16 MiB chunk"
echo " when first read (an index of 64 MiB or more; 'whole check': all of it at the opening); peak counts the mapped"
echo " index pages the frame touched, which the kernel can drop; pdtview --bench splits RssAnon/RssFile)"
