#!/usr/bin/env python3
"""pdt — a scaling PROJECTION (not a measurement) for P up to 1024 ranks and
n up to 10^9 points, computed from the per-phase costs of one measured run.

Usage: pdt triangulate IN -o OUT --stats 2> run.json   (under mpirun -np P, P >= 2)
       scripts/projection.py run.json [--alpha SECONDS] [--beta BYTES_PER_S]

Model (docs/parallel.md; the merge tree and border sets of
docs/algorithm.md §3.5 and §3.10), for uniform points:
  * each rank holds m = n/P points; read, partition, order and write cost a
    measured time per point of the rank's share (the slowest rank's phase
    time / its share), the local kernel a measured time per m*log2(m);
  * the merge tree has L = ceil(log2 P) levels; a seam's border set is
    |B| = k*sqrt(n) (k fitted to the measured largest border set: a seam is
    a line through the whole square, whatever P), a merge costs a measured
    time of 2x the local kernel's cost per |B|*log2|B| (the kernel on B plus
    ship, select and hull merge: the factor 2 is assumed; the measured
    merge phase is not used, as it includes waiting for the partner rank);
    the critical path takes one merge per level;
  * each seam is merged once (ceil(P/2^(l+1)) seams at level l, P-1 in all)
    and ships points and triangles near it: bytes per seam = b*sqrt(n), b
    fitted to the measured merge bytes (§3.10: 16 bytes a border point, 12 a
    shipped triangle, |B| ~ sqrt(n) for uniform points);
  * every collective adds latency alpha*log2(P) (assumed, default 20 us) and
    the partition's all-to-all sends 16*m bytes per rank at beta bytes/s
    (assumed, default 1e9) — neither measured here (one machine, no network).
Use a run of at least 10^6 points: below that, fixed costs (MPI start-up,
collective latency) swamp the per-point costs and the fit overstates them.
Critical path = read + partition + local + L merges + order + write + latency.
It ignores load imbalance, memory bandwidth limits and I/O contention."""
import json
import math
import sys

PHASES = ("read", "partition", "local", "merge", "order", "write")


def measured(j):
    par = j["parallel"]
    ranks = par["per_rank"]
    P = par["ranks"]
    n = par["unique"] or par["n"]
    native = all(isinstance(r.get("seconds"), dict) for r in ranks)
    ph = dict.fromkeys(PHASES, 0.0)
    for q, r in enumerate(ranks):
        if native:
            sec = r["seconds"]
        else:  # older builds: rank 0 read and wrote everything, order = gather
            top = j.get("seconds", {})
            sec = {"read": top.get("read", 0.0) / P if q == 0 else 0.0,
                   "partition": r["partition_s"], "local": r["local_s"],
                   "merge": r["merge_s"], "order": r["gather_s"],
                   "write": top.get("write", 0.0) / P if q == 0 else 0.0}
        for k in PHASES:
            ph[k] = max(ph[k], float(sec.get(k, 0.0)))
    return P, n, ph, par, native


def main(argv):
    args = [a for a in argv[1:] if not a.startswith("--")]
    opts = dict(a[2:].split("=", 1) for a in argv[1:] if a.startswith("--") and "=" in a)
    if len(args) != 1:
        print(__doc__, file=sys.stderr)
        return 2
    alpha = float(opts.get("alpha", 20e-6))
    beta = float(opts.get("beta", 1e9))
    text = open(args[0]).read()
    j = json.loads(text[text.index("{"):])
    P0, n0, ph, par, native = measured(j)
    if P0 < 2:
        print("projection: need a run with at least 2 ranks (a merge to measure)", file=sys.stderr)
        return 2
    m0 = n0 / P0
    per_point = {k: ph[k] / m0 for k in ("read", "partition", "order", "write")}
    c_local = ph["local"] / (m0 * math.log2(m0))
    B0 = max(par["largest_border_set"], 3)
    k_b = B0 / math.sqrt(n0)
    L0 = math.ceil(math.log2(P0))
    c_merge = 2 * c_local
    seams0 = sum(math.ceil(P0 / 2 ** (l + 1)) for l in range(L0))
    b_seam = par["merge_bytes"] / seams0 / math.sqrt(n0)

    print("PROJECTION — computed from one measured run, not measured at these sizes")
    print(f"measured: P = {P0}, n = {n0:,}: " + ", ".join(f"{k} {ph[k]:.3f} s" for k in PHASES)
          + f" (slowest rank each); largest border set {B0:,}; merge bytes {par['merge_bytes']:,}")
    if not native:
        print("  (this build's --stats has no per_rank[].seconds: read/write are rank 0's,")
        print("   divided by P as if every rank read its share; order = the gather to rank 0)")
    print(f"fitted: local {c_local * 1e9:.1f} ns per m*log2(m); |B| = {k_b:.2f}*sqrt(n); "
          f"merge (2x local) {c_merge * 1e9:.1f} ns per |B|*log2|B|; {b_seam:.1f}*sqrt(n) bytes per seam")
    print(f"assumed: latency alpha = {alpha * 1e6:.0f} us per collective step, partition bandwidth "
          f"beta = {beta / 1e9:.1f} GB/s per rank")
    print()
    print("| n | P | critical path s | speedup vs P=1 | merge levels | |B| per seam | merge bytes | merge/input | largest phase |")
    print("|---|---|---|---|---|---|---|---|---|")
    for n in (10**6, 10**7, 10**8, 10**9):
        t1 = None
        for P in [2 ** e for e in range(11)]:
            m = n / P
            L = math.ceil(math.log2(P)) if P > 1 else 0
            B = k_b * math.sqrt(n)
            t = {k: per_point[k] * m for k in per_point}
            t["local"] = c_local * m * math.log2(max(m, 2))
            t["merge"] = L * c_merge * B * math.log2(B) if L else 0.0
            t["partition"] += (16 * m / beta if P > 1 else 0.0)
            lat = alpha * 8 * math.log2(P) if P > 1 else 0.0  # ~8 collectives on the path
            total = sum(t.values()) + lat
            if t1 is None:
                t1 = total
            seams = sum(math.ceil(P / 2 ** (l + 1)) for l in range(L))
            mb = seams * b_seam * math.sqrt(n)
            top = max(t, key=t.get)
            thin = " (strips thinner than 4|B|: outside the model)" if m < 4 * B else ""
            print(f"| {n:.0e} | {P} | {total:.3f} | {t1 / total:.1f} | {L} | {B:,.0f} | "
                  f"{mb:,.0f} | {100 * mb / (8 * n):.3f}% | {top}{thin} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
