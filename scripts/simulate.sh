#!/bin/bash
# Run pdt on a simulated cluster: SimGrid's SMPI executes every rank's code
# here for real (all ranks are threads of one process, one at a time), times
# each stretch of computation on that rank's own CPU clock and simulates the
# network of a platform file (docs/simulation.md).
#
#   scripts/simulate.sh -np P [--platform FILE|NAME] [--host-speed FLOPS]
#                       [--smpi OPTION]... -- triangulate IN -o OUT [--stats]
#                       [--trace DIR] [other pdt options]
#
#   -np P          simulated ranks, one per node of the platform (more ranks
#                  than nodes: several share a node)
#   --platform     a SimGrid platform file, or the name of one in
#                  assets/platforms/ (default cluster-10g: 1024 nodes,
#                  10 Gb/s, 1.5 us per link; ethernet-1g: 1 Gb/s, 50 us)
#   --host-speed   smpi/host-speed, the flop rate SimGrid assumes for this
#                  machine (default 1Gf, the bundled platforms' nominal node
#                  speed: a CPU second measured here is a simulated second,
#                  i.e. every simulated node is one core of this machine; 2Gf
#                  models nodes half as fast as this machine's core)
#   --smpi OPTION  one more SimGrid option (e.g. --cfg=network/model:CM02)
#
# The output file is written for real and is byte-identical to the plain
# run's; --stats prints the JSON of a real run, with the simulated seconds
# of each phase and "simulated": true; --trace DIR writes one trace per rank
# whose clock is the simulated one.  Needs bin/smpi/pdt (make smpi).
# Exit status: pdt's (2 for a usage error of this script).
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PDT_SMPI_BIN=${PDT_SMPI_BIN:-$ROOT/bin/smpi/pdt}
usage() {
    sed -n '2,/^# Exit status/s/^# \{0,1\}//p' "$0" >&2
    exit 2
}
np="" platform=cluster-10g speed=1Gf extra=()
while [ $# -gt 0 ]; do
    case "$1" in
        -np|--np) [ $# -ge 2 ] || usage; np=$2; shift 2 ;;
        --platform) [ $# -ge 2 ] || usage; platform=$2; shift 2 ;;
        --host-speed) [ $# -ge 2 ] || usage; speed=$2; shift 2 ;;
        --smpi) [ $# -ge 2 ] || usage; extra+=("$2"); shift 2 ;;
        --) shift; break ;;
        -h|--help) usage ;;
        *) echo "simulate.sh: unknown option '$1' (pdt's options go after --)" >&2; exit 2 ;;
    esac
done
case "$np" in ''|*[!0-9]*|0) echo "simulate.sh: -np P needs a positive number of ranks" >&2; exit 2 ;; esac
[ $# -gt 0 ] || { echo "simulate.sh: no pdt command after --" >&2; exit 2; }
case "$platform" in
    */*|*.xml) ;;
    *) platform=$ROOT/assets/platforms/$platform.xml ;;
esac
[ -r "$platform" ] || { echo "simulate.sh: $platform: no such platform file" >&2; exit 2; }
command -v smpirun > /dev/null || { echo "simulate.sh: smpirun not found (make smpi installs libsimgrid-dev)" >&2; exit 2; }
[ -f "$PDT_SMPI_BIN" ] || { echo "simulate.sh: $PDT_SMPI_BIN missing (make smpi)" >&2; exit 2; }

# The hostfile: the platform's cluster hosts (prefix, radical a-b, suffix).
prefix=$(grep -o 'prefix="[^"]*"' "$platform" | head -1 | cut -d'"' -f2)
suffix=$(grep -o 'suffix="[^"]*"' "$platform" | head -1 | cut -d'"' -f2)
radical=$(grep -o 'radical="[0-9]*-[0-9]*"' "$platform" | head -1 | cut -d'"' -f2)
[ -n "$radical" ] || { echo "simulate.sh: $platform: no <cluster radical=\"a-b\">" >&2; exit 2; }
work=$(mktemp -d "${TMPDIR:-/tmp}/pdt-sim.XXXXXX")
trap 'rm -rf "$work"' EXIT
seq "${radical%-*}" "${radical#*-}" | sed "s/^/$prefix/; s/\$/$suffix/" > "$work/hosts"

# smpirun copies the program once per rank into $TMPDIR (each rank its own
# globals; its -tmpdir option takes the next word for the program); the
# collectives are Open MPI's algorithms (SMPI's defaults are linear in P)
# but for the broadcast: SMPI's k-nomial one (Open MPI's choice for most
# sizes from 16 ranks on) first runs a ring allgather over the whole
# communicator, P^2 messages (a third of a 1024-rank simulation), so the
# binomial tree instead; SimGrid's own messages only when something is wrong.
TMPDIR=$work smpirun -np "$np" -platform "$platform" -hostfile "$work/hosts" \
    --cfg=smpi/host-speed:"$speed" --cfg=smpi/coll-selector:ompi \
    --cfg=smpi/bcast:binomial_tree \
    --log=root.thres:warning --log=smpi_config.thres:error "${extra[@]}" \
    "$PDT_SMPI_BIN" "$@"
