/* Point generators: every family deterministic, the right size, and with
 * the property its name promises. */
#include "../harness.h"
#include "pdt/gen.h"

#include <string.h>

static int cmp_pt(const void *a, const void *b)
{
    return pdt_lex_cmp(*(const pdt_point *)a, *(const pdt_point *)b);
}

static size_t distinct(const pdt_point *p, size_t n)
{
    pdt_point *q = malloc((n ? n : 1) * sizeof *q);
    memcpy(q, p, n * sizeof *q);
    qsort(q, n, sizeof *q, cmp_pt);
    size_t u = 0;
    for (size_t i = 0; i < n; i++) u += i == 0 || cmp_pt(&q[i - 1], &q[i]) != 0;
    free(q);
    return u;
}

TEST(every_kind_deterministic)
{
    const char *const *k = pdt_gen_kinds();
    int nk = 0;
    for (; *k; k++, nk++) {
        for (size_t n = 0; n < 50; n += 7) {
            pdt_point *a, *b;
            pdt_err err = {0};
            CHECK_MSG(pdt_gen(*k, n, 42, &a, &err) == PDT_OK, "%s: %s", *k, err.msg);
            CHECK(pdt_gen(*k, n, 42, &b, &err) == PDT_OK);
            CHECK_MSG(memcmp(a, b, n * sizeof *a) == 0, "%s n=%zu differs between calls", *k, n);
            free(a);
            free(b);
        }
        pdt_point *a, *b;
        CHECK(pdt_gen(*k, 200, 1, &a, NULL) == PDT_OK);
        CHECK(pdt_gen(*k, 200, 2, &b, NULL) == PDT_OK);
        CHECK_MSG(memcmp(a, b, 200 * sizeof *a) != 0, "%s ignores the seed", *k);
        free(a);
        free(b);
    }
    CHECK(nk >= 9);
}

TEST(unknown_kind_lists_kinds)
{
    pdt_point *p;
    pdt_err err = {0};
    CHECK(pdt_gen("spiral", 10, 1, &p, &err) == PDT_ERR_ARG);
    CHECK(strstr(err.msg, "spiral") && strstr(err.msg, "circle-round") && strstr(err.msg, "column"));
}

TEST(circle_lattice_points_exact)
{
    pdt_point *p;
    CHECK(pdt_gen("circle", 36, 3, &p, NULL) == PDT_OK);
    for (int i = 0; i < 36; i++) CHECK(p[i].x * p[i].x + p[i].y * p[i].y == 65 * 65);
    CHECK(distinct(p, 36) == 36);
    free(p);
    size_t sizes[] = {1, 4, 5, 100, 1000, 4860, 5000, 30000};
    for (size_t s = 0; s < sizeof sizes / sizeof *sizes; s++) {
        size_t n = sizes[s];
        CHECK(pdt_gen("circle", n, 9, &p, NULL) == PDT_OK);
        int64_t r2 = (int64_t)p[0].x * p[0].x + (int64_t)p[0].y * p[0].y;
        size_t on = 0;
        for (size_t i = 0; i < n; i++) on += (int64_t)p[i].x * p[i].x + (int64_t)p[i].y * p[i].y == r2;
        CHECK_MSG(on == n || n > 4860, "n=%zu: %zu of the points on the first circle", n, on);
        CHECK(distinct(p, n) == n);
        free(p);
    }
}

TEST(families_have_their_shape)
{
    pdt_point *p;
    size_t n = 1000;
    CHECK(pdt_gen("parabola", n, 5, &p, NULL) == PDT_OK);
    size_t neg = 0;
    for (size_t i = 0; i < n; i++) {
        CHECK((int64_t)p[i].y == (int64_t)p[i].x * p[i].x);
        neg += p[i].x < 0;
    }
    CHECK(neg == n / 2);
    free(p);
    CHECK(pdt_gen("grid", 100, 5, &p, NULL) == PDT_OK);
    for (size_t i = 0; i < 100; i++) CHECK(p[i].x >= 0 && p[i].x < 10 && p[i].y >= 0 && p[i].y < 10);
    CHECK(distinct(p, 100) == 100);
    free(p);
    CHECK(pdt_gen("duplicates", n, 5, &p, NULL) == PDT_OK);
    CHECK(distinct(p, n) < n * 3 / 4);
    free(p);
    CHECK(pdt_gen("column", n, 5, &p, NULL) == PDT_OK);
    size_t col = 0;
    for (size_t i = 0; i < n; i++) col += p[i].x == 1 << 19;
    CHECK(col >= n / 2);
    free(p);
    CHECK(pdt_gen("uniform", n, 5, &p, NULL) == PDT_OK);
    for (size_t i = 0; i < n; i++) CHECK(p[i].x >= 0 && p[i].x < 1 << 20 && p[i].y >= 0 && p[i].y < 1 << 20);
    free(p);
    CHECK(pdt_gen("circle-round", n, 5, &p, NULL) == PDT_OK);
    for (size_t i = 0; i < n; i++) {
        int64_t r2 = (int64_t)p[i].x * p[i].x + (int64_t)p[i].y * p[i].y;
        int64_t R2 = (int64_t)1 << 40;
        CHECK_MSG(r2 > R2 - 3 * (1 << 20) && r2 < R2 + 3 * (1 << 20), "r2 %lld", (long long)r2);
    }
    CHECK(distinct(p, n) == n);
    free(p);
    CHECK(pdt_gen("collinear", n, 5, &p, NULL) == PDT_OK);
    /* at least half of the points on one line */
    size_t best = 0;
    for (size_t i = 0; i < 20; i++)
        for (size_t j = i + 1; j < 20; j++) {
            size_t c = 0;
            for (size_t k = 0; k < n; k++) {
                int64_t o = ((int64_t)p[j].x - p[i].x) * ((int64_t)p[k].y - p[i].y) -
                            ((int64_t)p[j].y - p[i].y) * ((int64_t)p[k].x - p[i].x);
                c += o == 0 && !(p[i].x == p[j].x && p[i].y == p[j].y);
            }
            if (c > best) best = c;
        }
    CHECK_MSG(best >= n / 2, "best line has %zu points", best);
    free(p);
}

int main(void)
{
    RUN(every_kind_deterministic);
    RUN(unknown_kind_lists_kinds);
    RUN(circle_lattice_points_exact);
    RUN(families_have_their_shape);
    return test_summary();
}
