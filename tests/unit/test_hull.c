/* Graham's scan (Version B) and the monotone chain: the thesis' cases, the
 * exact trace of a small example, and random sets against brute force. */
#include "../harness.h"
#include "pdt/hull.h"
#include "pdt/predicates.h"

#include <string.h>

static pdt_point P(int x, int y)
{
    pdt_point p = {x, y};
    return p;
}

static uint64_t rs = 0x2545F4914F6CDD1Du;
static uint64_t xr(void) { return th_xorshift(&rs); }

static int same(pdt_point a, pdt_point b)
{
    return a.x == b.x && a.y == b.y;
}

/* p lies in the closed segment ab (a != b) */
static int on_seg(pdt_point a, pdt_point b, pdt_point p)
{
    if (pdt_orient(a, b, p) != 0) return 0;
    return (p.x - (int64_t)a.x) * (p.x - (int64_t)b.x) <= 0 &&
           (p.y - (int64_t)a.y) * (p.y - (int64_t)b.y) <= 0;
}

/* Brute force: p = pts[i] is an extreme point iff it is in no closed triangle
 * or segment of points with other coordinates. */
static int brute_extreme(const pdt_point *pts, int n, int i)
{
    pdt_point p = pts[i];
    for (int a = 0; a < n; a++) {
        if (same(pts[a], p)) continue;
        for (int b = a + 1; b < n; b++) {
            if (same(pts[b], p) || same(pts[b], pts[a])) continue;
            if (on_seg(pts[a], pts[b], p)) return 0;
            for (int c = b + 1; c < n; c++) {
                if (same(pts[c], p)) continue;
                int o = pdt_orient(pts[a], pts[b], pts[c]);
                if (o == 0) continue;
                int s1 = pdt_orient(pts[a], pts[b], p), s2 = pdt_orient(pts[b], pts[c], p),
                    s3 = pdt_orient(pts[c], pts[a], p);
                if (s1 * o >= 0 && s2 * o >= 0 && s3 * o >= 0) return 0;
            }
        }
    }
    return 1;
}

/* p is on the boundary of the hull (extreme or on a hull edge) */
static int brute_boundary(const pdt_point *pts, int n, pdt_point p)
{
    for (int a = 0; a < n; a++)
        for (int b = 0; b < n; b++) {
            if (same(pts[a], pts[b])) continue;
            int left = 0, right = 0;
            for (int c = 0; c < n; c++) {
                int o = pdt_orient(pts[a], pts[b], pts[c]);
                left += o > 0;
                right += o < 0;
            }
            if (right == 0 && left > 0 && on_seg(pts[a], pts[b], p)) return 1;
        }
    return 0;
}

static void rand_pts(pdt_point *p, int n, int range)
{
    for (int i = 0; i < n; i++) p[i] = P((int)(xr() % (uint64_t)range), (int)(xr() % (uint64_t)range));
}

TEST(graham_square_with_side_points)
{
    /* thesis §2.1.3: the corners of a square with points along its sides give
     * just the four corners */
    pdt_point p[] = {P(0, 0), P(1, 0), P(2, 0), P(3, 0), P(4, 0), P(4, 1), P(4, 2), P(4, 3),
                     P(4, 4), P(3, 4), P(2, 4), P(1, 4), P(0, 4), P(0, 3), P(0, 2), P(0, 1),
                     P(2, 2), P(1, 3)};
    uint32_t out[18];
    size_t m;
    CHECK(pdt_hull_graham(p, 18, out, &m, NULL) == PDT_OK);
    CHECK_MSG(m == 4, "m = %zu", m);
    if (m == 4) {
        CHECK(out[0] == 4);  /* rightmost lowest (4,0) */
        CHECK(out[1] == 8);
        CHECK(out[2] == 12);
        CHECK(out[3] == 0);
    }
}

