/* pdt — Dwyer's alternating cuts for the Delaunay kernel, all made before
 * any edge exists (dt_int.h lists the kernel's files).
 *
 * The root splits the lexicographically sorted points at the median index
 * (a vertical cut); the levels below alternate between horizontal and
 * vertical cuts at the median, so the sub-problems stay roughly square and
 * the merges delete few edges (about a fifth of the in-circle tests of
 * vertical cuts only, on uniform points).  Cost: a selection per horizontal
 * cut, expected linear.
 *
 * With adaptive cuts (pdt_dt_cut_order's ax: the merges' kernels) a node
 * keeps the alternation unless its points spread more than twice as wide
 * one way as the other, and then cuts across the wider spread
 * (spread_frame): down to DT_SPREAD_MIN points, a thin band is cut across,
 * not along its length.
 *
 * A node splits its points at the median of its own frame (dt_frame_key):
 * frame 0 is the lexicographic (x, y) order, frame 1 the same order after
 * the rotation (x, y) -> (y, -x).  Rotations keep orient and in-circle signs
 * (and SoS depends only on the fixed lexicographic ranks), so the
 * Guibas–Stolfi merge runs unchanged in either frame; only "leftmost" and
 * "rightmost" are taken in the node's frame (dt_kernel.c). */
#include "dt_int.h"

#include <string.h>

/* The value of rank k among the distinct keys v[0, n) (v is reordered).
 * Quickselect with the median of three pseudo-random elements as pivot: the
 * expected time is O(n) for every input (the expectation is over the
 * generator, which is seeded from n, so runs are reproducible).  The split
 * is branch-free (Lomuto with an unconditional swap): on keys in random
 * order a branching split mispredicts about every other comparison. */
static uint64_t kth_key(uint64_t *v, size_t n, size_t k)
{
    uint64_t rs = n * UINT64_C(0x9e3779b97f4a7c15) + 1;
    size_t lo = 0, hi = n;
    while (hi - lo > 2) {
        size_t w = hi - lo, r[3];
        for (int q = 0; q < 3; q++) {
            rs ^= rs << 13;
            rs ^= rs >> 7;
            rs ^= rs << 17;
            r[q] = lo + (size_t)(((unsigned __int128)rs * w) >> 64); /* in [0, w): no division */
        }
        /* the median of the three, by conditional moves */
        uint64_t a = v[r[0]], b = v[r[1]], c = v[r[2]];
        uint64_t mn = a < b ? a : b, mx = a < b ? b : a;
        uint64_t piv = mx < c ? mx : c;
        piv = piv < mn ? mn : piv;
        size_t m = piv == a ? r[0] : r[1];
        m = piv == c ? r[2] : m;
        v[m] = v[lo];
        v[lo] = piv;
        /* [lo + 1, lt) < piv, [lt, i) > piv (the keys are distinct) */
        size_t lt = lo + 1;
        for (size_t i = lo + 1; i < hi; i++) {
            uint64_t x = v[i];
            v[i] = v[lt];
            v[lt] = x;
            lt += x < piv;
        }
        size_t p = lt - 1; /* piv's place */
        v[lo] = v[p];
        v[p] = piv;
        if (k == p) return piv;
        if (k < p) hi = p;
        else lo = p + 1;
    }
    if (hi - lo == 2 && v[lo] > v[lo + 1]) {
        uint64_t t = v[lo];
        v[lo] = v[lo + 1];
        v[lo + 1] = t;
    }
    return v[k];
}

/* ---- the cut tree, computed before any edge exists ----
 * The recursion's splits depend only on the points, so they are all made
 * first: afterwards id[0, n) lists the points in the order of the leaves
 * (every node's points form one contiguous range, each leaf sorted in its
 * frame).  The kernel then runs on a copy of the points in that order, so a
 * sub-problem touches one contiguous block of points, and its edges, made
 * while it runs, one contiguous block of edge records. */

typedef struct cutter {
    pdt_point *q;         /* the points, permuted along with id */
    uint32_t *id;
    uint64_t *k, *ks;     /* scratch: frame-1 keys, twice */
    uint32_t *tp;         /* scratch: the upper part of a split (ids) */
    pdt_point *tq;        /* scratch: the upper part of a split (points) */
    uint8_t *ax;          /* each node's frame (adaptive cuts), or NULL */
} cutter;

/* The frame-1 key of rank t among the keys of q[0, m) (the value with exactly
 * t keys below it), found from a sample: two sample keys a <= b that bracket
 * rank t with high probability, one pass that counts the keys below a and
 * gathers those in [a, b] (a few percent), a selection among those.  When
 * the bracket misses (rare; any input only costs the fallback), a selection
 * over all m keys.  The pass is branch-free: the old selection over all keys
 * mispredicted about every other comparison. */
