/* pdt — restricted-area tests of SRM (docs/algorithm.md §3.4, Proposition R).
 *
 * The restricted area of a triangle t is the set of plane points whose lift
 * lies on or below the plane through the lifted vertices of t: its closed
 * circumdisk.  A triangle is final when that disk misses every foreign
 * strip's bounding box.  The test only has to be SOUND (never "misses" when
 * the disk meets the box) and deterministic; a false "touches" costs a little
 * shipping, never correctness.  So it runs in double precision with an
 * explicit error margin.
 *
 * Error analysis.  With the smallest vertex a as origin, b' = b - a and
 * c' = c - a are exact int64 (|.| < 2^32), and the circumcentre is
 * u = (Nx / D, Ny / D) with D = 2 (b'x c'y - b'y c'x),
 * Nx = c'y |b'|^2 - b'y |c'|^2, Ny = b'x |c'|^2 - c'x |b'|^2.  All three are
 * EXACT in __int128 (|N| < 2^99), and already in int64 when every difference
 * is below 2^20 (|N| < 2^62; the common, faster case).  Converting them to double and dividing
 * gives each coordinate of u with relative error <= 3 eps (eps = 2^-53), so the
 * computed centre is within 5 eps |u| of the true one and the computed
 * radius |u| within 6 eps |u| of rho.  Distances to a box are then computed
 * with a few more roundings of relative size eps.  We declare "misses" only
 * if the computed distance exceeds the radius by a margin of 2^-40 times the
 * scale of every quantity involved — about 2^13 times the worst rounding
 * error — so a disk that meets the box is never declared missing it. */
#include "srm.h"

#include <math.h>

#define MARGIN 0x1p-40

static int lex_less(srm_pt a, srm_pt b)
{
    return a.x != b.x ? a.x < b.x : a.y < b.y;
}

void pdt_srm_disk_of(srm_disk *d, srm_pt a, srm_pt b, srm_pt c)
{
    /* origin = lexicographically smallest vertex, so the answer does not
     * depend on the rotation the triangle is stored in */
    if (lex_less(b, a) && !lex_less(c, b)) {
        srm_pt t = a; a = b; b = t;
    } else if (lex_less(c, a) && lex_less(c, b)) {
        srm_pt t = a; a = c; c = t;
    }
    d->ax = a.x;
    d->ay = a.y;
    d->all = 0;
    int64_t bx = (int64_t)b.x - a.x, by = (int64_t)b.y - a.y;
    int64_t cx = (int64_t)c.x - a.x, cy = (int64_t)c.y - a.y;
    const int64_t small = (int64_t)1 << 20;
    if (bx > -small && bx < small && by > -small && by < small && cx > -small && cx < small &&
        cy > -small && cy < small) {
        /* the same exact values in int64: |D| < 2^42, |b|^2 < 2^41, |N| < 2^62 */
        int64_t D = 2 * (bx * cy - by * cx);
        if (D == 0) {
            d->all = 1;
            d->ox = d->oy = d->r = 0;
            return;
        }
        int64_t b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
        d->ox = (double)(cy * b2 - by * c2) / (double)D;
        d->oy = (double)(bx * c2 - cx * b2) / (double)D;
    } else {
        __int128 D = 2 * ((__int128)bx * cy - (__int128)by * cx);
        if (D == 0) {
            d->all = 1;
            d->ox = d->oy = d->r = 0;
            return;
        }
        __int128 b2 = (__int128)bx * bx + (__int128)by * by;
        __int128 c2 = (__int128)cx * cx + (__int128)cy * cy;
        __int128 nx = (__int128)cy * b2 - (__int128)by * c2;
        __int128 ny = (__int128)bx * c2 - (__int128)cx * b2;
        d->ox = (double)nx / (double)D;
        d->oy = (double)ny / (double)D;
    }
    double rho = sqrt(d->ox * d->ox + d->oy * d->oy);
    double scale = rho + fabs(d->ox) + fabs(d->oy);
    d->r = rho + MARGIN * scale;
    if (!isfinite(d->r)) d->all = 1;
}