TEST(graham_trace_small_example)
{
    pdt_point p[] = {P(2, 2), P(0, 0), P(4, 0), P(4, 4), P(0, 4), P(2, 1)};
    pdt_trace tr;
    pdt_trace_buf buf;
    pdt_trace_buf_init(&tr, &buf, 1, 0);
    uint32_t out[6];
    size_t m;
    CHECK(pdt_hull_graham(p, 6, out, &m, &tr) == PDT_OK);
    CHECK(m == 4 && out[0] == 2 && out[1] == 3 && out[2] == 4 && out[3] == 1);
    /* kind, sub, a, b, c */
    static const uint32_t want[][5] = {
        {PDT_EV_PHASE_BEGIN, PDT_PH_GRAHAM_SORT, 0, 0, 0},
        {PDT_EV_SORT, 0, 2, 0, 0}, {PDT_EV_SORT, 0, 3, 1, 0}, {PDT_EV_SORT, 0, 0, 2, 0},
        {PDT_EV_SORT, 0, 4, 3, 0}, {PDT_EV_SORT, 0, 5, 4, 0}, {PDT_EV_SORT, 0, 1, 5, 0},
        {PDT_EV_DELETE, PDT_DEL_ANGULAR_TIE, 0, 4, 0},
        {PDT_EV_PHASE_END, PDT_PH_GRAHAM_SORT, 0, 0, 0},
        {PDT_EV_PHASE_BEGIN, PDT_PH_GRAHAM_SCAN, 0, 0, 0},
        {PDT_EV_PUSH, PDT_STACK_GRAHAM, 2, 1, 0}, {PDT_EV_PUSH, PDT_STACK_GRAHAM, 3, 2, 0},
        {PDT_EV_PUSH, PDT_STACK_GRAHAM, 4, 3, 0}, {PDT_EV_PUSH, PDT_STACK_GRAHAM, 5, 4, 0},
        {PDT_EV_POP, PDT_STACK_GRAHAM, 5, 3, 1},  {PDT_EV_PUSH, PDT_STACK_GRAHAM, 1, 4, 0},
        {PDT_EV_PHASE_END, PDT_PH_GRAHAM_SCAN, 0, 0, 0}};
    size_t nw = sizeof want / sizeof *want;
    CHECK_MSG(buf.n == nw, "%zu events, want %zu", buf.n, nw);
    for (size_t i = 0; i < nw && i < buf.n; i++) {
        const pdt_event *e = &buf.ev[i];
        CHECK_MSG(e->kind == want[i][0] && e->sub == want[i][1] && e->a == want[i][2] &&
                      e->b == want[i][3] && e->c == want[i][4],
                  "event %zu: %s %u %u %u %u", i, pdt_event_kind_name(e->kind), e->sub, e->a, e->b,
                  e->c);
    }
    pdt_trace_buf_free(&buf);
}

TEST(graham_angular_ties_and_coincident)
{
    /* a ray from the origin with three points, and copies */
    pdt_point p[] = {P(0, 0), P(1, 1), P(2, 2), P(3, 3), P(2, 2), P(-3, 3), P(0, 0), P(3, 3)};
    pdt_trace tr;
    pdt_trace_buf buf;
    pdt_trace_buf_init(&tr, &buf, 1, 0);
    uint32_t out[8];
    size_t m;
    CHECK(pdt_hull_graham(p, 8, out, &m, &tr) == PDT_OK);
    CHECK_MSG(m == 3, "m = %zu", m);
    /* origin: first rightmost lowest = index 0; copy 6 deleted as coincident;
     * on the ray (1,1)..(3,3) only (3,3) stays, and of its copies 3 and 7
     * the higher index 7 (the thesis deletes the lower index) */
    CHECK(m == 3 && out[0] == 0 && out[1] == 7 && out[2] == 5);
    int ties = 0, coinc = 0;
    for (size_t i = 0; i < buf.n; i++)
        if (buf.ev[i].kind == PDT_EV_DELETE) {
            if (buf.ev[i].sub == PDT_DEL_ANGULAR_TIE) {
                ties++;
                CHECK(buf.ev[i].b == 7);
            } else {
                coinc++;
                CHECK((buf.ev[i].a == 6 && buf.ev[i].b == 0) || (buf.ev[i].a == 3 && buf.ev[i].b == 7));
            }
        }
    CHECK_MSG(ties == 3 && coinc == 2, "ties %d coincident %d", ties, coinc);
    pdt_trace_buf_free(&buf);
}

TEST(graham_degenerate)
{
    uint32_t out[8];
    size_t m = 99;
    CHECK(pdt_hull_graham(NULL, 0, out, &m, NULL) == PDT_OK && m == 0);
    pdt_point one[] = {P(5, 5), P(5, 5), P(5, 5)};
    CHECK(pdt_hull_graham(one, 3, out, &m, NULL) == PDT_OK && m == 1 && out[0] == 0);
    pdt_point line[] = {P(0, 0), P(3, 3), P(1, 1), P(2, 2), P(-1, -1)};
    CHECK(pdt_hull_graham(line, 5, out, &m, NULL) == PDT_OK && m == 2 && out[0] == 4 && out[1] == 1);
    pdt_point hline[] = {P(0, 7), P(3, 7), P(1, 7)};
    CHECK(pdt_hull_graham(hline, 3, out, &m, NULL) == PDT_OK && m == 2 && out[0] == 1 && out[1] == 0);
    pdt_point extremes[] = {P(INT32_MIN, INT32_MIN), P(INT32_MAX, INT32_MIN),
                            P(INT32_MAX, INT32_MAX), P(INT32_MIN, INT32_MAX), P(0, 0)};
    CHECK(pdt_hull_graham(extremes, 5, out, &m, NULL) == PDT_OK && m == 4 && out[0] == 1);
}

