/* pdt — the independent checker.
 *
 * Shares no code path with the kernel: its own exact arithmetic (two's
 * complement 192-bit integers on 32-bit limbs, evaluated by plain schoolbook
 * multiplication — a different scheme from predicates.c's 64-bit limbs and
 * floating-point filter), its own sort, its own hull.
 *
 * Why these checks prove tris == T*(P):
 *  1. every triangle is strictly counter-clockwise and uses representatives;
 *  2. every undirected edge is used once or twice, twice only with opposite
 *     directions; the edges used once (boundary) form exactly the convex hull
 *     cycle of the distinct points, collinear boundary points included,
 *     traversed once counter-clockwise;
 *     => the chains of the triangle boundaries sum to the hull boundary, so a
 *     generic point is covered by (winding number) = 1 triangle inside the
 *     hull and 0 outside: the triangles tile the hull without overlap;
 *  3. every distinct point is a vertex (so no point hides inside a triangle);
 *  4. every interior edge is locally Delaunay under the tie rule (the
 *     opposite point is outside by incircle with simulation of simplicity):
 *     the perturbed lifted surface is locally convex over a convex domain,
 *     hence it is the lower hull of the perturbed lift, i.e. T*(P).
 *  The Euler count 2n - h - 2 (thesis D5) is checked as well. */
#include "pdt/check.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- own exact arithmetic ---- */

#define LIMBS 6 /* 192 bits, two's complement, w[0] least significant */

typedef struct wide {
    uint32_t w[LIMBS];
} wide;

static wide w_from(int64_t v)
{
    wide r;
    uint64_t u = (uint64_t)v;
    r.w[0] = (uint32_t)u;
    r.w[1] = (uint32_t)(u >> 32);
    for (int i = 2; i < LIMBS; i++) r.w[i] = v < 0 ? 0xffffffffu : 0u;
    return r;
}

static wide w_add(wide a, wide b)
{
    uint64_t c = 0;
    for (int i = 0; i < LIMBS; i++) {
        c += (uint64_t)a.w[i] + b.w[i];
        a.w[i] = (uint32_t)c;
        c >>= 32;
    }
    return a;
}

static wide w_sub(wide a, wide b)
{
    for (int i = 0; i < LIMBS; i++) b.w[i] = ~b.w[i];
    return w_add(a, w_add(b, w_from(1)));
}

/* a * b mod 2^192 (exact whenever the true product fits) */
static wide w_mul(wide a, wide b)
{
    uint32_t r[LIMBS] = {0};
    for (int i = 0; i < LIMBS; i++) {
        uint64_t c = 0;
        for (int j = 0; i + j < LIMBS; j++) {
            c += (uint64_t)a.w[i] * b.w[j] + r[i + j];
            r[i + j] = (uint32_t)c;
            c >>= 32;
        }
    }
    wide o;
    memcpy(o.w, r, sizeof r);
    return o;
}

static int w_sign(wide a)
{
    if (a.w[LIMBS - 1] & 0x80000000u) return -1;
    for (int i = 0; i < LIMBS; i++)
        if (a.w[i]) return 1;
    return 0;
}

/* sign of (b - a) x (c - a) */
static int ck_orient(pdt_point a, pdt_point b, pdt_point c)
{
    { /* screen: exact differences, two rounded products and one rounded
       * difference: |error| <= gamma_3 (|m1| + |m2|); we ask for 2^-50 */
        double m1 = (double)((int64_t)b.x - a.x) * (double)((int64_t)c.y - a.y);
        double m2 = (double)((int64_t)b.y - a.y) * (double)((int64_t)c.x - a.x);
        double det = m1 - m2, bound = (__builtin_fabs(m1) + __builtin_fabs(m2)) * 0x1p-50;
        if (det > bound) return 1;
        if (det < -bound) return -1;
    }
    wide bx = w_from((int64_t)b.x - a.x), by = w_from((int64_t)b.y - a.y);
    wide cx = w_from((int64_t)c.x - a.x), cy = w_from((int64_t)c.y - a.y);
    return w_sign(w_sub(w_mul(bx, cy), w_mul(by, cx)));
}

