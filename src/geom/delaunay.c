/* pdt — the sequential Delaunay kernel: Guibas–Stolfi divide and conquer
 * with Dwyer's alternating cuts, with the exact pdt_orient and the
 * simulation-of-simplicity pdt_incircle_sos for every in-circle decision, so
 * the result is T*(P) (docs/algorithm.md §2.3) — the projection of the lower hull
 * of the (perturbed) lifted points.
 *
 * Cuts: the root splits the lexicographically sorted points at the median
 * index (a vertical cut); the levels below alternate between horizontal and
 * vertical cuts at the median, so the sub-problems stay roughly square and
 * the merges delete few edges (on 10^6 uniform points: 7.9 M in-circle tests
 * instead of 35.7 M with vertical cuts only, 36 % less time).  Cost: a
 * selection per horizontal cut (expected linear) and a walk around both
 * child hulls per merge (linear in the hull sizes), so O(n log n) expected on
 * every input; the merges themselves are O(n log n) in the worst case.
 *
 * Order in memory: all cuts are made first (cut_order), the points are
 * copied in the order of the leaves, and the recursion then runs on that
 * copy, so every sub-problem is one contiguous block of points, and the edges
 * it makes one contiguous block of edge records: the caches see the
 * recursion's locality instead of the lexicographic order's.
 *
 * Edge structure: one flat array of 12-byte records {org, onext, oprev}
 * indexed by directed edge (no per-edge malloc).  Edge e and its twin e ^ 1
 * form an undirected edge; org is the origin, onext / oprev the next /
 * previous edge counter-clockwise around org (a doubly linked ring: the
 * primal half of a quad-edge, with the dual's work done by oprev).
 * Identities used: sym(e) = e ^ 1, lnext(e) = oprev(sym e), rprev(e) =
 * onext(sym e), lprev(e) = sym(onext e).
 *
 * Memory: at most 3n undirected edges are alive at any time (the union of the
 * sub-triangulations plus the cross edges is planar), freed edges are
 * reused, so 12 bytes per directed edge, ~72 bytes per point.  The triangle
 * list is written over the edge records once the merge is done, so it costs
 * no extra memory. */
#include "pdt/delaunay.h"

#include "pdt/predicates.h"

#include "pdt/bigmem.h"
#include "pred_inline.h"

#include <stdlib.h>
#include <string.h>

#define NIL UINT32_MAX

/* One directed edge: 12 bytes, e and its twin e ^ 1 side by side, so the
 * three fields an operation reads share a cache line. */
typedef struct edge {
    uint32_t org, onext, oprev;
} edge;

typedef struct dt {
    const pdt_point *p; /* the points in leaf order (see cut_order) */
    edge *e;
    size_t cap;   /* directed edges allocated */
    size_t used;  /* directed edges ever handed out (even) */
    uint32_t freelist; /* a free even edge, chained through onext, or NIL */
    pdt_trace *tr;
    int nomem;
    int small; /* every coordinate difference < 2^30: the int64 predicates */
} dt;

static inline uint32_t sym(uint32_t e)
{
    return e ^ 1u;
}

static inline uint32_t org(const dt *d, uint32_t e)
{
    return d->e[e].org;
}

static inline uint32_t onext(const dt *d, uint32_t e)
{
    return d->e[e].onext;
}

static inline uint32_t oprev(const dt *d, uint32_t e)
{
    return d->e[e].oprev;
}

static inline uint32_t dest(const dt *d, uint32_t e)
{
    return d->e[e ^ 1u].org;
}

static inline uint32_t lnext(const dt *d, uint32_t e)
{
    return d->e[e ^ 1u].oprev;
}

static inline uint32_t rprev(const dt *d, uint32_t e)
{
    return d->e[e ^ 1u].onext;
}

/* A new isolated edge a -> b; returns NIL when out of memory (the array is
 * sized for the planar bound up front, so that never happens in practice). */
static uint32_t make_edge(dt *d, uint32_t a, uint32_t b)
{
    /* a free edge if there is one, else the next new one; chosen with
     * conditional moves (whether the list is empty changes often) */
    uint32_t fl = d->freelist;
    int reuse = fl != NIL;
    if (d->used + 2 > d->cap && !reuse) {
        d->nomem = 1;
        return NIL;
    }
    uint32_t keep = 0u - (uint32_t)reuse; /* all ones to reuse (masks: gcc branched) */
    uint32_t e = (fl & keep) | ((uint32_t)d->used & ~keep);
    uint32_t next = d->e[e].onext; /* (a record below cap either way) */
    d->freelist = (next & keep) | (NIL & ~keep);
    d->used += 2u & ~keep;
    d->e[e] = (edge){ a, e, e };
    d->e[e ^ 1] = (edge){ b, e ^ 1, e ^ 1 };
    PDT_TRACE(d->tr, 2, PDT_EV_EDGE_ADD, 0, PDT_TRACE_PT(d->tr, a), PDT_TRACE_PT(d->tr, b), 0, 0);
    return e;
}

/* Guibas–Stolfi splice, primal part: exchange onext of a and b. */
static inline void splice(dt *d, uint32_t a, uint32_t b)
{
    uint32_t an = d->e[a].onext, bn = d->e[b].onext;
    d->e[a].onext = bn;
    d->e[b].onext = an;
    d->e[bn].oprev = a;
    d->e[an].oprev = b;
}

/* New edge from dest(a) to org(b), left faces of a, e, b the same. */
static uint32_t connect(dt *d, uint32_t a, uint32_t b)
{
    uint32_t e = make_edge(d, dest(d, a), org(d, b));
    if (e == NIL) return NIL;
    splice(d, e, lnext(d, a));
    splice(d, sym(e), b);
    return e;
}

static void delete_edge(dt *d, uint32_t e)
{
    PDT_TRACE(d->tr, 2, PDT_EV_EDGE_DEL, 0, PDT_TRACE_PT(d->tr, org(d, e)),
              PDT_TRACE_PT(d->tr, dest(d, e)), 0, 0);
    splice(d, e, oprev(d, e));
    splice(d, sym(e), oprev(d, sym(e)));
    e &= ~1u;
    d->e[e].org = d->e[e ^ 1].org = NIL;
    d->e[e].onext = d->freelist;
    d->freelist = e;
}

static inline int ccw(const dt *d, uint32_t a, uint32_t b, uint32_t c)
{
    if (d->small) return pdt_orient_small(d->p[a], d->p[b], d->p[c]) > 0;
    return pdt_orient_fast(d->p[a], d->p[b], d->p[c]) > 0;
}

/* x strictly right of edge e (i.e. x, dest e, org e counter-clockwise) */
static inline int right_of(const dt *d, uint32_t x, uint32_t e)
{
    return ccw(d, x, dest(d, e), org(d, e));
}

static inline int left_of(const dt *d, uint32_t x, uint32_t e)
{
    return ccw(d, x, org(d, e), dest(d, e));
}

/* d strictly inside the circle of counter-clockwise a, b, c, ties by SoS */
static inline int in_circle(const dt *d, uint32_t a, uint32_t b, uint32_t c, uint32_t q)
{
    pdt_point pa = d->p[a], pb = d->p[b], pc = d->p[c], pq = d->p[q];
    int s = d->small ? pdt_incircle0_small(pa, pb, pc, pq) : pdt_incircle0_fast(pa, pb, pc, pq);
    if (s == 0) s = pdt_incircle_ties(pa, pb, pc, pq);
    return s > 0;
}

