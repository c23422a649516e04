/* pdt — the sequential Delaunay kernel: Guibas–Stolfi divide and conquer
 * on Dwyer's alternating cuts (dt_cut.c), with the exact pdt_orient and the
 * simulation-of-simplicity pdt_incircle_sos for every in-circle decision, so
 * the result is T*(P) (docs/algorithm.md §2.3) — the projection of the lower hull
 * of the (perturbed) lifted points.  Cost: a walk around both child hulls
 * per merge (linear in the hull sizes) besides the merge itself, so
 * O(n log n) expected on every input, the merges O(n log n) in the worst
 * case.
 *
 * Order in memory: all cuts are made first (pdt_dt_cut_order), on the
 * points moved to the order of the leaves, and the recursion then runs on
 * that order, so every sub-problem is one contiguous block of points, and the
 * edges it makes one contiguous block of edge records: the caches see the
 * recursion's locality instead of the lexicographic order's.
 *
 * Edge structure: one flat array of 12-byte records {org, onext, oprev}
 * (dt_edge) indexed by directed edge (no per-edge malloc).  Edge e and its
 * twin e ^ 1 form an undirected edge; org is the origin, onext / oprev the
 * next / previous edge counter-clockwise around org (a doubly linked ring:
 * the primal half of a quad-edge, with the dual's work done by oprev).
 * Identities used: sym(e) = e ^ 1, lnext(e) = oprev(sym e), rprev(e) =
 * onext(sym e), lprev(e) = sym(onext e).
 *
 * Memory: at most 3n undirected edges are alive at any time (the union of the
 * sub-triangulations plus the cross edges is planar), freed edges are
 * reused, so 12 bytes per directed edge, ~72 bytes per point.  The triangle
 * list is written over the edge records once the merge is done, so it costs
 * no extra memory. */
#include "dt_int.h"

#include "pdt/predicates.h"

#include "pred_inline.h"

#include <stdlib.h>
#include <string.h>

#define NIL DT_NIL

typedef dt_edge edge;

