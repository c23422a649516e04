/* Unit tests of the MPI-free building blocks of the parallel triangulation:
 * the restricted-area tests against exact arithmetic, the partition helpers
 * (radix sort, duplicates, splitters) and the merge schedule.
 *
 * The code under test comes from libpdtpar.a (src/par without MPI). */
#include "../harness.h"

#include <math.h>
#include <string.h>

#include "../../src/par/srm.h"

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static uint64_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}
static int32_t rndi(int32_t lo, int32_t hi) { return lo + (int32_t)(rnd() % (uint64_t)(hi - lo + 1)); }

/* ---- restricted areas ------------------------------------------------------- */

/* Exact: does the closed circumdisk of (a, b, c) meet the closed box?
 * Small coordinates only (|.| < 2^20) so that everything fits in int128. */
static int exact_touch(srm_pt a, srm_pt b, srm_pt c, const srm_strip *bx)
{
    __int128 bxx = b.x - a.x, byy = b.y - a.y, cxx = c.x - a.x, cyy = c.y - a.y;
    __int128 D = 2 * (bxx * cyy - byy * cxx);
    __int128 b2 = bxx * bxx + byy * byy, c2 = cxx * cxx + cyy * cyy;
    __int128 nx = cyy * b2 - byy * c2, ny = bxx * c2 - cxx * b2;
    if (D < 0) {
        D = -D;
        nx = -nx;
        ny = -ny;
    }
    /* centre = a + (nx, ny) / D; closest box point, coordinates relative to a */
    __int128 lo[2] = {bx->xmin - a.x, bx->ymin - a.y}, hi[2] = {bx->xmax - a.x, bx->ymax - a.y};
    __int128 nn[2] = {nx, ny}, cc[2];
    for (int k = 0; k < 2; k++) cc[k] = nn[k] < lo[k] * D ? lo[k] : nn[k] > hi[k] * D ? hi[k] : 0;
    /* inside the box in that coordinate: distance 0 there */
    __int128 dist = 0; /* D^2 * dist^2 */
    for (int k = 0; k < 2; k++) {
        __int128 diff = nn[k] < lo[k] * D || nn[k] > hi[k] * D ? cc[k] * D - nn[k] : 0;
        dist += diff * diff;
    }
    __int128 rho = nx * nx + ny * ny; /* D^2 * rho^2 */
    return dist <= rho;
}

TEST(touch_is_sound)
{
    int wrong = 0, tight = 0, checked = 0;
    for (int it = 0; it < 200000; it++) {
        int32_t R = it % 3 == 0 ? 20 : it % 3 == 1 ? 1000 : 1 << 19;
        srm_pt p[3];
        for (int k = 0; k < 3; k++) p[k] = (srm_pt){rndi(-R, R), rndi(-R, R), (uint32_t)k};
        __int128 o = (__int128)(p[1].x - p[0].x) * (p[2].y - p[0].y) -
                     (__int128)(p[1].y - p[0].y) * (p[2].x - p[0].x);
        if (o == 0) continue;
        if (o < 0) {
            srm_pt t = p[1];
            p[1] = p[2];
            p[2] = t;
        }
        srm_strip bx = {1, 0, 0, rndi(-2 * R, 2 * R), 0, rndi(-2 * R, 2 * R), 0};
        bx.xmax = bx.xmin + rndi(0, R);
        bx.ymax = bx.ymin + rndi(0, R);
        srm_disk d;
        pdt_srm_disk_of(&d, p[0], p[1], p[2]);
        int ex = exact_touch(p[0], p[1], p[2], &bx);
        int ap = pdt_srm_disk_touch(&d, &bx);
        checked++;
        if (ex && !ap) wrong++;
        if (ex == ap) tight++;
    }
    CHECK_MSG(wrong == 0, "%d of %d unsound answers", wrong, checked);
    CHECK_MSG(tight > checked * 99 / 100, "only %d of %d exact", tight, checked);
}

