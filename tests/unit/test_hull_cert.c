/* pdt_hull_certify (src/trace/hullcert.h) accepts exactly what
 * pdt_hull_graham writes: its output on random, degenerate and generated
 * sets is accepted, and every other stack tried (all short stacks over tiny
 * sets, and edits of the true stack on larger ones) is rejected.  Also the
 * growable temporary file mapping the check's stacks go to. */
#include <string.h>
#include <sys/mman.h>

#include "../harness.h"
#include "pdt/bigmem.h"
#include "../../src/trace/hullcert.h"
#include "pdt/gen.h"
#include "pdt/hull.h"
#include "pdt/predicates.h"

static uint64_t rs = 0x9E3779B97F4A7C15u;
static uint64_t xr(void) { return th_xorshift(&rs); }

/* n points on a (side x side) grid offset by (x0, y0): many copies and
 * collinear points when side is small. */
static void grid_set(pdt_point *p, size_t n, int side, int32_t x0, int32_t y0)
{
    for (size_t i = 0; i < n; i++)
        p[i] = (pdt_point){x0 + (int32_t)(xr() % (uint64_t)side),
                           y0 + (int32_t)(xr() % (uint64_t)side)};
}

static pdt_status cert(const pdt_point *p, size_t n, const uint32_t *s, size_t h, char *msg)
{
    pdt_err err = {0};
    pdt_status st = pdt_hull_certify(p, n, s, h, NULL, NULL, &err);
    if (msg) strcpy(msg, st == PDT_OK ? "" : err.msg);
    CHECK_MSG(st == PDT_OK || (st == PDT_ERR_CHECK && err.msg[0]), "status %d", st);
    return st;
}

static int equal(const uint32_t *a, size_t na, const uint32_t *b, size_t nb)
{
    return na == nb && (na == 0 || memcmp(a, b, na * sizeof *a) == 0);
}

/* pdt_hull_graham's output of p[0..n) into out (n entries); its length. */
static size_t graham(const pdt_point *p, size_t n, uint32_t *out)
{
    size_t h = 0;
    CHECK(pdt_hull_graham(p, n, out, &h, NULL) == PDT_OK);
    return h;
}

/* The certificate's verdict on s equals "s is Graham's output g". */
static int agrees(const pdt_point *p, size_t n, const uint32_t *s, size_t h, const uint32_t *g,
                  size_t ng)
{
    int want = equal(s, h, g, ng);
    int got = cert(p, n, s, h, NULL) == PDT_OK;
    return want == got;
}

TEST(accepts_graham_output)
{
    enum { N = 64 };
    pdt_point p[N];
    uint32_t g[N];
    char msg[1024];
    for (int round = 0; round < 4000; round++) {
        size_t n = xr() % (N + 1);
        int side = 1 + (int)(xr() % 9);
        /* near the int32 extremes too: the predicates' range */
        int32_t x0 = round % 3 == 0 ? INT32_MIN : round % 3 == 1 ? 0 : INT32_MAX - side;
        grid_set(p, n, side, x0, round % 2 ? INT32_MAX - side : -4);
        size_t h = graham(p, n, g);
        CHECK_MSG(cert(p, n, g, h, msg) == PDT_OK, "round %d (n=%zu side %d): %s", round, n, side,
                  msg);
    }
    /* every generator family */
    const char *const *kinds = pdt_gen_kinds();
    for (int k = 0; kinds[k]; k++) {
        pdt_point *q;
        pdt_err err = {0};
        size_t n = 3000;
        CHECK(pdt_gen(kinds[k], n, 5, &q, &err) == PDT_OK);
        uint32_t *out = malloc(n * sizeof *out);
        size_t h = graham(q, n, out);
        CHECK_MSG(cert(q, n, out, h, msg) == PDT_OK, "%s: %s", kinds[k], msg);
        free(out);
        free(q);
    }
}

/* Every stack of up to 4 indices (repeats allowed) over tiny sets, the
 * degenerate ones included: only Graham's output passes. */
TEST(rejects_every_other_short_stack)
{
    enum { N = 6 };
    pdt_point p[N];
    uint32_t g[N], s[4];
    for (int round = 0; round < 300; round++) {
        size_t n = (size_t)(round % (N + 1));
        grid_set(p, n, 1 + round % 3, 0, 0);
        size_t ng = graham(p, n, g);
        size_t total = 1, tried = 0;
        for (size_t h = 0; h <= 4; h++, total *= n) {
            for (size_t code = 0; code < total; code++, tried++) {
                size_t c = code;
                for (size_t k = 0; k < h; k++, c /= n) s[k] = (uint32_t)(c % n);
                CHECK_MSG(agrees(p, n, s, h, g, ng), "round %d n=%zu: stack of %zu", round, n, h);
            }
            if (n == 0) break;
        }
        CHECK(tried > 0);
    }
}