/* ---- Dwyer's alternating cuts ----
 * A node splits its points at the median of its own frame: frame 0 is the
 * lexicographic (x, y) order, frame 1 the same order after the rotation
 * (x, y) -> (y, -x), i.e. by y, then by decreasing x.  Rotations keep orient
 * and in-circle signs (and SoS depends only on the fixed lexicographic
 * ranks), so the Guibas–Stolfi merge runs unchanged in either frame; only
 * "leftmost" and "rightmost" are taken in the node's frame. */

static inline uint64_t frame_key(pdt_point p, int axis)
{
    if (!axis) return pdt_key(p);
    return ((uint64_t)((uint32_t)p.y ^ 0x80000000u) << 32) |
           (uint64_t)(~((uint32_t)p.x ^ 0x80000000u));
}

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
        for (size_t i = 0; i < m; i++) k[i] = frame_key(q[i], 1);
        return kth_key(k, m, t);
    }
    size_t S = 4;
    while (S * S < 16 * m && S < 8192) S *= 2; /* ~ 4 sqrt(m), at most 8192 */
    for (size_t j = 0; j < S; j++) smp[j] = frame_key(q[(2 * j + 1) * m / (2 * S)], 1);
    size_t r = (size_t)((double)t * (double)S / (double)m), delta = 2;
    while (delta * delta < 3 * S) delta++; /* ~ 1.7 sqrt(S): over 3 standard deviations */
    size_t rlo = r > delta ? r - delta : 0, rhi = r + delta < S ? r + delta : S - 1;
    uint64_t a = kth_key(smp, S, rlo);
    uint64_t b = kth_key(smp + rlo, S - rlo, rhi - rlo); /* smp[rlo, S) >= a */
    size_t below = 0, nm = 0;
    uint64_t w = b - a;
    for (size_t i = 0; i < m; i++) {
        uint64_t x = frame_key(q[i], 1);
        below += x < a;
        k[nm] = x;
        nm += x - a <= w;
    }
    if (below <= t && t < below + nm) return kth_key(k, nm, t - below);
    for (size_t i = 0; i < m; i++) k[i] = frame_key(q[i], 1);
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
        size_t lt = frame_key(p, 1) < piv;
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
        uint64_t kv = frame_key(pv, axis);
        while (j > lo && frame_key(q[j - 1], axis) > kv) {
            id[j] = id[j - 1];
            q[j] = q[j - 1];
            j--;
        }
        id[j] = v;
        q[j] = pv;
    }
}

/* The cuts of node [lo, hi) in frame `axis` and of all nodes below it. */
static void cut_order(const cutter *c, uint32_t lo, uint32_t hi, int axis)
{
    uint32_t n = hi - lo;
    if (n <= 3) {
        sort_small(c, lo, hi, axis);
        return;
    }
    uint32_t mid = lo + n / 2;
    /* invariant: id[lo, hi) is in frame-0 order */
    if (axis == 1) split_frame1(c, lo, hi, mid);
    cut_order(c, lo, mid, 1 - axis);
    cut_order(c, mid, hi, 1 - axis);
}

/* Walk the hull from any hull edge e (counter-clockwise walk: e <- rprev e)
 * and return the counter-clockwise hull edge out of the frame-smallest vertex
 * and the clockwise hull edge out of the frame-largest one. */
static void frame_extremes(const dt *d, uint32_t e0, int axis, uint32_t *le, uint32_t *re)
{
    /* edges e_0 = e0, e_i+1 = rprev(e_i); the edge into org(e_i) is e_i-1.
     * The smallest and the largest so far are kept with conditional moves
     * (a branch on them mispredicted often on short hulls). */
    uint64_t k0 = frame_key(d->p[org(d, e0)], axis);
    uint64_t klo = k0, khi = k0;
    uint32_t lo_e = e0, hi_in = NIL; /* NIL: the largest is org(e0) */
    uint32_t prev = e0, e = rprev(d, e0);
    while (e != e0) {
        uint64_t k = frame_key(d->p[org(d, e)], axis);
        int lt = k < klo, gt = k > khi;
        klo = lt ? k : klo;
        lo_e = lt ? e : lo_e;
        khi = gt ? k : khi;
        hi_in = gt ? prev : hi_in;
        prev = e;
        e = rprev(d, e);
    }
    if (hi_in == NIL) hi_in = prev; /* the last edge walked leads into org(e0) */
    *le = lo_e;
    *re = sym(hi_in);
}

/* Guibas–Stolfi merge of two triangulations given by their frame extremes:
 * ldo / rdo counter-clockwise / clockwise hull edges out of the outer
 * extremes, ldi / rdi clockwise / counter-clockwise out of the inner ones. */
static int merge(dt *d, uint32_t ldo, uint32_t ldi, uint32_t rdi, uint32_t rdo, uint32_t *le,
                 uint32_t *re)
{
    /* lower common tangent */
    for (;;) {
        if (left_of(d, org(d, rdi), ldi))
            ldi = lnext(d, ldi);
        else if (right_of(d, org(d, ldi), rdi))
            rdi = rprev(d, rdi);
        else
            break;
    }
    uint32_t basel = connect(d, sym(rdi), ldi);
    if (basel == NIL) return 0;
    if (org(d, ldi) == org(d, ldo)) ldo = sym(basel);
    if (org(d, rdi) == org(d, rdo)) rdo = basel;

    /* the rising bubble */
    for (;;) {
        uint32_t bo = org(d, basel), bd = dest(d, basel);
        uint32_t lcand = onext(d, sym(basel));
        int lvalid = right_of(d, dest(d, lcand), basel);
        if (lvalid) {
            for (;;) {
                uint32_t nx = onext(d, lcand);
                if (nx == sym(basel) || !in_circle(d, bd, bo, dest(d, lcand), dest(d, nx))) break;
                delete_edge(d, lcand);
                lcand = nx;
            }
        }
        uint32_t rcand = oprev(d, basel);
        int rvalid = right_of(d, dest(d, rcand), basel);
        if (rvalid) {
            for (;;) {
                uint32_t nx = oprev(d, rcand);
                if (nx == basel || !in_circle(d, bd, bo, dest(d, rcand), dest(d, nx))) break;
                delete_edge(d, rcand);
                rcand = nx;
            }
        }
        if (!lvalid && !rvalid) break;
        if (!lvalid ||
            (rvalid && in_circle(d, dest(d, lcand), org(d, lcand), org(d, rcand), dest(d, rcand))))
            basel = connect(d, rcand, sym(basel));
        else
            basel = connect(d, sym(basel), sym(lcand));
        if (basel == NIL) return 0;
    }
    *le = ldo;
    *re = rdo;
    return 1;
}

/* Triangulate the points [lo, hi) (hi - lo >= 2, in leaf order: the cuts are
 * made), the node cutting at the median of frame `axis`.  *le: counter-
 * clockwise hull edge out of the frame-smallest point; *re: clockwise hull
 * edge out of the frame-largest point.  Returns 0 when out of memory. */
