/* pdt — T* certified side by side and boundary point by boundary point, on
 * disk.  The reasoning is in certify.h. */
#include <errno.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>

#include "pdt/predicates.h"
#include "certify.h"
#include "pdt/xsort.h"
#include "pdt/tmpfile.h"

/* The coordinates of this many corners are read between two givings-back
 * of the points' resident pages. */
#define RELEASE_EVERY ((uint64_t)1 << 20)

struct pdt_cert {
    const pdt_run *run;
    const pdt_point *pts;
    size_t npts;
    uint64_t budget;
    pdt_xsort *sides;       /* a side of a triangle: its points, far corner, direction */
    pdt_xsort *bnd;         /* a boundary side at each of its two points */
    uint64_t ntri, reads;
    uint64_t side_runs;     /* sorted runs of the sides (kept when they are freed) */
    pdt_kv ahead;           /* the grouping's look-ahead */
    int has_ahead;
};

/* A side's record: key = smaller point << 32 | larger, value = the far
 * corner << 1 | 1 when the triangle runs from the smaller to the larger. */
static uint64_t side_key(uint32_t a, uint32_t b)
{
    return a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
}

/* A boundary record: key = the point, value = the other end << 1 | 1 for
 * the side going out of the point, 0 for the side coming in. */
enum { BND_IN = 0, BND_OUT = 1 };

static pdt_point corner(pdt_cert *c, uint32_t i)
{
    if (++c->reads % RELEASE_EVERY == 0) pdt_run_release_points(c->run);
    return c->pts[i];
}

pdt_cert *pdt_cert_new(const pdt_run *run, uint64_t budget)
{
    pdt_cert *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->run = run;
    c->pts = pdt_run_points(run, &c->npts);
    c->budget = budget;
    if (!(c->sides = pdt_xsort_new(budget / 2))) {
        free(c);
        return NULL;
    }
    return c;
}


uint64_t pdt_cert_runs(const pdt_cert *c)
{
    return (c->sides ? pdt_xsort_runs(c->sides) : c->side_runs) +
           (c->bnd ? pdt_xsort_runs(c->bnd) : 0);
}

void pdt_cert_free(pdt_cert *c)
{
    if (!c) return;
    pdt_xsort_free(c->sides);
    pdt_xsort_free(c->bnd);
    free(c);
}

static pdt_status tmp_fail(pdt_err *err, const char *what)
{
    if (errno == ENOMEM) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    return pdt_err_set(err, PDT_ERR_IO, "temporary file for the triangles' sides in %s: %s: %s",
                       pdt_tmp_dir(), what, strerror(errno));
}

pdt_status pdt_cert_add(pdt_cert *c, const uint32_t v[3], pdt_err *err)
{
    c->ntri++;
    for (int i = 0; i < 3; i++) {
        uint32_t a = v[i], b = v[(i + 1) % 3], far = v[(i + 2) % 3];
        if (pdt_xsort_put(c->sides, side_key(a, b), (uint64_t)far << 1 | (a < b)))
            return tmp_fail(err, "cannot write");
    }
    return PDT_OK;
}

/* The next group of records with one key, at most `cap` of them kept in g
 * (*n counts them all).  1, 0 at the end, -1 (errno). */
static int next_group(pdt_cert *c, pdt_xsort *x, pdt_kv *g, int cap, int *n)
{
    if (!c->has_ahead) {
        int r = pdt_xsort_get(x, &c->ahead);
        if (r <= 0) return r;
    }
    c->has_ahead = 0;
    *n = 0;
    uint64_t key = c->ahead.key;
    pdt_kv kv = c->ahead;
    for (;;) {
        if (*n < cap) g[*n] = kv;
        (*n)++;
        int r = pdt_xsort_get(x, &kv);
        if (r < 0) return -1;
        if (r == 0) return 1;
        if (kv.key != key) {
            c->ahead = kv;
            c->has_ahead = 1;
            return 1;
        }
    }
}