void pdt_srm_disk_xrange(const srm_disk *d, double *lo, double *hi)
{
    if (d->all) {
        *lo = -INFINITY;
        *hi = INFINITY;
        return;
    }
    double cx = (double)d->ax + d->ox;
    double m = d->r + MARGIN * (fabs(cx) + d->r) + 1.0;
    *lo = cx - m;
    *hi = cx + m;
}

int pdt_srm_disk_touch(const srm_disk *d, const srm_strip *box)
{
    if (box->count == 0) return 0; /* an empty strip has no box */
    if (d->all) return 1;
    /* box relative to the origin: exact (|.| < 2^33) */
    double x0 = (double)((int64_t)box->xmin - d->ax), x1 = (double)((int64_t)box->xmax - d->ax);
    double y0 = (double)((int64_t)box->ymin - d->ay), y1 = (double)((int64_t)box->ymax - d->ay);
    double dx = d->ox < x0 ? x0 - d->ox : d->ox > x1 ? d->ox - x1 : 0.0;
    double dy = d->oy < y0 ? y0 - d->oy : d->oy > y1 ? d->oy - y1 : 0.0;
    double boxscale = fmax(fmax(fabs(x0), fabs(x1)), fmax(fabs(y0), fabs(y1)));
    double r = d->r + MARGIN * boxscale;
    return !(dx * dx + dy * dy > r * r);
}

static __int128 orient128(int64_t ax, int64_t ay, int64_t bx, int64_t by, int64_t cx, int64_t cy)
{
    return (__int128)(bx - ax) * (cy - ay) - (__int128)(by - ay) * (cx - ax);
}

int pdt_srm_edge_touch(srm_pt u, srm_pt v, const srm_strip *box)
{
    if (box->count == 0) return 0;
    const int32_t xs[2] = {box->xmin, box->xmax}, ys[2] = {box->ymin, box->ymax};
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            if (orient128(u.x, u.y, v.x, v.y, xs[i], ys[j]) <= 0) return 1;
    return 0;
}

void pdt_srm_slab_of(srm_slab *sl, const srm_strip *strip, int p, int h)
{
    sl->xl = sl->yl = -INFINITY;
    sl->xr = sl->yh = INFINITY;
    for (int q = h - 1; q >= 0; q--)
        if (strip[q].count) {
            sl->xl = strip[q].xmax;
            break;
        }
    for (int q = h + 1; q < p; q++)
        if (strip[q].count) {
            sl->xr = strip[q].xmin;
            break;
        }
}

void pdt_srm_cell_of(srm_slab *sl, const srm_tree *t, const srm_strip *strip, int h)
{
    sl->xl = sl->yl = -INFINITY;
    sl->xr = sl->yh = INFINITY;
    int r = h / t->k, lo = 0, hi = t->p, at = 0;
    while (hi - lo >= 2) {
        int mid = srm_bis_mid(lo, hi);
        srm_cut c = t->cut[at];
        pdt_point sp = srm_key_point(c.split); /* (y, x) for a y-cut */
        double v = (double)sp.x;
        double *lim = r < mid ? (c.axis ? &sl->yh : &sl->xr) : (c.axis ? &sl->yl : &sl->xl);
        if (r < mid ? v < *lim : v > *lim) *lim = v;
        if (r < mid) {
            hi = mid;
            at += 1;
        } else {
            at += mid - lo; /* past the left subtree's mid - lo - 1 cuts */
            lo = mid;
        }
    }
    if (t->k == 2) { /* the rank's other strip: a lexicographic neighbour */
        const srm_strip *o = &strip[h ^ 1];
        if (o->count && (h & 1) == 0 && (double)o->xmin < sl->xr) sl->xr = o->xmin;
        if (o->count && (h & 1) == 1 && (double)o->xmax > sl->xl) sl->xl = o->xmax;
    }
}
