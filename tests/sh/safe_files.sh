# pdt — nothing lost: run folders, outputs and edited files under failures and hostile
# folders (docs/files.md), as a user runs into them.  Every file pdt and pdtview write follows
# one rule (pdt/safefile.h): a temporary beside the target, mode and links kept, read-only
# refused, renamed into place only when everything succeeded; a run folder swapped in whole.
# san: yes
. "$(dirname "$0")/lib.sh"
V=$BIN/pdtview
# (Open MPI's own allocations: tests/lsan.supp names them; full stacks to match)
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
cd "$TMP" || exit 1
printf '0 0\n10 0\n0 10\n10 10\n5 4\n' > u.txt
printf '0 0\n4 0\n0 4\n4 4\n' > sq.txt
mpi() { timeout 120 mpirun -np "$@"; }
# snap DIR: every entry with its mode, links, size and checksum (a symlink: its target)
snap() {
    (cd "$1" && for f in $(ls -A | sort); do
        if [ -L "$f" ]; then echo "$f -> $(readlink "$f")"
        else echo "$f $(stat -c '%a %h %s' "$f") $(md5sum < "$f")"; fi
    done)
}
no_temps() { ! ls -A "${1:-.}" | grep -q 'pdt-tmp'; }

# ---- 1. a failed traced run leaves the previous run folder byte for byte ----------------
"$PDT" triangulate u.txt -o k.tri --trace run 2>/dev/null
before=$(snap run); kbefore=$(md5sum < k.tri)
"$PDT" triangulate typo.txt -o k.tri --trace run 2>err; rc=$?
if [ $rc -eq 2 ] && [ "$(snap run)" = "$before" ] && [ "$(md5sum < k.tri)" = "$kbefore" ] && no_temps &&
    "$PDT" trace check run >/dev/null 2>&1; then ok failed_traced_run_keeps_previous_run
else fail failed_traced_run_keeps_previous_run "rc=$rc $(cat err) $(snap run)"; fi
mpi 2 "$PDT" triangulate typo.txt -o k.tri --trace run >/dev/null 2>&1; rc=$?
if [ $rc -ne 0 ] && [ "$(snap run)" = "$before" ] && no_temps; then ok failed_mpi_traced_run_keeps_previous_run
else fail failed_mpi_traced_run_keeps_previous_run "rc=$rc $(snap run)"; fi
# the README: "Errors name the file, the line and the problem; nothing is written"
printf '0 0\n1 2\n3 4294967296\n' > bad.txt
"$PDT" triangulate bad.txt -o out.tri --trace newrun 2>/dev/null; rc=$?
if [ $rc -eq 2 ] && [ ! -e out.tri ] && [ ! -e newrun ] && no_temps; then ok readme_errors_nothing_is_written
else fail readme_errors_nothing_is_written "rc=$rc $(ls -A)"; fi
"$PDT" hull typo.txt -o h.txt --trace newrun 2>/dev/null
[ ! -e newrun ] && [ ! -e h.txt ] && no_temps && ok failed_hull_creates_no_stub_folder ||
    fail failed_hull_creates_no_stub_folder "$(ls -A)"
# a run into an existing run folder replaces it whole (rank files of a larger run go too)
mpi 3 "$PDT" triangulate u.txt -o k3.tri --trace run3 >/dev/null 2>&1
"$PDT" triangulate u.txt -o k3.tri --trace run3 2>/dev/null
[ -e run3/rank-0000.trace ] && [ ! -e run3/rank-0001.trace ] && "$PDT" trace check run3 >/dev/null 2>&1 &&
    ok rerun_replaces_the_whole_run_folder || fail rerun_replaces_the_whole_run_folder "$(ls run3)"