/* sign of the lifted determinant: > 0 iff d inside the circle of CCW a,b,c.
 * A coarse floating-point screen first, with our own (loose) bound: the six
 * differences are exact doubles (< 2^33); each of the three terms
 * lift * minor is a sum/product chain of depth 5 and the final sum adds 2
 * more roundings, so |error| <= gamma_7 * P with P the permanent
 * (sum of |lift| * (|xy| + |zw|)) and gamma_7 = 7u / (1 - 7u), u = 2^-53;
 * computing P itself in floating point loses at most another gamma_5.  We
 * accept the sign only if |det| > 2^-48 * P (= 32u * P, over 4x the
 * need); otherwise the exact 192-bit evaluation decides. */
static int ck_incircle(pdt_point a, pdt_point b, pdt_point c, pdt_point d)
{
    {
        double ax = (double)((int64_t)a.x - d.x), ay = (double)((int64_t)a.y - d.y);
        double bx = (double)((int64_t)b.x - d.x), by = (double)((int64_t)b.y - d.y);
        double cx = (double)((int64_t)c.x - d.x), cy = (double)((int64_t)c.y - d.y);
        double al = ax * ax + ay * ay, bl = bx * bx + by * by, cl = cx * cx + cy * cy;
        double m1 = bx * cy, m2 = cx * by, m3 = cx * ay, m4 = ax * cy, m5 = ax * by, m6 = bx * ay;
        double det = al * (m1 - m2) + bl * (m3 - m4) + cl * (m5 - m6);
        double perm = al * (__builtin_fabs(m1) + __builtin_fabs(m2)) +
                      bl * (__builtin_fabs(m3) + __builtin_fabs(m4)) +
                      cl * (__builtin_fabs(m5) + __builtin_fabs(m6));
        double bound = perm * 0x1p-48;
        if (det > bound) return 1;
        if (det < -bound) return -1;
    }
    wide ax = w_from((int64_t)a.x - d.x), ay = w_from((int64_t)a.y - d.y);
    wide bx = w_from((int64_t)b.x - d.x), by = w_from((int64_t)b.y - d.y);
    wide cx = w_from((int64_t)c.x - d.x), cy = w_from((int64_t)c.y - d.y);
    wide al = w_add(w_mul(ax, ax), w_mul(ay, ay));
    wide bl = w_add(w_mul(bx, bx), w_mul(by, by));
    wide cl = w_add(w_mul(cx, cx), w_mul(cy, cy));
    wide t1 = w_mul(al, w_sub(w_mul(bx, cy), w_mul(cx, by)));
    wide t2 = w_mul(bl, w_sub(w_mul(cx, ay), w_mul(ax, cy)));
    wide t3 = w_mul(cl, w_sub(w_mul(ax, by), w_mul(bx, ay)));
    return w_sign(w_add(w_add(t1, t2), t3));
}

/* the tie rule: on 0, the cofactor of the lexicographically smallest point */
static int ck_incircle_sos(pdt_point a, pdt_point b, pdt_point c, pdt_point d)
{
    int s = ck_incircle(a, b, c, d);
    if (s) return s;
    pdt_point q[4] = {a, b, c, d};
    int used[4] = {0, 0, 0, 0};
    for (int round = 0; round < 4; round++) {
        int m = -1;
        for (int i = 0; i < 4; i++)
            if (!used[i] && (m < 0 || pdt_lex_cmp(q[i], q[m]) < 0)) m = i;
        used[m] = 1;
        int cof = m == 0 ? ck_orient(b, c, d)
                : m == 1 ? -ck_orient(a, c, d)
                : m == 2 ? ck_orient(a, b, d)
                         : -ck_orient(a, b, c);
        if (cof) return cof;
    }
    return 0;
}

/* ---- helpers ---- */

typedef struct pidx {
    pdt_point p;
    uint32_t i;
} pidx;

static int pidx_cmp(const void *x, const void *y)
{
    const pidx *a = x, *b = y;
    int c = pdt_lex_cmp(a->p, b->p);
    if (c) return c;
    return (a->i > b->i) - (a->i < b->i);
}

typedef struct dedge {
    uint32_t lo, hi; /* endpoints, lo < hi */
    uint32_t tri;    /* triangle */
    uint8_t fwd;     /* 1 if the triangle runs lo -> hi */
    uint8_t k;       /* position of the edge in the triangle */
} dedge;

