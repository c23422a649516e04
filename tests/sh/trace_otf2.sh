#!/bin/bash
# pdt trace export --otf2: the archive read back by otf2-print (Debian's
# otf2-tools) holds, per rank, one Enter and one Leave per phase and merge
# step and one MPI send/recv record per message, as pdt trace dump counts them;
# clock properties come from the manifest; a damaged run still gives balanced
# regions; an existing folder is never overwritten.
# san: yes
source "$(dirname "$0")/lib.sh"
if ! command -v otf2-print >/dev/null; then fail otf2_print_available "otf2-print not found (otf2-tools)"; summary; exit; fi

# per-rank counts from pdt trace dump: "enters sends recvs" for rank $2 of run $1
dump_counts() {
    "$PDT" trace dump "$1" --rank "$2" |
        awk '$4 == "phase-begin" || $4 == "merge-begin" {e++} $4 == "send" {s++} $4 == "recv" {r++}
             END {print e + 0, s + 0, r + 0}'
}
# the same from otf2-print: "enters leaves sends recvs" for location $2
otf2_counts() {
    awk -v loc="$2" '$2 == loc && $1 == "ENTER" {e++} $2 == loc && $1 == "LEAVE" {l++}
                     $2 == loc && $1 == "MPI_SEND" {s++} $2 == loc && $1 == "MPI_RECV" {r++}
                     END {print e + 0, l + 0, s + 0, r + 0}' "$1"
}
# compare every rank of run $1 with archive $2; name $3
compare_ranks() {
    local run=$1 arc=$2 name=$3 p r bad=""
    otf2-print "$arc/run.otf2" >"$TMP/$name.print" 2>"$TMP/$name.err" || { fail "$name" "otf2-print failed: $(head -2 "$TMP/$name.err")"; return; }
    [ -s "$TMP/$name.err" ] && { fail "$name" "otf2-print warns: $(head -2 "$TMP/$name.err")"; return; }
    p=$(awk '$1 == "ranks" {print $2; exit}' <("$PDT" trace info "$run"))
    for ((r = 0; r < p; r++)); do
        read -r e s v <<<"$(dump_counts "$run" $r)"
        read -r oe ol os ov <<<"$(otf2_counts "$TMP/$name.print" $r)"
        [ "$e $e $s $v" = "$oe $ol $os $ov" ] || bad="$bad rank $r: dump $e/$s/$v, otf2 $oe/$ol/$os/$ov;"
    done
    [ -z "$bad" ] && ok "$name" || fail "$name" "$bad"
}

"$PDT" gen uniform 3000 -o "$TMP/u.txt"
# sequential run: one location, phases only
"$PDT" triangulate "$TMP/u.txt" -o "$TMP/u.tri" --trace "$TMP/seq" || fail seq_traced_run
"$PDT" trace export --otf2 "$TMP/seq" -o "$TMP/seq.otf2" 2>"$TMP/seq.msg" &&
    [ -f "$TMP/seq.otf2/run.otf2" ] && ok otf2_export_writes_archive ||
    fail otf2_export_writes_archive "$(cat "$TMP/seq.msg")"
compare_ranks "$TMP/seq" "$TMP/seq.otf2" otf2_seq_counts_match_dump

# global definitions: one location per rank, clock from the manifest
otf2-print -G "$TMP/seq.otf2/run.otf2" >"$TMP/seq.defs" 2>&1
wall=$(awk -F' = ' '$1 == "wall_start_ns" {print $2}' "$TMP/seq/manifest")
date_want=$(date -u -d "@$((wall / 1000000000))" '+%Y-%m-%d %H:%M:%S')
grep -q "Ticks per Seconds: 1000000000" "$TMP/seq.defs" && grep -q "Date: $date_want" "$TMP/seq.defs" &&
    ok otf2_clock_properties_from_manifest ||
    fail otf2_clock_properties_from_manifest "$(grep CLOCK "$TMP/seq.defs") want $date_want"