# a folder that holds other files is not a run folder to replace
mkdir notes; echo mine > notes/todo.txt
"$PDT" triangulate u.txt -o n.tri --trace notes 2>err; rc=$?
[ $rc -eq 2 ] && grep -q "holds todo.txt" err && [ "$(cat notes/todo.txt)" = mine ] && [ ! -e n.tri ] &&
    ok trace_refuses_folder_with_other_files || fail trace_refuses_folder_with_other_files "rc=$rc $(cat err)"

# ---- 2. --trace never deletes or overwrites the input -------------------------------------
mkdir d; printf '0 0\n10 0\n0 10\n' > d/points.bin; cp d/points.bin d.copy
"$PDT" triangulate d/points.bin -o x.tri --trace d 2>err; rc=$?
if [ $rc -eq 2 ] && cmp -s d/points.bin d.copy && grep -q "d/points.bin" err && grep -q "run folder d" err &&
    [ ! -e x.tri ]; then ok trace_refuses_input_inside_folder
else fail trace_refuses_input_inside_folder "rc=$rc $(cat err)"; fi
mpi 2 "$PDT" triangulate d/points.bin -o x.tri --trace d >/dev/null 2>err; rc=$?
[ $rc -ne 0 ] && cmp -s d/points.bin d.copy && ok mpi_trace_refuses_input_inside_folder ||
    fail mpi_trace_refuses_input_inside_folder "rc=$rc"
mkdir d2; cp u.txt d2/manifest
"$PDT" hull d2/manifest --trace d2 2>err; rc=$?
[ $rc -eq 2 ] && cmp -s d2/manifest u.txt && ok hull_trace_refuses_input_inside_folder ||
    fail hull_trace_refuses_input_inside_folder "rc=$rc $(cat err)"
ln -s d d.alias
"$PDT" triangulate d.alias/points.bin -o x.tri --trace d 2>/dev/null; rc=$?
[ $rc -eq 2 ] && cmp -s d/points.bin d.copy && ok trace_refuses_input_through_a_link ||
    fail trace_refuses_input_through_a_link "rc=$rc"

# ---- 3. rank files are never written through symlinks planted in the folder --------------
mkdir t; echo victim > v
ln -s "$PWD/v" t/rank-0000.trace; ln -s "$PWD/v" t/rank-0001.trace; ln -s "$PWD/v" t/manifest
"$PDT" triangulate sq.txt -o s.tri --trace t 2>/dev/null; rc=$?
[ $rc -eq 0 ] && [ "$(cat v)" = victim ] && [ ! -L t/rank-0000.trace ] && "$PDT" trace check t >/dev/null 2>&1 &&
    ok rank_file_symlink_not_followed || fail rank_file_symlink_not_followed "rc=$rc $(head -c 20 v)"
rm -rf t; mkdir t; ln -s "$PWD/v" t/rank-0000.trace; ln -s "$PWD/v" t/rank-0001.trace
mpi 2 "$PDT" triangulate sq.txt -o s.tri --trace t >/dev/null 2>&1; rc=$?
[ $rc -eq 0 ] && [ "$(cat v)" = victim ] && [ ! -L t/rank-0001.trace ] && "$PDT" trace check t >/dev/null 2>&1 &&
    ok mpi_rank_file_symlink_not_followed || fail mpi_rank_file_symlink_not_followed "rc=$rc $(head -c 20 v)"

# ---- 4. an .ele and its .node are replaced together -------------------------------------
"$PDT" triangulate sq.txt -o p.ele 2>/dev/null; cp p.ele p.ele.old
rm p.node; mkdir p.node
for np in 1 2; do
    if [ $np -eq 1 ]; then "$PDT" triangulate u.txt -o p.ele 2>err; rc=$?
    else mpi 2 "$PDT" triangulate u.txt -o p.ele >/dev/null 2>err; rc=$?; fi
    [ $rc -ne 0 ] && cmp -s p.ele p.ele.old && [ -d p.node ] && no_temps &&
        ok "ele_kept_when_node_cannot_be_replaced_np$np" ||
        fail "ele_kept_when_node_cannot_be_replaced_np$np" "rc=$rc $(cat err)"
