/* Exact predicates: compared with a slow, independent 256-bit reference that
 * evaluates the absolute 4x4 lifted determinant (Leibniz formula), at the
 * extremes of int32 and on random input; the SoS tie rule on the unit square,
 * grids and lattice circles. */
#include "../harness.h"
#include "pdt/predicates.h"

#include <string.h>

/* ---- reference: two's complement 256-bit integers, 8 x 32-bit limbs ---- */
typedef struct big {
    uint32_t w[8];
} big;

static big big_from_i64(int64_t v)
{
    big b;
    uint64_t u = (uint64_t)v;
    b.w[0] = (uint32_t)u;
    b.w[1] = (uint32_t)(u >> 32);
    for (int i = 2; i < 8; i++) b.w[i] = v < 0 ? 0xffffffffu : 0;
    return b;
}

static big big_add(big a, big b)
{
    uint64_t c = 0;
    for (int i = 0; i < 8; i++) {
        c += (uint64_t)a.w[i] + b.w[i];
        a.w[i] = (uint32_t)c;
        c >>= 32;
    }
    return a;
}

static big big_neg(big a)
{
    for (int i = 0; i < 8; i++) a.w[i] = ~a.w[i];
    return big_add(a, big_from_i64(1));
}

/* a * m mod 2^256 for unsigned 32-bit m */
static big big_mul32(big a, uint32_t m)
{
    uint64_t c = 0;
    for (int i = 0; i < 8; i++) {
        c += (uint64_t)a.w[i] * m;
        a.w[i] = (uint32_t)c;
        c >>= 32;
    }
    return a;
}

static big big_shl32(big a)
{
    for (int i = 7; i > 0; i--) a.w[i] = a.w[i - 1];
    a.w[0] = 0;
    return a;
}

/* a * m for unsigned 64-bit m */
static big big_mulu64(big a, uint64_t m)
{
    return big_add(big_mul32(a, (uint32_t)m), big_shl32(big_mul32(a, (uint32_t)(m >> 32))));
}

static big big_muls64(big a, int64_t m)
{
    if (m < 0) return big_neg(big_mulu64(a, (uint64_t)0 - (uint64_t)m));
    return big_mulu64(a, (uint64_t)m);
}

static int big_sign(big a)
{
    if (a.w[7] & 0x80000000u) return -1;
    for (int i = 0; i < 8; i++)
        if (a.w[i]) return 1;
    return 0;
}

/* A matrix entry: either signed or unsigned 64-bit. */
typedef struct ent {
    int is_u;
    int64_t s;
    uint64_t u;
} ent;