TEST(graham_random_vs_brute_force)
{
    pdt_point p[40];
    uint32_t out[40];
    int bad = 0;
    for (int it = 0; it < 600; it++) {
        int n = 1 + (int)(xr() % 30);
        rand_pts(p, n, it % 2 ? 6 : 1000);
        size_t m;
        if (pdt_hull_graham(p, (size_t)n, out, &m, NULL) != PDT_OK) { bad++; continue; }
        /* output: exactly the extreme points (one index per location), CCW,
         * strictly convex, starting at the rightmost lowest */
        int nextreme = 0;
        for (int i = 0; i < n; i++) {
            int first = 1;
            for (int j = 0; j < i; j++) first &= !same(p[i], p[j]);
            if (first && brute_extreme(p, n, i)) nextreme++;
        }
        if ((int)m != nextreme) bad++;
        for (size_t k = 0; k < m; k++) {
            if (!brute_extreme(p, n, (int)out[k])) bad++;
            if (m >= 3 && pdt_orient(p[out[k]], p[out[(k + 1) % m]], p[out[(k + 2) % m]]) <= 0) bad++;
            if (p[out[k]].y < p[out[0]].y || (p[out[k]].y == p[out[0]].y && p[out[k]].x > p[out[0]].x)) bad++;
        }
    }
    CHECK_MSG(bad == 0, "%d failures", bad);
}

static int lexcmp_pts(const void *a, const void *b)
{
    return pdt_lex_cmp(*(const pdt_point *)a, *(const pdt_point *)b);
}

TEST(chain_keeps_collinear_boundary_points)
{
    pdt_point p[] = {P(0, 0), P(0, 1), P(0, 2), P(1, 0), P(1, 1), P(2, 0), P(2, 2)};
    /* sorted; hull CCW from (0,0): (1,0) on the bottom edge, (2,0), (2,2),
     * (0,2), then (0,1) on the left edge; (1,1) is inside */
    uint32_t out[8];
    size_t m;
    int deg;
    CHECK(pdt_hull_chain(p, 7, out, &m, &deg, PDT_STACK_LOWER, PDT_STACK_UPPER, NULL) == PDT_OK);
    static const uint32_t want[] = {0, 3, 5, 6, 2, 1};
    CHECK_MSG(m == 6 && !deg, "m %zu deg %d", m, deg);
    for (size_t k = 0; k < 6 && k < m; k++) CHECK_MSG(out[k] == want[k], "out[%zu] = %u", k, out[k]);
}

TEST(chain_all_collinear_is_degenerate)
{
    pdt_point p[] = {P(0, 0), P(1, 2), P(2, 4), P(3, 6)};
    uint32_t out[5];
    size_t m;
    int deg;
    CHECK(pdt_hull_chain(p, 4, out, &m, &deg, PDT_STACK_LOWER, PDT_STACK_UPPER, NULL) == PDT_OK);
    CHECK(deg == 1 && m == 4 && out[0] == 0 && out[3] == 3);
    pdt_point v[] = {P(5, 0), P(5, 1), P(5, 9)};
    CHECK(pdt_hull_chain(v, 3, out, &m, &deg, PDT_STACK_LOWER, PDT_STACK_UPPER, NULL) == PDT_OK);
    CHECK(deg == 1 && m == 3);
    CHECK(pdt_hull_chain(v, 2, out, &m, &deg, PDT_STACK_LOWER, PDT_STACK_UPPER, NULL) == PDT_OK);
    CHECK(deg == 1 && m == 2);
    CHECK(pdt_hull_chain(v, 0, out, &m, &deg, PDT_STACK_LOWER, PDT_STACK_UPPER, NULL) == PDT_OK);
    CHECK(deg == 1 && m == 0);
}

