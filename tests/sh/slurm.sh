#!/bin/bash
# pdt triangulate under Slurm: the test starts a one-node Slurm on this
# machine (munged, slurmctld, slurmd; Debian's packages, every file under a
# temporary folder, ports chosen by the test), runs
#   srun -n 2 --mpi=pmix pdt triangulate ...      and
#   salloc -n 2 mpirun pdt triangulate ...
# and compares both outputs byte for byte with the plain run.  Every daemon
# it started is stopped on exit (trap); every Slurm command runs under a
# timeout, so the test cannot hang.
source "$(dirname "$0")/lib.sh"
cd "$TMP"
for prog in munged mungekey slurmctld slurmd srun salloc sinfo mpirun; do
    if ! command -v "$prog" > /dev/null; then
        fail "${prog}_available" "$prog not found (make deps installs slurmctld slurmd slurm-client munge)"
        summary; exit
    fi
done
D=$TMP/slurm
mkdir -p "$D/state" "$D/spool" "$D/log" "$D/munge"
chmod 700 "$D/munge"
# two free ports (nothing listening on either): slurmctld's and slurmd's
listening() { (exec 3<> "/dev/tcp/127.0.0.1/$1") 2> /dev/null; }
PORT=$((20000 + $$ % 20000))
for _ in $(seq 1 50); do
    listening "$PORT" || listening $((PORT + 1)) || break
    PORT=$((20000 + (PORT + 7) % 20000))
done

stop_daemons() {
    local f pid
    for f in "$D/slurmd.pid" "$D/slurmctld.pid"; do
        [ -s "$f" ] && pid=$(cat "$f") && kill "$pid" 2> /dev/null
    done
    [ -S "$D/munge/sock" ] && munged --stop --socket="$D/munge/sock" > /dev/null 2>&1
    for f in "$D/slurmd.pid" "$D/slurmctld.pid" "$D/munge/pid"; do
        [ -s "$f" ] || continue
        pid=$(cat "$f")
        for _ in 1 2 3 4 5 6 7 8 9 10; do kill -0 "$pid" 2> /dev/null || break; sleep 0.5; done
        kill -9 "$pid" 2> /dev/null
    done
    rm -rf "$TMP"
}
trap stop_daemons EXIT

mungekey -c -k "$D/munge/munge.key" -f > /dev/null 2>&1 &&
    munged -f --socket="$D/munge/sock" --key-file="$D/munge/munge.key" \
        --log-file="$D/log/munge.log" --pid-file="$D/munge/pid" --seed-file="$D/munge/seed"
check munged_started test -S "$D/munge/sock"

CPUS=$(nproc)
[ "$CPUS" -lt 2 ] && CPUS=2   # (-O below lets two ranks share one core)
cat > "$D/slurm.conf" << CONF
ClusterName=pdttest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$PORT
SlurmdPort=$((PORT + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$D/munge/sock
SlurmUser=$(id -un)
SlurmdUser=$(id -un)
StateSaveLocation=$D/state
SlurmdSpoolDir=$D/spool
SlurmctldPidFile=$D/slurmctld.pid
SlurmdPidFile=$D/slurmd.pid
SlurmctldLogFile=$D/log/slurmctld.log
SlurmdLogFile=$D/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
MpiDefault=pmix
ReturnToService=2
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$CPUS State=UNKNOWN
PartitionName=debug Nodes=localhost Default=YES MaxTime=10 State=UP
CONF
export SLURM_CONF=$D/slurm.conf
slurmctld -c -f "$SLURM_CONF" && slurmd -f "$SLURM_CONF"
# the node registers in about a second on a quiet machine; under load (the
# rest of the suite, a benchmark) it took over 20 s once: wait up to 90 s
up=0
for _ in $(seq 1 180); do
    if timeout 5 sinfo -h -o %t 2> /dev/null | grep -qx idle; then up=1; break; fi
    sleep 0.5
done
if [ "$up" -ne 1 ]; then
    fail slurm_up "the node did not become idle (state: $(timeout 5 sinfo -h -o %t 2>&1)):" \
        "$(tail -n 4 "$D/log/slurmctld.log" "$D/log/slurmd.log" 2>&1)"
    summary; exit
fi
ok slurm_up

"$PDT" gen uniform 3000 --seed 5 -o u.txt && "$PDT" triangulate u.txt -o ref.tri
check plain_run test -s ref.tri

# same_as_plain NAME OUT: the run's output equals the plain run's, and it ran on 2 ranks
same_as_plain() {
    local name=$1 out=$2 rc=$3
    if [ "$rc" -ne 0 ]; then fail "$name" "exit $rc: $(head -3 "$name.err")"
    elif ! cmp -s ref.tri "$out"; then fail "$name" "output differs from the plain run"
    elif ! grep -q '"ranks": 2' "$name.err"; then fail "$name" "not a 2-rank run: $(head -c 300 "$name.err")"
    else ok "$name"; fi
}

timeout 90 srun -O -n 2 --mpi=pmix "$PDT" triangulate u.txt --stats -o srun.tri > /dev/null 2> srun_n2.err
same_as_plain srun_n2 srun.tri $?
timeout 90 salloc -O -n 2 mpirun "$PDT" triangulate u.txt --stats -o salloc.tri > /dev/null 2> salloc_mpirun_n2.err
same_as_plain salloc_mpirun_n2 salloc.tri $?
summary