typedef struct dt {
    const pdt_point *p; /* the points in leaf order (see pdt_dt_cut_order) */
    edge *e;
    size_t cap;   /* directed edges allocated */
    size_t used;  /* directed edges ever handed out (even) */
    uint32_t freelist; /* a free even edge, chained through onext, or NIL */
    pdt_trace *tr;
    const uint8_t *ax; /* each node's frame (pdt_dt_cut_order), or NULL: they alternate */
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

/* Walk the hull from any hull edge e (counter-clockwise walk: e <- rprev e)
 * and return the counter-clockwise hull edge out of the frame-smallest vertex
 * and the clockwise hull edge out of the frame-largest one. */
static void frame_extremes(const dt *d, uint32_t e0, int axis, uint32_t *le, uint32_t *re)
{
    /* edges e_0 = e0, e_i+1 = rprev(e_i); the edge into org(e_i) is e_i-1.
     * The smallest and the largest so far are kept with conditional moves
     * (a branch on them mispredicted often on short hulls). */
    uint64_t k0 = dt_frame_key(d->p[org(d, e0)], axis);
    uint64_t klo = k0, khi = k0;
    uint32_t lo_e = e0, hi_in = NIL; /* NIL: the largest is org(e0) */
    uint32_t prev = e0, e = rprev(d, e0);
    while (e != e0) {
        uint64_t k = dt_frame_key(d->p[org(d, e)], axis);
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
    if (n <= 3) { /* sorted in frame `axis` by pdt_dt_cut_order */
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
    int la = d->ax ? d->ax[dt_node_at(lo, mid)] : 1 - axis;
    int ra = d->ax ? d->ax[dt_node_at(mid, hi)] : 1 - axis;
    if (!build(d, lo, mid, la, &ldo, &ldi) || !build(d, mid, hi, ra, &rdi, &rdo))
        return 0;
    /* the children answered in their own frames: find this frame's extremes */
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

/* The box of q[0, n): d->small when every coordinate difference is below
 * 2^30 (the int64 predicates), and the axis of the first cut, across the
 * longer side (then the sides alternate, or follow the points' spread: see
 * pdt_dt_cut_order): a strip taller than wide is cut first by y, so that no
 * merge seam runs its whole height; traced runs keep the x cut first (their
 * events are the lessons'). */
static int dt_box(dt *d, const pdt_point *q, size_t n, int traced)
{
    int32_t minx = INT32_MAX, maxx = INT32_MIN, miny = INT32_MAX, maxy = INT32_MIN;
    for (size_t i = 0; i < n; i++) {
        pdt_point v = q[i];
        minx = v.x < minx ? v.x : minx;
        maxx = v.x > maxx ? v.x : maxx;
        miny = v.y < miny ? v.y : miny;
        maxy = v.y > maxy ? v.y : maxy;
    }
    int64_t w = (int64_t)maxx - minx, h = (int64_t)maxy - miny;
    d->small = w < (INT64_C(1) << 30) && h < (INT64_C(1) << 30);
    return !traced && h > w ? 1 : 0;
}

/* The trace of the kernel: vertex v is point id[v], which the trace names
 * tr->gid[id[v]]; *tmap (malloc'd, NULL when tr has no gid) holds that
 * composition, *tid the names the kernel's events use.  Returns 0 when out
 * of memory. */
static int dt_trace_names(dt *d, pdt_trace *tr, pdt_trace *ktr, uint32_t *id, size_t n,
                          uint32_t **tid, uint32_t **tmap)
{
    *tid = id;
    *tmap = NULL;
    if (!tr) return 1;
    if (tr->gid) {
        *tmap = malloc(n * sizeof **tmap);
        if (!*tmap) return 0;
        for (size_t i = 0; i < n; i++) (*tmap)[i] = tr->gid[id[i]];
        *tid = *tmap;
    }
    *ktr = *tr;
    ktr->gid = *tid;
    d->tr = ktr;
    return 1;
}

pdt_status pdt_dt_kernel(uint32_t *id, pdt_point *q, size_t n, edge *e, size_t cap,
                         size_t *ntri, int run, pdt_trace *tr, uint32_t **hull, size_t *nhull,
                         int flags)
{
    *ntri = 0;
    dt d;
    memset(&d, 0, sizeof d);
    d.freelist = NIL;
    d.e = e;
    d.cap = cap; /* at most 3n undirected edges alive */
    int axis = dt_box(&d, q, n, tr != NULL);
    /* the cuts, on the points moved along with their ids (scratch: 7 words
     * per point, in the edge array before any edge exists); with DT_SPREAD
     * untraced, across the points' spread (a frame a node: n bytes), else
     * (traced: the lessons' events; without memory for the frames: the
     * same triangles) alternating */
    uint8_t *ax = !tr && (flags & DT_SPREAD) ? malloc(n + 1) : NULL;
    pdt_dt_cut_order(q, id, n, e, axis, ax);
    d.ax = ax;
    d.p = q;
    pdt_trace ktr;
    uint32_t *tid, *tmap;
    if (!dt_trace_names(&d, tr, &ktr, id, n, &tid, &tmap)) {
        free(ax);
        return PDT_ERR_NOMEM;
    }
    uint32_t le, re;
    int ok = build(&d, 0, (uint32_t)n, axis, &le, &re);
    if (ok && axis) frame_extremes(&d, le, 0, &le, &re); /* (the x frame's extremes) */
    int by_vertex = flags & DT_BY_VERTEX;
    if (ok && hull && n >= 3) ok = outer_hull(&d, le, n, by_vertex ? NULL : id, hull, nhull);
    if (ok) *ntri = by_vertex ? collect(&d, NULL, tid, run) : collect(&d, id, tid, run);
    free(ax);
    free(tmap);
    return ok ? PDT_OK : PDT_ERR_NOMEM;
}
