/* pdt — exact orientation and in-circle predicates on int32 points.
 *
 * Bit budget (docs/algorithm.md §2.2): a coordinate difference is < 2^32 in
 * magnitude (int64), orient < 2^65 (int128), incircle0 < 3 * 2^130 (133 bits,
 * wider than int128).
 *
 * incircle0 IS the orientation of the lifted points.  With p* = (x, y, x^2+y^2)
 * the sign of det[[x, y, x^2+y^2, 1]] over rows a, b, c, d tells on which side
 * of the plane through a*, b*, c* the point d* lies.  Subtracting row d from the
 * others (translate by d) leaves the 3x3 determinant
 *
 *     | a'x  a'y  a'x^2+a'y^2 |
 *     | b'x  b'y  b'x^2+b'y^2 |     p' = p - d
 *     | c'x  c'y  c'x^2+c'y^2 |
 *
 * because the lifted height of p - d differs from |p|^2 - |d|^2 by the linear
 * term 2 p.d, which is a combination of the first two columns.  We always
 * evaluate this translated form: the absolute lifted heights reach 2^63 and
 * would push the products beyond any fixed budget.
 *
 * incircle0 is evaluated in three stages:
 *   1. a floating-point filter.  The translated coordinates are integers below
 *      2^33, so they are exact doubles; the filter is Shewchuk's stage-A
 *      in-circle test, whose error bound (10 + 96 eps) eps * permanent
 *      (eps = 2^-53) is proven for inputs that themselves carry one rounding
 *      error (Shewchuk 1997, "Adaptive precision floating-point arithmetic and
 *      fast robust geometric predicates", §4.4); our inputs carry none, so the
 *      bound holds with room to spare.  No overflow (|values| < 2^140) and no
 *      underflow (all products of integers) can occur.
 *   2. if the filter cannot decide and every difference is < 2^30 in
 *      magnitude: an exact int64/int128 evaluation (|det| < 2^124).
 *   3. otherwise an exact evaluation with signed 192-bit integers (3 limbs).
 */
#include "pdt/predicates.h"

#include "pred_inline.h"

typedef __int128 i128;
typedef unsigned __int128 u128;

int pdt_orient(pdt_point a, pdt_point b, pdt_point c)
{
    return pdt_orient_fast(a, b, c);
}

/* ---- signed 192-bit integers: three 64-bit limbs, two's complement ---- */

typedef struct i192 {
    uint64_t w[3]; /* w[0] least significant */
} i192;

/* |u| * |v| with the sign of u * v, where u, v are int128 with |u|, |v| < 2^66. */
static i192 i192_mul(i128 u, i128 v)
{
    int neg = (u < 0) != (v < 0);
    u128 mu = u < 0 ? (u128)(-u) : (u128)u;
    u128 mv = v < 0 ? (u128)(-v) : (u128)v;
    uint64_t ul = (uint64_t)mu, uh = (uint64_t)(mu >> 64);  /* uh < 4 */
    uint64_t vl = (uint64_t)mv, vh = (uint64_t)(mv >> 64);
    u128 p0 = (u128)ul * vl;
    u128 p1 = (u128)uh * vl + (u128)ul * vh;                 /* < 2^67 */
    u128 p2 = (u128)uh * vh;                                 /* < 16 */
    u128 t = (p0 >> 64) + p1;
    i192 r;
    r.w[0] = (uint64_t)p0;
    r.w[1] = (uint64_t)t;
    r.w[2] = (uint64_t)(t >> 64) + (uint64_t)p2;
    if (neg) { /* two's complement negation */
        r.w[0] = ~r.w[0];
        r.w[1] = ~r.w[1];
        r.w[2] = ~r.w[2];
        if (++r.w[0] == 0 && ++r.w[1] == 0) ++r.w[2];
    }
    return r;
}

static i192 i192_add(i192 a, i192 b)
{
    i192 r;
    u128 s = (u128)a.w[0] + b.w[0];
    r.w[0] = (uint64_t)s;
    s = (s >> 64) + a.w[1] + b.w[1];
    r.w[1] = (uint64_t)s;
    r.w[2] = (uint64_t)(s >> 64) + a.w[2] + b.w[2];
    return r;
}

static int i192_sign(i192 a)
{
    if ((int64_t)a.w[2] < 0) return -1;
    return (a.w[0] | a.w[1] | a.w[2]) != 0;
}