static int dedge_cmp(const void *x, const void *y)
{
    const dedge *a = x, *b = y;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return (a->fwd > b->fwd) - (a->fwd < b->fwd);
}

/* Sort by (lo, hi, fwd): a counting sort on lo, then each bucket on its own
 * (insertion sort when short, qsort when long: O(n log n) in all cases). */
static int sort_edges(dedge *ed, size_t ne, size_t n)
{
    size_t *start = calloc(n + 1, sizeof *start);
    dedge *tmp = malloc((ne ? ne : 1) * sizeof *tmp);
    if (!start || !tmp) {
        free(start);
        free(tmp);
        return 0;
    }
    for (size_t i = 0; i < ne; i++) start[ed[i].lo + 1]++;
    for (size_t v = 0; v < n; v++) start[v + 1] += start[v];
    for (size_t i = 0; i < ne; i++) tmp[start[ed[i].lo]++] = ed[i];
    /* start[v] is now the end of bucket v */
    size_t b = 0;
    for (size_t v = 0; v < n; v++) {
        size_t e = start[v];
        if (e - b > 32) {
            qsort(tmp + b, e - b, sizeof *tmp, dedge_cmp);
        } else {
            for (size_t i = b + 1; i < e; i++) {
                dedge x = tmp[i];
                size_t j = i;
                while (j > b && dedge_cmp(&tmp[j - 1], &x) > 0) {
                    tmp[j] = tmp[j - 1];
                    j--;
                }
                tmp[j] = x;
            }
        }
        b = e;
    }
    memcpy(ed, tmp, ne * sizeof *ed);
    free(tmp);
    free(start);
    return 1;
}


