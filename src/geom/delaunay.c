/* pdt — the sequential Delaunay kernel: Guibas–Stolfi divide and conquer
 * with Dwyer's alternating cuts, with the exact pdt_orient and the
 * simulation-of-simplicity pdt_incircle_sos for every in-circle decision, so
 * the result is T*(P) (algorithm.md §2.3) — the projection of the lower hull
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
 * Edge structure: directed edges in flat arrays (no per-edge malloc).  Edge e
 * and its twin e ^ 1 form an undirected edge; org[e] is the origin, onext[e]
 * / oprev[e] the next / previous edge counter-clockwise around org[e] (a
 * doubly linked ring: the primal half of a quad-edge, with the dual's work
 * done by oprev).  Identities used: sym(e) = e ^ 1, lnext(e) = oprev(sym e),
 * rprev(e) = onext(sym e), lprev(e) = sym(onext e).
 *
 * Memory: at most 3n undirected edges are alive at any time (the union of the
 * sub-triangulations plus the cross edges is planar), freed edges are
 * reused, so 12 bytes per directed edge, ~72 bytes per point.  The triangle
 * list is written over the oprev array once the merge is done (it needs
 * only org and onext), so it costs no extra memory. */
#include "pdt/delaunay.h"

#include "pdt/predicates.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#define NIL UINT32_MAX

typedef struct dt {
    const pdt_point *p;
    uint32_t *org, *onext, *oprev;
    size_t cap;   /* directed edges allocated */
    size_t used;  /* directed edges ever handed out (even) */
    uint32_t freelist; /* a free even edge, chained through onext, or NIL */
    pdt_trace *tr;
    int nomem;
} dt;

static inline uint32_t sym(uint32_t e)
{
    return e ^ 1u;
}

static inline uint32_t dest(const dt *d, uint32_t e)
{
    return d->org[e ^ 1u];
}

static inline uint32_t lnext(const dt *d, uint32_t e)
{
    return d->oprev[e ^ 1u];
}

static inline uint32_t rprev(const dt *d, uint32_t e)
{
    return d->onext[e ^ 1u];
}

static int grow(dt *d)
{
    size_t cap = d->cap ? 2 * d->cap : 64;
    if (cap > (size_t)UINT32_MAX) return 0;
    uint32_t *o = realloc(d->org, cap * sizeof *o);
    if (!o) return 0;
    d->org = o;
    o = realloc(d->onext, cap * sizeof *o);
    if (!o) return 0;
    d->onext = o;
    o = realloc(d->oprev, cap * sizeof *o);
    if (!o) return 0;
    d->oprev = o;
    d->cap = cap;
    return 1;
}

/* A new isolated edge a -> b; returns NIL when out of memory. */
static uint32_t make_edge(dt *d, uint32_t a, uint32_t b)
{
    uint32_t e;
    if (d->freelist != NIL) {
        e = d->freelist;
        d->freelist = d->onext[e];
    } else {
        if (d->used + 2 > d->cap && !grow(d)) {
            d->nomem = 1;
            return NIL;
        }
        e = (uint32_t)d->used;
        d->used += 2;
    }
    d->org[e] = a;
    d->org[e ^ 1] = b;
    d->onext[e] = d->oprev[e] = e;
    d->onext[e ^ 1] = d->oprev[e ^ 1] = e ^ 1;
    PDT_TRACE(d->tr, 2, PDT_EV_EDGE_ADD, 0, PDT_TRACE_PT(d->tr, a), PDT_TRACE_PT(d->tr, b), 0, 0);
    return e;
}

/* Guibas–Stolfi splice, primal part: exchange onext of a and b. */
static inline void splice(dt *d, uint32_t a, uint32_t b)
{
    uint32_t an = d->onext[a], bn = d->onext[b];
    d->onext[a] = bn;
    d->onext[b] = an;
    d->oprev[bn] = a;
    d->oprev[an] = b;
}

/* New edge from dest(a) to org(b), left faces of a, e, b the same. */
static uint32_t connect(dt *d, uint32_t a, uint32_t b)
{
    uint32_t e = make_edge(d, dest(d, a), d->org[b]);
    if (e == NIL) return NIL;
    splice(d, e, lnext(d, a));
    splice(d, sym(e), b);
    return e;
}