TEST(touch_cocircular_corner)
{
    /* (3,4), (-4,3), (5,0) lie on x^2 + y^2 = 25; boxes touching the circle
     * at exactly one point must count as touching (closed disk) */
    srm_pt a = {5, 0, 0}, b = {3, 4, 1}, c = {-4, 3, 2};
    srm_disk d;
    pdt_srm_disk_of(&d, a, b, c);
    srm_strip at = {1, 0, 0, 0, 3, -8, -5}; /* corner... top edge y = -5 at x = 0 */
    srm_strip off = {1, 0, 0, 0, 3, -8, -6};
    srm_strip corner = {1, 0, 0, 4, 9, -9, -3}; /* corner (4,-3) is on the circle */
    CHECK(pdt_srm_disk_touch(&d, &at));
    CHECK(pdt_srm_disk_touch(&d, &corner));
    CHECK(!pdt_srm_disk_touch(&d, &off));
    /* empty strips are never touched */
    srm_strip empty = {0, 0, 0, 0, 3, -8, -5};
    CHECK(!pdt_srm_disk_touch(&d, &empty));
    /* the hull-edge test: closed half-plane right of u->v */
    srm_pt u = {0, 0, 0}, v = {10, 0, 1};
    srm_strip below = {1, 0, 0, 2, 3, -5, -1}, on = {1, 0, 0, 2, 3, 0, 4}, above = {1, 0, 0, 2, 3, 1, 4};
    CHECK(pdt_srm_edge_touch(u, v, &below));
    CHECK(pdt_srm_edge_touch(u, v, &on));
    CHECK(!pdt_srm_edge_touch(u, v, &above));
}

/* Exact: does the closed circumdisk of (a, b, c) lie inside the open slab
 * xl < x < xr?  |coordinates| < 2^15 so that everything fits in int128. */
static int exact_in_slab(srm_pt a, srm_pt b, srm_pt c, int64_t xl, int64_t xr, int open_l,
                         int open_r)
{
    __int128 bxx = b.x - a.x, byy = b.y - a.y, cxx = c.x - a.x, cyy = c.y - a.y;
    __int128 D = 2 * (bxx * cyy - byy * cxx);
    __int128 b2 = bxx * bxx + byy * byy, c2 = cxx * cxx + cyy * cyy;
    __int128 nx = cyy * b2 - byy * c2, ny = bxx * c2 - cxx * b2;
    if (D < 0) {
        D = -D;
        nx = -nx;
        ny = -ny;
    }
    /* centre u = a + (nx, ny) / D, rho^2 = (nx^2 + ny^2) / D^2; inside iff
     * u.x - rho > xl and u.x + rho < xr, i.e. (u.x - xl)^2 > rho^2 with
     * u.x > xl, and the same on the right */
    __int128 rho2 = nx * nx + ny * ny, l = nx - (xl - a.x) * D, r = (xr - a.x) * D - nx;
    return (open_l || (l > 0 && l * l > rho2)) && (open_r || (r > 0 && r * r > rho2));
}

TEST(slab_pretest_is_sound)
{
    int wrong = 0, yes = 0, easy = 0, easy_yes = 0, checked = 0;
    for (int it = 0; it < 300000; it++) {
        int32_t R = it % 3 == 0 ? 30 : it % 3 == 1 ? 500 : 1 << 13;
        srm_pt p[3];
        for (int k = 0; k < 3; k++) p[k] = (srm_pt){rndi(-R, R), rndi(-R, R), (uint32_t)k};
        __int128 o = (__int128)(p[1].x - p[0].x) * (p[2].y - p[0].y) -
                     (__int128)(p[1].y - p[0].y) * (p[2].x - p[0].x);
        if (o == 0) continue;
        int64_t xl = rndi(-3 * R, R), xr = xl + rndi(0, 4 * R);
        srm_slab sl = {(double)xl, (double)xr, -INFINITY, INFINITY};
        if (it % 7 == 0) sl.xl = -INFINITY; /* one side open */
        if (it % 11 == 0) sl.xr = INFINITY;
        int ap = srm_disk_in_slab(&sl, p[0], p[1], p[2]);
        int ex = exact_in_slab(p[0], p[1], p[2], xl, xr, it % 7 == 0, it % 11 == 0);
        checked++;
        yes += ap;
        if (ap && !ex) wrong++;
        /* a small fat triangle deep inside a wide slab: must be settled */
        srm_pt q[3] = {{0, 0, 0}, {rndi(5, 20), rndi(-3, 3), 1}, {rndi(-3, 3), rndi(5, 20), 2}};
        srm_slab wide = {-1000.0, 1000.0, -INFINITY, INFINITY};
        easy++;
        easy_yes += srm_disk_in_slab(&wide, q[0], q[1], q[2]);
    }
    /* far outside the int64 range of the pre-test: says nothing */
    srm_pt big[3] = {{-(1 << 30), 0, 0}, {1 << 30, 0, 1}, {0, 1 << 30, 2}};
    srm_slab all = {-INFINITY, INFINITY, -INFINITY, INFINITY};
    CHECK(!srm_disk_in_slab(&all, big[0], big[1], big[2]));
    CHECK_MSG(wrong == 0, "%d of %d unsound answers", wrong, checked);
    CHECK_MSG(yes > checked / 20, "only %d of %d settled", yes, checked);
    CHECK_MSG(easy_yes == easy, "%d of %d easy triangles settled", easy_yes, easy);
}

