#!/bin/bash
# One table of exit statuses for every command (README, pdt(1), pdtview(1)):
#   0 success, 1 a check failed, 2 usage error or unreadable/malformed input.
# san: yes
source "$(dirname "$0")/lib.sh"
V=$BIN/pdtview
cd "$TMP" || exit 1
# expect_rc NAME WANT COMMAND... : the command exits WANT
expect_rc() {
    local n=$1 want=$2; shift 2
    "$@" > out.txt 2> err.txt; local rc=$?
    [ $rc -eq "$want" ] && ok "$n" || fail "$n" "exit $rc, want $want: $* :: $(head -2 err.txt)"
}
"$PDT" gen uniform 40 --seed 5 -o p.txt
"$PDT" triangulate p.txt -o p.tri --trace run > /dev/null
head -n -1 p.tri > wrong.tri
printf '0 0\n1 x\n' > bad.txt
mkdir -p garbled && cp run/* garbled/ && printf 'garbage\n' > garbled/manifest
mkdir -p dirmf && cp run/rank-* run/points.bin dirmf/ && mkdir dirmf/manifest

for c in triangulate hull; do
    expect_rc "${c}_ok" 0 "$PDT" $c p.txt
    expect_rc "${c}_usage" 2 "$PDT" $c --no-such-option p.txt
    expect_rc "${c}_missing_file" 2 "$PDT" $c nosuch.txt
    expect_rc "${c}_malformed_input" 2 "$PDT" $c bad.txt
    expect_rc "${c}_unwritable_output" 2 "$PDT" $c p.txt -o nosuchdir/out.tri
done
expect_rc check_ok 0 "$PDT" check p.txt p.tri
expect_rc check_failed 1 "$PDT" check p.txt wrong.tri
expect_rc check_usage 2 "$PDT" check p.txt
expect_rc check_malformed_input 2 "$PDT" check bad.txt p.tri
expect_rc gen_ok 0 "$PDT" gen grid 9
expect_rc gen_unknown_kind 2 "$PDT" gen nosuch 9
expect_rc gen_usage 2 "$PDT" gen uniform
expect_rc main_version 0 "$PDT" --version
expect_rc main_unknown_command 2 "$PDT" frobnicate
expect_rc trace_usage 2 "$PDT" trace
expect_rc trace_unknown_subcommand 2 "$PDT" trace frob run
for s in info dump check; do
    expect_rc "trace_${s}_ok" 0 "$PDT" trace $s run
    expect_rc "trace_${s}_missing_folder" 2 "$PDT" trace $s nosuch
    expect_rc "trace_${s}_garbled_manifest" 2 "$PDT" trace $s garbled
    expect_rc "trace_${s}_manifest_unreadable" 2 "$PDT" trace $s dirmf
done
expect_rc trace_export_ok 0 "$PDT" trace export --chrome run -o run.json
expect_rc trace_export_missing_folder 2 "$PDT" trace export --chrome nosuch -o x.json
expect_rc trace_export_usage 2 "$PDT" trace export run
if [ -x "$V" ]; then
    expect_rc pdtview_headless_ok 0 "$V" --headless run --end -o end.png --size 320x200
    expect_rc pdtview_counts_ok 0 "$V" run --end --counts
    expect_rc pdtview_check_ok 0 "$V" run --check
    expect_rc pdtview_usage 2 "$V" --no-such-option run
    expect_rc pdtview_missing_run 2 "$V" --headless nosuch --end -o x.png
    expect_rc pdtview_garbled_run 2 "$V" --headless garbled --end -o x.png
    expect_rc pdtview_bad_phase 2 "$V" --headless run --phase nosuch -o x.png
fi
summary