static void delete_edge(dt *d, uint32_t e)
{
    PDT_TRACE(d->tr, 2, PDT_EV_EDGE_DEL, 0, PDT_TRACE_PT(d->tr, d->org[e]),
              PDT_TRACE_PT(d->tr, dest(d, e)), 0, 0);
    splice(d, e, d->oprev[e]);
    splice(d, sym(e), d->oprev[sym(e)]);
    e &= ~1u;
    d->org[e] = d->org[e ^ 1] = NIL;
    d->onext[e] = d->freelist;
    d->freelist = e;
}

static inline int ccw(const dt *d, uint32_t a, uint32_t b, uint32_t c)
{
    return pdt_orient(d->p[a], d->p[b], d->p[c]) > 0;
}

/* x strictly right of edge e (i.e. x, dest e, org e counter-clockwise) */
static inline int right_of(const dt *d, uint32_t x, uint32_t e)
{
    return ccw(d, x, dest(d, e), d->org[e]);
}

static inline int left_of(const dt *d, uint32_t x, uint32_t e)
{
    return ccw(d, x, d->org[e], dest(d, e));
}

/* d strictly inside the circle of counter-clockwise a, b, c, ties by SoS */
static inline int in_circle(const dt *d, uint32_t a, uint32_t b, uint32_t c, uint32_t q)
{
    return pdt_incircle_sos(d->p[a], d->p[b], d->p[c], d->p[q]) > 0;
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
 * generator, which is seeded from n, so runs are reproducible). */
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
            r[q] = lo + (size_t)(rs % w);
        }
        uint64_t a = v[r[0]], b = v[r[1]], c = v[r[2]];
        uint64_t piv = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
        /* three-way split: [lo, lt) < piv, [lt, gt) == piv, [gt, hi) > piv */
        size_t lt = lo, i = lo, gt = hi;
        while (i < gt) {
            uint64_t x = v[i];
            if (x < piv) {
                v[i++] = v[lt];
                v[lt++] = x;
            } else if (x > piv) {
                v[i] = v[--gt];
                v[gt] = x;
            } else {
                i++;
            }
        }
        if (k < lt) hi = lt;
        else if (k >= gt) lo = gt;
        else return piv;
    }
    if (hi - lo == 2 && v[lo] > v[lo + 1]) {
        uint64_t t = v[lo];
        v[lo] = v[lo + 1];
        v[lo + 1] = t;
    }
    return v[k];
}

/* Split perm[lo, hi) (in frame-0 order) at the frame-1 median: the mid - lo
 * frame-1 smallest points first; both parts stay in frame-0 order (a stable
 * partition), so frame-0 nodes never need a selection.
 * Scratch (5 words per point): the unused tail of the org array.  When this
 * node starts, only edges among the n - m points of finished subtrees exist,
 * at most 3(n - m) of them, so at least 6m + 12 words of org are free; those
 * pages would be touched by later edges anyway, so the scratch adds nothing
 * to the peak memory.  (malloc is the fallback.)  Returns 0 when out of
 * memory. */
static int split_frame1(dt *d, uint32_t *perm, uint32_t lo, uint32_t hi, uint32_t mid)
{
    size_t m = hi - lo;
    void *heap = NULL;
    uint64_t *k;
    if (d->cap - d->used >= 5 * m + 2) {
        k = (uint64_t *)(void *)(d->org + d->used + (d->used & 1)); /* 8-byte aligned */
    } else {
        heap = malloc(m * (2 * sizeof(uint64_t) + sizeof(uint32_t)));
        if (!heap) return 0;
        k = heap;
    }
    uint64_t *ks = k + m;
    uint32_t *tp = (uint32_t *)(void *)(ks + m);
    for (size_t i = 0; i < m; i++) ks[i] = k[i] = frame_key(d->p[perm[lo + i]], 1);
    uint64_t piv = kth_key(ks, m, mid - lo); /* the smallest key of the upper part */
    size_t a = lo, b = 0;
    for (size_t i = 0; i < m; i++) {
        if (k[i] < piv) perm[a++] = perm[lo + i];
        else tp[b++] = perm[lo + i];
    }
    memcpy(perm + a, tp, b * sizeof *tp);
    free(heap);
    return 1;
}

