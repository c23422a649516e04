/* The independent checker: accepts T*(P) on every family, rejects
 * deliberately broken triangulations with a message naming the fault. */
#include "../harness.h"
#include "pdt/check.h"
#include "pdt/delaunay.h"
#include "pdt/gen.h"
#include "pdt/predicates.h"

#include <string.h>

static pdt_point P(int x, int y)
{
    pdt_point p = {x, y};
    return p;
}

static uint64_t rs = 0xD1B54A32D192ED03u;
static uint64_t xr(void) { return th_xorshift(&rs); }

static pdt_status check(const pdt_point *p, size_t n, const pdt_tri *t, size_t nt, pdt_err *err)
{
    pdt_err_clear(err);
    return pdt_check_delaunay(p, n, t, nt, err);
}

TEST(accepts_every_gen_family)
{
    const char *const *k = pdt_gen_kinds();
    int bad = 0, runs = 0;
    pdt_err err;
    for (; *k; k++)
        for (size_t n = 0; n <= 60; n += 1 + n / 4)
            for (int s = 0; s < 4; s++) {
                pdt_point *p;
                pdt_tri *t;
                size_t nt;
                if (pdt_gen(*k, n, (uint64_t)s, &p, NULL) != PDT_OK) { bad++; continue; }
                if (pdt_triangulate(p, n, &t, &nt, NULL, NULL) != PDT_OK) { bad++; free(p); continue; }
                runs++;
                if (check(p, n, t, nt, &err) != PDT_OK) {
                    if (bad < 3) printf("#   %s n=%zu: %s\n", *k, n, err.msg);
                    bad++;
                }
                /* the oracle's answer is accepted too, in any rotation/order */
                pdt_tri *b;
                size_t nb;
                if (n <= 30 && pdt_brute_delaunay(p, n, &b, &nb) == PDT_OK) {
                    for (size_t i = 0; i < nb; i++) { /* rotate and reverse order */
                        uint32_t x = b[i].v[0];
                        b[i].v[0] = b[i].v[1];
                        b[i].v[1] = b[i].v[2];
                        b[i].v[2] = x;
                    }
                    for (size_t i = 0; i < nb / 2; i++) {
                        pdt_tri x = b[i];
                        b[i] = b[nb - 1 - i];
                        b[nb - 1 - i] = x;
                    }
                    if (check(p, n, b, nb, &err) != PDT_OK) bad++;
                    free(b);
                }
                free(t);
                free(p);
            }
    CHECK_MSG(bad == 0, "%d of %d rejected", bad, runs);
}

/* Flip the edge shared by t[i] and t[j] (a convex quadrilateral). */
static int flip(const pdt_point *p, pdt_tri *t, size_t i, size_t j)
{
    for (int k = 0; k < 3; k++)
        for (int l = 0; l < 3; l++) {
            uint32_t a = t[i].v[k], b = t[i].v[(k + 1) % 3], c = t[i].v[(k + 2) % 3];
            if (t[j].v[l] == b && t[j].v[(l + 1) % 3] == a) {
                uint32_t d = t[j].v[(l + 2) % 3];
                if (pdt_orient(p[c], p[a], p[d]) <= 0 || pdt_orient(p[d], p[b], p[c]) <= 0) return 0;
                t[i].v[0] = c; t[i].v[1] = a; t[i].v[2] = d;
                t[j].v[0] = d; t[j].v[1] = b; t[j].v[2] = c;
                return 1;
            }
        }
    return 0;
}

TEST(rejects_a_flipped_edge)
{
    int flips = 0, missed = 0;
    pdt_err err;
    for (int it = 0; it < 200; it++) {
        pdt_point *p;
        pdt_tri *t;
        size_t nt, n = 20 + (size_t)(xr() % 40);
        CHECK(pdt_gen(it % 2 ? "uniform" : "grid", n, (uint64_t)it, &p, NULL) == PDT_OK);
        CHECK(pdt_triangulate(p, n, &t, &nt, NULL, NULL) == PDT_OK);
        for (size_t i = 0; i < nt && i < 8; i++)
            for (size_t j = i + 1; j < nt; j++) {
                pdt_tri *c = malloc(nt * sizeof *c);
                memcpy(c, t, nt * sizeof *c);
                if (flip(p, c, i, j)) {
                    flips++;
                    if (check(p, n, c, nt, &err) != PDT_ERR_CHECK || !strstr(err.msg, "locally Delaunay"))
                        missed++;
                }
                free(c);
            }
        free(t);
        free(p);
    }
    CHECK(flips > 200);
    CHECK_MSG(missed == 0, "%d of %d flips accepted", missed, flips);
}

TEST(rejects_non_canonical_grid_diagonal)
{
    pdt_point sq[4] = {P(0, 0), P(1, 0), P(0, 1), P(1, 1)};
    pdt_tri good[2] = {{{0, 1, 2}}, {{1, 3, 2}}};
    pdt_tri bad[2] = {{{0, 1, 3}}, {{0, 3, 2}}}; /* the main diagonal: also empty-circle */
    pdt_err err;
    CHECK(check(sq, 4, good, 2, &err) == PDT_OK);
    CHECK(check(sq, 4, bad, 2, &err) == PDT_ERR_CHECK);
    CHECK_MSG(strstr(err.msg, "tie rule") != NULL, "%s", err.msg);
}

