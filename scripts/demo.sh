#!/bin/bash
# pdt — the classroom demo (`make demo`; the Makefile builds first).
#
# Records a run of the parallel triangulation on NP ranks (default 4) of a small
# bundled point set, checks it, and opens the viewer on it.  With no display it
# draws the key moments into out/demo/frames/ instead, says where, and exits 0.
#
#   scripts/demo.sh [--headless] [--view OPTS] [POINTS]
#   --view OPTS: more pdtview options (`make demo VIEW="--theme dark --font-scale 1.5"`)
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
view=""
points=$ROOT/assets/points/demo-48.txt
while [ $# -gt 0 ]; do
    case $1 in
        --headless) headless=1 ;;
        --view) view=$2; shift ;;
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

if ! mpirun -np "$NP" --oversubscribe "$BIN/pdt" triangulate "$points" -o "$OUT/triangles.tri" \
        --trace "$run" >"$OUT/log.txt" 2>&1; then
    cat "$OUT/log.txt" >&2
    die "the run failed (the messages above say why)"
fi
note=""
if [ "$(sed -n 's/^ranks = //p' "$run/manifest" 2>/dev/null)" != "$NP" ]; then
    # A pdt built without the parallel driver runs NP separate copies under
    # mpirun: say so and record one process instead.
    note="(This build of pdt does not run the parallel algorithm under mpirun, so the demo
   recorded a run with one process instead.)"
    NP=1
    rm -rf "$run"
    "$BIN/pdt" triangulate "$points" -o "$OUT/triangles.tri" --trace "$run" >"$OUT/log.txt" 2>&1 ||
        { cat "$OUT/log.txt" >&2; die "the run failed (the messages above say why)"; }
fi
echo "pdt demo: the Delaunay triangulation of $n points, computed by $NP process$([ "$NP" -gt 1 ] && echo es)."
echo
echo "1. The points are in $points."
if [ "$NP" -gt 1 ]; then
    echo "   $NP MPI processes (ranks) shared the work: each took a vertical strip of the"
    echo "   points, lifted them onto the paraboloid z = x² + y² and triangulated its strip;"
    echo "   then neighbouring strips were merged, two at a time.  Every step was recorded."
else
    echo "   The points were lifted onto the paraboloid z = x² + y², and the lower side of"
    echo "   their convex hull in space gave the triangles.  Every step was recorded."
    echo "   $note"
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
    # shellcheck disable=SC2086
    exec "$BIN/pdtview" "$run" $view
fi

# No display: draw the key moments instead.
frames=$OUT/frames
mkdir -p "$frames"
"$BIN/pdt" trace dump "$run" >"$OUT/dump.txt" 2>>"$OUT/log.txt"
echo "3. There is no display here, so the key moments are drawn as pictures instead:"
# picture name | position (as in lesson.conf: at N, end, first/last KIND ...) | what it shows
if [ "$NP" -gt 1 ]; then
    shots=(
        "01-points|at 1|the points, before anything happened"
        "02-strips|last phase-end partition|the last process has received its strip (one colour per process); the others, served earlier, are already further on — each runs at its own pace"
        "03-local|last phase-end kernel|the last process has triangulated its strip"
        "04-restricted|last phase-end classify|the last process has tested its triangles' restricted areas: solid ones are final, dashed ones wait for a merge"
        "05-merge|first merge-end|the first merge step: triangles near a seam re-done, non-Delaunay ones crossed out"
        "06-end|end|the finished Delaunay triangulation"
    )
else
    shots=(
        "01-points|at 1|the points, before anything happened"
        "02-lifted|last phase-end lift|every point lifted onto the paraboloid (right: the lifted view)"
        "03-kernel|last phase-end kernel|the triangles found by divide and conquer"
        "04-end|end|the finished Delaunay triangulation"
    )
fi
fail=0
for s in "${shots[@]}"; do
    IFS='|' read -r name pos what <<<"$s"
    read -r w1 rest <<<"$pos"
    case $w1 in
        at) args="--at $rest" ;;
        end) args="--end" ;;
        *) k=$(python3 -B "$ROOT/scripts/lesson-check.py" --find "$OUT/dump.txt" $pos) || k=""
           args=${k:+--at $k} ;;
    esac
    # shellcheck disable=SC2086
    if [ -n "$args" ] && "$BIN/pdtview" --headless "$run" $args $view -o "$frames/$name.png" >>"$OUT/log.txt" 2>&1; then
        echo "   $frames/$name.png"
        echo "$what" | fold -s -w 70 | sed 's/^/       /'
    else
        echo "   could not draw $name (see $OUT/log.txt)" >&2
        fail=1
    fi
done
echo
echo "Open these pictures with any image viewer.  On a machine with a screen,"
echo "'make demo' opens the viewer itself, and 'make lesson L=01' starts the course."
exit $fail