/* Sort perm[lo, hi) (at most 3 points) in frame `axis`. */
static void sort_small(const dt *d, uint32_t *perm, uint32_t lo, uint32_t hi, int axis)
{
    for (uint32_t i = lo + 1; i < hi; i++) {
        uint32_t v = perm[i], j = i;
        uint64_t kv = frame_key(d->p[v], axis);
        while (j > lo && frame_key(d->p[perm[j - 1]], axis) > kv) {
            perm[j] = perm[j - 1];
            j--;
        }
        perm[j] = v;
    }
}

/* Walk the hull from any hull edge e (counter-clockwise walk: e <- rprev e)
 * and return the counter-clockwise hull edge out of the frame-smallest vertex
 * and the clockwise hull edge out of the frame-largest one. */
static void frame_extremes(const dt *d, uint32_t e0, int axis, uint32_t *le, uint32_t *re)
{
    /* edges e_0 = e0, e_i+1 = rprev(e_i); the edge into org(e_i) is e_i-1 */
    uint32_t e = e0, prev = NIL, lo_e = NIL, hi_in = NIL;
    uint64_t klo = 0, khi = 0;
    int hi_at_start = 0;
    do {
        uint64_t k = frame_key(d->p[d->org[e]], axis);
        if (lo_e == NIL || k < klo) {
            klo = k;
            lo_e = e;
        }
        if (prev == NIL || k > khi) {
            khi = k;
            hi_in = prev;
            hi_at_start = prev == NIL;
        }
        prev = e;
        e = rprev(d, e);
    } while (e != e0);
    if (hi_at_start) hi_in = prev; /* the last edge walked leads into org(e0) */
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
        if (left_of(d, d->org[rdi], ldi))
            ldi = lnext(d, ldi);
        else if (right_of(d, d->org[ldi], rdi))
            rdi = rprev(d, rdi);
        else
            break;
    }
    uint32_t basel = connect(d, sym(rdi), ldi);
    if (basel == NIL) return 0;
    if (d->org[ldi] == d->org[ldo]) ldo = sym(basel);
    if (d->org[rdi] == d->org[rdo]) rdo = basel;

    /* the rising bubble */
    for (;;) {
        uint32_t bo = d->org[basel], bd = dest(d, basel);
        uint32_t lcand = d->onext[sym(basel)];
        int lvalid = right_of(d, dest(d, lcand), basel);
        if (lvalid) {
            for (;;) {
                uint32_t nx = d->onext[lcand];
                if (nx == sym(basel) || !in_circle(d, bd, bo, dest(d, lcand), dest(d, nx))) break;
                delete_edge(d, lcand);
                lcand = nx;
            }
        }
        uint32_t rcand = d->oprev[basel];
        int rvalid = right_of(d, dest(d, rcand), basel);
        if (rvalid) {
            for (;;) {
                uint32_t nx = d->oprev[rcand];
                if (nx == basel || !in_circle(d, bd, bo, dest(d, rcand), dest(d, nx))) break;
                delete_edge(d, rcand);
                rcand = nx;
            }
        }
        if (!lvalid && !rvalid) break;
        if (!lvalid ||
            (rvalid && in_circle(d, dest(d, lcand), d->org[lcand], d->org[rcand], dest(d, rcand))))
            basel = connect(d, rcand, sym(basel));
        else
            basel = connect(d, sym(basel), sym(lcand));
        if (basel == NIL) return 0;
    }
    *le = ldo;
    *re = rdo;
    return 1;
}

/* Triangulate the points perm[lo, hi) (hi - lo >= 2), cutting at the median
 * of frame `axis`.  *le: counter-clockwise hull edge out of the frame-smallest
 * point; *re: clockwise hull edge out of the frame-largest point.  Returns 0
 * when out of memory. */