/* Sign of a 4x4 determinant by the Leibniz formula. */
static int det4_sign(ent m[4][4])
{
    static const int perm[24][4] = {
        {0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 1, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {0, 3, 2, 1},
        {1, 0, 2, 3}, {1, 0, 3, 2}, {1, 2, 0, 3}, {1, 2, 3, 0}, {1, 3, 0, 2}, {1, 3, 2, 0},
        {2, 0, 1, 3}, {2, 0, 3, 1}, {2, 1, 0, 3}, {2, 1, 3, 0}, {2, 3, 0, 1}, {2, 3, 1, 0},
        {3, 0, 1, 2}, {3, 0, 2, 1}, {3, 1, 0, 2}, {3, 1, 2, 0}, {3, 2, 0, 1}, {3, 2, 1, 0}};
    big sum = big_from_i64(0);
    for (int p = 0; p < 24; p++) {
        int inv = 0;
        for (int i = 0; i < 4; i++)
            for (int j = i + 1; j < 4; j++) inv += perm[p][i] > perm[p][j];
        big t = big_from_i64(inv & 1 ? -1 : 1);
        for (int i = 0; i < 4; i++) {
            ent e = m[i][perm[p][i]];
            t = e.is_u ? big_mulu64(t, e.u) : big_muls64(t, e.s);
        }
        sum = big_add(sum, t);
    }
    return big_sign(sum);
}

static ent es(int64_t v)
{
    ent e = {0, v, 0};
    return e;
}

static ent eu(uint64_t v)
{
    ent e = {1, 0, v};
    return e;
}

/* Reference incircle0: the absolute lifted determinant [x, y, x^2+y^2, 1]. */
static int ref_incircle(pdt_point a, pdt_point b, pdt_point c, pdt_point d)
{
    pdt_point p[4] = {a, b, c, d};
    ent m[4][4];
    for (int i = 0; i < 4; i++) {
        m[i][0] = es(p[i].x);
        m[i][1] = es(p[i].y);
        m[i][2] = eu((uint64_t)((int64_t)p[i].x * p[i].x) + (uint64_t)((int64_t)p[i].y * p[i].y));
        m[i][3] = es(1);
    }
    return det4_sign(m);
}

/* Reference orient: det [[ax, ay, 1], [bx, by, 1], [cx, cy, 1]] embedded in 4x4. */
static int ref_orient(pdt_point a, pdt_point b, pdt_point c)
{
    pdt_point p[3] = {a, b, c};
    ent m[4][4];
    for (int i = 0; i < 3; i++) {
        m[i][0] = es(p[i].x);
        m[i][1] = es(p[i].y);
        m[i][2] = es(1);
        m[i][3] = es(0);
    }
    m[3][0] = m[3][1] = m[3][2] = es(0);
    m[3][3] = es(1);
    return det4_sign(m);
}

/* Reference SoS for small coordinates (|x|,|y| < 2^10): heights
 * z * B^4 + B^(3 - lexrank), B = 2^24, so the perturbation of the lex-smallest
 * point dominates the others and all of them are dominated by the exact part. */
static int ref_sos(pdt_point a, pdt_point b, pdt_point c, pdt_point d)
{
    pdt_point p[4] = {a, b, c, d};
    /* expand along the height column: det = sum_i (-1)^i h_i orient(rows != i) */
    big sum = big_from_i64(0);
    for (int i = 0; i < 4; i++) {
        int r[3], k = 0;
        for (int j = 0; j < 4; j++)
            if (j != i) r[k++] = j;
        int64_t minor = ((int64_t)p[r[1]].x - p[r[0]].x) * ((int64_t)p[r[2]].y - p[r[0]].y) -
                        ((int64_t)p[r[1]].y - p[r[0]].y) * ((int64_t)p[r[2]].x - p[r[0]].x);
        int rank = 0;
        for (int j = 0; j < 4; j++) rank += pdt_lex_cmp(p[j], p[i]) < 0;
        int64_t z = (int64_t)p[i].x * p[i].x + (int64_t)p[i].y * p[i].y;
        big h = big_mulu64(big_mulu64(big_from_i64(z), UINT64_C(1) << 48), UINT64_C(1) << 48);
        big pert = big_from_i64(1);
        for (int q = 0; q < 3 - rank; q++) pert = big_mulu64(pert, UINT64_C(1) << 24);
        h = big_add(h, pert);
        sum = big_add(sum, big_muls64(h, (i % 2 ? -1 : 1) * minor));
    }
    return big_sign(sum);
}

static uint64_t rs = 88172645463325252u;
static uint64_t xr(void) { return th_xorshift(&rs); }

static int32_t extreme_coord(void)
{
    static const int32_t v[] = {INT32_MIN, INT32_MIN + 1, INT32_MIN + 2, -1, 0, 1,
                                INT32_MAX - 2, INT32_MAX - 1, INT32_MAX, 1 << 30, -(1 << 30)};
    uint64_t r = xr();
    if (r % 3 == 0) return (int32_t)(uint32_t)xr();
    return v[(r >> 8) % (sizeof v / sizeof *v)];
}

static pdt_point P(int64_t x, int64_t y)
{
    pdt_point p = {(int32_t)x, (int32_t)y};
    return p;
}

TEST(orient_int32_extremes)
{
    for (int it = 0; it < 20000; it++) {
        pdt_point a = {extreme_coord(), extreme_coord()}, b = {extreme_coord(), extreme_coord()},
                  c = {extreme_coord(), extreme_coord()};
        int s = pdt_orient(a, b, c), r = ref_orient(a, b, c);
        CHECK_MSG(s == r, "orient (%d,%d) (%d,%d) (%d,%d): %d, reference %d", a.x, a.y, b.x, b.y,
                  c.x, c.y, s, r);
    }
    /* the largest possible orient magnitude */
    CHECK(pdt_orient(P(INT32_MIN, INT32_MIN), P(INT32_MAX, INT32_MIN), P(INT32_MIN, INT32_MAX)) == 1);
    CHECK(pdt_orient(P(INT32_MIN, INT32_MIN), P(INT32_MAX, INT32_MAX), P(INT32_MAX - 1, INT32_MAX - 1)) == 0);
    CHECK(pdt_orient(P(INT32_MIN, INT32_MIN), P(INT32_MAX, INT32_MAX), P(INT32_MAX - 1, INT32_MAX)) == 1);
}

TEST(incircle_int32_extremes)
{
    int zero = 0;
    for (int it = 0; it < 20000; it++) {
        pdt_point p[4];
        for (int k = 0; k < 4; k++) p[k] = P(extreme_coord(), extreme_coord());
        int s = pdt_incircle0(p[0], p[1], p[2], p[3]), r = ref_incircle(p[0], p[1], p[2], p[3]);
        zero += r == 0;
        CHECK_MSG(s == r, "incircle (%d,%d) (%d,%d) (%d,%d) (%d,%d): %d, reference %d", p[0].x,
                  p[0].y, p[1].x, p[1].y, p[2].x, p[2].y, p[3].x, p[3].y, s, r);
    }
    CHECK_MSG(zero > 100, "only %d exactly degenerate cases", zero);
}

TEST(incircle_rectangle_corners_at_int32_limits)
{
    /* corners of the largest rectangle are cocircular (the exact zero goes
     * through the 192-bit stage); moving one corner by one unit decides. */
    pdt_point a = P(INT32_MIN, INT32_MIN), b = P(INT32_MAX, INT32_MIN), c = P(INT32_MAX, INT32_MAX),
              d = P(INT32_MIN, INT32_MAX);
    CHECK(pdt_incircle0(a, b, c, d) == 0);
    CHECK(ref_incircle(a, b, c, d) == 0);
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++) {
            pdt_point e = P(INT32_MIN + 1 + dx, INT32_MAX - 1 + dy);
            int s = pdt_incircle0(a, b, c, e), r = ref_incircle(a, b, c, e);
            CHECK_MSG(s == r, "dx %d dy %d: %d vs %d", dx, dy, s, r);
            CHECK(r != 0 || (dx == -1 && dy == 1));
        }
    /* just inside / just outside a huge circle */
    CHECK(pdt_incircle0(a, b, c, P(INT32_MIN + 1, INT32_MAX - 1)) == 1);
    /* a huge but thin configuration where every product is near 2^130 */
    pdt_point f = P(INT32_MIN, 0), g = P(0, INT32_MIN), h = P(INT32_MAX, 0);
    for (int k = -3; k <= 3; k++) {
        pdt_point q = P(k, INT32_MAX - 3);
        CHECK(pdt_incircle0(f, g, h, q) == ref_incircle(f, g, h, q));
    }
}

