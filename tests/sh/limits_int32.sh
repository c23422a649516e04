#!/bin/bash
# The limits: inputs using the full int32 range triangulate exactly (checked
# by the independent `pdt check`), sequentially and under mpirun with 2 and
# 3 ranks (byte-identical), and what lies beyond the limits is refused with
# a message naming the file and line (exit status 2, no output file).
# Regression test for the README's "Limits" section.
# san: yes
source "$(dirname "$0")/lib.sh"
cd "$TMP"
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:fast_unwind_on_malloc=0"
export OMPI_MCA_mca_base_component_disable_dlclose=1 PMIX_MCA_mca_base_component_disable_dlclose=1

# full-range inputs (python3: deterministic, seed fixed)
python3 - <<'PY'
import random
lo, hi = -2**31, 2**31 - 1
r = random.Random(31)
def save(name, pts):
    with open(name, "w") as f:
        for x, y in pts:
            assert lo <= x <= hi and lo <= y <= hi
            f.write(f"{x} {y}\n")
# the four corners, the axis ends, uniform over the whole square
pts = [(lo, lo), (lo, hi), (hi, lo), (hi, hi), (0, lo), (0, hi), (lo, 0), (hi, 0), (0, 0)]
pts += [(r.randint(lo, hi), r.randint(lo, hi)) for _ in range(1500)]
save("uniform.txt", pts)
# clusters a few units from each corner: huge, nearly equal lifted heights
pts = []
for cx, cy in [(lo, lo), (lo, hi), (hi, lo), (hi, hi)]:
    sx = 1 if cx == lo else -1
    sy = 1 if cy == lo else -1
    pts += [(cx + sx * r.randint(0, 40), cy + sy * r.randint(0, 40)) for _ in range(120)]
save("corners.txt", pts)
# a 5x5 grid spanning the range: every cell's 4 corners are cocircular (ties)
step = 2**30 - 1
save("grid.txt", [(lo + i * step, lo + j * step) for i in range(5) for j in range(5)])
# nearly collinear: the diagonal, each point pushed off by at most 1
pts = [(lo + k * 4294967, lo + k * 4294967 + r.randint(-1, 1)) for k in range(1000)]
save("diagonal.txt", pts)
PY

for f in uniform corners grid diagonal; do
    if "$PDT" triangulate $f.txt -o $f.tri 2>$f.err && [ -s $f.tri ]; then
        if "$PDT" check $f.txt $f.tri >$f.chk 2>&1; then ok "full_range_${f}_is_delaunay"
        else fail "full_range_${f}_is_delaunay" "$(head -3 $f.chk)"; fi
    else fail "full_range_${f}_triangulates" "$(cat $f.err)"; fi
done
# the grid: 16 cells, 2 triangles each, whatever the tie rule picks
[ "$(wc -l <grid.tri)" -eq 32 ] && ok full_range_grid_count || fail full_range_grid_count "$(wc -l <grid.tri)"

if command -v mpirun >/dev/null; then
    for np in 2 3; do
        if mpirun -np $np "$PDT" triangulate uniform.txt -o par$np.tri >par$np.err 2>&1 &&
           cmp -s par$np.tri uniform.tri; then ok "full_range_mpi_${np}_ranks_identical"
        else fail "full_range_mpi_${np}_ranks_identical" "$(tail -2 par$np.err)"; fi
    done
else fail mpirun_available "mpirun not found"; fi

# beyond the limits: exit 2, the file and line named, no output left behind
beyond() { # NAME CONTENT FILE_NAME EXPECTED_MESSAGE
    printf "$2" >"$3"
    rm -f out.tri
    "$PDT" triangulate "$3" -o out.tri 2>b.err
    local rc=$?
    if [ "$rc" -eq 2 ] && grep -qF "$4" b.err && [ ! -e out.tri ]; then ok "$1"
    else fail "$1" "exit $rc: $(cat b.err)"; fi
}
beyond x_above_int32 '0 0\n1 1\n2147483648 5\n' big.txt 'big.txt:3: coordinate 2147483648 does not fit in 32 bits'
beyond y_below_int32 '0 0\n1 -2147483649\n' big.txt 'big.txt:2: coordinate -2147483649 does not fit in 32 bits'
beyond huge_number '99999999999999999999999 0\n' big.txt "big.txt:1: coordinate 99999999999999999999999 does not fit in 32 bits"
printf '0 0\n1073741824 0\n' >big.txt; rm -f out.tri
if ! "$PDT" triangulate big.txt --scale 2 -o out.tri 2>b.err && grep -qF 'big.txt:2: coordinate 1073741824 times scale 2 does not fit in 32 bits' b.err && [ ! -e out.tri ]
then ok scaled_beyond_with_scale; else fail scaled_beyond_with_scale "$(cat b.err)"; fi
# more than 2^32 - 1 points announced by a .node header (line 1, not line 2)
beyond node_header_too_many_points '4294967295 2 0 0\n0 1 1\n' many.node 'many.node:1: too many points (at most 4294967294)'
summary