static uint64_t frame1_rank(const cutter *c, const pdt_point *q, size_t m, size_t t)
{
    uint64_t *k = c->k, *smp = c->ks;
    if (m < 2048) {
        for (size_t i = 0; i < m; i++) k[i] = dt_frame_key(q[i], 1);
        return kth_key(k, m, t);
    }
    size_t S = 4;
    while (S * S < 16 * m && S < 8192) S *= 2; /* ~ 4 sqrt(m), at most 8192 */
    for (size_t j = 0; j < S; j++) smp[j] = dt_frame_key(q[(2 * j + 1) * m / (2 * S)], 1);
    size_t r = (size_t)((double)t * (double)S / (double)m), delta = 2;
    while (delta * delta < 3 * S) delta++; /* ~ 1.7 sqrt(S): over 3 standard deviations */
    size_t rlo = r > delta ? r - delta : 0, rhi = r + delta < S ? r + delta : S - 1;
    uint64_t a = kth_key(smp, S, rlo);
    uint64_t b = kth_key(smp + rlo, S - rlo, rhi - rlo); /* smp[rlo, S) >= a */
    size_t below = 0, nm = 0;
    uint64_t w = b - a;
    for (size_t i = 0; i < m; i++) {
        uint64_t x = dt_frame_key(q[i], 1);
        below += x < a;
        k[nm] = x;
        nm += x - a <= w;
    }
    if (below <= t && t < below + nm) return kth_key(k, nm, t - below);
    for (size_t i = 0; i < m; i++) k[i] = dt_frame_key(q[i], 1);
    return kth_key(k, m, t);
}

/* Split [lo, hi) (in frame-0 order) at the frame-1 median: the mid - lo
 * frame-1 smallest points first; both parts stay in frame-0 order (a stable
 * partition, branch-free), so frame-0 nodes never need a selection. */
static void split_frame1(const cutter *c, uint32_t lo, uint32_t hi, uint32_t mid)
{
    size_t m = hi - lo;
    uint32_t *id = c->id + lo;
    pdt_point *q = c->q + lo;
    uint64_t piv = frame1_rank(c, q, m, mid - lo); /* the smallest key of the upper part */
    size_t a = 0, b = 0;
    for (size_t i = 0; i < m; i++) {
        uint32_t v = id[i];
        pdt_point p = q[i];
        size_t lt = dt_frame_key(p, 1) < piv;
        id[a] = v;
        q[a] = p;
        c->tp[b] = v;
        c->tq[b] = p;
        a += lt;
        b += 1 - lt;
    }
    memcpy(id + a, c->tp, b * sizeof *c->tp);
    memcpy(q + a, c->tq, b * sizeof *c->tq);
}

/* Sort [lo, hi) (at most 3 points) in frame `axis`. */
static void sort_small(const cutter *c, uint32_t lo, uint32_t hi, int axis)
{
    uint32_t *id = c->id;
    pdt_point *q = c->q;
    for (uint32_t i = lo + 1; i < hi; i++) {
        uint32_t v = id[i], j = i;
        pdt_point pv = q[i];
        uint64_t kv = dt_frame_key(pv, axis);
        while (j > lo && dt_frame_key(q[j - 1], axis) > kv) {
            id[j] = id[j - 1];
            q[j] = q[j - 1];
            j--;
        }
        id[j] = v;
        q[j] = pv;
    }
}

/* The frame of a node [lo, hi) of DT_SPREAD_MIN points or more (in frame-0
 * order) with adaptive cuts: `alt`, the alternation's, unless one of its
 * points' spreads is more than twice the other, then across that one.  A
 * spread is the distance between the quartiles, in x exact (the order is by
 * x), in y from 16 of its points evenly spaced in x; not the box: the
 * border set of a merge is a thin band along a seam and a few hull vertices
 * far from it, whose box is square.  Cut along its length, a band gives
 * merges whose seams run its whole length (some twice the in-circle tests
 * of cuts across it); on square inputs the alternation stands. */
static int spread_frame(const pdt_point *q, uint32_t lo, uint32_t hi, int alt)
{
    uint32_t n = hi - lo;
    int64_t x = (int64_t)q[lo + 3 * n / 4].x - q[lo + n / 4].x;
    int32_t y[16];
    for (uint32_t j = 0; j < 16; j++) {
        int32_t v = q[lo + (2 * j + 1) * n / 32].y;
        uint32_t i = j;
        for (; i > 0 && y[i - 1] > v; i--) y[i] = y[i - 1];
        y[i] = v;
    }
    int64_t yq = (int64_t)y[12] - y[4];
    return yq > 2 * x ? 1 : x > 2 * yq ? 0 : alt;
}

/* The cuts of node [lo, hi) in frame `axis` and of all nodes below it. */
static void cut_node(const cutter *c, uint32_t lo, uint32_t hi, int axis)
{
    uint32_t n = hi - lo;
    if (c->ax && n >= 2) c->ax[dt_node_at(lo, hi)] = (uint8_t)axis;
    if (n <= 3) {
        sort_small(c, lo, hi, axis);
        return;
    }
    uint32_t mid = lo + n / 2;
    /* invariant: id[lo, hi) is in frame-0 order */
    if (axis == 1) split_frame1(c, lo, hi, mid);
    int la = 1 - axis, ra = 1 - axis;
    if (c->ax && mid - lo >= DT_SPREAD_MIN) la = spread_frame(c->q, lo, mid, la);
    if (c->ax && hi - mid >= DT_SPREAD_MIN) ra = spread_frame(c->q, mid, hi, ra);
    cut_node(c, lo, mid, la);
    cut_node(c, mid, hi, ra);
}

void pdt_dt_cut_order(pdt_point *q, uint32_t *id, size_t n, void *scratch, int axis,
                      uint8_t *ax)
{
    cutter c = { q, id, scratch, NULL, NULL, NULL, ax };
    c.ks = c.k + n;
    c.tp = (uint32_t *)(void *)(c.ks + n);
    c.tq = (pdt_point *)(void *)(c.tp + n);
    cut_node(&c, 0, (uint32_t)n, axis);
}
