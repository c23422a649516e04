/* pdt — planar convex hulls on one traced stack: Graham's scan (thesis
 * Chapter 2, Version B) and Andrew's monotone chain. */
#include "pdt/hull.h"

#include "pdt/predicates.h"
#include "pred_inline.h"

#include <stdlib.h>
#include <string.h>

/* ---- the traced stack ---- */

pdt_status pdt_stack_init(pdt_stack *s, size_t cap, int id, pdt_trace *tr)
{
    s->n = 0;
    s->id = id;
    s->tr = tr;
    s->cap = cap ? cap : 16;
    s->item = malloc(s->cap * sizeof *s->item);
    if (!s->item) {
        s->cap = 0;
        return PDT_ERR_NOMEM;
    }
    return PDT_OK;
}

void pdt_stack_free(pdt_stack *s)
{
    free(s->item);
    s->item = NULL;
    s->n = s->cap = 0;
}

pdt_status pdt_stack_push(pdt_stack *s, uint32_t i)
{
    if (s->n == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 16;
        uint32_t *t = realloc(s->item, cap * sizeof *t);
        if (!t) return PDT_ERR_NOMEM;
        s->item = t;
        s->cap = cap;
    }
    s->item[s->n++] = i;
    PDT_TRACE(s->tr, 1, PDT_EV_PUSH, s->id, PDT_TRACE_PT(s->tr, i), s->n, 0, 0);
    return PDT_OK;
}

uint32_t pdt_stack_pop(pdt_stack *s, uint32_t cause)
{
    uint32_t i = s->item[--s->n];
    PDT_TRACE(s->tr, 1, PDT_EV_POP, s->id, PDT_TRACE_PT(s->tr, i), s->n,
              cause == UINT32_MAX ? UINT32_MAX : PDT_TRACE_PT(s->tr, cause), 0);
    return i;
}

/* ---- Graham's scan, Version B ---- */

typedef struct angular_ctx {
    const pdt_point *pts;
    pdt_point o; /* the sorting origin p0 */
} angular_ctx;

static int64_t abs64(int64_t v)
{
    return v < 0 ? -v : v;
}

/* The angular order about p0 of the thesis, made a total order: points
 * coincident with p0 first; then by counter-clockwise angle from the
 * horizontal ray (all angles are in (0, pi] because p0 is the rightmost
 * lowest point), compared with the integer area test; on a tie the closer
 * point first; equal points by index.  No side effects. */
static int angular_cmp(const angular_ctx *c, uint32_t i, uint32_t j)
{
    pdt_point a = c->pts[i], b = c->pts[j];
    int ao = a.x == c->o.x && a.y == c->o.y, bo = b.x == c->o.x && b.y == c->o.y;
    if (ao != bo) return ao ? -1 : 1;
    if (!ao) {
        int s = pdt_orient(c->o, a, b);
        if (s > 0) return -1; /* b is left of p0->a: a comes first */
        if (s < 0) return 1;
        /* same ray: the one closer to p0 first (|dx| + |dy| grows along a ray) */
        int64_t da = abs64((int64_t)a.x - c->o.x) + abs64((int64_t)a.y - c->o.y);
        int64_t db = abs64((int64_t)b.x - c->o.x) + abs64((int64_t)b.y - c->o.y);
        if (da != db) return da < db ? -1 : 1;
    }
    return (i > j) - (i < j);
}

/* Stable merge sort of idx[0..n) with the angular order (tmp holds n). */
static void angular_sort(const angular_ctx *c, uint32_t *idx, uint32_t *tmp, size_t n)
{
    if (n < 2) return;
    if (n <= 16) { /* insertion sort for short runs */
        for (size_t i = 1; i < n; i++) {
            uint32_t v = idx[i];
            size_t j = i;
            while (j > 0 && angular_cmp(c, idx[j - 1], v) > 0) {
                idx[j] = idx[j - 1];
                j--;
            }
            idx[j] = v;
        }
        return;
    }
    size_t h = n / 2;
    angular_sort(c, idx, tmp, h);
    angular_sort(c, idx + h, tmp, n - h);
    size_t i = 0, j = h, k = 0;
    while (i < h && j < n) tmp[k++] = angular_cmp(c, idx[j], idx[i]) < 0 ? idx[j++] : idx[i++];
    while (i < h) tmp[k++] = idx[i++];
    while (j < n) tmp[k++] = idx[j++];
    memcpy(idx, tmp, n * sizeof *idx);
}

