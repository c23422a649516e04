#!/bin/bash
# pdt — the classroom demo (`make demo`; the Makefile builds first).
#
# Records a run of the parallel triangulation on NP ranks (default 4) of a small
# bundled point set, checks it, and opens the viewer on it.  With no display it
# draws the key moments into out/demo/frames/ instead, says where, and exits 0.
#
#   scripts/demo.sh [--headless] [POINTS]
#   environment: NP (ranks, default 4), OUT (default out/demo), BIN (default bin)
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"
BIN=${BIN:-$ROOT/bin}
NP=${NP:-4}
OUT=${OUT:-$ROOT/out/demo}
# Open MPI refuses to run as root unless told, and 4 ranks on a 2-core machine
# need --oversubscribe.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

headless=0
points=$ROOT/assets/points/demo-48.txt
while [ $# -gt 0 ]; do
    case $1 in
        --headless) headless=1 ;;
        -h|--help) sed -n '2,/^set -u/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
        *) points=$1 ;;
    esac
    shift
done
if [ -z "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then headless=1; fi

die() { echo "demo: $*" >&2; exit 1; }
[ -x "$BIN/pdt" ] || die "$BIN/pdt is not built: run 'make demo' (it builds first)"
[ -f "$points" ] || die "no point file $points"

n=$(grep -cE '^[[:space:]]*-?[0-9]' "$points")
run=$OUT/run
rm -rf "$OUT"
mkdir -p "$OUT"

echo "pdt demo: the Delaunay triangulation of $n points, computed by $NP processes."
echo
echo "1. The points are in $points."
echo "   $NP MPI processes (ranks) share the work: each takes a vertical strip of the"
echo "   points, lifts them onto the paraboloid z = x² + y² and triangulates its strip;"
echo "   then neighbouring strips are merged, two at a time.  Every step is recorded."
if ! mpirun -np "$NP" --oversubscribe "$BIN/pdt" triangulate "$points" -o "$OUT/triangles.tri" \
        --trace "$run" >"$OUT/log.txt" 2>&1; then
    cat "$OUT/log.txt" >&2
    die "the run failed (the messages above say why)"
fi
ntri=$(grep -c . "$OUT/triangles.tri")
echo "   Done: $ntri triangles, written to $OUT/triangles.tri;"
echo "   the recording of every step is in $run/."
echo

echo "2. Checking the answer independently (pdt check): no point may lie inside the"
echo "   circle through the corners of any triangle."
if "$BIN/pdt" check "$points" "$OUT/triangles.tri" >"$OUT/check.txt" 2>&1; then
    echo "   Passed: it is the Delaunay triangulation."
else
    cat "$OUT/check.txt" >&2
    die "the check failed"
fi
if "$BIN/pdt" trace check "$run" >"$OUT/trace-check.txt" 2>&1; then
    echo "   The recording is complete and consistent (pdt trace check passed)."
else
    cat "$OUT/trace-check.txt" >&2
    die "the recording is not consistent (pdt trace check)"
fi
echo

if [ ! -x "$BIN/pdtview" ]; then
    echo "3. The viewer (pdtview) is not built on this machine, so there is nothing to show."
    echo "   Look at the recording in words instead: $BIN/pdt trace dump $run | less"
    exit 0
fi

if [ "$headless" = 0 ]; then
    echo "3. Opening the viewer.  Space plays and pauses, the arrow keys step, h lists every"
    echo "   key, q quits.  Re-open it any time with: $BIN/pdtview $run"
    exec "$BIN/pdtview" "$run"
fi

# No display: draw the key moments instead.
frames=$OUT/frames
mkdir -p "$frames"
echo "3. There is no display here, so the key moments are drawn as pictures instead:"
# picture name | pdtview position | what it shows
shots=(
    "01-start|--at 0|the points, before anything happened"
    "02-strips|--phase partition|the points shared out into $NP vertical strips, one colour per process"
    "03-local|--phase classify|each strip triangulated on its own; the restricted areas decide which triangles are final"
    "04-merge|--phase merge|a merge step: the triangles near a seam are shipped and re-triangulated"
    "05-end|--end|the finished Delaunay triangulation"
)
fail=0
for s in "${shots[@]}"; do
    IFS='|' read -r name pos what <<<"$s"
    # shellcheck disable=SC2086
    if "$BIN/pdtview" --headless "$run" $pos -o "$frames/$name.png" >>"$OUT/log.txt" 2>&1; then
        printf '   %-34s %s\n' "$frames/$name.png" "$what"
    else
        echo "   could not draw $name (see $OUT/log.txt)" >&2
        fail=1
    fi
done
echo
echo "Open these pictures with any image viewer.  On a machine with a screen,"
echo "'make demo' opens the viewer itself, and 'make lesson L=01' starts the course."
exit $fail
