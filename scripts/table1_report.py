#!/usr/bin/env python3
"""pdt — the figures of `make table1` (scripts/table1.sh) from its runs.

Usage: table1_report.py DIR CORES "SIZES" "PS"
DIR holds LABEL.runs files (lines "wall_seconds stats.json [system_seconds
[steal_seconds]]"), LABEL = seq-N (the plain run), pP-N (mpirun -np P) or
ceilP-N (the ceiling, "wall_seconds - [system_seconds [steal_seconds]]")."""
import json
import statistics
import sys

PHASES = ("read", "partition", "local", "merge", "order", "write")


def load(w, label):
    rows = []
    for line in open(f"{w}/{label}.runs"):
        wall, path = line.split()[:2]
        text = open(path).read()
        rows.append((float(wall), json.loads(text[text.index("{"):])))
    return rows


def sys_col(w, label):
    """The median system seconds of LABEL's runs ("" when not recorded)."""
    vals = []
    for line in open(f"{w}/{label}.runs"):
        f = line.split()
        if len(f) >= 3:
            vals.append(float(f[2]))
    return f"{statistics.median(vals):.2f}" if vals else ""


STEAL_OK = 0.05  # seconds stolen by the host that a run may lose and still count as clean


def steal_col(w, label):
    """The CPU seconds stolen by the host during LABEL's runs: the largest, and
    how many runs lost more than STEAL_OK ("" when not recorded)."""
    vals = []
    for line in open(f"{w}/{label}.runs"):
        f = line.split()
        if len(f) >= 4:
            vals.append(float(f[3]))
    if not vals:
        return ""
    hit = sum(v > STEAL_OK for v in vals)
    return f"{max(vals):.2f}" + (f" ({hit} of {len(vals)})" if hit else "")


def clean_walls(w, label):
    """The walls of LABEL's runs that lost at most STEAL_OK s to the host, and
    how many runs there were (None when steal was not recorded)."""
    walls, total = [], 0
    for line in open(f"{w}/{label}.runs"):
        f = line.split()
        if len(f) < 4:
            return None
        total += 1
        if float(f[3]) <= STEAL_OK:
            walls.append(float(f[0]))
    return walls, total


def rank_phases(j):
    """{phase: seconds, max over ranks}, and whether the per-rank seconds were there."""
    par = j.get("parallel") or {}
    ranks = par.get("per_rank") or []
    native = bool(ranks) and all(isinstance(r.get("seconds"), dict) for r in ranks)
    out = dict.fromkeys(PHASES, 0.0)
    for q, r in enumerate(ranks):
        if native:
            sec = r["seconds"]
        else:  # older builds: rank 0 read and wrote, "gather" was the order phase
            top = j.get("seconds", {})
            sec = {"read": top.get("read", 0.0) if q == 0 else 0.0,
                   "partition": r.get("partition_s", 0.0), "local": r.get("local_s", 0.0),
                   "merge": r.get("merge_s", 0.0), "order": r.get("gather_s", 0.0),
                   "write": top.get("write", 0.0) if q == 0 else 0.0}
        for k in PHASES:
            out[k] = max(out[k], float(sec.get(k, 0.0)))
    return out, native


def peak_kib(j):
    ranks = (j.get("parallel") or {}).get("per_rank") or []
    vals = [r.get("peak_rss_kib", 0) for r in ranks] or [j.get("peak_rss_kib", 0)]
    return max(vals)