/* 1 of the pseudo-code: the rightmost lowest point (first such index). */
static uint32_t graham_p0(const pdt_point *pts, size_t n)
{
    uint32_t o = 0;
    for (uint32_t i = 1; i < (uint32_t)n; i++)
        if (pts[i].y < pts[o].y || (pts[i].y == pts[o].y && pts[i].x > pts[o].x)) o = i;
    return o;
}

/* 2: idx[0] = o, then the others sorted angularly about p0 = pts[o].
 * Returns 0 when out of memory. */
static int graham_sort(const pdt_point *pts, size_t n, uint32_t o, uint32_t *idx, pdt_trace *tr)
{
    uint32_t *tmp = malloc(n * sizeof *tmp);
    if (!tmp) return 0;
    size_t m = 0;
    idx[m++] = o;
    for (uint32_t i = 0; i < (uint32_t)n; i++)
        if (i != o) idx[m++] = i;
    angular_ctx ctx = {pts, pts[o]};
    angular_sort(&ctx, idx + 1, tmp, n - 1);
    free(tmp);
    for (size_t k = 0; k < n; k++)
        PDT_TRACE(tr, 1, PDT_EV_SORT, 0, PDT_TRACE_PT(tr, idx[k]), k, 0, 0);
    return 1;
}

/* 3, in a pass after the sort (not inside the comparator): delete on an
 * angular tie every point but the farthest, and of coincident points all
 * copies but one.  Copies of p0 go (p0 is kept); for the other coincident
 * points the thesis deletes the one with the lower index, so the copy with
 * the highest index stays (it sorts last in its group).  Returns the points
 * left, idx[0, m). */
static size_t graham_ties(const pdt_point *pts, size_t n, uint32_t o, uint32_t *idx,
                          pdt_trace *tr)
{
    size_t w = 1, k = 1;
    while (k < n && pts[idx[k]].x == pts[o].x && pts[idx[k]].y == pts[o].y) {
        PDT_TRACE(tr, 1, PDT_EV_DELETE, PDT_DEL_COINCIDENT, PDT_TRACE_PT(tr, idx[k]),
                  PDT_TRACE_PT(tr, o), 0, 0);
        k++;
    }
    while (k < n) {
        size_t e = k + 1; /* group [k, e): the same ray from p0 */
        while (e < n && pdt_orient(pts[o], pts[idx[k]], pts[idx[e]]) == 0) e++;
        uint32_t keep = idx[e - 1];
        for (size_t q = k; q + 1 < e; q++) {
            pdt_point a = pts[idx[q]], b = pts[keep];
            int reason = a.x == b.x && a.y == b.y ? PDT_DEL_COINCIDENT : PDT_DEL_ANGULAR_TIE;
            PDT_TRACE(tr, 1, PDT_EV_DELETE, reason, PDT_TRACE_PT(tr, idx[q]),
                      PDT_TRACE_PT(tr, keep), 0, 0);
        }
        idx[w++] = keep;
        k = e;
    }
    return w;
}

/* 4-9 of the pseudo-code (lessons/02, the viewer's panel): S := (p0, p1),
 * then push p_i only on a strict left turn, else pop.  The hull to out. */
static pdt_status graham_scan(const pdt_point *pts, const uint32_t *idx, size_t m, uint32_t *out,
                              size_t *nout, pdt_trace *tr)
{
    pdt_stack s;
    pdt_status st = pdt_stack_init(&s, m, PDT_STACK_GRAHAM, tr);
    if (st == PDT_OK) st = pdt_stack_push(&s, idx[0]);
    if (st == PDT_OK && m > 1) st = pdt_stack_push(&s, idx[1]);
    size_t i = 2;
    while (st == PDT_OK && i < m) {
        pdt_point p1 = pts[s.item[s.n - 2]], p2 = pts[s.item[s.n - 1]];
        if (pdt_orient(p1, p2, pts[idx[i]]) > 0) {
            st = pdt_stack_push(&s, idx[i]);
            i++;
        } else {
            pdt_stack_pop(&s, idx[i]);
        }
    }
    if (st == PDT_OK) {
        memcpy(out, s.item, s.n * sizeof *out);
        *nout = s.n;
    }
    pdt_stack_free(&s);
    return st;
}

