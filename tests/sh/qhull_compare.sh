#!/bin/bash
# pdt triangulate against Qhull's qdelaunay on general-position inputs of
# 10^4 and 10^5 points (distinct x and y coordinates drawn at random from a
# large range, so no four points are cocircular in practice and the Delaunay
# triangulation is unique).  qdelaunay's "Qt i" output is normalised to the
# canonical form (counter-clockwise, rotated to the smallest index, sorted);
# the two must be byte-equal.
source "$(dirname "$0")/lib.sh"
cd "$TMP"
if ! command -v qdelaunay > /dev/null; then
    fail qdelaunay_installed "qdelaunay not found (Debian package qhull-bin)"; summary; exit 1
fi

# N distinct x values and N distinct y values in [0, 2^24), paired at random.
make_points() { # N SEED FILE
    python3 - "$@" <<'PY'
import random, sys
n, seed, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
r = random.Random(seed)
xs = r.sample(range(1 << 24), n)
ys = r.sample(range(1 << 24), n)
with open(out, "w") as f:
    f.write("".join(f"{x} {y}\n" for x, y in zip(xs, ys)))
PY
}

# qdelaunay "Qt i" output -> canonical triangles.
normalise() { # POINTS QHULL_OUT
    python3 - "$@" <<'PY'
import sys
pts = [tuple(map(int, l.split())) for l in open(sys.argv[1]) if l.strip()]
lines = open(sys.argv[2]).read().split("\n")
m = int(lines[0])
tris = []
for l in lines[1:1 + m]:
    a, b, c = map(int, l.split())
    (ax, ay), (bx, by), (cx, cy) = pts[a], pts[b], pts[c]
    if (bx - ax) * (cy - ay) - (by - ay) * (cx - ax) < 0:
        b, c = c, b
    while a > b or a > c:
        a, b, c = b, c, a
    tris.append((a, b, c))
tris.sort()
sys.stdout.write("".join(f"{a} {b} {c}\n" for a, b, c in tris))
PY
}

for n in ${NS:-10000 100000}; do
    make_points "$n" "$n" "p$n.txt"
    { echo 2; echo "$n"; cat "p$n.txt"; } > "p$n.qh"
    qdelaunay Qt i < "p$n.qh" > "q$n.raw" 2> "q$n.err" || { fail "qhull_$n" "qdelaunay failed: $(head -3 "q$n.err")"; continue; }
    normalise "p$n.txt" "q$n.raw" > "q$n.tri"
    "$PDT" triangulate "p$n.txt" -o "d$n.tri" 2> "d$n.err" || { fail "qhull_$n" "pdt failed: $(cat "d$n.err")"; continue; }
    if cmp -s "q$n.tri" "d$n.tri" && [ "$(wc -l < "d$n.tri")" -gt $((n * 19 / 10)) ]; then
        ok "equal_to_qdelaunay_$n"
    else
        fail "equal_to_qdelaunay_$n" "pdt $(wc -l < "d$n.tri") triangles, qdelaunay $(wc -l < "q$n.tri"); first difference: $(diff "q$n.tri" "d$n.tri" | head -3 | tr '\n' ' ')"
    fi
done
summary