static int build(dt *d, uint32_t *perm, uint32_t lo, uint32_t hi, int axis, uint32_t *le,
                 uint32_t *re)
{
    uint32_t n = hi - lo;
    if (n <= 3) {
        sort_small(d, perm, lo, hi, axis);
        uint32_t s1 = perm[lo], s2 = perm[lo + 1];
        uint32_t a = make_edge(d, s1, s2);
        if (a == NIL) return 0;
        if (n == 2) {
            *le = a;
            *re = sym(a);
            return 1;
        }
        uint32_t s3 = perm[lo + 2];
        uint32_t b = make_edge(d, s2, s3);
        if (b == NIL) return 0;
        splice(d, sym(a), b);
        int o = pdt_orient(d->p[s1], d->p[s2], d->p[s3]);
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
    /* invariant: perm[lo, hi) is in frame-0 order */
    if (axis == 1 && !split_frame1(d, perm, lo, hi, mid)) {
        d->nomem = 1;
        return 0;
    }
    uint32_t ldo, ldi, rdi, rdo;
    if (!build(d, perm, lo, mid, 1 - axis, &ldo, &ldi) ||
        !build(d, perm, mid, hi, 1 - axis, &rdi, &rdo))
        return 0;
    /* the children answered in the other frame: find this frame's extremes */
    frame_extremes(d, ldo, axis, &ldo, &ldi);
    frame_extremes(d, rdi, axis, &rdi, &rdo);
    return merge(d, ldo, ldi, rdi, rdo, le, re);
}

pdt_status pdt_delaunay(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri, int run,
                        pdt_trace *tr)
{
    *tris = NULL;
    *ntri = 0;
    if (n < 2) return PDT_OK;
    if (n > (size_t)(UINT32_MAX / 8)) return PDT_ERR_ARG;
    for (size_t i = 1; i < n; i++) /* the precondition: distinct and sorted */
        if (pdt_key(pts[i - 1]) >= pdt_key(pts[i])) return PDT_ERR_ARG;
    dt d;
    memset(&d, 0, sizeof d);
    d.p = pts;
    d.tr = tr;
    d.freelist = NIL;
    d.cap = 6 * n + 12; /* at most 3n undirected edges alive */
    d.org = malloc(d.cap * sizeof *d.org);
    d.onext = malloc(d.cap * sizeof *d.onext);
    d.oprev = malloc(d.cap * sizeof *d.oprev);
    uint32_t *perm = malloc(n * sizeof *perm);
    uint32_t le, re;
    if (perm)
        for (uint32_t i = 0; i < (uint32_t)n; i++) perm[i] = i;
    int ok = perm && d.org && d.onext && d.oprev && build(&d, perm, 0, (uint32_t)n, 0, &le, &re);
    free(perm);
    if (!ok) {
        free(d.org);
        free(d.onext);
        free(d.oprev);
        return PDT_ERR_NOMEM;
    }

    /* Collect the counter-clockwise triangles: walk each left face with
     * lprev (needs only org and onext) and write triangles over oprev. */
    size_t words = (d.used + 63) / 64;
    uint64_t *seen = calloc(words ? words : 1, sizeof *seen);
    if (!seen) {
        free(d.org);
        free(d.onext);
        free(d.oprev);
        return PDT_ERR_NOMEM;
    }
    pdt_tri *out = (pdt_tri *)(void *)d.oprev; /* 3 words per triangle, <= 2n triangles */
    size_t nt = 0;
    for (uint32_t e = 0; e < (uint32_t)d.used; e++) {
        if (d.org[e] == NIL || (seen[e >> 6] >> (e & 63) & 1)) continue;
        uint32_t e1 = sym(d.onext[e]);  /* lprev(e) */
        uint32_t e2 = sym(d.onext[e1]); /* lprev(lprev(e)) */
        if (sym(d.onext[e2]) != e) continue;
        seen[e >> 6] |= UINT64_C(1) << (e & 63);
        seen[e1 >> 6] |= UINT64_C(1) << (e1 & 63);
        seen[e2 >> 6] |= UINT64_C(1) << (e2 & 63);
        uint32_t a = d.org[e], b = d.org[e2], c = d.org[e1];
        if (pdt_orient(pts[a], pts[b], pts[c]) <= 0) continue; /* the outer face */
        out[nt].v[0] = a;
        out[nt].v[1] = b;
        out[nt].v[2] = c;
        nt++;
        PDT_TRACE(tr, 1, PDT_EV_TRI_NEW, run, PDT_TRACE_PT(tr, a), PDT_TRACE_PT(tr, b),
                  PDT_TRACE_PT(tr, c), 0);
    }
    free(seen);
    free(d.org);
    free(d.onext);
    if (nt == 0) {
        free(d.oprev);
        return PDT_OK;
    }
    pdt_tri *shrunk = realloc(out, nt * sizeof *shrunk);
    *tris = shrunk ? shrunk : out;
    *ntri = nt;
    return PDT_OK;
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

static void tri_rotate(pdt_tri *t)
{
    uint32_t a = t->v[0], b = t->v[1], c = t->v[2];
    if (b < a && b < c) {
        t->v[0] = b;
        t->v[1] = c;
        t->v[2] = a;
    } else if (c < a && c < b) {
        t->v[0] = c;
        t->v[1] = a;
        t->v[2] = b;
    }
}

void pdt_tri_canonical(pdt_tri *tris, size_t ntri)
{
    if (ntri == 0) return;
    for (size_t i = 0; i < ntri; i++) tri_rotate(&tris[i]);
    /* bucket by the first index when that pays (few triangles per index),
     * then insertion-sort each bucket; fall back to qsort otherwise */
    uint32_t maxv = 0;
    for (size_t i = 0; i < ntri; i++)
        if (tris[i].v[0] > maxv) maxv = tris[i].v[0];
    size_t nb = (size_t)maxv + 2;
    size_t *cnt = ntri > 64 && nb <= 4 * ntri ? calloc(nb, sizeof *cnt) : NULL;
    pdt_tri *tmp = cnt ? malloc(ntri * sizeof *tmp) : NULL;
    if (!cnt || !tmp) {
        free(cnt);
        free(tmp);
        qsort(tris, ntri, sizeof *tris, tri_qcmp);
        return;
    }
    for (size_t i = 0; i < ntri; i++) cnt[tris[i].v[0] + 1]++;
    for (size_t b = 1; b < nb; b++) cnt[b] += cnt[b - 1];
    for (size_t i = 0; i < ntri; i++) tmp[cnt[tris[i].v[0]]++] = tris[i];
    /* cnt[v] is now the end of bucket v; sort within buckets (insertion sort
     * for short ones, qsort for long ones: a vertex of huge degree must not
     * make this quadratic) */
    size_t start = 0;
    for (size_t b = 0; b + 1 < nb; b++) {
        size_t end = cnt[b];
        if (end - start > 32) {
            qsort(tmp + start, end - start, sizeof *tmp, tri_qcmp);
            start = end;
            continue;
        }
        for (size_t i = start + 1; i < end; i++) {
            pdt_tri v = tmp[i];
            size_t j = i;
            while (j > start && tri_cmp(&tmp[j - 1], &v) > 0) {
                tmp[j] = tmp[j - 1];
                j--;
            }
            tmp[j] = v;
        }
        start = end;
    }
    memcpy(tris, tmp, ntri * sizeof *tris);
    free(tmp);
    free(cnt);
}

/* ---- sort and dedupe ---- */

typedef struct keyed {
    uint64_t key;
    uint32_t idx;
} keyed;

pdt_status pdt_sort_unique(const pdt_point *pts, size_t n, uint32_t *order, size_t *nu)
{
    *nu = 0;
    if (n == 0) return PDT_OK;
    if (n > UINT32_MAX) return PDT_ERR_ARG;
    keyed *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
    size_t *cnt = malloc(65536 * sizeof *cnt);
    if (!a || !b || !cnt) {
        free(a);
        free(b);
        free(cnt);
        return PDT_ERR_NOMEM;
    }
    uint64_t all_or = 0, all_and = ~UINT64_C(0);
    for (size_t i = 0; i < n; i++) {
        a[i].key = pdt_key(pts[i]);
        a[i].idx = (uint32_t)i;
        all_or |= a[i].key;
        all_and &= a[i].key;
    }
    /* LSD radix sort, 16-bit digits, stable (equal keys stay in index order);
     * digits on which all keys agree are skipped */
    for (int shift = 0; shift < 64; shift += 16) {
        if ((((all_or ^ all_and) >> shift) & 0xffff) == 0) continue;
        memset(cnt, 0, 65536 * sizeof *cnt);
        for (size_t i = 0; i < n; i++) cnt[(a[i].key >> shift) & 0xffff]++;
        size_t s = 0;
        for (size_t k = 0; k < 65536; k++) {
            size_t c = cnt[k];
            cnt[k] = s;
            s += c;
        }
        for (size_t i = 0; i < n; i++) b[cnt[(a[i].key >> shift) & 0xffff]++] = a[i];
        keyed *t = a;
        a = b;
        b = t;
    }
    size_t u = 0;
    for (size_t i = 0; i < n; i++)
        if (i == 0 || a[i].key != a[i - 1].key) order[u++] = a[i].idx;
    *nu = u;
    free(a);
    free(b);
    free(cnt);
    return PDT_OK;
}

/* ---- the pipeline ---- */

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

pdt_status pdt_triangulate(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri,
                           pdt_tri_stats *stats, pdt_trace *tr)
{
    *tris = NULL;
    *ntri = 0;
    pdt_tri_stats st;
    memset(&st, 0, sizeof st);
    st.n_in = n;
    if (n > (size_t)(UINT32_MAX / 8)) return PDT_ERR_ARG;

    double t0 = now();
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_PARTITION, 0, 0, 0, 0);
    uint32_t *order = malloc((n ? n : 1) * sizeof *order);
    if (!order) return PDT_ERR_NOMEM;
    size_t nu;
    pdt_status s = pdt_sort_unique(pts, n, order, &nu);
    if (s != PDT_OK) {
        free(order);
        return s;
    }
    pdt_point *sp = malloc((nu ? nu : 1) * sizeof *sp);
    if (!sp) {
        free(order);
        return PDT_ERR_NOMEM;
    }
    for (size_t i = 0; i < nu; i++) sp[i] = pts[order[i]];
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_PARTITION, 0, 0, 0, 0);
    st.n_unique = nu;
    st.n_dup = n - nu;
    double t1 = now();

    /* Kernel trace: kernel indices are positions in sp; translate to input
     * indices (composed with the caller's own translation, if any). */
    pdt_trace ktr, *kt = NULL;
    uint32_t *gid = NULL;
    if (tr) {
        ktr = *tr;
        if (tr->gid) {
            gid = malloc((nu ? nu : 1) * sizeof *gid);
            if (!gid) {
                free(order);
                free(sp);
                return PDT_ERR_NOMEM;
            }
            for (size_t i = 0; i < nu; i++) gid[i] = tr->gid[order[i]];
            ktr.gid = gid;
        } else {
            ktr.gid = order;
        }
        kt = &ktr;
    }
    if (PDT_TRACING(tr, 1)) {
        PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_LIFT, 0, 0, 0, 0);
        for (size_t i = 0; i < nu; i++)
            PDT_TRACE(kt, 1, PDT_EV_LIFT, 0, PDT_TRACE_PT(kt, i), 0, 0, (int64_t)pdt_lift(sp[i]).z);
        PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_LIFT, 0, 0, 0, 0);
    }

    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_KERNEL, 0, 0, 0, 0);
    pdt_tri *t = NULL;
    size_t nt = 0;
    s = pdt_delaunay(sp, nu, &t, &nt, 0, kt);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_KERNEL, 0, 0, 0, 0);
    free(gid);
    free(sp);
    if (s != PDT_OK) {
        free(order);
        return s;
    }
    double t2 = now();

    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_OUTPUT, 0, 0, 0, 0);
    for (size_t i = 0; i < nt; i++)
        for (int k = 0; k < 3; k++) t[i].v[k] = order[t[i].v[k]];
    free(order);
    pdt_tri_canonical(t, nt);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_OUTPUT, 0, 0, 0, 0);
    double t3 = now();

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