pdt_status pdt_hull_graham(const pdt_point *pts, size_t n, uint32_t *out, size_t *nout,
                           pdt_trace *tr)
{
    *nout = 0;
    if (n == 0) return PDT_OK;
    if (n > UINT32_MAX) return PDT_ERR_ARG;
    uint32_t *idx = malloc(n * sizeof *idx);
    if (!idx) return PDT_ERR_NOMEM;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_GRAHAM_SORT, 0, 0, 0, 0);
    uint32_t o = graham_p0(pts, n);
    if (!graham_sort(pts, n, o, idx, tr)) {
        free(idx);
        return PDT_ERR_NOMEM;
    }
    size_t m = graham_ties(pts, n, o, idx, tr);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_GRAHAM_SORT, 0, 0, 0, 0);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_GRAHAM_SCAN, 0, 0, 0, 0);
    pdt_status st = graham_scan(pts, idx, m, out, nout, tr);
    free(idx);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_GRAHAM_SCAN, 0, 0, 0, 0);
    return st;
}

/* ---- monotone chain ---- */

/* One chain of the monotone chain, untraced: the same pops and pushes as
 * the traced loop, without a call per step (a strip of 5*10^6 points makes
 * 10^7 of each).  dir 1: left to right, -1: right to left. */
static pdt_status chain_untraced(const pdt_point *pts, size_t n, pdt_stack *s, int dir)
{
    for (size_t k = 0; k < n; k++) {
        size_t i = dir > 0 ? k : n - 1 - k;
        while (s->n >= 2 &&
               pdt_orient_fast(pts[s->item[s->n - 2]], pts[s->item[s->n - 1]], pts[i]) < 0)
            s->n--;
        if (s->n < s->cap) {
            s->item[s->n++] = (uint32_t)i;
        } else {
            pdt_status st = pdt_stack_push(s, (uint32_t)i); /* (grows it) */
            if (st != PDT_OK) return st;
        }
    }
    return PDT_OK;
}

pdt_status pdt_hull_chain(const pdt_point *pts, size_t n, uint32_t *out, size_t *nout,
                          int *degenerate, int lower_id, int upper_id, pdt_trace *tr)
{
    *nout = 0;
    *degenerate = 1;
    if (n > UINT32_MAX) return PDT_ERR_ARG;
    if (n <= 2) {
        for (size_t i = 0; i < n; i++) out[i] = (uint32_t)i;
        *nout = n;
        return PDT_OK;
    }
    /* the stacks hold a chain of the points seen so far: a few dozen on most
     * inputs, all n on a line (they grow as needed) */
    size_t cap = n < 4096 ? n : 4096;
    pdt_stack lo, up;
    pdt_status st = pdt_stack_init(&lo, cap, lower_id, tr);
    if (st != PDT_OK) return st;
    st = pdt_stack_init(&up, cap, upper_id, tr);
    if (st != PDT_OK) {
        pdt_stack_free(&lo);
        return st;
    }
    /* lower hull left to right, upper hull right to left; pop only on a
     * strict right turn */
    if (PDT_TRACING(tr, 1)) {
        for (size_t i = 0; i < n && st == PDT_OK; i++) {
            while (lo.n >= 2 &&
                   pdt_orient(pts[lo.item[lo.n - 2]], pts[lo.item[lo.n - 1]], pts[i]) < 0)
                pdt_stack_pop(&lo, (uint32_t)i);
            st = pdt_stack_push(&lo, (uint32_t)i);
        }
        for (size_t i = n; i-- > 0 && st == PDT_OK;) {
            while (up.n >= 2 &&
                   pdt_orient(pts[up.item[up.n - 2]], pts[up.item[up.n - 1]], pts[i]) < 0)
                pdt_stack_pop(&up, (uint32_t)i);
            st = pdt_stack_push(&up, (uint32_t)i);
        }
    } else {
        st = chain_untraced(pts, n, &lo, 1);
        if (st == PDT_OK) st = chain_untraced(pts, n, &up, -1);
    }
    if (st == PDT_OK) {
        if (lo.n + up.n - 2 > n) { /* every point on both chains: collinear */
            for (size_t i = 0; i < n; i++) out[i] = (uint32_t)i;
            *nout = n;
        } else {
            size_t k = 0;
            for (size_t i = 0; i < lo.n; i++) out[k++] = lo.item[i];
            for (size_t i = 1; i + 1 < up.n; i++) out[k++] = up.item[i];
            *nout = k;
            *degenerate = 0;
        }
    }
    pdt_stack_free(&lo);
    pdt_stack_free(&up);
    return st;
}