static int build(dt *d, uint32_t lo, uint32_t hi, int axis, uint32_t *le, uint32_t *re)
{
    uint32_t n = hi - lo;
    if (n <= 3) { /* sorted in frame `axis` by cut_order */
        uint32_t s1 = lo, s2 = lo + 1;
        uint32_t a = make_edge(d, s1, s2);
        if (a == NIL) return 0;
        if (n == 2) {
            *le = a;
            *re = sym(a);
            return 1;
        }
        uint32_t s3 = lo + 2;
        uint32_t b = make_edge(d, s2, s3);
        if (b == NIL) return 0;
        splice(d, sym(a), b);
        int o = pdt_orient_fast(d->p[s1], d->p[s2], d->p[s3]);
        if (o > 0) {
            if (connect(d, b, a) == NIL) return 0;
            *le = a;
            *re = sym(b);
        } else if (o < 0) {
            uint32_t c = connect(d, b, a);
            if (c == NIL) return 0;
            *le = sym(c);
            *re = c;
        } else {
            *le = a;
            *re = sym(b);
        }
        return 1;
    }
    uint32_t mid = lo + n / 2;
    uint32_t ldo, ldi, rdi, rdo;
    if (!build(d, lo, mid, 1 - axis, &ldo, &ldi) || !build(d, mid, hi, 1 - axis, &rdi, &rdo))
        return 0;
    /* the children answered in the other frame: find this frame's extremes */
    frame_extremes(d, ldo, axis, &ldo, &ldi);
    frame_extremes(d, rdi, axis, &rdi, &rdo);
    return merge(d, ldo, ldi, rdi, rdo, le, re);
}

/* Collect the counter-clockwise triangles: the left face of every directed
 * edge e is (org e, dest e, dest lnext e), reported at its smallest edge, so
 * every face is seen once, in the order of its smallest edge; the outer face
 * (clockwise around the hull) fails the orientation test.  lnext(e) =
 * oprev(sym e) lies in the record beside e's, and the record of sym(lnext e)
 * holds both dest(lnext e) and lnext(lnext e): one record out of place per
 * edge, fetched PF_AHEAD edge pairs ahead (the walk was bound by those
 * misses).  Branch-free: both faces of a pair are tested and written, and
 * the count moves on only for the reported ones (whether a face is reported
 * is random: a branch on it mispredicted about once a face).  Edges go by
 * pairs (e, sym e), every record read before a triangle is written:
 * triangle k is written over edge record k, and k <= the current pair's
 * second edge.  Vertices are written as id[v].  Returns the number of
 * triangles. */
enum { PF_AHEAD = 16 };

/* The triangles, written over the edge records as they are read, named
 * id[v] (or v when id is NULL: the caller specializes both, inlined). */
static inline __attribute__((always_inline)) size_t collect(dt *d, const uint32_t *id,
                                                             const uint32_t *tid, int run)
{
    pdt_trace *tr = d->tr;
    const edge *r = d->e;
    const pdt_point *p = d->p;
    pdt_tri *out = (pdt_tri *)(void *)d->e; /* 12 bytes each, like an edge */
    size_t nt = 0, used = d->used;
    for (size_t e = 0; e < used; e += 2) {
        if (e + 2 * PF_AHEAD < used) {
            __builtin_prefetch(&r[r[e + 2 * PF_AHEAD + 1].oprev ^ 1u]);
            __builtin_prefetch(&r[r[e + 2 * PF_AHEAD].oprev ^ 1u]);
        }
        edge f = r[e], g = r[e + 1]; /* e and sym e */
        if (f.org == NIL) continue;  /* a deleted edge (both halves) */
        /* the left face of e: lnext e = g.oprev; of sym e: lnext = f.oprev;
         * h: the record of sym(lnext), org = dest(lnext), oprev = lnext(lnext) */
        edge h0 = r[g.oprev ^ 1u], h1 = r[f.oprev ^ 1u];
        pdt_point pf = p[f.org], pg = p[g.org];
        int c0 = (g.oprev > e) & (h0.oprev > e) & (pdt_orient_fast(pf, pg, p[h0.org]) > 0);
        int c1 = (f.oprev > e + 1) & (h1.oprev > e + 1) &
                 (pdt_orient_fast(pg, pf, p[h1.org]) > 0);
        uint32_t fi = id ? id[f.org] : f.org, gi = id ? id[g.org] : g.org;
        out[nt] = (pdt_tri){{fi, gi, id ? id[h0.org] : h0.org}};
        if (PDT_TRACING(tr, 1) && c0)
            PDT_TRACE(tr, 1, PDT_EV_TRI_NEW, run, tid[f.org], tid[g.org], tid[h0.org], 0);
        nt += (size_t)c0;
        out[nt] = (pdt_tri){{gi, fi, id ? id[h1.org] : h1.org}};
        if (PDT_TRACING(tr, 1) && c1)
            PDT_TRACE(tr, 1, PDT_EV_TRI_NEW, run, tid[g.org], tid[f.org], tid[h1.org], 0);
        nt += (size_t)c1;
    }
    return nt;
}

/* The convex hull from the triangulation's outer face, before the triangles
 * are written over the edges: the walk e <- rprev e from le (the
 * counter-clockwise hull edge out of the lexicographically smallest point)
 * goes around the hull counter-clockwise; every boundary point is a vertex
 * of the outer face, the collinear ones included.  *hull (malloc'd) names
 * them as id[v]; on a line the walk goes out and back (more than n steps)
 * and nothing is given (id NULL: the vertices themselves).  Returns 0 when
 * out of memory. */
static int outer_hull(const dt *d, uint32_t le, size_t n, const uint32_t *id, uint32_t **hull,
                      size_t *nhull)
{
    size_t k = 0;
    uint32_t e = le;
    do {
        if (++k > n) return 1; /* collinear */
        e = rprev(d, e);
    } while (e != le);
    uint32_t *h = malloc(k * sizeof *h);
    if (!h) return 0;
    for (size_t i = 0; i < k; i++, e = rprev(d, e)) h[i] = id ? id[org(d, e)] : org(d, e);
    *hull = h;
    *nhull = k;
    return 1;
}

/* The kernel on q[0, n) (distinct, sorted), moved to its leaf order along
 * with id; the triangles (and the hull) named id[v], or the vertex v itself
 * when by_vertex. */
static pdt_status kernel_on(uint32_t *id, pdt_point *q, size_t n, edge *e, size_t cap,
                            size_t *ntri, int run, pdt_trace *tr, uint32_t **hull, size_t *nhull,
                            int by_vertex)
{
    *ntri = 0;
    dt d;
    memset(&d, 0, sizeof d);
    d.freelist = NIL;
    d.e = e;
    d.cap = cap; /* at most 3n undirected edges alive */
    int32_t minx = INT32_MAX, maxx = INT32_MIN, miny = INT32_MAX, maxy = INT32_MIN;
    for (size_t i = 0; i < n; i++) {
        pdt_point v = q[i];
        minx = v.x < minx ? v.x : minx;
        maxx = v.x > maxx ? v.x : maxx;
        miny = v.y < miny ? v.y : miny;
        maxy = v.y > maxy ? v.y : maxy;
    }
    d.small = (int64_t)maxx - minx < (INT64_C(1) << 30) && (int64_t)maxy - miny < (INT64_C(1) << 30);
    /* the cuts, on the points moved along with their ids (scratch: 7 words
     * per point, in the edge array before any edge exists) */
    cutter c = { q, id, (uint64_t *)(void *)d.e, NULL, NULL, NULL };
    c.ks = c.k + n;
    c.tp = (uint32_t *)(void *)(c.ks + n);
    c.tq = (pdt_point *)(void *)(c.tp + n);
    /* the first cut across the longer side of the points' box (then the
     * sides alternate): a strip taller than wide is cut first by y, so that
     * no merge seam runs its whole height; traced runs keep the x cut first
     * (their events are the lessons') */
    int axis = !tr && (int64_t)maxy - miny > (int64_t)maxx - minx ? 1 : 0;
    cut_order(&c, 0, (uint32_t)n, axis);
    d.p = q;

    /* kernel vertex v is point id[v]; the trace names it tr->gid[id[v]] */
    pdt_trace ktr;
    uint32_t *tid = id, *tmap = NULL;
    if (tr) {
        if (tr->gid) {
            tmap = malloc(n * sizeof *tmap);
            if (!tmap) return PDT_ERR_NOMEM;
            for (size_t i = 0; i < n; i++) tmap[i] = tr->gid[id[i]];
            tid = tmap;
        }
        ktr = *tr;
        ktr.gid = tid;
        d.tr = &ktr;
    }
    uint32_t le, re;
    int ok = build(&d, 0, (uint32_t)n, axis, &le, &re);
    if (ok && axis) frame_extremes(&d, le, 0, &le, &re); /* (the x frame's extremes) */
    if (ok && hull && n >= 3) ok = outer_hull(&d, le, n, by_vertex ? NULL : id, hull, nhull);
    if (ok) *ntri = by_vertex ? collect(&d, NULL, tid, run) : collect(&d, id, tid, run);
    free(tmap);
    return ok ? PDT_OK : PDT_ERR_NOMEM;
}