TEST(rejects_missing_triangle)
{
    pdt_point *p;
    pdt_tri *t;
    size_t nt, n = 50;
    pdt_err err;
    CHECK(pdt_gen("uniform", n, 3, &p, NULL) == PDT_OK);
    CHECK(pdt_triangulate(p, n, &t, &nt, NULL, NULL) == PDT_OK);
    for (size_t i = 0; i < nt; i += 7) {
        pdt_tri *c = malloc(nt * sizeof *c);
        memcpy(c, t, i * sizeof *c);
        memcpy(c + i, t + i + 1, (nt - i - 1) * sizeof *c);
        CHECK_MSG(check(p, n, c, nt - 1, &err) == PDT_ERR_CHECK, "removing %zu accepted", i);
        free(c);
    }
    /* and an extra copy of a triangle */
    pdt_tri *c = malloc((nt + 1) * sizeof *c);
    memcpy(c, t, nt * sizeof *c);
    c[nt] = t[3];
    CHECK(check(p, n, c, nt + 1, &err) == PDT_ERR_CHECK && strstr(err.msg, "edge"));
    free(c);
    free(t);
    free(p);
}

TEST(rejects_bad_triangles)
{
    pdt_point p[5] = {P(0, 0), P(4, 0), P(0, 4), P(4, 4), P(0, 0)};
    pdt_err err;
    pdt_tri cw[2] = {{{0, 2, 1}}, {{1, 3, 2}}};
    CHECK(check(p, 5, cw, 2, &err) == PDT_ERR_CHECK && strstr(err.msg, "counter-clockwise"));
    pdt_tri dup[2] = {{{4, 1, 2}}, {{1, 3, 2}}}; /* 4 duplicates 0 */
    CHECK(check(p, 5, dup, 2, &err) == PDT_ERR_CHECK && strstr(err.msg, "duplicate"));
    pdt_tri range[2] = {{{0, 1, 9}}, {{1, 3, 2}}};
    CHECK(check(p, 5, range, 2, &err) == PDT_ERR_CHECK && strstr(err.msg, "out of range"));
    pdt_tri ok[2] = {{{0, 1, 2}}, {{1, 3, 2}}};
    CHECK(check(p, 5, ok, 2, &err) == PDT_OK);
    CHECK(check(p, 5, ok, 0, &err) == PDT_ERR_CHECK && strstr(err.msg, "no triangles"));
    /* a point left out (inside a triangle) */
    pdt_point q[4] = {P(0, 0), P(9, 0), P(0, 9), P(2, 2)};
    pdt_tri one[1] = {{{0, 1, 2}}};
    CHECK(check(q, 4, one, 1, &err) == PDT_ERR_CHECK && strstr(err.msg, "in no triangle"));
    /* collinear input must have no triangles */
    pdt_point l[3] = {P(0, 0), P(1, 1), P(2, 2)};
    pdt_tri deg[1] = {{{0, 1, 2}}};
    CHECK(check(l, 3, deg, 1, &err) == PDT_ERR_CHECK);
    CHECK(check(l, 3, NULL, 0, &err) == PDT_OK);
    CHECK(check(l, 0, NULL, 0, &err) == PDT_OK);
    /* boundary skipping a collinear hull point: (2,0) on the bottom edge */
    pdt_point c[4] = {P(0, 0), P(4, 0), P(0, 4), P(2, 0)};
    pdt_tri skip[2] = {{{0, 1, 2}}, {{3, 1, 2}}};
    CHECK(check(c, 4, skip, 2, &err) == PDT_ERR_CHECK);
    pdt_tri good[2] = {{{0, 3, 2}}, {{3, 1, 2}}};
    CHECK(check(c, 4, good, 2, &err) == PDT_OK);
}

TEST(large_random_checked)
{
    const char *kinds[] = {"uniform", "grid", "circle", "parabola", "duplicates", "column"};
    for (size_t k = 0; k < sizeof kinds / sizeof *kinds; k++) {
        pdt_point *p;
        pdt_tri *t;
        size_t nt, n = 10000;
        pdt_err err;
        CHECK(pdt_gen(kinds[k], n, 11, &p, NULL) == PDT_OK);
        CHECK(pdt_triangulate(p, n, &t, &nt, NULL, NULL) == PDT_OK);
        CHECK_MSG(check(p, n, t, nt, &err) == PDT_OK, "%s: %s", kinds[k], err.msg);
        free(t);
        free(p);
    }
}

int main(void)
{
    RUN(accepts_every_gen_family);
    RUN(rejects_a_flipped_edge);
    RUN(rejects_non_canonical_grid_diagonal);
    RUN(rejects_missing_triangle);
    RUN(rejects_bad_triangles);
    RUN(large_random_checked);
    return test_summary();
}