/* Edits of Graham's output on larger sets: each one is rejected (unless it
 * happens to give the same stack). */
TEST(rejects_edited_stacks)
{
    enum { N = 48 };
    pdt_point p[N];
    uint32_t g[N], s[N + 1];
    for (int round = 0; round < 3000; round++) {
        size_t n = 1 + xr() % N;
        grid_set(p, n, 2 + (int)(xr() % 12), -3, 5);
        size_t ng = graham(p, n, g);
        for (int edit = 0; edit < 8; edit++) {
            size_t h = ng, k = ng ? xr() % ng : 0;
            memcpy(s, g, ng * sizeof *g);
            uint32_t any = (uint32_t)(xr() % n);
            switch (edit) {
            case 0: /* a corner dropped */
                if (!ng) continue;
                memmove(s + k, s + k + 1, (ng - k - 1) * sizeof *s);
                h--;
                break;
            case 1: /* a point inserted */
                k = xr() % (ng + 1);
                memmove(s + k + 1, s + k, (ng - k) * sizeof *s);
                s[k] = any;
                h++;
                break;
            case 2: /* a corner replaced by any point */
                if (!ng) continue;
                s[k] = any;
                break;
            case 3: /* a corner replaced by another copy of it */
                if (!ng) continue;
                for (uint32_t i = 0; i < n; i++)
                    if (i != s[k] && p[i].x == p[s[k]].x && p[i].y == p[s[k]].y) s[k] = i;
                break;
            case 4: /* started one corner later */
                for (size_t i = 0; i < ng; i++) s[i] = g[(i + 1) % ng];
                break;
            case 5: /* clockwise */
                for (size_t i = 1; i < ng; i++) s[i] = g[ng - i];
                break;
            case 6: /* two neighbours swapped */
                if (ng < 2) continue;
                k = xr() % (ng - 1);
                s[k] = g[k + 1];
                s[k + 1] = g[k];
                break;
            default: /* a point of a side (not a corner) kept between its corners */
                if (ng < 2) continue;
                for (uint32_t i = 0; i < n; i++) {
                    pdt_point a = p[g[k]], b = p[g[(k + 1) % ng]], q = p[i];
                    if (pdt_orient(a, b, q) == 0 && (q.x - (int64_t)a.x) * (q.x - (int64_t)b.x) <= 0 &&
                        (q.y - (int64_t)a.y) * (q.y - (int64_t)b.y) <= 0 &&
                        !(q.x == a.x && q.y == a.y) && !(q.x == b.x && q.y == b.y)) {
                        memmove(s + k + 2, s + k + 1, (ng - k - 1) * sizeof *s);
                        s[k + 1] = i;
                        h++;
                        break;
                    }
                }
                break;
            }
            CHECK_MSG(agrees(p, n, s, h, g, ng), "round %d n=%zu edit %d", round, n, edit);
        }
    }
}

