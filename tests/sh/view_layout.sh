#!/bin/bash
# pdtview --layout-report: every text of the frame with its box, pixel size
# and panel; scripts/layout-check.py finds overlapping, cut and small texts.
# The layout itself is held to the lecture-room rules: at 1024x768 and
# 1920x1080, font scales 1, 1.5 and 2, every panel shown, no text overlaps
# or is cut, none is under 16 px, code and event line at least 18 px.
# san: yes
. "$(dirname "$0")/lib.sh"
V=$BIN/pdtview
CHECK="python3 $ROOT/scripts/layout-check.py"
RUN=synth:srm:8:8:4

# the report: valid JSON, every text of the frame, each in its panel
if "$V" --headless "$RUN" --phase merge -o "$TMP/m.png" --size 1600x1000 --layout-report "$TMP/m.json" --quiet &&
   python3 - "$TMP/m.json" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
panels = {t["panel"] for t in d["texts"]}
need = {"picture", "event", "legend", "code", "stack", "lifted", "timeline"}
assert need <= panels, f"panels {sorted(panels)} lack {sorted(need - panels)}"
assert d["width"] == 1600 and d["height"] == 1000
for t in d["texts"]:
    assert t["w"] > 0 and t["h"] > 0 and t["px"] > 0 and t["text"], t
assert any(t["panel"] == "code" and t["text"][0].isdigit() for t in d["texts"])
EOF
then ok report_has_every_panel; else fail report_has_every_panel "$(cat "$TMP/m.json" | head -5)"; fi

# the report needs a picture to describe
"$V" --headless "$RUN" --end --layout-report "$TMP/x.json" --frames "$TMP/fr" >/dev/null 2>"$TMP/err"
if [ $? -eq 2 ] && grep -q "layout-report" "$TMP/err"; then ok report_needs_output
else fail report_needs_output "$(cat "$TMP/err")"; fi

# the checker finds what is wrong (overlap, cut, small, no status) ...
cat >"$TMP/bad.json" <<'EOF'
{"width": 100, "height": 100, "texts": [
 {"text": "a", "x": 10, "y": 10, "w": 30, "h": 12, "px": 16, "panel": "code", "clipped": false},
 {"text": "b", "x": 20, "y": 15, "w": 30, "h": 12, "px": 16, "panel": "code", "clipped": false},
 {"text": "c", "x": 90, "y": 50, "w": 30, "h": 12, "px": 16, "panel": "event", "clipped": false},
 {"text": "d", "x": 10, "y": 70, "w": 10, "h": 8, "px": 9, "panel": "picture", "clipped": false},
 {"text": "e", "x": 40, "y": 70, "w": 10, "h": 8, "px": 20, "panel": "stack", "clipped": true}]}
EOF
$CHECK --min-px 12 --status "$TMP/bad.json" >"$TMP/bad.out"
if [ $? -eq 1 ] && grep -q 'overlap: "a"' "$TMP/bad.out" && grep -q 'cut: "c"' "$TMP/bad.out" &&
   grep -q 'cut: "e"' "$TMP/bad.out" && grep -q 'small: "d"' "$TMP/bad.out" &&
   grep -q 'no status text' "$TMP/bad.out"; then ok checker_finds_problems
else fail checker_finds_problems "$(cat "$TMP/bad.out")"; fi
# ... and passes a clean one
if $CHECK --min-px 12 "$TMP/m.json" >"$TMP/ok.out"; then ok checker_passes_clean
else fail checker_passes_clean "$(head -5 "$TMP/ok.out")"; fi

# the lecture-room rules, on a projector (1024x768) and a large screen,
# at font scales 1, 1.5 and 2: a Graham run and an SRM run of four ranks
# with every panel, at their busy moments (at 780 both merge stacks of a
# rank are open: at font scale 2 the elements go below their names)
for sz in 1024x768 1920x1080; do
    for fs in 1 1.5 2; do
        for spec in "synth:graham:40 --at 60" "synth:srm:8:8:4 --phase merge" "synth:srm:8:8:4 --at 465" \
                    "synth:srm:8:8:4 --panels all --at 780"; do
            set -- $spec
            n=$(echo "$spec $sz $fs" | tr -c 'a-z0-9\n' _)
            "$V" --headless $spec -o "$TMP/$n.png" --size $sz --font-scale $fs --layout-report "$TMP/$n.json" --quiet
            if $CHECK --min-px 16 --min-big 18 --panel event --panel code "$TMP/$n.json" >"$TMP/$n.out"; then
                ok "readable_${n}"
            else fail "readable_${n}" "$(head -4 "$TMP/$n.out")"; fi
        done
    done
done

# a recorded run of 8 ranks (lesson 09's), the same rules through it, at
# 1024x768 and font scale 2 with every panel asked for: every 50th step and
# the steps where the event line spills over a named point's label (2705,
# 3395, 3440) or a merge stack's name fills its line (2065)
R8=$ROOT/assets/runs/uniform-300-p8
steps=$( (seq 0 50 5650; echo 2065 2705 3395 3440) | tr '\n' ' ')
reports=()
for k in $steps; do
    "$V" --headless "$R8" --panels all --at "$k" -o "$TMP/r8.png" --size 1024x768 --font-scale 2 \
        --layout-report "$TMP/r8-$k.json" --quiet && reports+=("$TMP/r8-$k.json")
done
if [ "${#reports[@]}" -eq "$(echo $steps | wc -w)" ] &&
   $CHECK --min-px 16 --min-big 18 --panel event "${reports[@]}" >"$TMP/r8.out"; then
    ok "readable_recorded_8_ranks: ${#reports[@]} steps"