/* Edge records for the kernel on n points (the planar bound and a margin). */
static size_t edge_cap(size_t n)
{
    return 6 * n + 12;
}

pdt_status pdt_delaunay(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri, int run,
                        pdt_trace *tr)
{
    *tris = NULL;
    *ntri = 0;
    if (n < 2) return PDT_OK;
    if (n > PDT_KERNEL_MAX_POINTS) return PDT_ERR_ARG;
    for (size_t i = 1; i < n; i++) /* the precondition: distinct and sorted */
        if (pdt_key(pts[i - 1]) >= pdt_key(pts[i])) return PDT_ERR_ARG;
    size_t cap = edge_cap(n);
    uint32_t *id = malloc(n * sizeof *id);
    pdt_point *q = pdt_big_alloc(n * sizeof *q);
    edge *e = malloc(cap * sizeof *e); /* becomes the triangle array */
    if (!id || !q || !e) {
        free(id);
        pdt_big_free(q, n * sizeof *q);
        free(e);
        return PDT_ERR_NOMEM;
    }
    pdt_big_advise(e, cap * sizeof *e);
    for (uint32_t i = 0; i < (uint32_t)n; i++) id[i] = i;
    memcpy(q, pts, n * sizeof *q);
    size_t nt = 0;
    pdt_status s = kernel_on(id, q, n, e, cap, &nt, run, tr, NULL, NULL, 0);
    free(id);
    pdt_big_free(q, n * sizeof *q);
    if (s != PDT_OK || nt == 0) {
        free(e);
        return s;
    }
    pdt_tri *shrunk = realloc(e, nt * sizeof *shrunk);
    *tris = shrunk ? shrunk : (pdt_tri *)(void *)e;
    *ntri = nt;
    return PDT_OK;
}

/* The contract of the kernels on the caller's memory: not too many points,
 * work_bytes >= PDT_DELAUNAY_WORK(n), the points distinct and sorted. */
static int on_args_ok(const pdt_point *pts, size_t n, size_t work_bytes)
{
    if (n > PDT_KERNEL_MAX_POINTS || work_bytes < PDT_DELAUNAY_WORK(n)) return 0;
    for (size_t i = 1; i < n; i++)
        if (pdt_key(pts[i - 1]) >= pdt_key(pts[i])) return 0;
    return 1;
}

/* The kernel on the caller's memory, with no copy of the points: they are
 * the kernel's (leaf-order) array during the call and are put back from
 * id afterwards, through scratch in work beyond the triangles (8 bytes per
 * point; the triangles take at most 24 of the 72). */
pdt_status pdt_delaunay_hull_on(pdt_point *pts, size_t n, uint32_t *id, void *work,
                                size_t work_bytes, size_t *ntri, uint32_t **hull, size_t *nhull,
                                int run, pdt_trace *tr)
{
    *ntri = 0;
    if (hull) {
        *hull = NULL;
        *nhull = 0;
    }
    if (n < 2) return PDT_OK;
    if (!on_args_ok(pts, n, work_bytes)) return PDT_ERR_ARG;
    for (uint32_t i = 0; i < (uint32_t)n; i++) id[i] = i;
    size_t nt = 0;
    pdt_status s = kernel_on(id, pts, n, (edge *)work, edge_cap(n), &nt, run, tr, hull, nhull, 0);
    pdt_point *tmp = (pdt_point *)(void *)((pdt_tri *)work + (s == PDT_OK ? nt : 0));
    memcpy(tmp, pts, n * sizeof *tmp);
    for (size_t v = 0; v < n; v++) pts[id[v]] = tmp[v];
    if (s == PDT_OK) *ntri = nt;
    if (hull && (s != PDT_OK || nt == 0)) { /* (none on a line) */
        free(*hull);
        *hull = NULL;
        *nhull = 0;
    }
    return s;
}

pdt_status pdt_delaunay_on(pdt_point *pts, size_t n, uint32_t *id, void *work, size_t work_bytes,
                           size_t *ntri, int run, pdt_trace *tr)
{
    return pdt_delaunay_hull_on(pts, n, id, work, work_bytes, ntri, NULL, NULL, run, tr);
}

/* A point and its name, for putting a strip back in order (below). */
typedef struct named_pt {
    pdt_point p;
    uint32_t name;
} named_pt;

static int named_cmp(const void *a, const void *b)
{
    uint64_t ka = pdt_key(((const named_pt *)a)->p), kb = pdt_key(((const named_pt *)b)->p);
    return ka < kb ? -1 : ka > kb;
}

/* The kernel without putting the points back: the caller reads the
 * triangles against the leaf order, which is the order they come out in
 * (the restore was a random scatter of every point, and the caller's pass
 * over the triangles then read the points out of order).  Only a strip with
 * no hull (a line, or fewer than 3 points) is put back in order, by a sort:
 * the caller runs its own chain on it. */
pdt_status pdt_delaunay_strip(pdt_point *pts, size_t n, uint32_t *name, void *work,
                              size_t work_bytes, size_t *ntri, uint32_t **hull, size_t *nhull)
{
    *ntri = 0;
    *hull = NULL;
    *nhull = 0;
    if (n < 2) return PDT_OK;
    if (!on_args_ok(pts, n, work_bytes)) return PDT_ERR_ARG;
    size_t nt = 0;
    pdt_status s = kernel_on(name, pts, n, (edge *)work, edge_cap(n), &nt, 0, NULL, hull, nhull, 1);
    if (s == PDT_OK && *hull && nt > 0) {
        *ntri = nt;
        return PDT_OK;
    }
    free(*hull);
    *hull = NULL;
    *nhull = 0;
    named_pt *tmp = work; /* no triangle to keep: 12 of the 72 bytes per point */
    for (size_t i = 0; i < n; i++) tmp[i] = (named_pt){pts[i], name[i]};
    qsort(tmp, n, sizeof *tmp, named_cmp);
    for (size_t i = 0; i < n; i++) {
        pts[i] = tmp[i].p;
        name[i] = tmp[i].name;
    }
    return s;
}

/* ---- canonical order ---- */

static int tri_cmp(const pdt_tri *a, const pdt_tri *b)
{
    for (int k = 0; k < 3; k++)
        if (a->v[k] != b->v[k]) return a->v[k] < b->v[k] ? -1 : 1;
    return 0;
}

static int tri_qcmp(const void *a, const void *b)
{
    return tri_cmp(a, b);
}