TEST(chain_random_vs_brute_force)
{
    pdt_point p[40];
    uint32_t out[41];
    int bad = 0;
    for (int it = 0; it < 600; it++) {
        int n = 1 + (int)(xr() % 30);
        rand_pts(p, n, it % 2 ? 5 : 1000);
        qsort(p, (size_t)n, sizeof *p, lexcmp_pts);
        int u = 0; /* dedupe */
        for (int i = 0; i < n; i++)
            if (u == 0 || !same(p[u - 1], p[i])) p[u++] = p[i];
        n = u;
        size_t m;
        int deg;
        pdt_trace tr;
        pdt_trace_buf buf;
        pdt_trace_buf_init(&tr, &buf, 1, 0);
        if (pdt_hull_chain(p, (size_t)n, out, &m, &deg, PDT_STACK_LOWER, PDT_STACK_UPPER, &tr) != PDT_OK) {
            bad++;
            continue;
        }
        int col = 1;
        for (int i = 2; i < n; i++) col &= pdt_orient(p[0], p[1], p[i]) == 0;
        if (deg != (n <= 2 || col)) bad++;
        if (!deg) {
            int nb = 0;
            for (int i = 0; i < n; i++) nb += brute_boundary(p, n, p[i]);
            if ((int)m != nb) bad++;
            if (out[0] != 0) bad++;
            for (size_t k = 0; k < m; k++) {
                if (!brute_boundary(p, n, p[out[k]])) bad++;
                if (pdt_orient(p[out[k]], p[out[(k + 1) % m]], p[out[(k + 2) % m]]) < 0) bad++;
            }
        }
        /* untraced (no calls per step): the same hull */
        uint32_t out2[41];
        size_t m2;
        int deg2;
        if (pdt_hull_chain(p, (size_t)n, out2, &m2, &deg2, PDT_STACK_LOWER, PDT_STACK_UPPER,
                           NULL) != PDT_OK ||
            m2 != m || deg2 != deg || memcmp(out, out2, m * sizeof *out) != 0)
            bad++;
        /* pushes - pops = final stack sizes; every event on the two stacks */
        long pushes = 0, pops = 0;
        for (size_t i = 0; i < buf.n; i++) {
            pushes += buf.ev[i].kind == PDT_EV_PUSH;
            pops += buf.ev[i].kind == PDT_EV_POP;
            if (buf.ev[i].sub != PDT_STACK_LOWER && buf.ev[i].sub != PDT_STACK_UPPER) bad++;
        }
        if (n > 2 && pushes != 2L * n) bad++;
        if (!deg && pushes - pops != (long)m + 2) bad++;
        pdt_trace_buf_free(&buf);
    }
    CHECK_MSG(bad == 0, "%d failures", bad);
}

/* Stacks longer than their first allocation (4096): 10 000 points on a line
 * (degenerate: all of them), then with one point above (all on the hull,
 * the line's points as the lower chain), traced and untraced alike. */
TEST(chain_long_stacks_grow)
{
    enum { N = 10000 };
    pdt_point *p = malloc((N + 1) * sizeof *p);
    uint32_t *out = malloc((N + 2) * sizeof *out), *out2 = malloc((N + 2) * sizeof *out2);
    for (int i = 0; i < N; i++) p[i] = (pdt_point){i, 2 * i};
    size_t m, m2;
    int deg, deg2;
    CHECK(pdt_hull_chain(p, N, out, &m, &deg, PDT_STACK_LOWER, PDT_STACK_UPPER, NULL) == PDT_OK);
    CHECK(deg == 1 && m == N);
    for (int i = 0; i < N; i++) p[i] = (pdt_point){i, 0};
    p[N] = (pdt_point){N, 5}; /* lex-sorted: last */
    pdt_trace tr;
    pdt_trace_buf buf;
    pdt_trace_buf_init(&tr, &buf, 1, 0);
    CHECK(pdt_hull_chain(p, N + 1, out, &m, &deg, PDT_STACK_LOWER, PDT_STACK_UPPER, &tr) ==
          PDT_OK);
    CHECK(pdt_hull_chain(p, N + 1, out2, &m2, &deg2, PDT_STACK_LOWER, PDT_STACK_UPPER, NULL) ==
          PDT_OK);
    CHECK_MSG(deg == 0 && m == N + 1, "deg %d, %zu on the hull", deg, m);
    CHECK(deg2 == deg && m2 == m && memcmp(out, out2, m * sizeof *out) == 0);
    pdt_trace_buf_free(&buf);
    free(p);
    free(out);
    free(out2);
}

int main(void)
{
    RUN(graham_square_with_side_points);
    RUN(chain_long_stacks_grow);
    RUN(graham_trace_small_example);
    RUN(graham_angular_ties_and_coincident);
    RUN(graham_degenerate);
    RUN(graham_random_vs_brute_force);
    RUN(chain_keeps_collinear_boundary_points);
    RUN(chain_all_collinear_is_degenerate);
    RUN(chain_random_vs_brute_force);
    return test_summary();
}
