#!/bin/bash
# pdt triangulate under `mpirun --hostfile F -np 2`, F naming this machine
# with two slots: the output is byte-identical to the plain run and the run
# had 2 ranks.
source "$(dirname "$0")/lib.sh"
cd "$TMP"
if ! command -v mpirun > /dev/null; then fail mpirun_available "mpirun not found"; summary; exit; fi
echo "localhost slots=2" > hosts
"$PDT" gen clusters 3000 --seed 9 -o c.txt && "$PDT" triangulate c.txt -o ref.tri
check plain_run test -s ref.tri
timeout 120 mpirun --hostfile hosts -np 2 "$PDT" triangulate c.txt --stats -o h.tri > /dev/null 2> h.err
rc=$?
if [ "$rc" -ne 0 ]; then fail hostfile_np2 "exit $rc: $(head -3 h.err)"
elif ! cmp -s ref.tri h.tri; then fail hostfile_np2 "output differs from the plain run"
elif ! grep -q '"ranks": 2' h.err; then fail hostfile_np2 "not a 2-rank run"
else ok hostfile_np2; fi
summary
