/* Unit tests of the pieces the parallel local phase runs on one block of
 * memory: the kernel on the caller's memory (pdt_delaunay_on) against
 * pdt_delaunay, and the canonical order with the caller's scratch.
 *
 * The code under test comes from libpdt.a and libpdtpar.a. */
#include "../harness.h"

#include <stdlib.h>
#include <string.h>

#include "pdt/delaunay.h"
#include "pdt/gen.h"
#include "pdt/hull.h"

static int cmp_key(const void *a, const void *b)
{
    uint64_t x = pdt_key(*(const pdt_point *)a), y = pdt_key(*(const pdt_point *)b);
    return x < y ? -1 : x > y;
}

/* pts sorted and made distinct in place; returns the new count */
static size_t sort_distinct(pdt_point *p, size_t n)
{
    qsort(p, n, sizeof *p, cmp_key);
    size_t u = 0;
    for (size_t i = 0; i < n; i++)
        if (u == 0 || pdt_key(p[i]) != pdt_key(p[u - 1])) p[u++] = p[i];
    return u;
}

/* The same triangles as pdt_delaunay, the points given back unchanged, in
 * exactly the work the contract names; too small a work is refused before
 * anything is touched. */
TEST(delaunay_on_equals_delaunay)
{
    int runs = 0;
    for (const char *const *k = pdt_gen_kinds(); *k; k++) {
        static const size_t ns[] = {0, 1, 2, 3, 4, 9, 100, 2500};
        for (size_t ni = 0; ni < sizeof ns / sizeof *ns; ni++) {
            pdt_point *pts = NULL;
            pdt_err err;
            pdt_err_clear(&err);
            if (pdt_gen(*k, ns[ni], 7 + ni, &pts, &err) != PDT_OK) {
                CHECK_MSG(0, "gen %s: %s", *k, err.msg);
                continue;
            }
            size_t n = sort_distinct(pts, ns[ni]);
            pdt_point *orig = malloc((n + 1) * sizeof *orig);
            if (n) memcpy(orig, pts, n * sizeof *pts);
            pdt_tri *ref = NULL;
            size_t nref = 0;
            CHECK(pdt_delaunay(pts, n, &ref, &nref, 0, NULL) == PDT_OK);
            pdt_tri_canonical(ref, nref);
            size_t wb = PDT_DELAUNAY_WORK(n);
            void *work = malloc(wb);
            uint32_t *id = malloc((n + 1) * sizeof *id);
            memset(work, 0xa5, wb);
            size_t nt = 99;
            if (n >= 2) { /* too small: refused, points untouched */
                CHECK(pdt_delaunay_on(pts, n, id, work, wb - 1, &nt, 0, NULL) == PDT_ERR_ARG);
                CHECK(nt == 0);
            }
            CHECK(pdt_delaunay_on(pts, n, id, work, wb, &nt, 0, NULL) == PDT_OK);
            CHECK_MSG(n == 0 || memcmp(pts, orig, n * sizeof *pts) == 0, "%s n=%zu: points changed",
                      *k, n);
            pdt_tri *t = work;
            pdt_tri_canonical(t, nt);
            CHECK_MSG(nt == nref && (nt == 0 || memcmp(t, ref, nt * sizeof *t) == 0),
                      "%s n=%zu: %zu triangles, expected %zu", *k, n, nt, nref);
            runs++;
            free(work);
            free(id);
            free(ref);
            free(orig);
            free(pts);
        }
    }
    /* not sorted: refused, points untouched */
    pdt_point uns[3] = {{5, 0}, {0, 0}, {1, 7}}, keep[3];
    memcpy(keep, uns, sizeof uns);
    uint32_t id[3];
    void *work = malloc(PDT_DELAUNAY_WORK(3));
    size_t nt = 5;
    CHECK(pdt_delaunay_on(uns, 3, id, work, PDT_DELAUNAY_WORK(3), &nt, 0, NULL) == PDT_ERR_ARG);
    CHECK(nt == 0 && memcmp(uns, keep, sizeof uns) == 0);
    free(work);
    printf("# %d kernel runs on the caller's memory\n", runs);
}

/* The hull the kernel gives with its triangles (its outer face) is the
 * monotone chain's, vertex for vertex (collinear boundary points kept,
 * counter-clockwise from the smallest point), on every family the
 * generator has -- grids, circles and columns put many points on the hull's
 * edges -- and none when the chain calls the set degenerate. */