else fail readable_recorded_8_ranks "$(grep -v '^ok ' "$TMP/r8.out" | head -4)"; fi
# ... and when the stack panel has no line for every open stack, the stack
# a push or pop event names is among those it shows (2100, 3800, 4550, 5200
# and 5500 are such steps)
if python3 - "${reports[@]}" >"$TMP/r8s.out" <<'EOF2'
import json, re, sys
bad = seen = 0
for f in sys.argv[1:]:
    d = json.load(open(f))
    ev = " ".join(t["text"] for t in d["texts"] if t["panel"] == "event")
    m = re.search(r"rank (\d+): (?:push|pop) .*?(?:on|from) the ([a-z-]+) stack", ev)
    if not m:
        continue
    seen += 1
    st = " ".join(t["text"] for t in d["texts"] if t["panel"] == "stack")
    if not re.search(rf"\br{m.group(1)} {m.group(2)}\b", st):
        print(f"{f}: r{m.group(1)} {m.group(2)} not in the stack panel: {st[:100]!r}")
        bad = 1
print(f"{seen} stack events")
assert seen >= 20, seen
sys.exit(bad)
EOF2
then ok "stack_panel_shows_the_events_stack: $(tail -1 "$TMP/r8s.out")"
else fail stack_panel_shows_the_events_stack "$(head -3 "$TMP/r8s.out")"; fi

# the recorded run of 256 ranks (lesson 12's), the same rules at the steps
# where a build of the viewer put a named point's label over a group's
# label, another named point's, the event line's spill or the picture's
# edge, or a stack's name past its panel: at 1024x768, font scales 1 and 2,
# and 1920x1080
tar xJf "$ROOT/lessons/12-cluster/r256-uniform-3000.tar.xz" -C "$TMP"
R256=$TMP/r256-uniform-3000
reports=(); want=0
for spec in "1024x768 1 10200 10950 16950 21600 43500 65400 120450" "1024x768 2 31800 117750" \
            "1920x1080 1 10200 43500"; do
    set -- $spec
    sz=$1 fs=$2
    shift 2
    for k; do
        want=$((want + 1))
        "$V" --headless "$R256" --panels all --at "$k" -o "$TMP/r256.png" --size "$sz" --font-scale "$fs" \
            --layout-report "$TMP/r256-$sz-$fs-$k.json" --quiet && reports+=("$TMP/r256-$sz-$fs-$k.json")
    done
done
if [ "${#reports[@]}" -eq "$want" ] &&
   $CHECK --min-px 16 --panel event "${reports[@]}" >"$TMP/r256.out"; then
    ok "readable_recorded_256_ranks: $want steps"
else fail readable_recorded_256_ranks "$(grep -v '^ok ' "$TMP/r256.out" | head -4)"; fi

# the legend's groups and the timeline's rows of a 64-rank run, held to the
# same rules: the legend flows its groups into rows and is given their height,
# or, with no room for it, is named on the bottom line (Tab shows it)
for sz in 1024x768 1920x1080; do
    for fs in 1 1.5 2; do
        n=ranks_64_${sz}_$(echo $fs | tr . _)
        "$V" --headless synth:srm:128:4:64 --end -o "$TMP/$n.png" --size $sz --font-scale $fs --layout-report "$TMP/$n.json" --quiet
        want=$(python3 - "$TMP/$n.json" <<'EOF2'
import json, sys
d = json.load(open(sys.argv[1]))
more = " ".join(t["text"] for t in d["texts"] if t["panel"] == "more")
for p in ("legend", "timeline"):
    if p in d["hidden"]:
        assert p in more and "Tab" in more, f"{p} hidden, not named: {more!r}"
        assert p not in d["panels"], p
    else:
        print("--panel", p)
EOF2
) || { fail "readable_legend_timeline_$n" "hidden panel not named"; continue; }
        if $CHECK --min-px 16 --min-big 18 $want "$TMP/$n.json" >"$TMP/$n.out"; then
            ok "readable_legend_timeline_$n"
        else fail "readable_legend_timeline_$n" "$(head -4 "$TMP/$n.out")"; fi
    done
done

# a projector at font scale 2, every panel asked for: the picture keeps a
# fair share (a third of the room under the top bar), the panels with no
# room are named on the bottom line with the key that shows them
for spec in "synth:srm:8:8:4 --phase merge" "synth:graham:40 --at 60" "synth:srm:128:4:64 --end"; do
    n=share_$(echo "$spec" | tr -c 'a-z0-9\n' _)
    "$V" --headless $spec -o "$TMP/$n.png" --size 1024x768 --font-scale 2 --layout-report "$TMP/$n.json" --quiet
    if python3 - "$TMP/$n.json" >"$TMP/$n.out" 2>&1 <<'EOF2'
import json, sys
d = json.load(open(sys.argv[1]))
P = d["panels"]
top = P["event"][3]
x, y, w, h = P["picture"]
assert w * h >= 0.33 * d["width"] * (d["height"] - top), f"picture {w}x{h}"
more = " ".join(t["text"] for t in d["texts"] if t["panel"] == "more")
names = {"legend": "legend", "timeline": "timeline", "stack": "stacks", "lifted": "lifted"}
for p in d["hidden"]:
    assert names[p] in more and "Tab" in more, (p, more)
assert not d["hidden"] or "more" in P
EOF2
    then ok "fair_share_$n"; else fail "fair_share_$n" "$(tail -2 "$TMP/$n.out")"; fi
done

summary