/* Rotate t to start at its smallest index, branch-free (which corner is
 * the smallest is random: a branch on it mispredicted every other
 * triangle). */
static void tri_rotate(pdt_tri *t)
{
    uint32_t a = t->v[0], b = t->v[1], c = t->v[2];
    uint32_t w[5] = {a, b, c, a, b};
    unsigned r = (unsigned)((b < a) & (b < c)) + 2u * (unsigned)((c < a) & (c < b));
    t->v[0] = w[r];
    t->v[1] = w[r + 1];
    t->v[2] = w[r + 2];
}

/* a before b in the canonical order */
static inline int tri_less(const pdt_tri *a, const pdt_tri *b)
{
    uint64_t ka = (uint64_t)a->v[0] << 32 | a->v[1], kb = (uint64_t)b->v[0] << 32 | b->v[1];
    return ka < kb || (ka == kb && a->v[2] < b->v[2]);
}

/* Sort tris[lo, hi), all with the same first index, by (v[1], v[2]):
 * insertion sort for short runs, qsort for long ones (a vertex of huge degree
 * must not make this quadratic). */
static void sort_run(pdt_tri *t, size_t lo, size_t hi)
{
    if (hi - lo > 32) {
        qsort(t + lo, hi - lo, sizeof *t, tri_qcmp);
        return;
    }
    for (size_t i = lo + 1; i < hi; i++) {
        pdt_tri v = t[i];
        size_t j = i;
        while (j > lo && tri_cmp(&t[j - 1], &v) > 0) {
            t[j] = t[j - 1];
            j--;
        }
        t[j] = v;
    }
}

/* t[lo, hi) is in order by first index: put each run of one first index in
 * order by the other two.  One insertion pass over the whole range (a
 * triangle moves only within its run; runs are two triangles long on
 * average, so a check per triangle and few moves, where finding each run's
 * end first mispredicted once a run); when the moves pass 8 per triangle (a
 * vertex of huge degree), the rest goes run by run with sort_run. */
static void order_first_runs(pdt_tri *t, size_t lo, size_t hi)
{
    size_t budget = 8 * (hi - lo) + 64;
    for (size_t i = lo + 1; i < hi; i++) {
        if (!tri_less(&t[i], &t[i - 1])) continue;
        pdt_tri v = t[i];
        size_t j = i;
        do {
            t[j] = t[j - 1];
            j--;
        } while (j > lo && tri_less(&v, &t[j - 1]));
        t[j] = v;
        if (i - j >= budget) {
            for (size_t a = lo; a < hi;) {
                size_t b = a + 1;
                while (b < hi && t[b].v[0] == t[a].v[0]) b++;
                if (b - a > 1) sort_run(t, a, b);
                a = b;
            }
            return;
        }
        budget -= i - j;
    }
}

/* One bucket of first indices [base, base + nlo) whose triangles lie in ns
 * places seg[k][0, len[k]) and have been counted by first index into
 * lc[v - base + 1] (lc: nlo + 1 counters): written to out in canonical order
 * (a counting pass by first index, then the runs of one first index by the
 * other two). */
static void bucket_place(const pdt_tri *const *seg, const size_t *len, size_t ns, uint32_t base,
                         size_t nlo, size_t *lc, pdt_tri *out)
{
    lc[0] = 0;
    for (size_t l = 1; l <= nlo; l++) lc[l] += lc[l - 1];
    for (size_t k = 0; k < ns; k++)
        for (size_t i = 0; i < len[k]; i++) out[lc[seg[k][i].v[0] - base]++] = seg[k][i];
    order_first_runs(out, 0, lc[nlo]);
}

/* The triangles are put in order by their first (smallest) index with two
 * counting passes: first by its high bits into at most 2048 buckets (2048
 * output streams: cache lines and huge pages enough for all), then each
 * bucket, now small enough for the cache, by its low bits; equal first
 * indices (two triangles per vertex on average) are then sorted by the other
 * two.  A random scatter of all triangles in one pass, as before, missed the
 * cache and the TLB on every triangle at 10^7 points. */
/* The canonical order of in[0, ntri), written to out[0, ntri) (out may be
 * in, or overlap it: in is read whole before out is written); scratch: room
 * for ntri triangles overlapping neither (NULL: allocated here). */
static void canonical(pdt_tri *in, pdt_tri *out, size_t ntri, pdt_tri *scratch)
{
    if (ntri == 0) return;
    uint32_t minv = UINT32_MAX, maxv = 0;
    for (size_t i = 0; i < ntri; i++) {
        tri_rotate(&in[i]);
        if (in[i].v[0] > maxv) maxv = in[i].v[0];
        if (in[i].v[0] < minv) minv = in[i].v[0];
    }
    uint32_t span = maxv - minv;
    int bits = 32 - __builtin_clz(span | 1u), shift = bits > 11 ? bits - 11 : 0;
    size_t nhi = ((size_t)span >> shift) + 1, nlo = (size_t)1 << shift;
    pdt_tri *tmp = ntri <= 64 ? NULL : scratch ? scratch : pdt_big_alloc(ntri * sizeof *tmp);
    size_t *hc = tmp ? calloc(nhi + 1, sizeof *hc) : NULL;
    size_t *lc = hc ? malloc((nlo + 1) * sizeof *lc) : NULL;
    if (!lc) {
        if (tmp != scratch) pdt_big_free(tmp, ntri * sizeof *tmp);
        free(hc);
        qsort(in, ntri, sizeof *in, tri_qcmp);
        if (out != in) memmove(out, in, ntri * sizeof *out);
        return;
    }
    for (size_t i = 0; i < ntri; i++) hc[((in[i].v[0] - minv) >> shift) + 1]++;
    for (size_t h = 1; h <= nhi; h++) hc[h] += hc[h - 1];
    for (size_t i = 0; i < ntri; i++) tmp[hc[(in[i].v[0] - minv) >> shift]++] = in[i];
    /* hc[h] is now the end of high bucket h */
    size_t start = 0;
    for (size_t h = 0; h < nhi; h++) {
        size_t end = hc[h];
        if (end == start) continue; /* (no counters to clear for an empty bucket) */
        const pdt_tri *seg = tmp + start;
        size_t len = end - start;
        uint32_t base = minv + ((uint32_t)h << shift);
        memset(lc, 0, (nlo + 1) * sizeof *lc);
        for (size_t i = 0; i < len; i++) lc[seg[i].v[0] - base + 1]++;
        bucket_place(&seg, &len, 1, base, nlo, lc, out + start);
        start = end;
    }
    if (tmp != scratch) pdt_big_free(tmp, ntri * sizeof *tmp);
    free(hc);
    free(lc);
}

void pdt_tri_canonical(pdt_tri *tris, size_t ntri)
{
    canonical(tris, tris, ntri, NULL);
}

void pdt_tri_canonical_on(pdt_tri *tris, size_t ntri, pdt_tri *scratch)
{
    canonical(tris, tris, ntri, scratch);
}

/* ---- the canonical order in buckets (spread over ranks) ---- */

void pdt_tri_bucket_count(pdt_tri *t, size_t n, int shift, uint64_t *hist)
{
    for (size_t i = 0; i < n; i++) {
        tri_rotate(&t[i]);
        hist[t[i].v[0] >> shift]++;
    }
}

void pdt_tri_bucket_scatter(const pdt_tri *t, size_t n, int shift, uint64_t *at, pdt_tri *dst)
{
    for (size_t i = 0; i < n; i++) dst[at[t[i].v[0] >> shift]++] = t[i];
}