/* Conditions 2 and 3 for every side; the unshared ones go to c->bnd. */
static pdt_status check_sides(pdt_cert *c, uint64_t *nbnd, pdt_err *err)
{
    if (pdt_xsort_done(c->sides)) return tmp_fail(err, "cannot read back");
    if (!(c->bnd = pdt_xsort_new(c->budget / 4)))
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    c->has_ahead = 0;
    pdt_kv g[3];
    int n, r;
    while ((r = next_group(c, c->sides, g, 3, &n)) == 1) {
        uint32_t lo = (uint32_t)(g[0].key >> 32), hi = (uint32_t)g[0].key;
        if (n > 2)
            return pdt_err_set(err, PDT_ERR_CHECK, "the side %" PRIu32 "-%" PRIu32 " belongs to %d "
                               "final triangles (a side of a triangulation belongs to at most 2)",
                               lo, hi, n);
        if (n == 1) {  /* a boundary side, from tail to head */
            uint32_t tail = g[0].val & 1 ? lo : hi, head = g[0].val & 1 ? hi : lo;
            if (pdt_xsort_put(c->bnd, tail, (uint64_t)head << 1 | BND_OUT) ||
                pdt_xsort_put(c->bnd, head, (uint64_t)tail << 1 | BND_IN))
                return tmp_fail(err, "cannot write");
            (*nbnd)++;
            continue;
        }
        uint32_t f0 = (uint32_t)(g[0].val >> 1), f1 = (uint32_t)(g[1].val >> 1);
        if ((g[0].val & 1) == (g[1].val & 1)) {
            uint32_t a = g[0].val & 1 ? lo : hi, b = g[0].val & 1 ? hi : lo;
            return pdt_err_set(err, PDT_ERR_CHECK, "the final triangles %" PRIu32 " %" PRIu32 " %"
                               PRIu32 " and %" PRIu32 " %" PRIu32 " %" PRIu32 " both lie left of "
                               "their side %" PRIu32 "-%" PRIu32 ": they overlap",
                               a, b, f0, a, b, f1, a, b);
        }
        /* (lo, hi, up) and (hi, lo, down) are counter-clockwise */
        uint32_t up = g[0].val & 1 ? f0 : f1, down = g[0].val & 1 ? f1 : f0;
        if (pdt_incircle_sos(corner(c, lo), corner(c, hi), corner(c, up), corner(c, down)) >= 0)
            return pdt_err_set(err, PDT_ERR_CHECK, "the side %" PRIu32 "-%" PRIu32 " of the final "
                               "triangles %" PRIu32 " %" PRIu32 " %" PRIu32 " and %" PRIu32 " %"
                               PRIu32 " %" PRIu32 " is not locally Delaunay: point %" PRIu32
                               " is inside the circle through %" PRIu32 " %" PRIu32 " %" PRIu32
                               " (by the tie rule), so they are not triangles of T* of the run's "
                               "points", lo, hi, lo, hi, up, hi, lo, down, down, lo, hi, up);
    }
    if (r < 0) return tmp_fail(err, "cannot read back");
    c->side_runs = pdt_xsort_runs(c->sides);
    pdt_xsort_free(c->sides);
    c->sides = NULL;
    return PDT_OK;
}

/* 0 for a direction in [0, pi) (counter-clockwise from +x), 1 in [pi, 2 pi). */
static int lower_half(int64_t dx, int64_t dy)
{
    return dy < 0 || (dy == 0 && dx < 0);
}

/* Condition 4 at every boundary point; *turns counts the times the
 * boundary's direction passes +x (its turning number, summed over cycles). */
static pdt_status check_boundary(pdt_cert *c, uint64_t *turns, pdt_err *err)
{
    if (pdt_xsort_done(c->bnd)) return tmp_fail(err, "cannot read back");
    c->has_ahead = 0;
    pdt_kv g[2];
    int n, r;
    while ((r = next_group(c, c->bnd, g, 2, &n)) == 1) {
        uint32_t v = (uint32_t)g[0].key;
        int outs = (n >= 1 && (g[0].val & 1)) + (n >= 2 && (g[1].val & 1));
        if (n != 2 || outs != 1)
            return pdt_err_set(err, PDT_ERR_CHECK, "point %" PRIu32 " is an end of %d boundary sides "
                               "of the final triangles (%s): the boundary of a triangulation "
                               "passes each of its points once, one side in and one out", v, n,
                               n == 2 ? (outs ? "both going out" : "both coming in") : "not 2");
        uint32_t prev = (uint32_t)(g[0].val & 1 ? g[1].val >> 1 : g[0].val >> 1);
        uint32_t next = (uint32_t)(g[0].val & 1 ? g[0].val >> 1 : g[1].val >> 1);
        pdt_point a = corner(c, prev), p = corner(c, v), b = corner(c, next);
        int o = pdt_orient(a, p, b);
        int64_t dx1 = (int64_t)p.x - a.x, dy1 = (int64_t)p.y - a.y;
        int64_t dx2 = (int64_t)b.x - p.x, dy2 = (int64_t)b.y - p.y;
        __int128 dot = (__int128)dx1 * dx2 + (__int128)dy1 * dy2;
        if (o < 0 || (o == 0 && dot <= 0))
            return pdt_err_set(err, PDT_ERR_CHECK, "the boundary of the final triangles %s at point %"
                               PRIu32 " (%" PRIu32 " -> %" PRIu32 " -> %" PRIu32 "): T*'s "
                               "boundary is the convex hull, which turns left or goes straight on",
                               o < 0 ? "turns right" : "turns back", v, prev, v, next);
        if (lower_half(dx1, dy1) && !lower_half(dx2, dy2)) (*turns)++;
    }
    if (r < 0) return tmp_fail(err, "cannot read back");
    return PDT_OK;
}

pdt_status pdt_cert_finish(pdt_cert *c, uint64_t nu, pdt_err *err)
{
    if (!c->ntri) return PDT_OK;
    uint64_t h = 0, turns = 0;
    pdt_status st = check_sides(c, &h, err);
    if (st == PDT_OK) st = check_boundary(c, &turns, err);
    pdt_run_release_points(c->run);
    if (st != PDT_OK) return st;
    if (turns != 1)
        return pdt_err_set(err, PDT_ERR_CHECK, "the boundary of the final triangles (%" PRIu64
                           " sides) turns round %" PRIu64 " times: T*'s boundary, the convex hull, "
                           "turns round once", h, turns);
    uint64_t v2 = c->ntri + h + 2;  /* twice the corners, by Euler's formula for a disc */
    if (v2 % 2 || v2 / 2 != nu)
        return pdt_err_set(err, PDT_ERR_CHECK, "the %" PRIu64 " final triangles with %" PRIu64
                           " boundary sides have %" PRIu64 "%s corners (by Euler's formula), "
                           "but the run has %" PRIu64 " distinct points, all of them corners "
                           "of T*", c->ntri, h, v2 / 2, v2 % 2 ? ".5" : "", nu);
    return PDT_OK;
}