/* The slab of a rank: from the nearest non-empty strips on either side. */
TEST(slab_of_strips)
{
    srm_strip st[5] = {{3, 0, 0, -50, -10, 0, 9}, {0, 0, 0, 0, 0, 0, 0}, {4, 0, 0, -10, 20, 5, 6},
                       {0, 0, 0, 0, 0, 0, 0}, {2, 0, 0, 40, 41, 0, 1}};
    srm_slab sl;
    pdt_srm_slab_of(&sl, st, 5, 2);
    CHECK(sl.xl == -10.0 && sl.xr == 40.0);
    pdt_srm_slab_of(&sl, st, 5, 0);
    CHECK(isinf(sl.xl) && sl.xl < 0 && sl.xr == -10.0);
    pdt_srm_slab_of(&sl, st, 5, 4);
    CHECK(sl.xl == 20.0 && isinf(sl.xr) && sl.xr > 0);
    pdt_srm_slab_of(&sl, st, 1, 0);
    CHECK(isinf(sl.xl) && isinf(sl.xr));
}

/* ---- partition helpers and schedule ------------------------------------------ */

/* pdt_srm_runs_to_strip: k = 1..7 key-sorted runs with keys repeated within
 * and across runs: the same points and indices as pdt_srm_merge_runs, then
 * pdt_srm_dedupe, then each record's point. */
TEST(runs_to_strip_same_as_merge_dedupe)
{
    enum { N = 3000 };
    srm_rec *r = malloc(N * sizeof *r), *t = malloc(N * sizeof *t), *r2 = malloc(N * sizeof *r2);
    pdt_point *pt = malloc(N * sizeof *pt);
    uint32_t *g = malloc(N * sizeof *g);
    int bad = 0;
    for (int k = 1; k <= 7; k++)
        for (int it = 0; it < 20; it++) {
            size_t start[9], n = 0;
            for (int q = 0; q < k; q++) {
                start[q] = n;
                size_t len = rnd() % (N / 8);
                for (size_t i = 0; i < len; i++) {
                    pdt_point p = {rndi(-20, 20), rndi(-3, 3)};
                    r[n + i] = (srm_rec){pdt_key(p), (uint32_t)(n + i), 0};
                }
                pdt_srm_radix_sort(r + n, t, len);
                n += len;
            }
            start[k] = n;
            size_t s2[9];
            memcpy(s2, start, sizeof s2);
            memcpy(r2, r, n * sizeof *r);
            size_t m = pdt_srm_runs_to_strip(r, t, start, k, pt, g);
            srm_rec *want = pdt_srm_merge_runs(r2, t, s2, k);
            size_t mw = pdt_srm_dedupe(want, n);
            if (m != mw) bad++;
            for (size_t i = 0; i < m && i < mw; i++) {
                pdt_point w = srm_key_point(want[i].key);
                if (pt[i].x != w.x || pt[i].y != w.y || g[i] != want[i].idx) bad++;
            }
        }
    CHECK_MSG(bad == 0, "%d differences", bad);
    free(r);
    free(t);
    free(r2);
    free(pt);
    free(g);
}

TEST(radix_sort_stable_dedupe)
{
    size_t n = 50000;
    srm_rec *r = malloc(n * sizeof *r), *t = malloc(n * sizeof *t);
    for (size_t i = 0; i < n; i++) {
        pdt_point p = {rndi(-30, 30), rndi(-3, 3)};
        if (i % 7 == 0) p.x = (int32_t)(rnd() >> 33) * (rnd() & 1 ? 1 : -1);
        r[i] = (srm_rec){pdt_key(p), (uint32_t)i, 0};
    }
    pdt_srm_radix_sort(r, t, n);
    int bad = 0;
    for (size_t i = 1; i < n; i++) {
        pdt_point a = srm_key_point(r[i - 1].key), b = srm_key_point(r[i].key);
        int c = pdt_lex_cmp(a, b);
        if (c > 0 || (c == 0 && r[i - 1].idx >= r[i].idx)) bad++;
    }
    CHECK_MSG(bad == 0, "%d out of order", bad);
    size_t m = pdt_srm_dedupe(r, n);
    for (size_t i = 1; i < m; i++) CHECK(r[i - 1].key < r[i].key);
    free(r);
    free(t);
}