def main():
    w, cores, sizes, ps = sys.argv[1], int(sys.argv[2]), sys.argv[3].split(), sys.argv[4].split()
    med = statistics.median
    hdr = ("n", "run", "wall s", "speedup") + tuple(f"{k} s" for k in PHASES) + ("sys s", "steal s", "")
    print("| " + " | ".join(hdr) + " |")
    print("|" + "|".join("---" for _ in hdr) + "|")
    all_native = True
    extra = []
    for n in sizes:
        seq = load(w, f"seq-{n}")
        seq_wall = med([wall for wall, _ in seq])
        s = [j.get("seconds", {}) for _, j in seq]
        seq_read = med([x.get("read", 0.0) for x in s])
        seq_write = med([x.get("write", 0.0) for x in s])
        seq_peak = med([j.get("peak_rss_kib", 0) for _, j in seq])
        plain = [("plain", f"seq-{n}", seq)]
        try:
            plain.append(("plain, whole kernel (PDT_PLAIN_STRIPS=0)", f"whole-{n}",
                          load(w, f"whole-{n}")))
        except (OSError, ValueError):
            pass
        walls = {label: med([wall for wall, _ in rows]) for _, label, rows in plain}
        ref = min(walls.values())  # speedups against the faster plain run
        peaks = {}
        for name, label, rows in plain:
            s = [j.get("seconds", {}) for _, j in rows]
            rd = med([x.get("read", 0.0) for x in s])
            wr = med([x.get("write", 0.0) for x in s])
            peaks[name] = med([j.get("peak_rss_kib", 0) for _, j in rows])
            print(f"| {int(n):,} | {name} | {walls[label]:.3f} | {ref / walls[label]:.2f} | {rd:.3f} | | "
                  f"{walls[label] - rd - wr:.3f}† | | | {wr:.3f} | {sys_col(w, label)} | "
                  f"{steal_col(w, label)} | |")
        seq_wall = ref
        for p in ps:
            runs = load(w, f"p{p}-{n}")
            wall = med([wall for wall, _ in runs])
            ph = [rank_phases(j) for _, j in runs]
            all_native = all_native and all(nat for _, nat in ph)
            cols = " | ".join(f"{med([x[k] for x, _ in ph]):.3f}" for k in PHASES)
            mark = "* P > cores" if int(p) > cores else ""
            print(f"| {int(n):,} | mpirun -np {p} | {wall:.3f} | {seq_wall / wall:.2f} | {cols} | "
                  f"{sys_col(w, f'p{p}-{n}')} | {steal_col(w, f'p{p}-{n}')} | {mark} |")
        for p in ps:
            try:
                walls = [float(line.split()[0]) for line in open(f"{w}/ceil{p}-{n}.runs")]
            except OSError:
                continue
            sysc = sys_col(w, f"ceil{p}-{n}") + " | " + steal_col(w, f"ceil{p}-{n}")
            wall = med(walls)
            blank = " | ".join("" for _ in PHASES)
            print(f"| {int(n):,} | ceiling: {p} plain runs on n/{p} at once | {wall:.3f} | "
                  f"{seq_wall / wall:.2f} | {blank} | {sysc} | ‡ |")
        big = max(ps, key=int)
        j = load(w, f"p{big}-{n}")[0][1]["parallel"]
        rel = 100 * j["merge_bytes_rel_input"]
        line = f"n = {int(n):,}: merge traffic at P = {big}: {j['merge_bytes']:,} bytes = {rel:.3f}% of the input"
        if "2" in ps:
            p2 = med([peak_kib(j) for _, j in load(w, f"p2-{n}")])
            line += (f"; peak memory, largest rank at P = 2: {p2:,.0f} KiB vs plain {seq_peak:,.0f} KiB"
                     f" = {p2 / seq_peak:.2f}x" if seq_peak else "")
            whole = peaks.get("plain, whole kernel (PDT_PLAIN_STRIPS=0)")
            if whole:
                line += f" (whole kernel {whole:,.0f} KiB = {p2 / whole:.2f}x)"
        extra.append(line)
        # the same speedups from the runs the host took (almost) nothing from
        clean = []
        base = [clean_walls(w, label) for _, label, _ in plain]
        base = [b for b in base if b and b[0]]
        if base and len(base) == len(plain):
            ref_clean = min(med(b[0]) for b in base)
            for p in ps:
                c = clean_walls(w, f"p{p}-{n}")
                if c is None:
                    continue
                if c[0]:
                    clean.append(f"P = {p} {med(c[0]):.3f} s = {ref_clean / med(c[0]):.2f}x "
                                 f"({len(c[0])} of {c[1]} runs)")
                else:
                    clean.append(f"P = {p} none of {c[1]} runs")
        if clean:
            extra.append(f"n = {int(n):,}, runs that lost at most {STEAL_OK} s to the host only: plain "
                         f"{ref_clean:.3f} s; " + "; ".join(clean))
    print()
    for line in extra:
        print(line)
    print()
    print("wall = the whole command (MPI start-up, read, compute, write); speedup = plain wall / wall,")
    print("the plain run being the faster of the two plain rows (default: from 2^21 points two strips")
    print("one after the other, 62 bytes per point; PDT_PLAIN_STRIPS=0: the whole kernel, 84).")
    print("A plain run prints its output on one thread per CPU (PDT_WRITE_THREADS; a rank prints")
    print("its own block on its one CPU), so on this machine its write phase uses both cores, as")
    print("do the ceiling's runs.")
    print("sys = the command's system CPU seconds (all its processes), median: memory the VM has")
    print("handed back to its host costs about 1.25 s per GiB on first touch (0.05 s when it was in")
    print("use a moment before), and the wall with it; MEMSTATE (printed above) says which state")
    print("each command started in.  steal = CPU seconds the host took from this VM during a")
    print("command (/proc/stat): the largest over the runs, and how many lost more than 0.05 s;")
    print("such a run of two ranks can take twice its time (the lines above give the medians of")
    print("the runs that lost at most 0.05 s, and their speedups).  The runs go in rounds (plain, each")
    print("P, each ceiling, again).")
    print("Phases: seconds, the largest over the ranks, median over the runs.  † plain run:")
    print("everything between read and write (sort, kernel, canonical order).")
    print("‡ ceiling: P plain runs started together, each on a consecutive n/P of the input's")
    print("lines; wall until the last ends.  What P processes can do on this machine with no")
    print("communication, merge or canonical order at all: the speedup a P-rank run could reach.")
    if not all_native:
        print("(This build's --stats has no per_rank[].seconds: read and write are rank 0's,")
        print(" \"order\" is the gather to rank 0.)")


if __name__ == "__main__":
    main()
