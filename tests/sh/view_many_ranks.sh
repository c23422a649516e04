#!/bin/bash
# A run folder of many ranks opens under a descriptor limit smaller than its
# rank count (issue 33: a cluster run has 64 to 1024 rank files, `ulimit -n`
# is often 1024): the readers map a rank file and close it at once, so the
# kept index's build, its later openings and the trace tools hold a bounded
# number of descriptors.  A 256-rank synthetic run, opened under
# `ulimit -n 64`, gives the same answers and picture as without the limit.
. "$(dirname "$0")/lib.sh"
V=$BIN/pdtview
R=$TMP/run256
"$V" synth:srm:512:6:256 --write-run "$R" >/dev/null 2>"$TMP/ew" || { fail write_run "$(cat "$TMP/ew")"; summary; exit 1; }
n=$(ls "$R" | grep -c '^rank-.*\.trace$')
[ "$n" = 256 ] && ok write_run_256_ranks || fail write_run_256_ranks "$n rank files"

# the answers without a limit (the run held in memory), then with one
want=$("$V" "$R" --counts --end --index off 2>&1)
"$V" --headless "$R" --end -o "$TMP/want.png" --size 640x400 --quiet --index off
limited() { (ulimit -n 64 && "$@"); }
got=$(limited "$V" "$R" --counts --end --mem 1M 2>"$TMP/e1")
if [ "$got" = "$want" ] && [ -s "$R/.pdtview-index" ]; then ok index_built_under_fd_limit
else fail index_built_under_fd_limit "got '$got' want '$want'; $(tail -3 "$TMP/e1")"; fi
got=$(limited "$V" "$R" --counts --end --mem 1M 2>"$TMP/e2")
[ "$got" = "$want" ] && ok index_reopened_under_fd_limit ||
    fail index_reopened_under_fd_limit "got '$got'; $(tail -3 "$TMP/e2")"
limited "$V" --headless "$R" --end -o "$TMP/got.png" --size 640x400 --quiet --mem 1M 2>"$TMP/e3"
cmp -s "$TMP/got.png" "$TMP/want.png" && ok picture_under_fd_limit ||
    fail picture_under_fd_limit "$(tail -3 "$TMP/e3")"
a=$("$PDT" trace dump "$R" | md5sum)
b=$(limited "$PDT" trace dump "$R" 2>"$TMP/e4" | md5sum)
[ "$a" = "$b" ] && ok trace_dump_under_fd_limit || fail trace_dump_under_fd_limit "$(tail -3 "$TMP/e4")"
summary
