#!/usr/bin/env python3
"""pdt — check a pdtview layout report (`--layout-report F.json`).

    scripts/layout-check.py [options] F.json [F2.json ...]

The report lists every text the frame placed: its ink box (x, y, w, h in
pixels), its font size px, its panel and whether a clip cut it.  Checked:

  * no two texts overlap (by more than --slack pixels each way; the texts of
    a layer drawn over the frame (the help overlay; the window's notes pane
    and key-effect line, panels notes and keys) are not compared with the
    texts under them);
  * no text is cut: neither by the frame nor by its panel's clip;
  * no text is smaller than --min-px;
  * the texts of the panels --big names (default code, event) are at least
    --min-big px;
  * with --status: a status text is present.

--ignore PANELS leaves those panels' texts out of every check.

Prints one line per problem and `ok F.json (N texts)`; exits 1 when a report
has a problem, 2 on a usage error.
"""
import argparse
import json
import sys


def overlap(a, b, slack):
    return (a["x"] + slack < b["x"] + b["w"] and b["x"] + slack < a["x"] + a["w"]
            and a["y"] + slack < b["y"] + b["h"] and b["y"] + slack < a["y"] + a["h"])


# Layers drawn over the frame: a text in one is not compared with the texts
# it covers (the help overlay; the window's notes pane and key-effect line).
LAYERS = {"help": "help", "notes": "lecture", "keys": "lecture"}


def layer(t):
    return LAYERS.get(t["panel"], "frame")


def overlaps(texts, slack):
    """Pairs of overlapping texts (sorted by x so that the scan stays short)."""
    order = sorted(range(len(texts)), key=lambda i: texts[i]["x"])
    found = []
    for n, i in enumerate(order):
        a = texts[i]
        for j in order[n + 1:]:
            b = texts[j]
            if b["x"] >= a["x"] + a["w"] - slack:
                break
            if layer(a) != layer(b):
                continue
            if overlap(a, b, slack):
                found.append((a, b))
    return found


def name(t):
    return f'"{t["text"][:40]}" ({t["panel"]}, {t["x"]:.0f},{t["y"]:.0f} {t["w"]:.0f}x{t["h"]:.0f}, {t["px"]:.1f} px)'


def check(path, o):
    with open(path, encoding="utf-8") as f:
        rep = json.load(f)
    texts, W, H = rep["texts"], rep.get("width", 1e9), rep.get("height", 1e9)
    skip = set(o.ignore.split(",")) if o.ignore else set()
    texts = [t for t in texts if t["panel"] not in skip]
    bad = []
    for a, b in overlaps(texts, o.slack):
        bad.append(f"overlap: {name(a)} and {name(b)}")
    big = set(o.big.split(",")) if o.big else set()
    for t in texts:
        if t.get("clipped") or t["x"] < -0.5 or t["y"] < -0.5 or t["x"] + t["w"] > W + 0.5 \
                or t["y"] + t["h"] > H + 0.5:
            bad.append(f"cut: {name(t)}")
        if t["px"] < o.min_px - 0.05:
            bad.append(f"small: {name(t)} under {o.min_px} px")
        elif t["panel"] in big and t["px"] < o.min_big - 0.05:
            bad.append(f"small: {name(t)} under {o.min_big} px ({t['panel']})")
    if o.status and not any(t["panel"] == "status" for t in texts):
        bad.append("no status text")
    for p in o.panel or []:
        if not any(t["panel"] == p for t in texts):
            bad.append(f"no text in panel {p}")
    for line in bad[:o.max_lines]:
        print(f"{path}: {line}")
    if len(bad) > o.max_lines:
        print(f"{path}: ... and {len(bad) - o.max_lines} more")
    if not bad:
        print(f"ok {path} ({len(texts)} texts)")
    return not bad


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("reports", nargs="+")
    ap.add_argument("--min-px", type=float, default=12, help="smallest text allowed (12)")
    ap.add_argument("--min-big", type=float, default=0, help="smallest text of the --big panels")
    ap.add_argument("--big", default="code,event", help="panels held to --min-big (code,event)")
    ap.add_argument("--status", action="store_true", help="a status text must be present")
    ap.add_argument("--panel", action="append", help="a panel that must hold a text")
    ap.add_argument("--ignore", default="", help="panels left out of the checks (comma list)")
    ap.add_argument("--slack", type=float, default=1.0, help="overlap allowed, pixels (1)")
    ap.add_argument("--max-lines", type=int, default=20, help="problems printed per report")
    o = ap.parse_args()
    good = True
    for p in o.reports:
        try:
            good = check(p, o) and good
        except (OSError, ValueError, KeyError) as e:
            print(f"{p}: unreadable report: {e}")
            good = False
    sys.exit(0 if good else 1)


if __name__ == "__main__":
    main()