/* Exact incircle0 for arbitrary int32 input (stage 3). */
static __attribute__((noinline)) int incircle_exact192(int64_t adx, int64_t ady, int64_t bdx,
                                                       int64_t bdy, int64_t cdx, int64_t cdy)
{
    i128 al = (i128)adx * adx + (i128)ady * ady; /* < 2^65 */
    i128 bl = (i128)bdx * bdx + (i128)bdy * bdy;
    i128 cl = (i128)cdx * cdx + (i128)cdy * cdy;
    i128 bc = (i128)bdx * cdy - (i128)cdx * bdy; /* |.| < 2^65 */
    i128 ca = (i128)cdx * ady - (i128)adx * cdy;
    i128 ab = (i128)adx * bdy - (i128)bdx * ady;
    i192 s = i192_add(i192_add(i192_mul(al, bc), i192_mul(bl, ca)), i192_mul(cl, ab));
    return i192_sign(s);
}

/* Exact incircle0 when every difference is < 2^30 in magnitude (stage 2). */
static __attribute__((noinline)) int incircle_exact128(int64_t adx, int64_t ady, int64_t bdx,
                                                       int64_t bdy, int64_t cdx, int64_t cdy)
{
    int64_t al = adx * adx + ady * ady; /* < 2^61 */
    int64_t bl = bdx * bdx + bdy * bdy;
    int64_t cl = cdx * cdx + cdy * cdy;
    int64_t bc = bdx * cdy - cdx * bdy; /* |.| < 2^61 */
    int64_t ca = cdx * ady - adx * cdy;
    int64_t ab = adx * bdy - bdx * ady;
    i128 s = (i128)al * bc + (i128)bl * ca + (i128)cl * ab; /* |.| < 2^124 */
    return (s > 0) - (s < 0);
}

static inline int small30(int64_t v)
{
    return v > -(INT64_C(1) << 30) && v < (INT64_C(1) << 30);
}

/* Stages 2 and 3 (stage 1, the filter, is pdt_incircle0_fast in pred_inline.h). */
int pdt_incircle_exact(int64_t adx, int64_t ady, int64_t bdx, int64_t bdy, int64_t cdx,
                       int64_t cdy)
{
    if (small30(adx) && small30(ady) && small30(bdx) && small30(bdy) && small30(cdx) &&
        small30(cdy))
        return incircle_exact128(adx, ady, bdx, bdy, cdx, cdy);
    return incircle_exact192(adx, ady, bdx, bdy, cdx, cdy);
}

int pdt_incircle0(pdt_point a, pdt_point b, pdt_point c, pdt_point d)
{
    return pdt_incircle0_fast(a, b, c, d);
}

/* The tie-breaking part, kept out of line: it runs only on exact zeros. */
int pdt_incircle_ties(pdt_point a, pdt_point b, pdt_point c, pdt_point d)
{
    /* H(eps) = incircle0 + d_a orient(b,c,d) - d_b orient(a,c,d) + d_c orient(a,b,d)
     *          - d_d orient(a,b,c), the lexicographically smallest point having
     * the largest perturbation: take the first non-zero cofactor in lex order. */
    pdt_point p[4] = {a, b, c, d};
    int idx[4] = {0, 1, 2, 3};
    for (int i = 1; i < 4; i++) { /* insertion sort of 4 by lex order */
        int v = idx[i], j = i;
        while (j > 0 && pdt_lex_cmp(p[idx[j - 1]], p[v]) > 0) {
            idx[j] = idx[j - 1];
            j--;
        }
        idx[j] = v;
    }
    for (int k = 0; k < 4; k++) {
        int cof;
        switch (idx[k]) {
        case 0: cof = pdt_orient(b, c, d); break;
        case 1: cof = -pdt_orient(a, c, d); break;
        case 2: cof = pdt_orient(a, b, d); break;
        default: cof = -pdt_orient(a, b, c); break;
        }
        if (cof != 0) return cof;
    }
    return 0;
}

int pdt_incircle_sos(pdt_point a, pdt_point b, pdt_point c, pdt_point d)
{
    return pdt_incircle_sos_fast(a, b, c, d);
}

pdt_lifted pdt_lift(pdt_point p)
{
    pdt_lifted l;
    l.x = p.x;
    l.y = p.y;
    l.z = (uint64_t)((int64_t)p.x * p.x) + (uint64_t)((int64_t)p.y * p.y);
    return l;
}