TEST(incircle_random_by_magnitude)
{
    /* random points at every scale 2^1 .. 2^31: exercises stages 1, 2, 3 */
    for (int bits = 1; bits <= 32; bits++) {
        for (int it = 0; it < 1500; it++) {
            pdt_point p[4];
            int64_t m = bits == 32 ? 0 : (INT64_C(1) << bits);
            for (int k = 0; k < 4; k++) {
                if (bits == 32)
                    p[k] = P((int32_t)(uint32_t)xr(), (int32_t)(uint32_t)xr());
                else
                    p[k] = P((int64_t)(xr() % (uint64_t)m) - m / 2, (int64_t)(xr() % (uint64_t)m) - m / 2);
            }
            if (it % 3 == 0) { /* force a near-cocircular case: reflect a point */
                p[3] = P(p[0].x, p[1].y);
                p[2] = P(p[1].x, p[0].y);
            } else if (it % 3 == 1) { /* and one unit off */
                p[3] = P(p[0].x, p[1].y == INT32_MAX ? p[1].y - 1 : p[1].y + 1);
                p[2] = P(p[1].x, p[0].y);
            }
            int s = pdt_incircle0(p[0], p[1], p[2], p[3]), r = ref_incircle(p[0], p[1], p[2], p[3]);
            CHECK_MSG(s == r, "bits %d: %d vs %d", bits, s, r);
        }
    }
}

TEST(incircle_is_lifted_orientation)
{
    /* incircle0 is antisymmetric under row swaps and +1 for d inside a CCW circle */
    pdt_point a = P(0, 0), b = P(10, 0), c = P(0, 10);
    CHECK(pdt_incircle0(a, b, c, P(1, 1)) == 1);
    CHECK(pdt_incircle0(a, b, c, P(20, 20)) == -1);
    CHECK(pdt_incircle0(a, b, c, P(10, 10)) == 0);
    CHECK(pdt_incircle0(b, a, c, P(1, 1)) == -1);
    pdt_lifted l = pdt_lift(P(INT32_MIN, INT32_MIN));
    CHECK(l.z == UINT64_C(1) << 63);
    l = pdt_lift(P(-3, 4));
    CHECK(l.x == -3 && l.y == 4 && l.z == 25);
}

