#!/bin/bash
# pdt — run one lesson: record its run(s), then open the viewer at the right place.
#
#   scripts/lesson.sh [options] LESSON        (LESSON = lessons/NN-name, NN-name or NN)
#   make lesson L=NN
#
# What it does, for every run the lesson's lesson.conf describes:
#   1. records the run with `pdt COMMAND POINTS --trace DIR` (under `mpirun -np R`
#      when the lesson uses R > 1 ranks) into build/lessons/NN/RUN/trace, or uses
#      the recorded run the lesson names (`recorded = ...`);
#   2. checks the recording with `pdt trace check` and writes `pdt trace dump`
#      into build/lessons/NN/RUN/dump.txt, and what the viewer says about every
#      event (`pdtview --describe`: event line, lit code line, the start) into
#      build/lessons/NN/RUN/describe.txt (when pdtview is built), and the
#      lesson's key moments (its start, the `step` lines of its checks) into
#      build/lessons/NN/RUN/moments.tsv: the window's bookmarks (b, Shift+b)
#      and the text of its notes pane (n);
#   3. with a display ($DISPLAY or $WAYLAND_DISPLAY set): opens `pdtview` on the
#      run at the lesson's start point; without one (or with --headless): renders
#      the start frame and the key frames into build/lessons/NN/RUN/frames/.
#
# Options
#   --headless     never open a window, render frames (default without a display)
#   --record-only  record, check and describe, render nothing, open nothing
#   --out DIR      where to put the runs (default: build/lessons/NN in a checkout,
#                  ./pdt-lessons/NN when installed as pdt-lesson)
#   --quiet        print only where things are
#   --points FILE  record every run on FILE instead of the lesson's points (a
#                  teacher's own; the lesson's checked facts are about its own)
#   --view OPTS    more pdtview options for the window and the frames, after the
#                  lesson's own (`make lesson L=NN VIEW="--theme dark --font-scale 1.5"`)
#
# lesson.conf: `key = value` lines, `#` comments; optional `[NAME]` sections, one
# per run (keys before the first section apply to every run).  Keys:
#   title      one line
#   command    hull | triangulate
#   points     the input file, relative to the lesson folder
#   ranks      number of MPI ranks (default 1: no mpirun)
#   simulate   P: record on P simulated ranks instead (scripts/simulate.sh, SimGrid's
#              SMPI on the bundled 10 Gb/s cluster; needs bin/smpi/pdt, which is
#              built with `make smpi` first when missing: that installs
#              libsimgrid-dev if needed); the trace's clock is the simulated one
#   level      trace level, 1 or 2 (default 1)
#   partition  strips | bisect: how the ranks' regions are cut (pdt --partition;
#              default: pdt's own, which bisects from 16 ranks on)
#   start      where the viewer starts: `at N` (the viewer's counter: N events
#              applied), `phase NAME` (just after the phase first begins), `end`,
#              or `first KIND ...` / `last KIND ...` (the first/last event of
#              that kind, words and fields: see scripts/lesson-check.py)
#   frames     key frames rendered headless, separated by `;` (same forms as start)
#   view       extra pdtview options, passed as they are (e.g. --panels code,stack)
#   recorded   a run folder recorded ahead (relative to the lesson folder): not re-recorded;
#              or a tar archive of one (NAME.tar.xz, .tar.gz), unpacked into the run's folder
#
# Exit status: 0 when every run was recorded, checked and shown/rendered; 1 otherwise.
set -u
# Where its files are: in a checkout, ROOT (lessons/, scripts/, bin/); installed by
# `make install` as PREFIX/bin/pdt-lesson, PREFIX/share/pdt (lessons/, assets/,
# lesson-check.py) beside PREFIX/bin, runs going to ./pdt-lessons/NN.
# PDT_DATADIR overrides the data folder.
HERE=$(cd "$(dirname "$0")" && pwd)
if [ -z "${PDT_DATADIR:-}" ] && [ -f "$HERE/lesson-check.py" ] && [ -d "$HERE/../lessons" ]; then
    ROOT=$(cd "$HERE/.." && pwd)           # the checkout
    BIN=${BIN:-$ROOT/bin}
    CHECKPY=$ROOT/scripts/lesson-check.py
    OUTBASE=$ROOT/build/lessons