done
rmdir p.node
printf 'x\n' > p.node; chmod 444 p.node
"$PDT" triangulate u.txt -o p.ele 2>err; rc=$?
[ $rc -eq 2 ] && cmp -s p.ele p.ele.old && grep -q "p.node: is read-only" err &&
    ok ele_kept_when_node_is_read_only || fail ele_kept_when_node_is_read_only "rc=$rc $(cat err)"
if cp sq.txt imm.node 2>/dev/null && chattr +i imm.node 2>/dev/null; then
    cp p.ele.old imm.ele
    "$PDT" triangulate u.txt -o imm.ele 2>/dev/null; rc=$?
    [ $rc -eq 2 ] && cmp -s imm.ele p.ele.old && ok ele_kept_when_node_is_immutable ||
        fail ele_kept_when_node_is_immutable "rc=$rc"
    chattr -i imm.node
else
    echo "ok - ele_kept_when_node_is_immutable # skip: chattr +i not permitted here"
fi

# ---- 5. permissions and links are kept -----------------------------------------------------
echo old > priv.tri; chmod 600 priv.tri
"$PDT" triangulate u.txt -o priv.tri
[ "$(stat -c %a priv.tri)" = 600 ] && [ "$(wc -l < priv.tri)" -gt 1 ] && ok output_keeps_mode_600 ||
    fail output_keeps_mode_600 "$(stat -c %a priv.tri)"
mpi 2 "$PDT" triangulate u.txt -o priv.tri
[ "$(stat -c %a priv.tri)" = 600 ] && ok mpi_output_keeps_mode_600 || fail mpi_output_keeps_mode_600
echo ro > ro.tri; chmod 444 ro.tri
"$PDT" triangulate u.txt -o ro.tri 2>err; rc=$?
[ $rc -eq 2 ] && [ "$(cat ro.tri)" = ro ] && grep -q "ro.tri: is read-only" err && no_temps &&
    ok read_only_output_refused || fail read_only_output_refused "rc=$rc $(cat err)"
if id nobody >/dev/null 2>&1; then
    echo theirs > other.tri; chown nobody other.tri; chmod 444 other.tri
    "$PDT" triangulate u.txt -o other.tri 2>err; rc=$?
    [ $rc -eq 2 ] && [ "$(cat other.tri)" = theirs ] && grep -q "another user's" err &&
        ok other_users_read_only_file_refused || fail other_users_read_only_file_refused "rc=$rc $(cat err)"
    echo theirs > own.tri; chown nobody own.tri; chmod 640 own.tri
    "$PDT" triangulate u.txt -o own.tri 2>/dev/null
    [ "$(stat -c '%U %a' own.tri)" = "nobody 640" ] && ok output_keeps_owner || fail output_keeps_owner "$(stat -c '%U %a' own.tri)"
fi
echo real > real.tri; ln -s real.tri link.tri
"$PDT" triangulate u.txt -o link.tri
[ -L link.tri ] && [ "$(wc -l < real.tri)" -gt 1 ] && ok output_through_symlink_keeps_link ||
    fail output_through_symlink_keeps_link "$(ls -l link.tri real.tri)"
echo h > h1.tri; ln h1.tri h2.tri
"$PDT" triangulate u.txt -o h1.tri
[ "$(stat -c %h h1.tri)" = 2 ] && cmp -s h1.tri h2.tri && [ "$(wc -l < h2.tri)" -gt 1 ] &&
    ok output_keeps_hard_links || fail output_keeps_hard_links "$(stat -c '%h %i' h1.tri h2.tri)"
ln -s "$TMP/run" runlink
"$PDT" triangulate u.txt -o rl.tri --trace runlink 2>/dev/null
[ -L runlink ] && [ -d run ] && "$PDT" trace check runlink >/dev/null 2>&1 && ok trace_folder_symlink_keeps_link ||
    fail trace_folder_symlink_keeps_link "$(ls -l runlink)"