void pdt_tri_bucket_scatter_round(const pdt_tri *t, size_t n, int shift, const uint8_t *in,
                                  uint64_t *at, pdt_tri *dst)
{
    for (size_t i = 0; i < n; i++) { /* (branch-free: which round is random) */
        uint32_t b = t[i].v[0] >> shift;
        uint64_t a = at[b];
        dst[a] = t[i];
        at[b] = a + in[b];
    }
}

/* Each bucket in turn, the smallest at a run's head first: its part of every
 * run found and counted by first index in one scan, then placed. */
pdt_status pdt_tri_bucket_order(const pdt_tri *const *src, const size_t *len, size_t ns, int shift,
                                pdt_tri *out)
{
    size_t nlo = (size_t)1 << shift;
    size_t *lc = malloc((nlo + 1) * sizeof *lc), *at = calloc(ns + 1, sizeof *at),
           *sl = malloc((ns + 1) * sizeof *sl);
    const pdt_tri **seg = malloc((ns + 1) * sizeof *seg);
    pdt_status st = lc && at && sl && seg ? PDT_OK : PDT_ERR_NOMEM;
    while (st == PDT_OK) {
        uint64_t b = UINT64_MAX;
        for (size_t k = 0; k < ns; k++) {
            uint64_t head = at[k] < len[k] ? src[k][at[k]].v[0] >> shift : UINT64_MAX;
            b = head < b ? head : b;
        }
        if (b == UINT64_MAX) break;
        uint32_t base = (uint32_t)(b << shift);
        memset(lc, 0, (nlo + 1) * sizeof *lc);
        for (size_t k = 0; k < ns; k++) {
            size_t e = at[k];
            for (; e < len[k] && (src[k][e].v[0] >> shift) == b; e++)
                lc[src[k][e].v[0] - base + 1]++;
            seg[k] = src[k] + at[k];
            sl[k] = e - at[k];
            at[k] = e;
        }
        bucket_place(seg, sl, ns, base, nlo, lc, out);
        out += lc[nlo];
    }
    free(lc);
    free(at);
    free(sl);
    free((void *)seg);
    return st;
}

/* ---- sort and dedupe ---- */

typedef struct keyed {
    uint64_t key;
    uint32_t idx;
} keyed;

static int bit_length(uint64_t v)
{
    return v ? 64 - __builtin_clzll(v) : 0;
}

/* Stable LSD radix sort of src[0, m) by the low `bits` bits of key, digits of
 * at most 11 bits (2048 counters: they and the output streams stay in the
 * cache); digits on which all keys agree are skipped.  The sorted records end
 * in src or dst: returns the one that holds them. */
static keyed *lsd_sort(keyed *src, keyed *dst, size_t m, int bits, size_t *cnt)
{
    if (m < 2 || bits == 0) return src;
    if (m <= 32) { /* stable insertion sort */
        for (size_t i = 1; i < m; i++) {
            keyed v = src[i];
            size_t j = i;
            while (j > 0 && src[j - 1].key > v.key) {
                src[j] = src[j - 1];
                j--;
            }
            src[j] = v;
        }
        return src;
    }
    uint64_t all_or = 0, all_and = ~UINT64_C(0);
    for (size_t i = 0; i < m; i++) {
        all_or |= src[i].key;
        all_and &= src[i].key;
    }
    int dmax = bit_length(m) - 1; /* about as many counters as records, at most 2048 */
    if (dmax > 11) dmax = 11;
    if (dmax < 4) dmax = 4;
    int passes = (bits + dmax - 1) / dmax, d = (bits + passes - 1) / passes;
    uint64_t mask = (UINT64_C(1) << d) - 1;
    for (int shift = 0; shift < bits; shift += d) {
        if ((((all_or ^ all_and) >> shift) & mask) == 0) continue;
        memset(cnt, 0, ((size_t)mask + 1) * sizeof *cnt);
        for (size_t i = 0; i < m; i++) cnt[(src[i].key >> shift) & mask]++;
        size_t sum = 0;
        for (size_t k = 0; k <= mask; k++) {
            size_t c = cnt[k];
            cnt[k] = sum;
            sum += c;
        }
        for (size_t i = 0; i < m; i++) dst[cnt[(src[i].key >> shift) & mask]++] = src[i];
        keyed *t = src;
        src = dst;
        dst = t;
    }
    return src;
}

/* lsd_sort for packed records: src[0, m) by their bits [lo, lo + bits),
 * the bits below lo (the input index) increasing within equal digits, so
 * the result is in (key, index) order.  Returns src or dst. */
static uint64_t *lsd_sort64(uint64_t *src, uint64_t *dst, size_t m, int lo, int bits, size_t *cnt)
{
    if (m < 2 || bits == 0) return src;
    if (m <= 32) { /* insertion sort on the whole word: (key, index) */
        for (size_t i = 1; i < m; i++) {
            uint64_t v = src[i];
            size_t j = i;
            while (j > 0 && src[j - 1] > v) {
                src[j] = src[j - 1];
                j--;
            }
            src[j] = v;
        }
        return src;
    }
    uint64_t all_or = 0, all_and = ~UINT64_C(0);
    for (size_t i = 0; i < m; i++) {
        all_or |= src[i];
        all_and &= src[i];
    }
    int dmax = bit_length(m) - 1;
    if (dmax > 11) dmax = 11;
    if (dmax < 4) dmax = 4;
    int passes = (bits + dmax - 1) / dmax, d = (bits + passes - 1) / passes;
    uint64_t mask = (UINT64_C(1) << d) - 1;
    for (int shift = lo; shift < lo + bits; shift += d) {
        if ((((all_or ^ all_and) >> shift) & mask) == 0) continue;
        memset(cnt, 0, ((size_t)mask + 1) * sizeof *cnt);
        for (size_t i = 0; i < m; i++) cnt[(src[i] >> shift) & mask]++;
        size_t sum = 0;
        for (size_t k = 0; k <= mask; k++) {
            size_t c = cnt[k];
            cnt[k] = sum;
            sum += c;
        }
        for (size_t i = 0; i < m; i++) dst[cnt[(src[i] >> shift) & mask]++] = src[i];
        uint64_t *t = src;
        src = dst;
        dst = t;
    }
    return src;
}

/* The points are keyed by (x - min x) * 2^by + (y - min y), which orders
 * them lexicographically with as few bits as the data need (40 for points in
 * [0, 2^20)^2).  One counting pass by the top 11 bits splits them into
 * buckets small enough for the cache (about n / 2048 points each), then each
 * bucket is finished by LSD passes in the cache.  Stable throughout, so equal
 * points stay in input order and the first is kept.  (Four passes of 16-bit
 * digits over the whole array, as before, had 65 536 output streams: far
 * past the cache and the TLB at 10^7 points.) */
/* What the sort writes: order[0, nu) the input indices of the distinct
 * points in order, each the smallest of its copies; q (NULL, or room for n
 * points): the distinct points in order, decoded from the keys (q[i] ==
 * pts[order[i]]); dup (NULL, or room for 2n words): a pair (index of a
 * copy, index kept for it) for each of the ndup copies dropped. */
typedef struct sorted {
    uint32_t *order;
    pdt_point *q;
    uint32_t *dup;
    size_t nu, ndup;
} sorted;

/* The key of p: (x - min x) * 2^by + (y - min y). */
static inline uint64_t point_key(pdt_point p, pdt_point mn, int by)
{
    return ((uint64_t)((int64_t)p.x - mn.x) << by) | (uint64_t)((int64_t)p.y - mn.y);
}