TEST(radix_sort_every_small_size)
{
    /* sizes around the insertion sort's limit and one key repeated (no
     * pass at all): sorted by key, equal keys in their input order */
    for (size_t n = 0; n <= 130; n++)
        for (int same = 0; same < 2; same++) {
            srm_rec r[130], t[130];
            for (size_t i = 0; i < n; i++) {
                pdt_point p = same ? (pdt_point){7, -3} : (pdt_point){rndi(-5, 5), rndi(-1000, 1000)};
                r[i] = (srm_rec){pdt_key(p), (uint32_t)i, 0};
            }
            pdt_srm_radix_sort(r, t, n);
            int bad = 0;
            for (size_t i = 1; i < n; i++)
                bad += r[i - 1].key > r[i].key || (r[i - 1].key == r[i].key && r[i - 1].idx >= r[i].idx);
            CHECK_MSG(bad == 0, "n = %zu%s: %d out of order", n, same ? ", one key" : "", bad);
        }
}

TEST(merge_runs_stable)
{
    /* three sorted runs with shared keys: the merge is sorted and keeps run
     * order on equal keys (the smallest index first, as the partition needs) */
    srm_rec r[9] = {{1, 0, 0}, {5, 1, 0}, {9, 2, 0}, {5, 10, 0}, {7, 11, 0},
                    {1, 20, 0}, {5, 21, 0}, {9, 22, 0}, {9, 23, 0}};
    srm_rec t[9];
    size_t start[4] = {0, 3, 5, 9};
    srm_rec *m = pdt_srm_merge_runs(r, t, start, 3);
    const uint32_t want[9] = {0, 20, 1, 10, 21, 11, 2, 22, 23};
    for (int i = 0; i < 9; i++) CHECK_MSG(m[i].idx == want[i], "position %d: %u", i, m[i].idx);
    CHECK(pdt_srm_count_lt(m, 9, 5) == 2);
    CHECK(pdt_srm_count_lt(m, 9, 6) == 5);
    CHECK(pdt_srm_count_lt(m, 9, 0) == 0);
    CHECK(pdt_srm_count_lt(m, 9, 10) == 9);
}

TEST(schedule)
{
    int gl, gr, ge;
    CHECK(pdt_srm_pair(1, 5, 0, &gl, &gr, &ge) && gl == 0 && gr == 1 && ge == 2);
    CHECK(!pdt_srm_pair(4, 5, 0, &gl, &gr, &ge));
    CHECK(!pdt_srm_pair(4, 5, 1, &gl, &gr, &ge));
    CHECK(pdt_srm_pair(4, 5, 2, &gl, &gr, &ge) && gl == 0 && gr == 4 && ge == 5);
    CHECK(pdt_srm_pair(6, 7, 1, &gl, &gr, &ge) && gl == 4 && gr == 6 && ge == 7);
    CHECK(pdt_srm_holder(3, 8, 2) == 2);
    CHECK(pdt_srm_holder(0, 8, 3) == 4);
    CHECK(pdt_srm_holder(4, 5, 2) == 4);
    CHECK(pdt_srm_holder(0, 5, 3) == 4);
    CHECK(pdt_srm_holder(5, 6, 2) == 5 && pdt_srm_holder(0, 6, 3) == 4);
    CHECK(pdt_srm_ceil_log2(1) == 0 && pdt_srm_ceil_log2(2) == 1 && pdt_srm_ceil_log2(5) == 3);
}

int main(void)
{
    RUN(touch_is_sound);
    RUN(touch_cocircular_corner);
    RUN(slab_pretest_is_sound);
    RUN(slab_of_strips);
    RUN(radix_sort_stable_dedupe);
    RUN(radix_sort_every_small_size);
    RUN(runs_to_strip_same_as_merge_dedupe);
    RUN(merge_runs_stable);
    RUN(schedule);
    return test_summary();
}