/* Record a violation (PDT_ERR_CHECK) with a printf-style message. */
static pdt_status fail(pdt_err *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static pdt_status fail(pdt_err *err, const char *fmt, ...)
{
    char msg[sizeof err->msg];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return pdt_err_set(err, PDT_ERR_CHECK, "%s", msg);
}

/* pdt_check_delaunay's state: the input, its distinct points (s[0..m):
 * sorted, each its smallest index; rep: every index's representative), our
 * own hull (h vertices, collinear boundary points included), and the
 * triangles' directed edges (ed) with the boundary's successor of each
 * vertex (nxt, nb edges). */
typedef struct dcheck {
    const pdt_point *pts;
    const pdt_tri *tris;
    size_t n, ntri, m, h, nb;
    pidx *s;
    uint32_t *rep, *hull, *nxt;
    uint8_t *usedv;
    dedge *ed;
    pdt_err *err;
} dcheck;

/* The representatives: the smallest index of each location. */
static void distinct_points(dcheck *d)
{
    for (size_t i = 0; i < d->n; i++) {
        d->s[i].p = d->pts[i];
        d->s[i].i = (uint32_t)i;
    }
    qsort(d->s, d->n, sizeof *d->s, pidx_cmp);
    size_t m = 0; /* distinct points, in s[0..m) after compaction */
    for (size_t i = 0; i < d->n; i++) {
        if (i > 0 && pdt_lex_cmp(d->s[i].p, d->s[m - 1].p) == 0) {
            d->rep[d->s[i].i] = d->s[m - 1].i;
            continue;
        }
        d->rep[d->s[i].i] = d->s[i].i;
        d->s[m++] = d->s[i];
    }
    d->m = m;
}

/* Our own monotone chain over the distinct points, collinear points kept
 * (d->h vertices).  0 when they are all collinear (or fewer than 3). */
static int own_hull(dcheck *d)
{
    const pidx *s = d->s;
    const pdt_point *pts = d->pts;
    uint32_t *hull = d->hull;
    size_t m = d->m, h = 0;
    int collinear = 1;
    for (size_t i = 2; i < m && collinear; i++) collinear = ck_orient(s[0].p, s[1].p, s[i].p) == 0;
    if (collinear) return 0;
    for (size_t i = 0; i < m; i++) {
        while (h >= 2 && ck_orient(pts[hull[h - 2]], pts[hull[h - 1]], s[i].p) < 0) h--;
        hull[h++] = s[i].i;
    }
    size_t low = h;
    for (size_t i = m - 1; i-- > 0;) {
        while (h > low && ck_orient(pts[hull[h - 2]], pts[hull[h - 1]], s[i].p) < 0) h--;
        hull[h++] = s[i].i;
    }
    d->h = h - 1; /* the start point came back */
    return 1;
}

/* 1: every triangle names representatives, three of them, counter-
 * clockwise; its directed edges go to d->ed and its corners are marked used. */
static pdt_status check_triangles(dcheck *d)
{
    for (size_t t = 0; t < d->ntri; t++) {
        const uint32_t *v = d->tris[t].v;
        for (int k = 0; k < 3; k++) {
            if (v[k] >= d->n)
                return fail(d->err, "triangle %zu (%u %u %u): index %u out of range (n = %zu)", t, v[0],
                            v[1], v[2], v[k], d->n);
            if (d->rep[v[k]] != v[k])
                return fail(d->err,
                            "triangle %zu (%u %u %u) uses %u, a duplicate of point %u "
                            "(the smallest index must represent it)",
                            t, v[0], v[1], v[2], v[k], d->rep[v[k]]);
        }
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
            return fail(d->err, "triangle %zu (%u %u %u) repeats a vertex", t, v[0], v[1], v[2]);
        if (ck_orient(d->pts[v[0]], d->pts[v[1]], d->pts[v[2]]) <= 0)
            return fail(d->err, "triangle %zu (%u %u %u) is not counter-clockwise", t, v[0], v[1], v[2]);
        for (int k = 0; k < 3; k++) {
            uint32_t a = v[k], b = v[(k + 1) % 3];
            dedge *e = &d->ed[3 * t + (size_t)k];
            e->lo = a < b ? a : b;
            e->hi = a < b ? b : a;
            e->fwd = a < b;
            e->tri = (uint32_t)t;
            e->k = (uint8_t)k;
            d->usedv[a] = 1;
        }
    }
    return PDT_OK;
}

/* 3: every distinct point is a corner. */
static pdt_status check_points_used(dcheck *d)
{
    for (size_t i = 0; i < d->m; i++)
        if (!d->usedv[d->s[i].i])
            return fail(d->err, "point %u (%d, %d) is in no triangle", d->s[i].i, d->s[i].p.x,
                        d->s[i].p.y);
    return PDT_OK;
}

/* 2: every edge in at most two triangles, on both sides when two; the
 * edges of one triangle are the boundary (d->nxt, d->nb). */
static pdt_status check_edge_multiplicity(dcheck *d)
{
    size_t ne = 3 * d->ntri;
    const dedge *ed = d->ed;
    if (!sort_edges(d->ed, ne, d->n)) return pdt_err_set(d->err, PDT_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < d->n; i++) d->nxt[i] = UINT32_MAX;
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && ed[j].lo == ed[i].lo && ed[j].hi == ed[i].hi) j++;
        if (j - i > 2 || (j - i == 2 && ed[i].fwd == ed[i + 1].fwd)) {
            const pdt_tri *a = &d->tris[ed[i].tri], *b = &d->tris[ed[i + 1].tri];
            return fail(d->err, "edge %u-%u is used by %zu triangles (%u %u %u), (%u %u %u)%s", ed[i].lo,
                        ed[i].hi, j - i, a->v[0], a->v[1], a->v[2], b->v[0], b->v[1], b->v[2],
                        j - i == 2 ? " on the same side" : ", ...");
        }
        if (j - i == 1) { /* boundary edge, directed as in its triangle */
            uint32_t from = ed[i].fwd ? ed[i].lo : ed[i].hi, to = ed[i].fwd ? ed[i].hi : ed[i].lo;
            if (d->nxt[from] != UINT32_MAX)
                return fail(d->err,
                            "boundary vertex %u has two outgoing boundary edges (to %u "
                            "and %u)", from, d->nxt[from], to);
            d->nxt[from] = to;
            d->nb++;
        }
        i = j;
    }
    return PDT_OK;
}

/* The boundary is exactly the hull cycle, and Euler's count (thesis D5)
 * holds. */