/* Write the point of key k (the inverse of point_key) as the u-th distinct
 * point, and its input index, to o. */
static inline void put_distinct(sorted *o, size_t u, uint64_t k, uint32_t idx, pdt_point mn,
                                int by)
{
    if (o->q) {
        uint64_t ymask = by ? (~UINT64_C(0) >> (64 - by)) : 0;
        o->q[u].x = (int32_t)((int64_t)(k >> by) + mn.x);
        o->q[u].y = (int32_t)((int64_t)(k & ymask) + mn.y);
    }
    o->order[u] = idx;
}

/* The sort when a key without its top hb bits and an input index fit one
 * word (shift + ib <= 64: 10^7 points of [0, 2^20)^2 need 29 + 24): the
 * counting pass by the top hb bits reads the points themselves and writes
 * words (low key bits << ib | index) into bucket order, so the records are 8
 * bytes instead of 16 and there is no key array to write first; each bucket
 * is then finished in the cache by the bits of its keys below the top. */
static void sort_packed(const pdt_point *pts, size_t n, uint64_t *a, uint64_t *b, size_t *cnt,
                        size_t *hc, sorted *o, pdt_point mn, int by, int shift, int hb, int ib)
{
    size_t nb = (size_t)1 << hb;
    uint64_t lmask = shift ? (~UINT64_C(0) >> (64 - shift)) : 0;
    uint64_t imask = ib ? (~UINT64_C(0) >> (64 - ib)) : 0;
    memset(hc, 0, (nb + 1) * sizeof *hc);
    for (size_t i = 0; i < n; i++) hc[(point_key(pts[i], mn, by) >> shift) + 1]++;
    for (size_t h = 1; h <= nb; h++) hc[h] += hc[h - 1];
    for (size_t i = 0; i < n; i++) {
        uint64_t k = point_key(pts[i], mn, by);
        b[hc[k >> shift]++] = ((k & lmask) << ib) | i;
    }
    /* hc[h] is the end of bucket h, in b */
    size_t u = 0, nd = 0, start = 0;
    uint64_t prev = 0;
    int have_prev = 0;
    for (size_t h = 0; h < nb; h++) {
        size_t end = hc[h];
        uint64_t *r = lsd_sort64(b + start, a + start, end - start, ib, shift, cnt);
        uint64_t top = (uint64_t)h << shift;
        for (size_t i = 0; i < end - start; i++) {
            uint64_t k = top | r[i] >> ib;
            uint32_t idx = (uint32_t)(r[i] & imask);
            if (!have_prev || k != prev) {
                put_distinct(o, u++, k, idx, mn, by);
            } else if (o->dup) {
                o->dup[2 * nd] = idx;
                o->dup[2 * nd + 1] = o->order[u - 1];
                nd++;
            }
            prev = k;
            have_prev = 1;
        }
        start = end;
    }
    o->nu = u;
    o->ndup = n - u;
}

/* The sort on the caller's scratch: a and b room for n records each, cnt
 * and hc 2049 counters each.  n >= 1. */
static void sort_core(const pdt_point *pts, size_t n, keyed *a, keyed *b, size_t *cnt,
                      size_t *hc, sorted *o)
{
    int32_t minx = INT32_MAX, maxx = INT32_MIN, miny = INT32_MAX, maxy = INT32_MIN;
    for (size_t i = 0; i < n; i++) {
        if (pts[i].x < minx) minx = pts[i].x;
        if (pts[i].x > maxx) maxx = pts[i].x;
        if (pts[i].y < miny) miny = pts[i].y;
        if (pts[i].y > maxy) maxy = pts[i].y;
    }
    int by = bit_length((uint64_t)((int64_t)maxy - miny));
    int bits = bit_length((uint64_t)((int64_t)maxx - minx)) + by; /* <= 64 */
    uint64_t ymask = by ? (~UINT64_C(0) >> (64 - by)) : 0;
    int hb = bits < 11 ? bits : 11, shift = bits - hb;
    size_t nb = (size_t)1 << hb;
    int ib = bit_length(n - 1); /* bits of an input index */
    if (shift + ib <= 64) {
        sort_packed(pts, n, (uint64_t *)(void *)a, (uint64_t *)(void *)b, cnt, hc, o,
                    (pdt_point){ minx, miny }, by, shift, hb, ib);
        return;
    }
    for (size_t i = 0; i < n; i++) {
        uint64_t kx = (uint64_t)((int64_t)pts[i].x - minx), ky = (uint64_t)((int64_t)pts[i].y - miny);
        a[i].key = (kx << by) | ky;
        a[i].idx = (uint32_t)i;
    }
    memset(hc, 0, (nb + 1) * sizeof *hc);
    for (size_t i = 0; i < n; i++) hc[(a[i].key >> shift) + 1]++;
    for (size_t h = 1; h <= nb; h++) hc[h] += hc[h - 1];
    for (size_t i = 0; i < n; i++) b[hc[a[i].key >> shift]++] = a[i];
    /* hc[h] is the end of bucket h, in b */
    size_t u = 0, nd = 0, start = 0;
    int have_prev = 0;
    uint64_t prev = 0;
    for (size_t h = 0; h < nb; h++) {
        size_t end = hc[h];
        keyed *r = lsd_sort(b + start, a + start, end - start, shift, cnt);
        for (size_t i = 0; i < end - start; i++) {
            if (!have_prev || r[i].key != prev) {
                if (o->q) {
                    uint64_t kx = by ? r[i].key >> by : r[i].key, ky = r[i].key & ymask;
                    o->q[u].x = (int32_t)((int64_t)kx + minx);
                    o->q[u].y = (int32_t)((int64_t)ky + miny);
                }
                o->order[u++] = r[i].idx;
            } else if (o->dup) {
                o->dup[2 * nd] = r[i].idx;
                o->dup[2 * nd + 1] = o->order[u - 1];
                nd++;
            }
            prev = r[i].key;
            have_prev = 1;
        }
        start = end;
    }
    o->nu = u;
    o->ndup = n - u;
}

pdt_status pdt_sort_unique_on(const pdt_point *pts, size_t n, void *work, uint32_t *order,
                              pdt_point *q, size_t *nu)
{
    *nu = 0;
    if (n == 0) return PDT_OK;
    if (n > UINT32_MAX) return PDT_ERR_ARG;
    _Static_assert(sizeof(keyed) == 16, "PDT_SORT_WORK counts 16 bytes a record");
    keyed *a = work, *b = a + n;
    size_t *cnt = (size_t *)(void *)(b + n), *hc = cnt + 2049;
    sorted o = { order, q, NULL, 0, 0 };
    sort_core(pts, n, a, b, cnt, hc, &o);
    *nu = o.nu;
    return PDT_OK;
}

pdt_status pdt_sort_unique(const pdt_point *pts, size_t n, uint32_t *order, size_t *nu)
{
    *nu = 0;
    if (n == 0) return PDT_OK;
    if (n > UINT32_MAX) return PDT_ERR_ARG;
    size_t bytes = PDT_SORT_WORK(n);
    void *work = pdt_big_alloc(bytes);
    if (!work) return PDT_ERR_NOMEM;
    pdt_status st = pdt_sort_unique_on(pts, n, work, order, NULL, nu);
    pdt_big_free(work, bytes);
    return st;
}

/* ---- the pipeline ---- */

/* Working memory below this is not worth a thread faulting it in. */
enum { PREFAULT_MIN = 8 << 20 };

