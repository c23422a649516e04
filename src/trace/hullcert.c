/* pdt — Graham's hull certified from its stack and one pass over the points.
 * The reasoning is in hullcert.h. */
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>

#include "pdt/predicates.h"
#include "hullcert.h"

/* Points read between two calls of the caller's release. */
#define RELEASE_EVERY ((size_t)1 << 16)

typedef struct hc {
    const pdt_point *pts;
    const uint32_t *s;
    size_t h;
    pdt_point o;        /* pts[s[0]] */
    pdt_err *err;
} hc;

static pdt_status fail(hc *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static pdt_status fail(hc *c, const char *fmt, ...)
{
    char what[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return pdt_err_set(c->err, PDT_ERR_CHECK, "%s", what);
}

static pdt_point corner(const hc *c, size_t k)
{
    return c->pts[c->s[k]];
}

static int same(pdt_point a, pdt_point b)
{
    return a.x == b.x && a.y == b.y;
}

/* p would be the origin rather than o: lower, or as low and further right. */
static int before_origin(pdt_point p, pdt_point o)
{
    return p.y < o.y || (p.y == o.y && p.x > o.x);
}

static pdt_status not_lowest(hc *c, size_t i)
{
    return fail(c, "its first point, pt %" PRIu32 ", is not the rightmost lowest point: pt %zu is "
                   "lower, or as low and further right", c->s[0], i);
}

/* 2 (and 1 for the corners themselves): the corners after the first lie
 * above it, or level with it and to its left, at strictly increasing
 * angles around it, and S turns strictly left at every corner. */
static pdt_status stack_shape(hc *c)
{
    for (size_t k = 1; k < c->h; k++) {
        pdt_point p = corner(c, k);
        if (same(p, c->o))
            return fail(c, "pt %" PRIu32 " at position %zu coincides with its first point pt %"
                           PRIu32, c->s[k], k, c->s[0]);
        if (before_origin(p, c->o)) return not_lowest(c, c->s[k]);
    }
    for (size_t k = 1; k + 1 < c->h; k++)
        if (pdt_orient(c->o, corner(c, k), corner(c, k + 1)) <= 0)
            return fail(c, "positions %zu and %zu (pts %" PRIu32 " and %" PRIu32 ") are not in "
                           "counter-clockwise order around its first point pt %" PRIu32,
                        k, k + 1, c->s[k], c->s[k + 1], c->s[0]);
    for (size_t k = 0; c->h >= 3 && k < c->h; k++) {
        size_t b = (k + 1) % c->h, d = (k + 2) % c->h;
        if (pdt_orient(corner(c, k), corner(c, b), corner(c, d)) <= 0)
            return fail(c, "no strict left turn at position %zu (pts %" PRIu32 " %" PRIu32 " %"
                           PRIu32 ")", b, c->s[k], c->s[b], c->s[d]);
    }
    return PDT_OK;
}

static pdt_status outside(hc *c, size_t i, pdt_point p)
{
    return fail(c, "pt %zu (%" PRId32 ", %" PRId32 ") lies outside it", i, p.x, p.y);
}

static int32_t min32(int32_t a, int32_t b) { return a < b ? a : b; }
static int32_t max32(int32_t a, int32_t b) { return a > b ? a : b; }

/* 3 for h >= 3: p (not at o, above it) in the polygon.  The corners k
 * and k + 1 of its wedge to *k; 0 outside. */
static int in_polygon(const hc *c, pdt_point p, size_t *k)
{
    if (pdt_orient(c->o, corner(c, 1), p) < 0 || pdt_orient(c->o, corner(c, c->h - 1), p) > 0)
        return 0;
    /* the angles around o increase with the position: bisect for the
     * wedge, keeping orient(o, S[lo], p) >= 0 and orient(o, S[hi], p) <= 0 */
    size_t lo = 1, hi = c->h - 1;
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (pdt_orient(c->o, corner(c, mid), p) > 0) lo = mid;
        else hi = mid;
    }
    *k = lo;
    return pdt_orient(corner(c, lo), corner(c, hi), p) >= 0;
}

/* 3 for h = 2: p on the segment from o to S[1]. */
static int on_segment(const hc *c, pdt_point p)
{
    pdt_point q = corner(c, 1);
    return pdt_orient(c->o, q, p) == 0 && min32(c->o.x, q.x) <= p.x && p.x <= max32(c->o.x, q.x) &&
           min32(c->o.y, q.y) <= p.y && p.y <= max32(c->o.y, q.y);
}

/* 1, 3 and 4 for point i. */
static pdt_status check_point(hc *c, size_t i)
{
    pdt_point p = c->pts[i];
    if (before_origin(p, c->o)) return not_lowest(c, i);
    if (same(p, c->o)) {
        if (i < c->s[0])
            return fail(c, "its first point, pt %" PRIu32 ", is not the first copy of the rightmost "
                           "lowest point: pt %zu is an earlier copy", c->s[0], i);
        return PDT_OK;
    }
    size_t k = 1;  /* the corners p may be a copy of: k and k + 1 */
    if (c->h == 1 || (c->h == 2 && !on_segment(c, p)) || (c->h >= 3 && !in_polygon(c, p, &k)))
        return outside(c, i, p);
    for (size_t j = k; j <= k + 1 && j < c->h; j++)
        if (same(p, corner(c, j)) && i > c->s[j])
            return fail(c, "pt %zu is a later copy of its point pt %" PRIu32 " at position %zu "
                           "(of coincident points Graham's scan keeps the last)", i, c->s[j], j);
    return PDT_OK;
}

pdt_status pdt_hull_certify(const pdt_point *pts, size_t n, const uint32_t *s, size_t h,
                            void (*release)(void *ctx), void *ctx, pdt_err *err)
{
    hc c = {pts, s, h, {0, 0}, err};
    if (n == 0 && h == 0) return PDT_OK;
    if (h == 0) return fail(&c, "it is empty (the run has %zu points)", n);
    c.o = pts[s[0]];
    pdt_status st = stack_shape(&c);
    for (size_t i = 0; st == PDT_OK && i < n; i++) {
        if (release && i % RELEASE_EVERY == RELEASE_EVERY - 1) release(ctx);
        st = check_point(&c, i);
    }
    return st;
}
