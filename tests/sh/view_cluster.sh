#!/bin/bash
# pdtview on runs of 8, 64, 256 and 1024 ranks (8 and 64 real, by mpirun on
# this machine, the 64 on 5000 points; 256 and 1024 synthetic): headless
# frames at 1024x768 and 1920x1080, at the end and in the merges, checked by
# their layout report (--layout-report): no two texts overlap, none is cut by
# the frame, none is under 12 px, none under 16 px at 1024x768
# (scripts/layout-check.py); the timeline's axis is labelled in time
# (ms) in the real runs; every rank or
# group on screen (a timeline row, a label in the picture) is in the legend;
# the timeline's rows are at least as tall as their labels.
. "$(dirname "$0")/lib.sh"
V=$BIN/pdtview
CHECK=$ROOT/scripts/layout-check.py
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

# Every rank range named in the timeline's rows and the picture's labels
# lies in a group the legend lists; timeline rows at least as tall as their text.
groups_check() {
    python3 - "$1" <<'EOF'
import json, re, sys
rep = json.load(open(sys.argv[1]))
T = rep["texts"]
def rng(s):
    m = re.fullmatch(r"(?:ranks? |r)?(\d+)(?:–(\d+))?", s.strip())
    return (int(m.group(1)), int(m.group(2) or m.group(1))) if m else None
legend = []
for t in T:
    if t["panel"] != "legend":
        continue
    r = rng(t["text"])
    if r:
        legend.append(r)
bad = []
rows = []
for t in T:
    if t["panel"] not in ("timeline", "picture"):
        continue
    r = rng(t["text"])
    if not r or (t["panel"] == "timeline" and not t["text"].startswith("r")):
        continue
    if not any(a <= r[0] and r[1] <= b for a, b in legend):
        bad.append(f'{t["panel"]} names "{t["text"]}", in no group of the legend {legend}')
    if t["panel"] == "timeline" and t["x"] < 80:
        rows.append(t)
rows.sort(key=lambda t: t["y"])
for a, b in zip(rows, rows[1:]):
    if b["y"] - a["y"] < max(a["h"], b["h"]):
        bad.append(f'rows "{a["text"]}" and "{b["text"]}" {b["y"] - a["y"]:.1f} px apart, text {a["h"]:.0f} px')
if not legend:
    bad.append("no rank or group in the legend")
if not rows:
    bad.append("no timeline row")
for b in bad[:10]:
    print(b)
sys.exit(1 if bad else 0)
EOF
}

# The timeline's axis in time: at least three tick labels in ms (or µs, s)
# under the rows, their centres at x proportional to their times.
axis_check() {
    python3 - "$1" <<'EOF'
import json, re, sys
T = json.load(open(sys.argv[1]))["texts"]
unit = {"µs": 1e-3, "ms": 1.0, "s": 1e3}
ticks = []
for t in T:
    m = re.fullmatch(r"(\d+(?:\.\d+)?) (µs|ms|s)", t["text"]) if t["panel"] == "timeline" else None
    if m:
        ticks.append((float(m.group(1)) * unit[m.group(2)], t["x"] + t["w"] / 2))
ticks.sort()
if len(ticks) < 3:
    print(f"{len(ticks)} tick labels in time: {ticks}")
    sys.exit(1)
(v0, x0), (v1, x1) = ticks[0], ticks[-1]
for v, x in ticks:
    want = x0 + (v - v0) / (v1 - v0) * (x1 - x0)
    if abs(x - want) > 2:
        print(f"tick {v} ms at x {x:.1f}, {want:.1f} for a linear axis")
        sys.exit(1)
EOF
}

# frames NAME RUN LEVEL: at the end and in the merges (level 1 and LEVEL),
# at both sizes, with every panel and with code, timeline and tree.
frames() {
    local name=$1 run=$2 n=0 lbad=0 gbad=0 msg="" gmsg="" f where size panels
    for f in "--end 1024x768 all" "--phase=merge:1 1920x1080 code,timeline,tree" \
             "--phase=merge:$3 1024x768 code,timeline,tree" "--phase=merge:$3 1920x1080 all" \
             "--end 1920x1080 timeline,tree"; do
        read -r where size panels <<<"$f"
        n=$((n + 1))
        local out="$TMP/$name-$n"
        if ! "$V" --headless "$run" ${where/=/ } --size "$size" --panels "$panels" -o "$out.png" \
                --layout-report "$out.json" --quiet 2>"$out.err"; then
            lbad=1; msg="$msg [$f] $(head -1 "$out.err")"; continue
        fi
        local min=12
        [ "$size" = 1024x768 ] && min=16
        python3 "$CHECK" --min-px "$min" "$out.json" >"$out.chk" || { lbad=1; msg="$msg [$f] $(head -2 "$out.chk")"; }
        groups_check "$out.json" >"$out.grp" || { gbad=1; gmsg="$gmsg [$f] $(head -2 "$out.grp")"; }
    done
    if [ $lbad = 0 ]; then ok "${name}_frames_no_overlap_cut_or_small_text_16px_at_1024"; else fail "${name}_frames_no_overlap_cut_or_small_text_16px_at_1024" "$msg"; fi
    if [ $gbad = 0 ]; then ok "${name}_groups_on_screen_in_legend_rows_tall_enough"; else fail "${name}_groups_on_screen_in_legend_rows_tall_enough" "$gmsg"; fi
}

"$BIN/pdt" gen uniform 2000 --seed 3 -o "$TMP/u2k.txt"
"$BIN/pdt" gen uniform 5000 --seed 4 -o "$TMP/u5k.txt"
if command -v mpirun >/dev/null &&
   mpirun --oversubscribe -np 8 "$BIN/pdt" triangulate "$TMP/u2k.txt" -o "$TMP/r8.tri" --trace "$TMP/r8" >/dev/null 2>"$TMP/r8.err"; then
    frames ranks_8 "$TMP/r8" 2
else fail ranks_8_run "$(head -3 "$TMP/r8.err" 2>/dev/null)"; fi
if command -v mpirun >/dev/null &&
   mpirun --oversubscribe -np 64 "$BIN/pdt" triangulate "$TMP/u5k.txt" -o "$TMP/r64.tri" --trace "$TMP/r64" >/dev/null 2>"$TMP/r64.err"; then
    frames ranks_64_real_5000_points "$TMP/r64" 4
    if axis_check "$TMP/ranks_64_real_5000_points-5.json" >"$TMP/axis.txt"; then ok timeline_axis_in_ms_linear
    else fail timeline_axis_in_ms_linear "$(head -2 "$TMP/axis.txt")"; fi
else fail ranks_64_run "$(head -3 "$TMP/r64.err" 2>/dev/null)"; fi
frames ranks_256 synth:srm:512:4:256 5
frames ranks_1024 synth:srm:2048:4:1024 7

# the legend lists eight groups of a 1024-rank run, not "…" after rank 8
"$V" --headless synth:srm:2048:4:1024 --end --size 1024x768 -o "$TMP/l.png" --layout-report "$TMP/l.json" --quiet
nleg=$(python3 -c 'import json,re,sys; print(sum(1 for t in json.load(open(sys.argv[1]))["texts"] if t["panel"]=="legend" and re.fullmatch(r"(?:ranks )?\d+–\d+", t["text"])))' "$TMP/l.json")
if [ "$nleg" = 8 ]; then ok legend_lists_eight_groups_of_1024_ranks; else fail legend_lists_eight_groups_of_1024_ranks "$nleg group labels"; fi
summary