TEST(sos_unit_square)
{
    /* docs/algorithm.md §2.3: t = ((0,0),(1,0),(1,1)), d = (0,1): lex-min a has
     * cofactor orient(b,c,d) = 1 > 0, so d counts as inside: t is rejected;
     * the square is split by the anti-diagonal (1,0)-(0,1). */
    pdt_point a = P(0, 0), b = P(1, 0), c = P(1, 1), d = P(0, 1);
    CHECK(pdt_incircle0(a, b, c, d) == 0);
    CHECK(pdt_incircle_sos(a, b, c, d) == 1);
    CHECK(pdt_incircle_sos(b, d, a, c) == -1 || pdt_orient(b, d, a) < 0);
    /* triangle (1,0),(1,1),(0,1) CCW, test (0,0): outside */
    CHECK(pdt_orient(b, c, d) == 1);
    CHECK(pdt_incircle_sos(b, c, d, a) == -1);
    /* triangle (0,0),(1,0),(0,1) CCW, test (1,1): outside */
    CHECK(pdt_incircle_sos(a, b, d, c) == -1);
    /* triangle (0,0),(1,1),(0,1) CCW, test (1,0): inside */
    CHECK(pdt_incircle_sos(a, c, d, b) == 1);
}

static int perm_sign(const int *q)
{
    int inv = 0;
    for (int i = 0; i < 4; i++)
        for (int j = i + 1; j < 4; j++) inv += q[i] > q[j];
    return inv & 1 ? -1 : 1;
}

static void check_sos_set(const pdt_point *s, int n, int *bad)
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            for (int k = 0; k < n; k++)
                for (int l = 0; l < n; l++) {
                    if (i == j || i == k || i == l || j == k || j == l || k == l) continue;
                    pdt_point a = s[i], b = s[j], c = s[k], d = s[l];
                    int v = pdt_incircle_sos(a, b, c, d);
                    int r = ref_sos(a, b, c, d);
                    int col = pdt_orient(a, b, c) == 0 && pdt_orient(a, b, d) == 0;
                    if (v != r || (v == 0) != col) (*bad)++;
                    /* antisymmetry under every permutation */
                    pdt_point q[4] = {a, b, c, d};
                    static const int perms[4][4] = {{1, 0, 2, 3}, {0, 2, 1, 3}, {3, 1, 2, 0},
                                                    {2, 3, 0, 1}};
                    for (int t = 0; t < 4; t++) {
                        int w = pdt_incircle_sos(q[perms[t][0]], q[perms[t][1]], q[perms[t][2]],
                                                 q[perms[t][3]]);
                        if (w != perm_sign(perms[t]) * v) (*bad)++;
                    }
                }
}

TEST(sos_grid_cocircular)
{
    pdt_point g[16];
    for (int i = 0; i < 16; i++) g[i] = P(i % 4, i / 4);
    int bad = 0;
    check_sos_set(g, 16, &bad);
    CHECK_MSG(bad == 0, "%d disagreements with the reference SoS", bad);
}

TEST(sos_lattice_circle_65)
{
    /* all 36 lattice points on x^2 + y^2 = 65^2 (checked by enumeration) */
    pdt_point c[64];
    int m = 0;
    for (int x = -65; x <= 65; x++)
        for (int y = -65; y <= 65; y++)
            if (x * x + y * y == 65 * 65) c[m++] = P(x, y);
    CHECK(m == 36);
    int bad = 0;
    check_sos_set(c, 12, &bad); /* a 12-point subset keeps the n^4 loop fast */
    pdt_point d[12];
    for (int i = 0; i < 12; i++) d[i] = c[3 * i];
    check_sos_set(d, 12, &bad);
    CHECK_MSG(bad == 0, "%d disagreements", bad);
    /* every quadruple of the circle is exactly cocircular */
    CHECK(pdt_incircle0(c[0], c[5], c[17], c[30]) == 0);
}

TEST(sos_random_small)
{
    int bad = 0;
    for (int it = 0; it < 20000; it++) {
        pdt_point p[4];
        for (int k = 0; k < 4; k++) p[k] = P((int64_t)(xr() % 5) - 2, (int64_t)(xr() % 5) - 2);
        int dup = 0;
        for (int i = 0; i < 4; i++)
            for (int j = i + 1; j < 4; j++) dup |= p[i].x == p[j].x && p[i].y == p[j].y;
        if (dup) continue;
        if (pdt_incircle_sos(p[0], p[1], p[2], p[3]) != ref_sos(p[0], p[1], p[2], p[3])) bad++;
    }
    CHECK_MSG(bad == 0, "%d disagreements", bad);
}

int main(void)
{
    RUN(orient_int32_extremes);
    RUN(incircle_int32_extremes);
    RUN(incircle_rectangle_corners_at_int32_limits);
    RUN(incircle_random_by_magnitude);
    RUN(incircle_is_lifted_orientation);
    RUN(sos_unit_square);
    RUN(sos_grid_cocircular);
    RUN(sos_lattice_circle_65);
    RUN(sos_random_small);
    return test_summary();
}