/* Put pts back as they were: the distinct points from q (== pts[0, nu), in
 * the kernel's order, id naming them) through a copy in `scratch` (room for
 * nu points), then each dropped copy from the point kept for it. */
static void restore_points(pdt_point *pts, size_t nu, const uint32_t *id, const uint32_t *dup,
                           size_t ndup, pdt_point *scratch)
{
    memcpy(scratch, pts, nu * sizeof *pts);
    for (size_t v = 0; v < nu; v++) pts[id[v]] = scratch[v];
    for (size_t k = 0; k < ndup; k++) pts[dup[2 * k]] = pts[dup[2 * k + 1]];
}

/* Memory of the pipeline (n input points, nu distinct): one block R of
 * edge_cap(n) edge records (72 bytes per point) is the sort's scratch (two
 * key arrays, the sorted points and the copies dropped: 48 bytes per point),
 * then the kernel's cut scratch, edges and triangles, then the canonical
 * order's scratch, and at last (shrunk) the triangles returned; order (4
 * bytes per point) names the distinct points; the points themselves (8 bytes
 * per point) are the caller's array, in the kernel's order during the
 * kernel.  Peak: 84 bytes per point (92 when the kernel had its own copy of
 * the points and the sort its own scratch); every page of R is touched once
 * (the fresh-page faults were a sixth of the time at 10^7 points).  With
 * PDT_TRI_PREFAULT a second thread faults R and order in ahead of use (on
 * an idle core: docs/geometry.md, "Fresh memory"). */
pdt_status pdt_triangulate_inplace(pdt_point *pts, size_t n, int keep, pdt_tri **tris,
                                   size_t *ntri, pdt_tri_stats *stats, pdt_trace *tr)
{
    *tris = NULL;
    *ntri = 0;
    pdt_tri_stats st;
    memset(&st, 0, sizeof st);
    st.n_in = n;
    if (n > PDT_KERNEL_MAX_POINTS) return PDT_ERR_ARG;
    if (n == 0) {
        st.collinear = 1;
        if (stats) *stats = st;
        return PDT_OK;
    }

    double t0 = pdt_seconds();
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_PARTITION, 0, 0, 0, 0);
    size_t cap = edge_cap(n);
    edge *R = malloc(cap * sizeof *R);
    uint32_t *order = malloc(n * sizeof *order), *dup = NULL;
    size_t *cnt = malloc(2049 * sizeof *cnt), *hc = malloc(2049 * sizeof *hc);
    if (!R || !order || !cnt || !hc) {
        free(R);
        free(order);
        free(cnt);
        free(hc);
        return PDT_ERR_NOMEM;
    }
    pdt_big_advise(R, cap * sizeof *R);
    pdt_big_advise(order, n * sizeof *order);
    pdt_prefault *pf = NULL;
    if ((keep & PDT_TRI_PREFAULT) && cap * sizeof *R >= PREFAULT_MIN) {
        /* in the order the sort and the kernel need them: the buckets the
         * sort's counting pass writes (R[16n, 24n) bytes: the helper starts
         * there while the sort scans the points twice, then both fault it),
         * the index list, the sort's other records and points, then the
         * rest of R, where the kernel's edges grow */
        char *rb = (char *)(void *)R;
        pdt_range rr[4] = { { rb + 16 * n, 8 * n }, { order, n * sizeof *order }, { rb, 16 * n },
                            { rb + 24 * n, cap * sizeof *R - 24 * n } };
        pf = pdt_prefault_start(rr, 4);
        st.prefaulted = pf != NULL;
    }
    keyed *ka = (keyed *)(void *)R, *kb = ka + n;
    pdt_point *q = (pdt_point *)(void *)(kb + n);
    sorted so = { order, q, (uint32_t *)(void *)(q + n), 0, 0 };
    sort_core(pts, n, ka, kb, cnt, hc, &so);
    free(cnt);
    free(hc);
    size_t nu = so.nu;
    if (so.ndup && (keep & PDT_PTS_RESTORE)) {
        dup = malloc(2 * so.ndup * sizeof *dup);
        if (!dup) {
            pdt_prefault_stop(pf);
            free(R);
            free(order);
            return PDT_ERR_NOMEM;
        }
        memcpy(dup, so.dup, 2 * so.ndup * sizeof *dup);
    }
    memcpy(pts, q, nu * sizeof *pts); /* from here on pts[0, nu) are the kernel's */
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_PARTITION, 0, 0, 0, 0);
    st.n_unique = nu;
    st.n_dup = n - nu;
    double t1 = pdt_seconds();

    if (PDT_TRACING(tr, 1)) {
        PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_LIFT, 0, 0, 0, 0);
        for (size_t i = 0; i < nu; i++)
            PDT_TRACE(tr, 1, PDT_EV_LIFT, 0, PDT_TRACE_PT(tr, order[i]), 0, 0,
                      (int64_t)pdt_lift(pts[i]).z);
        PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_LIFT, 0, 0, 0, 0);
    }

    /* the kernel on the distinct points, named by their input indices:
     * triangles come out as input indices, the trace names points as before
     * (tr->gid composed) */
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_KERNEL, 0, 0, 0, 0);
    size_t nt = 0;
    pdt_status s = nu >= 2 ? kernel_on(order, pts, nu, R, cap, &nt, 0, tr, NULL, NULL, 0) : PDT_OK;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_KERNEL, 0, 0, 0, 0);
    pdt_prefault_stop(pf); /* (long done, but it must end before R shrinks) */
    double t2 = pdt_seconds();

    /* the triangles fill R[0, nt) (12 bytes each: at most 24 bytes per point);
     * the rest of R is scratch for what follows */
    pdt_tri *t = (pdt_tri *)(void *)R;
    if ((keep & PDT_PTS_RESTORE))
        restore_points(pts, nu, order, dup, so.ndup, (pdt_point *)(void *)(t + nt));
    free(order);
    free(dup);
    if (s != PDT_OK) {
        free(R);
        return s;
    }
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_OUTPUT, 0, 0, 0, 0);
    canonical(t, t, nt, t + nt);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_OUTPUT, 0, 0, 0, 0);
    if (nt == 0) {
        free(R);
        t = NULL;
    } else {
        pdt_tri *shrunk = realloc(t, nt * sizeof *shrunk);
        if (shrunk) t = shrunk;
    }
    double t3 = pdt_seconds();

    st.n_tri = nt;
    st.collinear = nt == 0;
    /* Euler (thesis D5): triangles = 2n - h - 2 for non-collinear input */
    st.n_hull = nt ? 2 * nu - 2 - nt : nu;
    st.t_sort = t1 - t0;
    st.t_kernel = t2 - t1;
    st.t_canon = t3 - t2;
    if (stats) *stats = st;
    *tris = t;
    *ntri = nt;
    return PDT_OK;
}

pdt_status pdt_triangulate(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri,
                           pdt_tri_stats *stats, pdt_trace *tr)
{
    *tris = NULL;
    *ntri = 0;
    if (n > PDT_KERNEL_MAX_POINTS) return PDT_ERR_ARG;
    pdt_point *w = pdt_big_alloc(n * sizeof *w);
    if (!w) return PDT_ERR_NOMEM;
    if (n) memcpy(w, pts, n * sizeof *w); /* (pts may be NULL when n == 0) */
    pdt_status s = pdt_triangulate_inplace(w, n, PDT_PTS_SPEND, tris, ntri, stats, tr);
    pdt_big_free(w, n * sizeof *w);
    return s;
}
