#!/bin/bash
# make bench, section "big": 10^7 uniform points triangulated with the plain
# run (P = 1) and under mpirun with P = 2, and a full-int32-range input of
# 10^6 points triangulated and verified by `pdt check`.  Prints wall time and
# peak memory from /usr/bin/time -v (for P = 2: each rank's peak, and their
# sum as an upper bound of the job's peak), and bytes of peak memory per
# input point.  One run each (these take minutes); override the sizes with
# BIG_N=... FULL_N=... .  Inputs are cached in build/bench/big/.
set -u
cd "$(dirname "$0")/../.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
PDT=$PWD/bin/pdt
N=${BIG_N:-10000000}
FULL=${FULL_N:-1000000}
W=build/bench/big
mkdir -p "$W"
[ -x /usr/bin/time ] || { echo "big: /usr/bin/time missing (Debian package 'time'), skipped"; exit 0; }

# field NAME FILE: a value from /usr/bin/time -v output
field() { sed -n "s/^[[:space:]]*$1: //p" "$2" | head -1; }
secs() { # "h:mm:ss" or "m:ss.ss" -> seconds
    echo "$1" | awk -F: '{ s = 0; for (i = 1; i <= NF; i++) s = s * 60 + $i; printf "%.2f", s }'
}
report() { # LABEL N WALL_S PEAK_KB [note]
    awk -v l="$1" -v n="$2" -v w="$3" -v kb="$4" -v note="${5:-}" 'BEGIN {
        printf "%-34s n=%-9d wall %8.2f s   peak %8.1f MiB   %6.1f bytes/point %s\n",
               l, n, w, kb / 1024, kb * 1024 / n, note }'
}

in=$W/uniform-$N.txt
[ -s "$in" ] || "$PDT" gen uniform "$N" --seed 1 -o "$in" || exit 1

# P = 1: the plain sequential run (no MPI)
/usr/bin/time -v -o "$W/p1.time" "$PDT" triangulate "$in" -o "$W/p1.tri" || exit 1
report "uniform, P=1 (plain run)" "$N" "$(secs "$(field 'Elapsed (wall clock) time (h:mm:ss or m:ss)' "$W/p1.time")")" \
    "$(field 'Maximum resident set size (kbytes)' "$W/p1.time")"

# P = 2 under mpirun: time each rank, and the whole job
if command -v mpirun >/dev/null; then
    rm -f "$W"/p2.rank*.time
    /usr/bin/time -v -o "$W/p2.time" mpirun -np 2 sh -c \
        '/usr/bin/time -v -o "$0.rank$OMPI_COMM_WORLD_RANK.time" "$@"' "$W/p2" \
        "$PDT" triangulate "$in" -o "$W/p2.tri" || exit 1
    wall=$(secs "$(field 'Elapsed (wall clock) time (h:mm:ss or m:ss)' "$W/p2.time")")
    r0=$(field 'Maximum resident set size (kbytes)' "$W/p2.rank0.time")
    r1=$(field 'Maximum resident set size (kbytes)' "$W/p2.rank1.time")
    report "uniform, P=2 rank 0" "$N" "$wall" "$r0"
    report "uniform, P=2 rank 1" "$N" "$wall" "$r1"
    report "uniform, P=2 both ranks (sum)" "$N" "$wall" $((r0 + r1))
    if cmp -s "$W/p1.tri" "$W/p2.tri"; then echo "P=2 output identical to P=1 ($(wc -l <"$W/p1.tri") triangles)"
    else echo "big: P=2 output DIFFERS from P=1"; exit 1; fi
else
    echo "big: mpirun not found, P=2 skipped"
fi

# full int32 range: coordinates uniform over [-2^31, 2^31 - 1], corners included
fin=$W/fullrange-$FULL.txt
if [ ! -s "$fin" ]; then
    python3 - "$FULL" "$fin" <<'PY' || exit 1
import random, sys
n, out = int(sys.argv[1]), sys.argv[2]
lo, hi = -2**31, 2**31 - 1
r = random.Random(1)
with open(out, "w") as f:
    for p in [(lo, lo), (lo, hi), (hi, lo), (hi, hi)]:
        f.write("%d %d\n" % p)
    f.write("".join("%d %d\n" % (r.randint(lo, hi), r.randint(lo, hi)) for _ in range(n - 4)))
PY
fi
/usr/bin/time -v -o "$W/full.time" "$PDT" triangulate "$fin" -o "$W/full.tri" || exit 1
report "full int32 range, P=1" "$FULL" "$(secs "$(field 'Elapsed (wall clock) time (h:mm:ss or m:ss)' "$W/full.time")")" \
    "$(field 'Maximum resident set size (kbytes)' "$W/full.time")"
/usr/bin/time -v -o "$W/check.time" "$PDT" check "$fin" "$W/full.tri" >"$W/check.out" 2>&1
rc=$?
report "  pdt check of it" "$FULL" "$(secs "$(field 'Elapsed (wall clock) time (h:mm:ss or m:ss)' "$W/check.time")")" \
    "$(field 'Maximum resident set size (kbytes)' "$W/check.time")" "-> $(head -1 "$W/check.out")"
exit $rc