mkdir m750; chmod 750 m750
"$PDT" triangulate u.txt -o m.tri --trace m750 2>/dev/null
[ "$(stat -c %a m750)" = 750 ] && ok trace_folder_keeps_mode || fail trace_folder_keeps_mode "$(stat -c %a m750)"

# ---- 7. other commands do not clobber run folders ------------------------------------------
before=$(snap run)
"$PDT" trace export --chrome run -o run/manifest 2>err; rc=$?
[ $rc -eq 2 ] && [ "$(snap run)" = "$before" ] && "$PDT" trace check run >/dev/null 2>&1 &&
    ok export_refuses_run_file || fail export_refuses_run_file "rc=$rc $(cat err)"
ln -s run/manifest mlink
"$PDT" trace export --chrome run -o mlink 2>/dev/null; rc=$?
[ $rc -eq 2 ] && [ "$(snap run)" = "$before" ] && ok export_refuses_link_to_run_file ||
    fail export_refuses_link_to_run_file "rc=$rc"
"$PDT" trace export --chrome run -o run.json && ok export_beside_run_allowed || fail export_beside_run_allowed
"$PDT" triangulate u.txt -o run/manifest --trace run 2>err; rc=$?
[ $rc -eq 2 ] && [ "$(snap run)" = "$before" ] && grep -q "inside the run folder" err &&
    ok trace_refuses_output_inside_folder || fail trace_refuses_output_inside_folder "rc=$rc $(cat err)"
mpi 2 "$PDT" triangulate u.txt -o run/manifest --trace run >/dev/null 2>&1; rc=$?
[ $rc -ne 0 ] && [ "$(snap run)" = "$before" ] && ok mpi_trace_refuses_output_inside_folder ||
    fail mpi_trace_refuses_output_inside_folder "rc=$rc"
"$PDT" triangulate u.txt -o run/k.ele --trace run 2>/dev/null; rc=$?
[ $rc -eq 2 ] && [ "$(snap run)" = "$before" ] && ok trace_refuses_ele_inside_folder ||
    fail trace_refuses_ele_inside_folder "rc=$rc"

# ---- 8. a traced run whose trace cannot be written leaves no new output -----------------
"$PDT" gen uniform 1500 -o big.txt 2>/dev/null  # (the output fits in 80 KiB, the trace does not)
echo previous > full.tri
( trap '' XFSZ; ulimit -f 80; "$PDT" triangulate big.txt -o full.tri --trace fullrun --trace-level 2 ) 2>err; rc=$?
if [ $rc -eq 2 ] && grep -q "full.tri\|fullrun\|too large" err && [ "$(cat full.tri)" = previous ] &&
    [ ! -e fullrun ] && no_temps; then ok trace_write_failure_leaves_no_output
else fail trace_write_failure_leaves_no_output "rc=$rc $(cat err) $(head -c 30 full.tri)"; fi

# ---- 10. leftovers of killed runs: only pdt's own are removed ---------------------------
sh -c 'exit 0' & dead=$!; wait $dead
echo stale > ".out.tri.pdt-tmp.$dead.0badf00d"
echo mine > .out.tri.tmp123
"$PDT" triangulate u.txt -o out.tri
[ ! -e ".out.tri.pdt-tmp.$dead.0badf00d" ] && [ "$(cat .out.tri.tmp123)" = mine ] &&
    ok killed_runs_temporary_removed_by_next_run || fail killed_runs_temporary_removed_by_next_run "$(ls -A)"
mkdir ".krun.pdt-tmp.$dead.0badf00d"; echo x > ".krun.pdt-tmp.$dead.0badf00d/rank-0000.trace"
"$PDT" triangulate u.txt -o kr.tri --trace krun 2>/dev/null
[ ! -e ".krun.pdt-tmp.$dead.0badf00d" ] && ok killed_runs_temporary_folder_removed ||
    fail killed_runs_temporary_folder_removed "$(ls -A)"