nev=$(awk '$1 == "LOCATION" && $2 == 0 {for (i = 1; i <= NF; i++) if ($i == "Events:") {v = $(i + 1); sub(",", "", v); print v}}' "$TMP/seq.defs")
read -r e l s v <<<"$(otf2_counts "$TMP/otf2_seq_counts_match_dump.print" 0)"
[ "$nev" = "$((e + l + s + v))" ] && [ "$nev" -gt 0 ] && ok otf2_location_event_count ||
    fail otf2_location_event_count "location says ${nev:-?}, records $((e + l + s + v))"
grep -q 'REGION .*Name: "kernel"' "$TMP/seq.defs" && ok otf2_phase_regions_named ||
    fail otf2_phase_regions_named "$(grep REGION "$TMP/seq.defs" | head -3)"

# MPI run: messages as MPI point-to-point records, merge steps as regions
if command -v mpirun >/dev/null; then
    # the run itself comes from the release build (Open MPI under ASan exits non-zero)
    mpirun -np 4 "$ROOT/bin/pdt" triangulate "$TMP/u.txt" -o "$TMP/p.tri" --trace "$TMP/par" 2>"$TMP/mpi.err" ||
        fail mpi_traced_run "$(head -3 "$TMP/mpi.err")"
    "$PDT" trace export --otf2 "$TMP/par" -o "$TMP/par.otf2" 2>"$TMP/par.msg" ||
        fail otf2_mpi_export "$(cat "$TMP/par.msg")"
    compare_ranks "$TMP/par" "$TMP/par.otf2" otf2_mpi_counts_match_dump
    sends=$(grep -c '^MPI_SEND' "$TMP/otf2_mpi_counts_match_dump.print")
    [ "$sends" -gt 0 ] && [ "$sends" = "$("$PDT" trace dump "$TMP/par" --kind send | wc -l)" ] &&
        ok otf2_every_message_sent || fail otf2_every_message_sent "$sends sends"
    otf2-print -G "$TMP/par.otf2/run.otf2" 2>&1 | grep -q 'REGION .*"merge step level 0"' &&
        ok otf2_merge_step_regions || fail otf2_merge_step_regions
else
    fail mpirun_available "mpirun not found"
fi

# a damaged run (last blocks cut off): regions still balanced per location
cp -r "$TMP/seq" "$TMP/cut"
f="$TMP/cut/rank-0000.trace"
truncate -s $(( $(stat -c %s "$f") * 2 / 3 )) "$f"
"$PDT" trace export --otf2 "$TMP/cut" -o "$TMP/cut.otf2" 2>/dev/null &&
    otf2-print "$TMP/cut.otf2/run.otf2" >"$TMP/cut.print" 2>&1 &&
    read -r e l s v <<<"$(otf2_counts "$TMP/cut.print" 0)" && [ "$e" -gt 0 ] && [ "$e" = "$l" ] &&
    ok otf2_damaged_run_balanced || fail otf2_damaged_run_balanced "$(head -3 "$TMP/cut.print")"

# an existing non-empty folder is refused (exit 2) and left alone
mkdir -p "$TMP/busy" && echo keep >"$TMP/busy/file"
"$PDT" trace export --otf2 "$TMP/seq" -o "$TMP/busy" 2>"$TMP/busy.err"
rc=$?
[ $rc = 2 ] && [ "$(cat "$TMP/busy/file")" = keep ] && grep -q "busy: exists" "$TMP/busy.err" &&
    [ -z "$(ls -d "$TMP"/busy.tmp-* 2>/dev/null)" ] && ok otf2_refuses_existing_folder ||
    fail otf2_refuses_existing_folder "rc $rc: $(cat "$TMP/busy.err")"
"$PDT" trace export --otf2 "$TMP/seq" 2>/dev/null
[ $? = 2 ] && ok otf2_needs_output_folder || fail otf2_needs_output_folder
summary