else
    ROOT=${PDT_DATADIR:-$(cd "$HERE/../share/pdt" 2>/dev/null && pwd)}
    [ -d "$ROOT/lessons" ] || { echo "lesson: no lessons in '$ROOT' (set PDT_DATADIR)" >&2; exit 2; }
    BIN=${BIN:-$HERE}
    CHECKPY=$ROOT/lesson-check.py
    OUTBASE=$(pwd)/pdt-lessons
fi
PDT=${PDT:-$BIN/pdt}
PDTVIEW=${PDTVIEW:-$BIN/pdtview}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

headless=0; record_only=0; out=""; quiet=0; lesson=""; own_points=""; user_view=""
while [ $# -gt 0 ]; do
    case $1 in
        --headless) headless=1 ;;
        --record-only) record_only=1 ;;
        --out) out=$2; shift ;;
        --quiet) quiet=1 ;;
        --points) own_points=$2; shift ;;
        --view) user_view=$2; shift ;;
        -h|--help) sed -n '2,/^set -u/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
        -*) echo "lesson: unknown option $1 (see --help)" >&2; exit 2 ;;
        *) lesson=$1 ;;
    esac
    shift
done
[ -n "$lesson" ] || { echo "usage: scripts/lesson.sh [--headless] LESSON   (e.g. lessons/02-graham or 02)" >&2; exit 2; }

# ---- find the lesson folder ------------------------------------------------
if [ ! -d "$lesson" ]; then
    for cand in "$ROOT/lessons/$lesson" "$ROOT"/lessons/"$lesson"-* "$ROOT"/lessons/0"$lesson"-*; do
        if [ -d "$cand" ]; then lesson=$cand; break; fi
    done
fi
[ -f "$lesson/lesson.conf" ] || { echo "lesson: no lesson.conf in '$lesson'" >&2; exit 2; }
LDIR=$(cd "$lesson" && pwd)
LNAME=$(basename "$LDIR")
NN=${LNAME%%-*}
[ -n "$out" ] || out=$OUTBASE/$NN
mkdir -p "$out"
out=$(cd "$out" && pwd)

say() { [ "$quiet" = 1 ] || echo "$@"; }

# ---- read lesson.conf --------------------------------------------------------
declare -A CONF
RUNS=()
section=""
while IFS= read -r line || [ -n "$line" ]; do
    line=${line%%#*}
    line=$(echo "$line" | sed 's/^[[:space:]]*//; s/[[:space:]]*$//')
    [ -z "$line" ] && continue
    if [[ $line =~ ^\[([A-Za-z0-9_-]+)\]$ ]]; then
        section=${BASH_REMATCH[1]}; RUNS+=("$section"); continue
    fi
    if [[ $line =~ ^([a-z]+)[[:space:]]*=[[:space:]]*(.*)$ ]]; then
        CONF["$section.${BASH_REMATCH[1]}"]=${BASH_REMATCH[2]}
    else
        echo "lesson: $LDIR/lesson.conf: cannot read line: $line" >&2; exit 2
    fi
done <"$LDIR/lesson.conf"
[ ${#RUNS[@]} -gt 0 ] || RUNS=(run)

# conf RUN KEY DEFAULT: the run's value, else the global one, else DEFAULT
conf() {
    if [ -n "${CONF[$1.$2]+x}" ]; then echo "${CONF[$1.$2]}"
    elif [ -n "${CONF[.$2]+x}" ]; then echo "${CONF[.$2]}"
    else echo "$3"; fi
}

# pos_args POSITION DUMP: viewer position -> pdtview options.  Positions:
#   at N | phase NAME | end | first KIND [W..] [F=V..] | last KIND [W..] [F=V..]
# (first/last: the cursor that shows the first/last event of the run that
# matches, found in the dump: stable across runs of several ranks, whose
# merged event numbers vary with timing)
pos_args() {
    local w1 w2 k
    read -r w1 w2 <<<"$1"
    case $w1 in
        at) # with your own points the run may be shorter than the lesson's
            if [ -n "$own_points" ] && [ "$w2" -gt "$(wc -l <"$2")" ]; then echo "--end"
            else echo "--at $w2"; fi ;;
        phase) echo "--phase $w2" ;;
        end) echo "--end" ;;
        first|last)
            # shellcheck disable=SC2086
            if k=$(python3 -B "$CHECKPY" --find "$2" $1 2>/dev/null); then
                echo "--at $k"
            elif [ -n "$own_points" ]; then
                echo "lesson: '$1' does not happen with your points: showing the end" >&2
                echo "--end"
            else
                python3 -B "$CHECKPY" --find "$2" $1 >/dev/null; return 1
            fi ;;
        *) echo "lesson: bad viewer position '$1' (at N | phase NAME | end | first/last KIND ...)" >&2; return 1 ;;
    esac
}
# file-name form of a position: "at 12" -> at-12
pos_name() { echo "$1" | tr ' ' '-' | tr -cd 'A-Za-z0-9_-'; }