# ---- the same families on pdtview's outputs ------------------------------------------------
if [ -x "$V" ]; then
    "$PDT" triangulate u.txt -o vr.tri --trace vrun 2>/dev/null
    echo mine > "vrun/.pdtview-index.tmp$dead"  # (a process that is gone: the old cleaner took it for its own)
    "$V" vrun --headless --quiet --index on -o vpic.png 2>err; rc=$?
    [ $rc -eq 0 ] && [ "$(cat "vrun/.pdtview-index.tmp$dead")" = mine ] && ok index_build_keeps_users_lookalike_file ||
        fail index_build_keeps_users_lookalike_file "rc=$rc $(cat err)"
    rm -f vrun/.pdtview-index "vrun/.pdtview-index.tmp$dead"; echo victim > v2
    ln -s "$PWD/v2" vrun/.pdtview-index
    "$V" vrun --headless --quiet --index on -o vpic.png 2>/dev/null
    [ "$(cat v2)" = victim ] && ok index_not_written_through_planted_link || fail index_not_written_through_planted_link
    before=$(snap vrun)
    "$V" vrun --headless --quiet -o vrun/manifest 2>err; rc=$?
    [ $rc -ne 0 ] && [ "$(snap vrun)" = "$before" ] && ok view_output_refuses_run_file ||
        fail view_output_refuses_run_file "rc=$rc $(cat err)"
    "$V" vrun --headless --quiet --gif vrun/points.bin 2>/dev/null; rc=$?
    [ $rc -ne 0 ] && [ "$(snap vrun)" = "$before" ] && ok view_gif_refuses_run_file ||
        fail view_gif_refuses_run_file "rc=$rc"
    echo old > vp.png; chmod 600 vp.png
    "$V" vrun --headless --quiet -o vp.png 2>/dev/null
    [ "$(stat -c %a vp.png)" = 600 ] && [ "$(head -c 4 vp.png | tail -c 3)" = PNG ] && ok view_picture_keeps_mode ||
        fail view_picture_keeps_mode "$(stat -c %a vp.png)"
    mkdir frames; echo victim > v3; ln -s "$PWD/v3" frames/frame-000000.png
    "$V" vrun --headless --quiet --frames frames --every 1000000 2>err; rc=$?
    [ $rc -eq 0 ] && [ "$(cat v3)" = victim ] && [ -f frames/frame-000000.png ] && [ ! -L frames/frame-000000.png ] &&
        ok frames_not_written_through_planted_link || fail frames_not_written_through_planted_link "rc=$rc $(cat err)"
    mkdir wr; cp u.txt wr/manifest
    "$V" --edit wr/manifest --write-run wr --quiet 2>err; rc2=$?
    [ $rc2 -eq 2 ] && cmp -s wr/manifest u.txt && grep -q "inside the run folder wr" err &&
        ok edit_write_run_refuses_input_inside_folder || fail edit_write_run_refuses_input_inside_folder "rc=$rc2 $(cat err)"
    "$V" --write-run vrun vrun 2>err; rc=$?
    [ $rc -eq 2 ] && [ "$(snap vrun)" = "$before" ] && ok write_run_refuses_its_own_input ||
        fail write_run_refuses_its_own_input "rc=$rc $(cat err)"
    mkdir wt; ln -s "$PWD/v" wt/rank-0000.trace
    "$V" --edit u.txt --write-run wt --quiet 2>/dev/null; rc=$?
    [ $rc -eq 0 ] && [ "$(cat v)" = victim ] && "$PDT" trace check wt >/dev/null 2>&1 &&
        ok write_run_rank_symlink_not_followed || fail write_run_rank_symlink_not_followed "rc=$rc"
fi
no_temps && ok no_temporaries_left || fail no_temporaries_left "$(ls -A | grep pdt-tmp)"
summary