TEST(kernel_hull_is_chain_hull)
{
    int runs = 0, degenerate = 0;
    for (const char *const *k = pdt_gen_kinds(); *k; k++) {
        static const size_t ns[] = {0, 1, 2, 3, 4, 5, 9, 16, 100, 2500, 20000};
        for (size_t ni = 0; ni < sizeof ns / sizeof *ns; ni++) {
            pdt_point *pts = NULL;
            pdt_err err;
            pdt_err_clear(&err);
            if (pdt_gen(*k, ns[ni], 11 + ni, &pts, &err) != PDT_OK) {
                CHECK_MSG(0, "gen %s: %s", *k, err.msg);
                continue;
            }
            size_t n = sort_distinct(pts, ns[ni]);
            uint32_t *ch = malloc((n + 1) * sizeof *ch), *id = malloc((n + 1) * sizeof *id);
            size_t nch = 0, nt = 0, nkh = 99;
            int deg = 0;
            CHECK(pdt_hull_chain(pts, n, ch, &nch, &deg, 0, 1, NULL) == PDT_OK);
            void *work = malloc(PDT_DELAUNAY_WORK(n));
            uint32_t *kh = (uint32_t *)(void *)&nkh; /* must be replaced */
            CHECK(pdt_delaunay_hull_on(pts, n, id, work, PDT_DELAUNAY_WORK(n), &nt, &kh, &nkh, 0,
                                       NULL) == PDT_OK);
            if (deg) {
                CHECK_MSG(kh == NULL && nkh == 0, "%s n=%zu: a hull for a degenerate set", *k, n);
                degenerate++;
            } else {
                CHECK_MSG(kh && nkh == nch && memcmp(kh, ch, nch * sizeof *ch) == 0,
                          "%s n=%zu: kernel hull of %zu vertices, chain %zu", *k, n, nkh, nch);
            }
            runs++;
            free(kh);
            free(work);
            free(id);
            free(ch);
            free(pts);
        }
    }
    printf("# %d sets, %d of them degenerate\n", runs, degenerate);
    CHECK(degenerate > 0 && degenerate < runs);
}

/* The strip kernel (the points left in the kernel's order) against
 * pdt_delaunay_hull_on on the same points: named through the permuted
 * names, the same triangles in the same order and the same hull; every
 * point still called by its own name; with no hull (degenerate sets), the
 * points and names back as they were.  Names are a scramble of the
 * indices, as a strip's global indices are. */
TEST(strip_kernel_same_as_hull_on)
{
    int runs = 0, degenerate = 0;
    for (const char *const *k = pdt_gen_kinds(); *k; k++) {
        static const size_t ns[] = {0, 1, 2, 3, 4, 5, 9, 100, 2500, 20000};
        for (size_t ni = 0; ni < sizeof ns / sizeof *ns; ni++) {
            pdt_point *pts = NULL;
            pdt_err err;
            pdt_err_clear(&err);
            if (pdt_gen(*k, ns[ni], 13 + ni, &pts, &err) != PDT_OK) {
                CHECK_MSG(0, "gen %s: %s", *k, err.msg);
                continue;
            }
            size_t n = sort_distinct(pts, ns[ni]);
            pdt_point *orig = malloc((n + 1) * sizeof *orig);
            uint32_t *id = malloc((n + 1) * sizeof *id), *name = malloc((n + 1) * sizeof *name);
            uint32_t *name0 = malloc((n + 1) * sizeof *name0);
            for (size_t i = 0; i < n; i++) name0[i] = name[i] = (uint32_t)(i * 2654435761u);
            if (n) memcpy(orig, pts, n * sizeof *pts);
            size_t wb = PDT_DELAUNAY_WORK(n), nref = 0, nt = 0, nrh = 0, nkh = 0;
            pdt_tri *ref = malloc(wb), *t = malloc(wb);
            uint32_t *rh = NULL, *kh = NULL;
            CHECK(pdt_delaunay_hull_on(pts, n, id, ref, wb, &nref, &rh, &nrh, 0, NULL) == PDT_OK);
            CHECK(pdt_delaunay_strip(pts, n, name, t, wb, &nt, &kh, &nkh) == PDT_OK);
            int same = nt == nref && nkh == nrh;
            for (size_t i = 0; same && i < nt; i++)
                for (int e = 0; e < 3; e++)
                    same &= name[t[i].v[e]] == name0[ref[i].v[e]];
            for (size_t i = 0; same && i < nkh; i++) same &= name[kh[i]] == name0[rh[i]];
            CHECK_MSG(same, "%s n=%zu: %zu triangles and %zu hull vertices, expected %zu and %zu",
                      *k, n, nt, nkh, nref, nrh);
            int named = 1; /* pts[v] is still called name[v] */
            for (size_t v = 0; v < n; v++) {
                size_t j = (size_t)(name[v] * 244002641u); /* the inverse of the scramble */
                named &= j < n && pts[v].x == orig[j].x && pts[v].y == orig[j].y;
            }
            CHECK_MSG(named, "%s n=%zu: a point lost its name", *k, n);
            if (!kh) {
                degenerate++;
                CHECK_MSG(nt == 0 && (n == 0 || (memcmp(pts, orig, n * sizeof *pts) == 0 &&
                                                 memcmp(name, name0, n * sizeof *name) == 0)),
                          "%s n=%zu: no hull, and not given back in order", *k, n);
            }
            runs++;
            free(orig);
            free(id);
            free(name);
            free(name0);
            free(ref);
            free(t);
            free(rh);
            free(kh);
            free(pts);
        }
    }
    printf("# %d sets, %d of them without a hull\n", runs, degenerate);
    CHECK(degenerate > 0 && degenerate < runs);
}

int main(void)
{
    RUN(delaunay_on_equals_delaunay);
    RUN(kernel_hull_is_chain_hull);
    RUN(strip_kernel_same_as_hull_on);
    return test_summary();
}