# need_smpi: the simulated build bin/smpi/pdt (scripts/simulate.sh), made
# with `make smpi` in a checkout when missing
need_smpi() {
    [ -f "${PDT_SMPI_BIN:-$ROOT/bin/smpi/pdt}" ] && command -v smpirun >/dev/null && return 0
    if [ -f "$ROOT/Makefile" ] && [ -f "$ROOT/scripts/simulate.sh" ]; then
        say "  building the simulated pdt (make smpi: installs libsimgrid-dev when missing)"
        make -C "$ROOT" --no-print-directory smpi >&2 && return 0
    fi
    echo "lesson: this lesson simulates a cluster and needs bin/smpi/pdt: run 'make smpi' in a checkout of pdt" >&2
    return 1
}

have_display=0
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then have_display=1; fi
[ "$headless" = 1 ] && have_display=0

title=$(conf "" title "$LNAME")
say "Lesson $NN: $title"
say "  text: $LDIR/README.md"
status=0
VIEW_QUEUE=()

for run in "${RUNS[@]}"; do
    rdir=$out/$run
    command=$(conf "$run" command triangulate)
    points=$(conf "$run" points points.txt)
    if [ -n "$own_points" ]; then
        [ -f "$own_points" ] || { echo "lesson: --points $own_points: no such file" >&2; exit 2; }
        points=$(cd "$(dirname "$own_points")" && pwd)/$(basename "$own_points")
    fi
    ranks=$(conf "$run" ranks 1)
    simulate=$(conf "$run" simulate "")
    level=$(conf "$run" level 1)
    partition=$(conf "$run" partition "")
    start=$(conf "$run" start end)
    frames=$(conf "$run" frames "")
    view="$(conf "$run" view "") $user_view"
    recorded=$(conf "$run" recorded "")
    [ -n "$own_points" ] && recorded=""
    mkdir -p "$rdir"
    rm -rf "$rdir/frames" "$rdir/dump.txt" "$rdir/describe.txt" "$rdir/output.txt" "$rdir/log.txt"

    # 1. record (or use the recorded run)
    if [ -n "$recorded" ]; then
        trace=$LDIR/$recorded
        case $recorded in *.tar|*.tar.*)
            rm -rf "$rdir/recorded"; mkdir -p "$rdir/recorded"
            tar -xf "$trace" -C "$rdir/recorded" ||
                { echo "lesson: [$run] cannot unpack $trace" >&2; status=1; continue; }
            trace=$(dirname "$(find "$rdir/recorded" -name manifest | head -1)") ;;
        esac
        say "  [$run] using the run recorded ahead: $LDIR/$recorded"
    else
        trace=$rdir/trace
        rm -rf "$trace"
        case $points in /*) pfile=$points ;; *) pfile=$LDIR/$points ;; esac
        popt=()
        [ -n "$partition" ] && [ "$command" = triangulate ] && popt=(--partition "$partition")
        cmd=("$PDT" "$command" "$pfile" --trace "$trace" --trace-level "$level" "${popt[@]}")
        if [ -n "$simulate" ]; then
            need_smpi || { status=1; continue; }
            ranks=$simulate
            cmd=(bash "$ROOT/scripts/simulate.sh" -np "$ranks" -- "$command" "$pfile" --trace "$trace" --trace-level "$level" "${popt[@]}")
            say "  [$run] simulating: $command of $points on $ranks simulated rank(s) (scripts/simulate.sh)"
        elif [ "$ranks" -gt 1 ]; then
            cmd=(mpirun -np "$ranks" --oversubscribe "${cmd[@]}")
        fi
        [ -n "$simulate" ] || say "  [$run] recording: $command of $points on $ranks rank(s), trace level $level"
        if ! "${cmd[@]}" >"$rdir/output.txt" 2>"$rdir/log.txt"; then
            echo "lesson: [$run] the run failed: ${cmd[*]}" >&2
            sed 's/^/    /' "$rdir/log.txt" >&2
            status=1; continue
        fi
        got=$(sed -n 's/^ranks = //p' "$trace/manifest" 2>/dev/null)
        if [ "$got" != "$ranks" ]; then
            echo "lesson: [$run] mpirun started $ranks processes but the recorded run has '${got:-?}' rank(s):" >&2
            echo "    this pdt does not run the parallel algorithm under mpirun" >&2
            status=1; continue
        fi
    fi

    # 2. check and dump
    if ! "$PDT" trace check "$trace" >"$rdir/check.txt" 2>&1; then
        echo "lesson: [$run] pdt trace check failed on $trace:" >&2
        sed 's/^/    /' "$rdir/check.txt" >&2
        status=1; continue
    fi
    "$PDT" trace dump "$trace" >"$rdir/dump.txt" 2>>"$rdir/log.txt" || { echo "lesson: [$run] pdt trace dump failed" >&2; status=1; continue; }
    say "  [$run] trace: $trace ($(wc -l <"$rdir/dump.txt") events, pdt trace check passed)"

    # 3. what the viewer says (event lines, lit code lines, the start) for the
    #    checks, then view or render
    startargs=$(pos_args "$start" "$rdir/dump.txt") || { status=1; continue; }
    if [ -x "$PDTVIEW" ]; then
        # shellcheck disable=SC2086
        "$PDTVIEW" "$trace" $startargs --describe >"$rdir/describe.txt" 2>>"$rdir/log.txt" ||
            { echo "lesson: [$run] pdtview --describe failed (see $rdir/log.txt)" >&2; status=1; continue; }
    fi
    # the lesson's key moments (its start and each step of "In the viewer"):
    # the window's bookmarks (b / Shift+b) and its notes pane (n)
    bm=""
    if [ -s "$rdir/describe.txt" ] && [ -z "$own_points" ] &&
        python3 -B "$CHECKPY" --moments "$LDIR" "$out" "$run" >"$rdir/moments.tsv" 2>>"$rdir/log.txt" &&
        [ -s "$rdir/moments.tsv" ]; then
        bm="--bookmarks $rdir/moments.tsv"
    fi
    [ "$record_only" = 1 ] && continue
    if [ "$have_display" = 1 ]; then
        VIEW_QUEUE+=("$trace|$startargs $bm $view|$run")
        continue
    fi
    if [ ! -x "$PDTVIEW" ]; then
        echo "lesson: [$run] $PDTVIEW is not built: no frames rendered (the trace is recorded and checked)" >&2
        status=1; continue
    fi
    mkdir -p "$rdir/frames"
    k=0
    IFS=';' read -r -a keys <<<"start;$frames"
    for key in "${keys[@]}"; do
        key=$(echo "$key" | sed 's/^[[:space:]]*//; s/[[:space:]]*$//')
        [ -z "$key" ] && continue
        if [ "$key" = start ]; then pos=$start; else pos=$key; fi
        args=$(pos_args "$pos" "$rdir/dump.txt") || { status=1; continue; }
        png=$(printf '%s/frames/%02d-%s.png' "$rdir" "$k" "$(pos_name "$pos")")
        # shellcheck disable=SC2086
        if ! "$PDTVIEW" --headless "$trace" $args $view -o "$png" >>"$rdir/log.txt" 2>&1; then
            echo "lesson: [$run] rendering '$pos' failed (see $rdir/log.txt)" >&2
            status=1
        fi
        k=$((k + 1))
    done
    say "  [$run] no display: $k frame(s) rendered into $rdir/frames/"
done

# with a display: open the viewer on each run in turn
if [ ${#VIEW_QUEUE[@]} -gt 0 ]; then
    if [ ! -x "$PDTVIEW" ]; then
        echo "lesson: $PDTVIEW is not built (make)" >&2; exit 1
    fi
    for item in "${VIEW_QUEUE[@]}"; do
        IFS='|' read -r trace args run <<<"$item"
        say "  [$run] opening the viewer (h shows every key; q closes it)"
        # shellcheck disable=SC2086
        "$PDTVIEW" "$trace" $args || status=1
    done
fi
exit $status
