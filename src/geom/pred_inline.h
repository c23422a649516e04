/* pdt — the fast paths of the exact predicates, inlined into the kernel
 * (internal to src/geom).  The same code as pdt_orient / pdt_incircle_sos
 * (predicates.c defines those with these functions), so every answer is the
 * same bit for bit; only the call overhead goes: at 10^6 points the kernel
 * makes ~8 M in-circle and ~20 M orientation tests.  The exact stages and the
 * tie rule stay out of line in predicates.c (they run on a tiny fraction of
 * the calls).  Bit budget: see predicates.c and docs/algorithm.md §2.2. */
#ifndef PDT_GEOM_PRED_INLINE_H
#define PDT_GEOM_PRED_INLINE_H

#include "pdt/common.h"

/* Exact incircle0 of the translated rows (stages 2 and 3 of predicates.c);
 * the sign, for differences of int32 coordinates. */
int pdt_incircle_exact(int64_t adx, int64_t ady, int64_t bdx, int64_t bdy, int64_t cdx,
                       int64_t cdy);

/* The tie rule of pdt_incircle_sos (docs/algorithm.md §2.3), for incircle0 == 0. */
int pdt_incircle_ties(pdt_point a, pdt_point b, pdt_point c, pdt_point d);

/* pdt_orient: the sign of (b-a) x (c-a), exact (int128). */
static inline __attribute__((always_inline)) int pdt_orient_fast(pdt_point a, pdt_point b,
                                                                pdt_point c)
{
    int64_t bx = (int64_t)b.x - a.x, by = (int64_t)b.y - a.y;
    int64_t cx = (int64_t)c.x - a.x, cy = (int64_t)c.y - a.y;
    __int128 l = (__int128)bx * cy, r = (__int128)by * cx;
    return (l > r) - (l < r);
}

/* pdt_incircle0: Shewchuk's stage-A floating-point filter (all six
 * differences are exact doubles; the bound is proven for inputs carrying one
 * rounding error, ours carry none), then the exact evaluation out of line. */
static inline __attribute__((always_inline)) int pdt_incircle0_fast(pdt_point a, pdt_point b,
                                                                   pdt_point c, pdt_point d)
{
    int64_t adx = (int64_t)a.x - d.x, ady = (int64_t)a.y - d.y;
    int64_t bdx = (int64_t)b.x - d.x, bdy = (int64_t)b.y - d.y;
    int64_t cdx = (int64_t)c.x - d.x, cdy = (int64_t)c.y - d.y;
    double fadx = (double)adx, fady = (double)ady, fbdx = (double)bdx, fbdy = (double)bdy;
    double fcdx = (double)cdx, fcdy = (double)cdy;
    double bdxcdy = fbdx * fcdy, cdxbdy = fcdx * fbdy;
    double cdxady = fcdx * fady, adxcdy = fadx * fcdy;
    double adxbdy = fadx * fbdy, bdxady = fbdx * fady;
    double alift = fadx * fadx + fady * fady;
    double blift = fbdx * fbdx + fbdy * fbdy;
    double clift = fcdx * fcdx + fcdy * fcdy;
    double det = alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) +
                 clift * (adxbdy - bdxady);
    double perm = (__builtin_fabs(bdxcdy) + __builtin_fabs(cdxbdy)) * alift +
                  (__builtin_fabs(cdxady) + __builtin_fabs(adxcdy)) * blift +
                  (__builtin_fabs(adxbdy) + __builtin_fabs(bdxady)) * clift;
    /* Shewchuk's bound is (10 + 96 eps) eps = 1.11022302462515...e-15; a
     * slightly larger constant only widens the band that goes exact. */
    const double errbound = 1.2e-15 * perm;
    if (det > errbound) return 1;
    if (-det > errbound) return -1;
    return pdt_incircle_exact(adx, ady, bdx, bdy, cdx, cdy);
}

/* pdt_incircle0 when every coordinate difference among a, b, c, d is below
 * 2^30 in magnitude (e.g. all four in a box of side < 2^30): exact in int64 /
 * int128 (lifts and minors < 2^61, the determinant < 3 * 2^122), no filter.
 * The kernel uses it when its whole point set fits such a box. */
static inline __attribute__((always_inline)) int pdt_incircle0_small(pdt_point a, pdt_point b,
                                                                    pdt_point c, pdt_point d)
{
    int64_t adx = (int64_t)a.x - d.x, ady = (int64_t)a.y - d.y;
    int64_t bdx = (int64_t)b.x - d.x, bdy = (int64_t)b.y - d.y;
    int64_t cdx = (int64_t)c.x - d.x, cdy = (int64_t)c.y - d.y;
    int64_t al = adx * adx + ady * ady;
    int64_t bl = bdx * bdx + bdy * bdy;
    int64_t cl = cdx * cdx + cdy * cdy;
    int64_t bc = bdx * cdy - cdx * bdy;
    int64_t ca = cdx * ady - adx * cdy;
    int64_t ab = adx * bdy - bdx * ady;
    __int128 s = (__int128)al * bc + (__int128)bl * ca + (__int128)cl * ab;
    return (s > 0) - (s < 0);
}

/* pdt_orient under the same precondition (products < 2^60: int64). */
static inline __attribute__((always_inline)) int pdt_orient_small(pdt_point a, pdt_point b,
                                                                 pdt_point c)
{
    int64_t l = ((int64_t)b.x - a.x) * ((int64_t)c.y - a.y);
    int64_t r = ((int64_t)b.y - a.y) * ((int64_t)c.x - a.x);
    return (l > r) - (l < r);
}

/* pdt_incircle_sos. */
static inline __attribute__((always_inline)) int pdt_incircle_sos_fast(pdt_point a, pdt_point b,
                                                                      pdt_point c, pdt_point d)
{
    int s = pdt_incircle0_fast(a, b, c, d);
    return s != 0 ? s : pdt_incircle_ties(a, b, c, d);
}

#endif