static pdt_status check_boundary(dcheck *d)
{
    size_t h = d->h, m = d->m;
    if (d->nb != h)
        return fail(d->err,
                    "%zu boundary edges, but the convex hull has %zu vertices "
                    "(collinear boundary points included)", d->nb, h);
    for (size_t k = 0; k < h; k++) {
        uint32_t a = d->hull[k], b = d->hull[(k + 1) % h];
        if (d->nxt[a] == b) continue;
        if (d->nxt[a] == UINT32_MAX)
            return fail(d->err,
                        "hull edge %u-%u is not a boundary edge (hull vertex %u has "
                        "no outgoing boundary edge)", a, b, a);
        return fail(d->err, "boundary edge %u-%u is not the hull edge %u-%u", a, d->nxt[a], a, b);
    }
    if (d->ntri != 2 * m - h - 2)
        return fail(d->err, "%zu triangles, Euler count 2n - h - 2 = %zu (n = %zu, h = %zu)", d->ntri,
                    2 * m - h - 2, m, h);
    return PDT_OK;
}

/* 4: every interior edge locally Delaunay under the tie rule. */
static pdt_status check_locally_delaunay(dcheck *d)
{
    const dedge *ed = d->ed;
    const pdt_point *pts = d->pts;
    for (size_t i = 0; i + 1 < 3 * d->ntri; i++) {
        if (ed[i].lo != ed[i + 1].lo || ed[i].hi != ed[i + 1].hi) continue;
        const pdt_tri *t1 = &d->tris[ed[i].tri], *t2 = &d->tris[ed[i + 1].tri];
        uint32_t a = t1->v[ed[i].k], b = t1->v[(ed[i].k + 1) % 3], c = t1->v[(ed[i].k + 2) % 3];
        uint32_t x = t2->v[(ed[i + 1].k + 2) % 3];
        if (ck_incircle_sos(pts[a], pts[b], pts[c], pts[x]) >= 0) {
            int inside = ck_incircle(pts[a], pts[b], pts[c], pts[x]) > 0;
            return fail(d->err,
                        "edge %u-%u is not locally Delaunay: point %u is %s the circle of "
                        "triangle (%u %u %u), the file's triangle %zu%s", ed[i].lo, ed[i].hi, x,
                        inside ? "inside" : "on", a, b, c, (size_t)ed[i].tri + 1,
                        inside ? "" : " and the tie rule says inside");
        }
        i++;
    }
    return PDT_OK;
}

pdt_status pdt_check_delaunay(const pdt_point *pts, size_t n, const pdt_tri *tris, size_t ntri,
                              pdt_err *err)
{
    if (n > UINT32_MAX || ntri > (size_t)UINT32_MAX / 3)
        return pdt_err_set(err, PDT_ERR_ARG, "input too large");
    dcheck d = {.pts = pts, .tris = tris, .n = n, .ntri = ntri, .err = err};
    d.s = malloc((n ? n : 1) * sizeof *d.s);
    d.rep = malloc((n ? n : 1) * sizeof *d.rep);
    d.hull = malloc((2 * n + 2) * sizeof *d.hull); /* the chains may overshoot */
    d.nxt = malloc((n ? n : 1) * sizeof *d.nxt);
    d.usedv = calloc(n ? n : 1, 1);
    d.ed = malloc((ntri ? 3 * ntri : 1) * sizeof *d.ed);
    pdt_status st = PDT_OK;
    if (!d.s || !d.rep || !d.hull || !d.nxt || !d.usedv || !d.ed) {
        st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    } else {
        distinct_points(&d);
        if (!own_hull(&d)) { /* fewer than 3 distinct points, or all collinear */
            if (ntri)
                st = fail(err, "%zu triangles for %s input (expected none)", ntri,
                          d.m < 3 ? "fewer than 3 distinct points" : "all-collinear");
        } else if (ntri == 0) {
            st = fail(err, "no triangles, but the %zu distinct points are not collinear", d.m);
        } else if ((st = check_triangles(&d)) == PDT_OK && (st = check_points_used(&d)) == PDT_OK &&
                   (st = check_edge_multiplicity(&d)) == PDT_OK && (st = check_boundary(&d)) == PDT_OK) {
            st = check_locally_delaunay(&d);
        }
    }
    free(d.s);
    free(d.rep);
    free(d.hull);
    free(d.nxt);
    free(d.usedv);
    free(d.ed);
    return st;
}