/* Each condition broken on purpose is named. */
TEST(names_what_fails)
{
    /* a square with a point in the middle of each side, a point inside and
     * copies: Graham writes 4 (origin), 2, 6, 0 */
    pdt_point p[10] = {{0, 4}, {2, 0}, {4, 4}, {2, 4}, {4, 0}, {2, 2}, {4, 4}, {0, 0}, {4, 0}, {0, 2}};
    uint32_t g[10];
    char msg[1024];
    size_t h = graham(p, 10, g);
    uint32_t want[4] = {4, 6, 0, 7};
    CHECK_MSG(equal(g, h, want, 4), "h=%zu %u %u %u %u", h, g[0], g[1], g[2], g[3]);
    CHECK(cert(p, 10, want, 4, msg) == PDT_OK);

    uint32_t later0[4] = {8, 6, 0, 7};  /* a later copy of the origin */
    CHECK(cert(p, 10, later0, 4, msg) == PDT_ERR_CHECK &&
          strstr(msg, "is not the first copy of the rightmost lowest point: pt 4 is an earlier copy"));
    uint32_t early[4] = {4, 2, 0, 7};  /* an earlier copy of a corner */
    CHECK(cert(p, 10, early, 4, msg) == PDT_ERR_CHECK &&
          strstr(msg, "pt 6 is a later copy of its point pt 2 at position 1"));
    uint32_t side[5] = {4, 6, 3, 0, 7};  /* a point in the middle of a side */
    CHECK_MSG(cert(p, 10, side, 5, msg) == PDT_ERR_CHECK &&
              strstr(msg, "no strict left turn at position 2 (pts 6 3 0)"), "%s", msg);
    uint32_t cut[3] = {4, 6, 0};  /* a corner missing */
    CHECK_MSG(cert(p, 10, cut, 3, msg) == PDT_ERR_CHECK && strstr(msg, "pt 1 (2, 0) lies outside it"),
              "%s", msg);
    uint32_t notlow[4] = {6, 0, 7, 4};  /* started at another corner */
    CHECK_MSG(cert(p, 10, notlow, 4, msg) == PDT_ERR_CHECK &&
              strstr(msg, "its first point, pt 6, is not the rightmost lowest point: pt 7"), "%s", msg);
    uint32_t cw[4] = {4, 7, 0, 6};  /* clockwise */
    CHECK_MSG(cert(p, 10, cw, 4, msg) == PDT_ERR_CHECK &&
              strstr(msg, "are not in counter-clockwise order around its first point pt 4"), "%s", msg);
    uint32_t twice[8] = {4, 6, 0, 7, 4, 6, 0, 7};  /* round twice */
    CHECK_MSG(cert(p, 10, twice, 8, msg) == PDT_ERR_CHECK &&
              strstr(msg, "coincides with its first point"), "%s", msg);
    CHECK(cert(p, 10, g, 0, msg) == PDT_ERR_CHECK && strstr(msg, "it is empty (the run has 10 points)"));
    /* a pentagon's corners as a pentagram: left turns only, but round twice */
    pdt_point pent[5] = {{10, 0}, {13, 9}, {5, 15}, {-3, 9}, {0, 0}};
    uint32_t star[5] = {0, 2, 4, 1, 3}, pw[5] = {0, 1, 2, 3, 4};
    CHECK(cert(pent, 5, pw, 5, msg) == PDT_OK);
    CHECK_MSG(cert(pent, 5, star, 5, msg) == PDT_ERR_CHECK &&
              strstr(msg, "positions 2 and 3 (pts 4 and 1) are not in counter-clockwise order"), "%s",
              msg);
    CHECK(cert(p, 0, g, 0, msg) == PDT_OK);

    /* all on a line: Graham writes the two ends, first copy of the origin,
     * last copy of the other end */
    pdt_point l[6] = {{3, 3}, {1, 1}, {2, 2}, {3, 3}, {1, 1}, {0, 0}};
    h = graham(l, 6, g);
    uint32_t lw[2] = {5, 3};
    CHECK(equal(g, h, lw, 2) && cert(l, 6, lw, 2, msg) == PDT_OK);
    uint32_t lnear[2] = {5, 4};
    CHECK_MSG(cert(l, 6, lnear, 2, msg) == PDT_ERR_CHECK && strstr(msg, "pt 0 (3, 3) lies outside it"),
              "%s", msg);
    uint32_t learly[2] = {5, 0};
    CHECK_MSG(cert(l, 6, learly, 2, msg) == PDT_ERR_CHECK && strstr(msg, "pt 3 is a later copy"),
              "%s", msg);
    /* all at one point: the first copy alone */
    pdt_point one[3] = {{7, -7}, {7, -7}, {7, -7}};
    uint32_t o0[1] = {0}, o1[1] = {1}, o01[2] = {0, 1};
    CHECK(cert(one, 3, o0, 1, msg) == PDT_OK);
    CHECK(cert(one, 3, o1, 1, msg) == PDT_ERR_CHECK && strstr(msg, "pt 0 is an earlier copy"));
    CHECK(cert(one, 3, o01, 2, msg) == PDT_ERR_CHECK && strstr(msg, "coincides with its first point"));
}

/* The growable mapping keeps what was written and reads zeros beyond. */
TEST(temp_map_grows)
{
    pdt_temp_map m = {0};
    CHECK(pdt_temp_map_new(&m, 100) == 0 && m.p && m.bytes == 100);
    if (!m.p) return;
    memset(m.p, 0xAB, 100);
    CHECK(pdt_temp_map_grow(&m, 50) == 0 && m.bytes == 100);  /* never shrinks */
    CHECK(pdt_temp_map_grow(&m, (size_t)3 << 20) == 0 && m.bytes == (size_t)3 << 20);
    const unsigned char *b = m.p;
    int ok = 1;
    for (size_t i = 0; i < m.bytes; i++) ok &= b[i] == (i < 100 ? 0xAB : 0);
    CHECK(ok);
    pdt_release_pages(m.p, m.bytes);  /* given back, not lost */
    CHECK(b[0] == 0xAB && b[99] == 0xAB && b[100] == 0);
    pdt_temp_map_free(&m);
    CHECK(m.p == NULL);
    pdt_temp_map_free(&m);  /* twice: nothing */
}

int main(void)
{
    RUN(accepts_graham_output);
    RUN(rejects_every_other_short_stack);
    RUN(rejects_edited_stacks);
    RUN(names_what_fails);
    RUN(temp_map_grows);
    return test_summary();
}
