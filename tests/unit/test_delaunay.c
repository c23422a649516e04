/* The Delaunay kernel and pipeline: equal to the brute-force lift-up oracle
 * on thousands of small inputs from every generator family and on hand-made
 * degenerate sets; traces; sort/dedupe; canonical order. */
#include "../harness.h"
#include "pdt/check.h"
#include "pdt/delaunay.h"
#include "pdt/gen.h"
#include "pdt/predicates.h"
#include "pdt/bigmem.h"

#include <pthread.h>
#include <sched.h>
#include <string.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>
#include <time.h>

static pdt_point P(int x, int y)
{
    pdt_point p = {x, y};
    return p;
}

static uint64_t rs = 0x9E3779B97F4A7C15u;
static uint64_t xr(void) { return th_xorshift(&rs); }

/* pdt_triangulate == pdt_brute_delaunay, and the checker accepts it; returns 1 if so.  *nt gets the
 * triangle count. */
static int same_as_oracle(const pdt_point *p, size_t n, size_t *nt)
{
    pdt_tri *a = NULL, *b = NULL;
    size_t na = 0, nb = 0;
    pdt_tri_stats st;
    if (pdt_triangulate(p, n, &a, &na, &st, NULL) != PDT_OK) return 0;
    if (pdt_brute_delaunay(p, n, &b, &nb) != PDT_OK) {
        free(a);
        return 0;
    }
    int ok = na == nb && (na == 0 || memcmp(a, b, na * sizeof *a) == 0);
    ok = ok && st.n_tri == na && st.n_in == n && st.n_unique + st.n_dup == n;
    ok = ok && (na == 0) == (st.collinear != 0);
    if (na) ok = ok && na == 2 * st.n_unique - st.n_hull - 2;
    pdt_err err = {0};
    if (pdt_check_delaunay(p, n, a, na, &err) != PDT_OK) {
        printf("#   checker: %s\n", err.msg);
        ok = 0;
    }
    if (nt) *nt = na;
    free(a);
    free(b);
    return ok;
}

TEST(oracle_every_gen_family)
{
    const char *const *k = pdt_gen_kinds();
    int runs = 0, bad = 0;
    for (; *k; k++) {
        for (size_t n = 0; n <= 40; n++) {
            int seeds = n < 12 ? 12 : 5;
            for (int s = 0; s < seeds; s++) {
                pdt_point *p;
                if (pdt_gen(*k, n, (uint64_t)(1000 * n + (size_t)s), &p, NULL) != PDT_OK) {
                    bad++;
                    continue;
                }
                runs++;
                if (!same_as_oracle(p, n, NULL)) {
                    if (bad < 3) printf("#   %s n=%zu seed %d differs\n", *k, n, s);
                    bad++;
                }
                free(p);
            }
        }
    }
    CHECK_MSG(bad == 0, "%d of %d runs differ", bad, runs);
    CHECK(runs > 2000);
}

TEST(oracle_random_small_ranges)
{
    /* coordinates from tiny ranges: collinear triples, cocircular
     * quadruples and duplicates everywhere */
    int bad = 0;
    pdt_point p[40];
    for (int it = 0; it < 3000; it++) {
        size_t n = (size_t)(xr() % 30);
        int range = it % 3 == 0 ? 3 : it % 3 == 1 ? 6 : 20;
        for (size_t i = 0; i < n; i++) p[i] = P((int)(xr() % (uint64_t)range) - range / 2, (int)(xr() % (uint64_t)range));
        if (!same_as_oracle(p, n, NULL)) bad++;
    }
    CHECK_MSG(bad == 0, "%d differ", bad);
}

TEST(tiny_inputs)
{
    pdt_point p[3] = {P(0, 0), P(5, 1), P(2, 7)};
    size_t nt = 99;
    for (size_t n = 0; n <= 2; n++) {
        CHECK(same_as_oracle(p, n, &nt));
        CHECK(nt == 0);
    }
    pdt_tri *t;
    CHECK(pdt_triangulate(p, 3, &t, &nt, NULL, NULL) == PDT_OK);
    CHECK(nt == 1 && t[0].v[0] == 0 && t[0].v[1] == 1 && t[0].v[2] == 2);
    free(t);
    pdt_point q[3] = {P(0, 0), P(2, 7), P(5, 1)}; /* clockwise input */
    CHECK(pdt_triangulate(q, 3, &t, &nt, NULL, NULL) == PDT_OK);
    pdt_tri_canonical(t, nt); /* the kernel's rotation is unspecified */
    CHECK(nt == 1 && t[0].v[0] == 0 && t[0].v[1] == 2 && t[0].v[2] == 1);
    free(t);
}

TEST(all_collinear)
{
    pdt_point p[50];
    size_t nt = 99;
    for (int i = 0; i < 50; i++) p[i] = P(7 * ((i * 17) % 50) - 3, 3 * ((i * 17) % 50) + 1);
    pdt_tri_stats st;
    pdt_tri *t;
    CHECK(pdt_triangulate(p, 50, &t, &nt, &st, NULL) == PDT_OK);
    CHECK(nt == 0 && st.collinear == 1);
    free(t);
    CHECK(same_as_oracle(p, 20, &nt) && nt == 0);
}

TEST(vertical_line)
{
    pdt_point p[30];
    size_t nt = 99;
    for (int i = 0; i < 30; i++) p[i] = P(4, (i * 7) % 30);
    CHECK(same_as_oracle(p, 30, &nt) && nt == 0);
    for (int i = 0; i < 30; i++) p[i] = P((i * 7) % 30, -2); /* horizontal */
    CHECK(same_as_oracle(p, 30, &nt) && nt == 0);
}

TEST(line_plus_one_point)
{
    pdt_point p[21];
    size_t nt;
    for (int i = 0; i < 20; i++) p[i] = P(i, 0);
    p[20] = P(9, 5);
    CHECK(same_as_oracle(p, 21, &nt) && nt == 19);
    p[20] = P(-3, 1); /* off to the side */
    CHECK(same_as_oracle(p, 21, &nt) && nt == 19);
    for (int i = 0; i < 20; i++) p[i] = P(0, i); /* vertical line + 1 */
    p[20] = P(1, 30);
    CHECK(same_as_oracle(p, 21, &nt) && nt == 19);
}

TEST(four_cocircular)
{
    pdt_point sq[4] = {P(0, 0), P(1, 0), P(0, 1), P(1, 1)};
    pdt_tri *t;
    size_t nt;
    CHECK(pdt_triangulate(sq, 4, &t, &nt, NULL, NULL) == PDT_OK);
    /* the anti-diagonal (1,0)-(0,1), i.e. indices 1-2, splits the square */
    CHECK(nt == 2);
    if (nt == 2) {
        CHECK(t[0].v[0] == 0 && t[0].v[1] == 1 && t[0].v[2] == 2);
        CHECK(t[1].v[0] == 1 && t[1].v[1] == 3 && t[1].v[2] == 2);
    }
    free(t);
    pdt_point kite[4] = {P(5, 0), P(0, 5), P(-5, 0), P(0, -5)};
    CHECK(same_as_oracle(kite, 4, &nt) && nt == 2);
    pdt_point circ[4] = {P(3, 4), P(-4, 3), P(-3, -4), P(5, 0)};
    CHECK(same_as_oracle(circ, 4, &nt) && nt == 2);
}

TEST(grid_cocircular)
{
    pdt_point p[100];
    size_t nt;
    for (int k = 2; k <= 10; k++) {
        for (int i = 0; i < k * k; i++) p[i] = P(i % k, i / k);
        CHECK(same_as_oracle(p, (size_t)(k * k), &nt));
        CHECK(nt == (size_t)(2 * (k - 1) * (k - 1)));
    }
    /* every unit square split by its anti-diagonal */
    for (int i = 0; i < 25; i++) p[i] = P(i % 5, i / 5);
    pdt_tri *t;
    CHECK(pdt_triangulate(p, 25, &t, &nt, NULL, NULL) == PDT_OK);
    int diag = 0;
    for (size_t i = 0; i < nt; i++)
        for (int e = 0; e < 3; e++) {
            pdt_point a = p[t[i].v[e]], b = p[t[i].v[(e + 1) % 3]];
            if (a.x != b.x && a.y != b.y) {
                diag++;
                CHECK((b.x - a.x) * (b.y - a.y) < 0); /* anti-diagonal */
            }
        }
    CHECK(diag == 2 * 16);
    free(t);
}

TEST(lattice_circle_65)
{
    pdt_point c[36];
    int m = 0;
    for (int x = -65; x <= 65; x++)
        for (int y = -65; y <= 65; y++)
            if (x * x + y * y == 65 * 65) c[m++] = P(x, y);
    size_t nt;
    CHECK(m == 36);
    CHECK(same_as_oracle(c, 36, &nt) && nt == 34);
    /* replace one circle point by the centre: it is strictly inside every
     * circle through three circle points, so it is joined to all 35 */
    c[0] = P(0, 0);
    CHECK(same_as_oracle(c, 36, &nt) && nt == 35);
}

TEST(duplicate_points)
{
    pdt_point p[12] = {P(0, 0), P(4, 0), P(0, 4), P(4, 0), P(1, 1), P(0, 0),
                       P(4, 4), P(1, 1), P(4, 4), P(0, 4), P(2, 3), P(2, 3)};
    pdt_tri *t;
    size_t nt;
    pdt_tri_stats st;
    CHECK(pdt_triangulate(p, 12, &t, &nt, &st, NULL) == PDT_OK);
    CHECK(st.n_unique == 6 && st.n_dup == 6);
    for (size_t i = 0; i < nt; i++)
        for (int k = 0; k < 3; k++) {
            uint32_t v = t[i].v[k];
            CHECK(v == 0 || v == 1 || v == 2 || v == 4 || v == 6 || v == 10);
        }
    free(t);
    CHECK(same_as_oracle(p, 12, &nt));
    pdt_point same[5] = {P(3, 3), P(3, 3), P(3, 3), P(3, 3), P(3, 3)};
    CHECK(same_as_oracle(same, 5, &nt) && nt == 0);
}

TEST(int32_extreme_coordinates)
{
    pdt_point p[] = {P(INT32_MIN, INT32_MIN), P(INT32_MAX, INT32_MIN), P(INT32_MAX, INT32_MAX),
                     P(INT32_MIN, INT32_MAX), P(0, 0), P(INT32_MIN + 1, INT32_MAX - 1),
                     P(1, -1), P(INT32_MAX, 0), P(-5, INT32_MAX)};
    size_t nt;
    CHECK(same_as_oracle(p, sizeof p / sizeof *p, &nt) && nt > 0);
}

TEST(sort_unique_keeps_smallest_index)
{
    pdt_point p[8] = {P(3, 1), P(-2, 5), P(3, 1), P(-2, -5), P(0, 0), P(-2, 5), P(3, 0), P(0, 0)};
    uint32_t o[8];
    size_t nu;
    CHECK(pdt_sort_unique(p, 8, o, &nu) == PDT_OK);
    static const uint32_t want[] = {3, 1, 4, 6, 0};
    CHECK(nu == 5);
    for (size_t i = 0; i < 5 && i < nu; i++) CHECK_MSG(o[i] == want[i], "o[%zu] = %u", i, o[i]);
    /* a large random case: strictly increasing keys, each the first index */
    size_t n = 200000;
    pdt_point *q = malloc(n * sizeof *q);
    uint32_t *u = malloc(n * sizeof *u);
    for (size_t i = 0; i < n; i++) q[i] = P((int)(xr() % 300) - 150, (int)(int32_t)(uint32_t)xr() % 1000);
    CHECK(pdt_sort_unique(q, n, u, &nu) == PDT_OK);
    int bad = 0;
    for (size_t i = 1; i < nu; i++) bad += pdt_key(q[u[i - 1]]) >= pdt_key(q[u[i]]);
    for (size_t i = 0; i < n; i++) /* every point has a representative <= i */
        if (i % 1000 == 0) {
            size_t lo = 0, hi = nu;
            while (lo < hi) {
                size_t mid = (lo + hi) / 2;
                if (pdt_key(q[u[mid]]) < pdt_key(q[i])) lo = mid + 1; else hi = mid;
            }
            bad += lo == nu || pdt_key(q[u[lo]]) != pdt_key(q[i]) || u[lo] > i;
        }
    CHECK_MSG(bad == 0, "%d bad", bad);
    free(q);
    free(u);
}

TEST(kernel_rejects_unsorted_or_duplicate_points)
{
    pdt_point dup[3] = {P(0, 0), P(0, 0), P(1, 5)};
    pdt_point uns[3] = {P(0, 0), P(2, 0), P(1, 5)};
    pdt_point ok[3] = {P(0, 0), P(1, 5), P(2, 0)};
    pdt_tri *t;
    size_t nt;
    CHECK(pdt_delaunay(dup, 3, &t, &nt, 0, NULL) == PDT_ERR_ARG && nt == 0);
    CHECK(pdt_delaunay(uns, 3, &t, &nt, 0, NULL) == PDT_ERR_ARG && nt == 0);
    CHECK(pdt_delaunay(ok, 3, &t, &nt, 0, NULL) == PDT_OK && nt == 1);
    pdt_tri_canonical(t, nt); /* the kernel's rotation is unspecified */
    CHECK(nt == 1 && t[0].v[0] == 0 && t[0].v[1] == 2 && t[0].v[2] == 1);
    free(t);
}

TEST(canonical_order)
{
    pdt_tri t[4] = {{{5, 2, 9}}, {{1, 7, 3}}, {{4, 0, 6}}, {{2, 9, 5}}};
    pdt_tri_canonical(t, 4);
    CHECK(t[0].v[0] == 0 && t[0].v[1] == 6 && t[0].v[2] == 4);
    CHECK(t[1].v[0] == 1 && t[1].v[1] == 7 && t[1].v[2] == 3);
    CHECK(t[2].v[0] == 2 && t[2].v[1] == 9 && t[2].v[2] == 5);
    CHECK(t[3].v[0] == 2 && t[3].v[1] == 9 && t[3].v[2] == 5);
}

/* The canonical order in buckets, as the parallel order phase uses it: the
 * triangles dealt at random to ns ranks, each rank counts and groups its own
 * by bucket, every rank gets a range of buckets (cut at random places) from
 * every rank and orders them; the ranks' outputs one after the other are
 * pdt_tri_canonical's order, for small and large counts, shifts from 0 (a
 * bucket per index) to past the largest index (one bucket), and with runs of
 * equal triangles. */
TEST(bucket_order_is_canonical)
{
    size_t sizes[] = {0, 1, 50, 3000, 200000};
    int shifts[] = {0, 3, 11, 20};
    for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++)
        for (size_t si = 0; si < sizeof shifts / sizeof *shifts; si++)
            for (size_t ns = 1; ns <= 5; ns += 2) {
                size_t n = sizes[k];
                int shift = shifts[si];
                uint32_t lo = (uint32_t)(k * 1003u), span = (uint32_t)(2 * n + 3);
                pdt_tri *ref = malloc((n + 1) * sizeof *ref), *all = malloc((n + 1) * sizeof *all);
                pdt_tri *grp = malloc((n + 1) * sizeof *grp), *out = malloc((n + 1) * sizeof *out);
                size_t nb = (size_t)((lo + span) >> shift) + 1;
                uint64_t *hist = calloc(ns * nb, sizeof *hist), *at = calloc(ns * nb, sizeof *at);
                size_t *cut = calloc(ns + 1, sizeof *cut), *cnt = calloc(ns + 1, sizeof *cnt);
                size_t *first = calloc(ns + 1, sizeof *first);
                for (size_t i = 0; i < n; i++) {
                    for (int e = 0; e < 3; e++) ref[i].v[e] = lo + (uint32_t)(rand() % (int)span);
                    if (i % 7 == 3) ref[i] = ref[i - 1]; /* runs of equal triangles */
                }
                /* deal: rank r holds all[first[r], first[r] + cnt[r]) */
                for (size_t i = 0; i < n; i++) cnt[(size_t)rand() % ns]++;
                for (size_t r = 1; r <= ns; r++) first[r] = first[r - 1] + cnt[r - 1];
                memcpy(all, ref, n * sizeof *ref);
                pdt_tri_canonical(ref, n);
                for (size_t r = 0; r < ns; r++) /* count, then group by bucket */
                    pdt_tri_bucket_count(all + first[r], cnt[r], shift, hist + r * nb);
                for (size_t r = 0; r < ns; r++) {
                    uint64_t pos = first[r];
                    for (size_t b = 0; b < nb; b++) {
                        at[r * nb + b] = pos;
                        pos += hist[r * nb + b];
                    }
                    pdt_tri_bucket_scatter(all + first[r], cnt[r], shift, at + r * nb, grp);
                }
                /* rank q gets buckets [cut[q], cut[q + 1]) of every rank */
                for (size_t q = 1; q < ns; q++) cut[q] = (size_t)rand() % (nb + 1);
                cut[ns] = nb;
                for (size_t q = 1; q < ns; q++)
                    for (size_t j = q; j > 1 && cut[j - 1] > cut[j]; j--) {
                        size_t t = cut[j];
                        cut[j] = cut[j - 1];
                        cut[j - 1] = t;
                    }
                pdt_tri *o = out;
                for (size_t q = 0; q < ns; q++) {
                    const pdt_tri *src[5];
                    size_t len[5], got = 0;
                    for (size_t r = 0; r < ns; r++) {
                        size_t from = first[r], to;
                        for (size_t b = 0; b < cut[q]; b++) from += hist[r * nb + b];
                        to = from;
                        for (size_t b = cut[q]; b < cut[q + 1]; b++) to += hist[r * nb + b];
                        src[r] = grp + from;
                        len[r] = to - from;
                        got += len[r];
                    }
                    CHECK(pdt_tri_bucket_order(src, len, ns, shift, o) == PDT_OK);
                    o += got;
                }
                int same = (size_t)(o - out) == n &&
                           (n == 0 || memcmp(out, ref, n * sizeof *ref) == 0);
                CHECK_MSG(same, "n = %zu, shift %d, %zu ranks: order differs", n, shift, ns);
                free(ref);
                free(all);
                free(grp);
                free(out);
                free(hist);
                free(at);
                free(cut);
                free(cnt);
                free(first);
            }
}

/* A range of first indices far wider than its triangles (the last rank's,
 * where first indices are rare) is ordered flat, by a radix sort over its
 * span: one, two and three passes (spans of 2^12, 2^20 and 2^31 indices),
 * runs of equal first indices and of equal triangles, from three runs
 * grouped by bucket as the exchange leaves them; the same order as
 * pdt_tri_canonical's. */
TEST(bucket_order_flat_is_canonical)
{
    uint32_t spans[] = {1u << 12, 1u << 20, 1u << 31};
    size_t counts[] = {300, 6000, 6000};
    for (size_t si = 0; si < sizeof spans / sizeof *spans; si++) {
        enum { NS = 3, SHIFT = 8 };
        size_t N = counts[si];
        uint32_t lo = 1000;
        pdt_tri *ref = malloc(N * sizeof *ref), *run = malloc(N * sizeof *run);
        pdt_tri *out = malloc(N * sizeof *out);
        for (size_t i = 0; i < N; i++) {
            uint32_t a = lo + (uint32_t)(((uint64_t)rand() << 16 ^ (uint64_t)rand()) % spans[si]);
            if (i % 5 == 2) a = ref[i - 1].v[0]; /* runs of one first index */
            ref[i] = (pdt_tri){{a, a + 1 + (uint32_t)(rand() % 50), a + 1 + (uint32_t)(rand() % 50)}};
            if (i % 11 == 7) ref[i] = ref[i - 1]; /* and of equal triangles */
        }
        /* three runs (every third triangle), each grouped by bucket */
        const pdt_tri *src[NS];
        size_t len[NS];
        for (size_t r = 0, at = 0; r < NS; r++) {
            src[r] = run + at;
            len[r] = 0;
            for (size_t i = r; i < N; i += NS) run[at + len[r]++] = ref[i];
            pdt_tri_canonical(run + at, len[r]); /* (sorted: grouped by bucket too) */
            at += len[r];
        }
        pdt_tri_canonical(ref, N);
        CHECK(pdt_tri_bucket_order(src, len, NS, SHIFT, out) == PDT_OK);
        CHECK_MSG(memcmp(out, ref, N * sizeof *ref) == 0, "span 2^%d: order differs",
                  __builtin_ctz(spans[si]));
        free(ref);
        free(run);
        free(out);
    }
}

/* The order phase in two rounds (bucket b in round b % 2): the first round's
 * split groups its buckets as one scatter of those triangles would, the
 * others end at the front of the input in their order (their number
 * returned), and the second round's scatter of those groups the rest; the
 * spare place past the first round's group takes the others' writes. */
TEST(bucket_scatter_split_rounds)
{
    size_t sizes[] = {0, 1, 7, 5000};
    for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++) {
        size_t n = sizes[k];
        int shift = 4;
        size_t nb = ((size_t)(4 * n + 8) >> shift) + 1;
        pdt_tri *t = malloc((n + 1) * sizeof *t), *orig = malloc((n + 1) * sizeof *t);
        pdt_tri *want = malloc((n + 1) * sizeof *t), *grp = malloc((n + 2) * sizeof *t);
        uint64_t *hist = calloc(nb, sizeof *hist), *at = calloc(nb, sizeof *at);
        uint64_t *at2 = calloc(nb, sizeof *at2);
        uint8_t *in = calloc(nb, 1);
        for (size_t i = 0; i < n; i++)
            for (int e = 0; e < 3; e++) t[i].v[e] = (uint32_t)(rand() % (int)(4 * n + 8));
        pdt_tri_bucket_count(t, n, shift, hist);
        memcpy(orig, t, n * sizeof *t);
        uint64_t pos[2] = {0, 0};
        for (size_t b = 0; b < nb; b++) {
            in[b] = b % 2 == 0;
            at[b] = pos[b % 2];
            pos[b % 2] += hist[b];
        }
        memcpy(at2, at, nb * sizeof *at);
        for (size_t b = 0; b < nb; b++)
            if (!in[b]) at[b] = pos[0]; /* the spare place */
        /* what each round must give: a stable grouping of its own triangles */
        size_t nw = 0, left = 0;
        for (size_t r = 0; r < 2; r++) {
            uint64_t *w = calloc(nb, sizeof *w);
            for (size_t b = 0; b < nb; b++) w[b] = at2[b];
            for (size_t i = 0; i < n; i++) {
                size_t b = orig[i].v[0] >> shift;
                if (b % 2 == r) want[nw + w[b]++] = orig[i];
            }
            nw += (size_t)pos[r];
            free(w);
        }
        left = pdt_tri_bucket_scatter_split(t, n, shift, in, at, grp);
        CHECK(left == (size_t)pos[1]);
        CHECK(n == 0 || memcmp(grp, want, (size_t)pos[0] * sizeof *grp) == 0);
        int kept = 1;
        for (size_t i = 0, j = 0; i < n; i++)
            if ((orig[i].v[0] >> shift) % 2 == 1)
                kept &= j < left && memcmp(&t[j++], &orig[i], sizeof *t) == 0;
        CHECK_MSG(kept, "n = %zu: the others are not at the front in their order", n);
        pdt_tri_bucket_scatter(t, left, shift, at2, grp);
        CHECK(left == 0 || memcmp(grp, want + pos[0], left * sizeof *grp) == 0);
        free(t);
        free(orig);
        free(want);
        free(grp);
        free(hist);
        free(at);
        free(at2);
        free(in);
    }
}

TEST(trace_events)
{
    pdt_point *p;
    size_t n = 300, nt;
    CHECK(pdt_gen("uniform", n, 7, &p, NULL) == PDT_OK);
    p[5] = p[17]; /* one duplicate */
    pdt_trace tr;
    pdt_trace_buf buf;
    pdt_trace_buf_init(&tr, &buf, 2, 0);
    pdt_tri *t;
    pdt_tri_stats st;
    CHECK(pdt_triangulate(p, n, &t, &nt, &st, &tr) == PDT_OK);
    size_t lift = 0, tri = 0, add = 0, del = 0, bad = 0;
    for (size_t i = 0; i < buf.n; i++) {
        const pdt_event *e = &buf.ev[i];
        if (e->kind == PDT_EV_LIFT) {
            lift++;
            bad += e->a >= n || e->a == 17 ||
                   (uint64_t)e->v != (uint64_t)((int64_t)p[e->a].x * p[e->a].x + (int64_t)p[e->a].y * p[e->a].y);
        }
        if (e->kind == PDT_EV_TRI_NEW) {
            tri++;
            bad += e->sub != 0 || pdt_orient(p[e->a], p[e->b], p[e->c]) <= 0;
        }
        add += e->kind == PDT_EV_EDGE_ADD;
        del += e->kind == PDT_EV_EDGE_DEL;
    }
    CHECK(lift == n - 1 && tri == nt && bad == 0);
    /* edges alive at the end: 3n - 3 - h */
    CHECK_MSG(add - del == 3 * st.n_unique - 3 - st.n_hull, "add %zu del %zu", add, del);
    CHECK(buf.ev[0].kind == PDT_EV_PHASE_BEGIN && buf.ev[buf.n - 1].kind == PDT_EV_PHASE_END);
    free(t);
    pdt_trace_buf_free(&buf);
    /* level 1: no edge events */
    pdt_trace_buf_init(&tr, &buf, 1, 0);
    CHECK(pdt_triangulate(p, n, &t, &nt, &st, &tr) == PDT_OK);
    for (size_t i = 0; i < buf.n; i++) CHECK(buf.ev[i].kind != PDT_EV_EDGE_ADD);
    free(t);
    pdt_trace_buf_free(&buf);
    free(p);
}

TEST(symmetric_parabola_and_circle_large)
{
    /* O(n log n) on the classic quadratic cases: just run them (a quadratic
     * kernel would take minutes here) and count */
    pdt_point *p;
    pdt_tri *t;
    size_t nt;
    pdt_tri_stats st;
    CHECK(pdt_gen("parabola", 80000, 1, &p, NULL) == PDT_OK);
    CHECK(pdt_triangulate(p, 80000, &t, &nt, &st, NULL) == PDT_OK);
    CHECK(nt == 80000 - 2 && st.n_hull == 80000);
    free(t);
    free(p);
    CHECK(pdt_gen("circle", 4860, 1, &p, NULL) == PDT_OK);
    CHECK(pdt_triangulate(p, 4860, &t, &nt, &st, NULL) == PDT_OK);
    CHECK(nt == 4860 - 2);
    free(t);
    free(p);
}

static double cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

TEST(high_degree_vertex)
{
    /* a line of n points and one apex joined to all of them: the apex (index
     * 0, so every triangle starts with it in canonical order) once made the
     * canonical sort quadratic (minutes for 10^6); now linearithmic */
    size_t n = 300000, nt;
    pdt_point *p = malloc(n * sizeof *p);
    for (size_t i = 0; i < n; i++) p[i] = P((int)i, 0);
    p[0] = P(1000, 7);
    pdt_tri *t;
    double c0 = cpu_seconds();
    CHECK(pdt_triangulate(p, n, &t, &nt, NULL, NULL) == PDT_OK);
    double c1 = cpu_seconds();
    CHECK(nt == n - 2);
    int bad = 0;
    for (size_t i = 0; i < nt; i++) bad += t[i].v[0] != 0 || (i && t[i - 1].v[1] >= t[i].v[1]);
    CHECK_MSG(bad == 0, "%d triangles out of canonical order", bad);
    CHECK_MSG(c1 - c0 < 5.0, "%.2f s of CPU time for %zu points", c1 - c0, n);
    free(t);
    free(p);
}

/* pdt_triangulate_inplace works on the caller's points: with PDT_PTS_RESTORE
 * they hold their values again afterwards (duplicates included), and the
 * triangles and figures are pdt_triangulate's; with PDT_PTS_SPEND only the
 * triangles are promised. */
TEST(inplace_restores_points)
{
    static const size_t sizes[] = {0, 1, 2, 3, 5, 17, 100, 4000, 70000};
    for (size_t si = 0; si < sizeof sizes / sizeof *sizes; si++) {
        size_t n = sizes[si];
        for (int range = 3; range <= 3000; range *= 10) { /* many copies, then few */
            pdt_point *p = malloc((n ? n : 1) * sizeof *p), *w = malloc((n ? n : 1) * sizeof *w);
            for (size_t i = 0; i < n; i++)
                p[i] = P((int)(xr() % (uint64_t)range) - range / 2, (int)(xr() % (uint64_t)range));
            memcpy(w, p, n * sizeof *p);
            pdt_tri *a = NULL, *b = NULL, *c = NULL;
            size_t na = 0, nb = 0, nc = 0;
            pdt_tri_stats sa, sb;
            CHECK(pdt_triangulate(p, n, &a, &na, &sa, NULL) == PDT_OK);
            CHECK(pdt_triangulate_inplace(w, n, PDT_PTS_RESTORE, &b, &nb, &sb, NULL) == PDT_OK);
            CHECK_MSG(n == 0 || memcmp(p, w, n * sizeof *p) == 0, "n=%zu range %d: points not restored",
                      n, range);
            CHECK(na == nb && (na == 0 || memcmp(a, b, na * sizeof *a) == 0));
            CHECK(sa.n_unique == sb.n_unique && sa.n_dup == sb.n_dup && sa.n_hull == sb.n_hull &&
                  sa.collinear == sb.collinear);
            CHECK(pdt_triangulate_inplace(w, n, PDT_PTS_SPEND, &c, &nc, NULL, NULL) == PDT_OK);
            CHECK(na == nc && (na == 0 || memcmp(a, c, na * sizeof *a) == 0));
            free(a);
            free(b);
            free(c);
            free(p);
            free(w);
        }
    }
}

/* PDT_TRI_PREFAULT (a second thread faults the working memory in) changes
 * nothing in the results: sizes below and above the threshold at which the
 * thread starts (8 MiB of edge records: about 116 000 points), with and
 * without duplicates, restored and spent. */
TEST(prefault_same_triangles)
{
    static const size_t sizes[] = {0, 3, 1000, 200000};
    for (size_t si = 0; si < sizeof sizes / sizeof *sizes; si++) {
        size_t n = sizes[si];
        for (int ri = 0; ri < 2; ri++) {
            int range = ri ? 3000000 : 300; /* many duplicates, then few */
            pdt_point *p = malloc((n ? n : 1) * sizeof *p), *w = malloc((n ? n : 1) * sizeof *w);
            for (size_t i = 0; i < n; i++)
                p[i] = P((int)(xr() % (uint64_t)range), (int)(xr() % (uint64_t)range));
            memcpy(w, p, n * sizeof *p);
            pdt_tri *a = NULL, *b = NULL, *c = NULL;
            size_t na = 0, nb = 0, nc = 0;
            pdt_tri_stats sa, sb;
            CHECK(pdt_triangulate(p, n, &a, &na, &sa, NULL) == PDT_OK);
            CHECK(pdt_triangulate_inplace(w, n, PDT_PTS_RESTORE | PDT_TRI_PREFAULT, &b, &nb, &sb,
                                          NULL) == PDT_OK);
            CHECK_MSG(n == 0 || memcmp(p, w, n * sizeof *p) == 0, "n=%zu: points not restored", n);
            CHECK(na == nb && (na == 0 || memcmp(a, b, na * sizeof *a) == 0));
            CHECK(sa.n_unique == sb.n_unique && sa.n_dup == sb.n_dup && sa.n_hull == sb.n_hull);
            CHECK(pdt_triangulate_inplace(w, n, PDT_PTS_SPEND | PDT_TRI_PREFAULT, &c, &nc, NULL,
                                          NULL) == PDT_OK);
            CHECK(na == nc && (na == 0 || memcmp(a, c, na * sizeof *a) == 0));
            free(a);
            free(b);
            free(c);
            free(p);
            free(w);
        }
    }
}

/* The prefault thread makes the pages of its ranges resident (mincore) and
 * leaves their contents alone; stopping it at once is allowed. */
TEST(prefault_makes_pages_resident)
{
    size_t pg = (size_t)sysconf(_SC_PAGESIZE), bytes = 64 * pg;
    char *m = mmap(NULL, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    CHECK(m != MAP_FAILED);
    m[0] = 7; /* page 0 written by us; the others untouched */
    unsigned char vec[64];
    CHECK(mincore(m, bytes, vec) == 0);
    int resident = 0;
    for (int i = 0; i < 64; i++) resident += vec[i] & 1;
    CHECK(resident < 64);
    pdt_range r = { m, bytes };
    pdt_prefault *pf = pdt_prefault_start(&r, 1);
    CHECK(pf != NULL);
    for (int tries = 0; tries < 1000 && resident < 64; tries++) { /* at most ~10 s */
        struct timespec ts = { 0, 10 * 1000 * 1000 };
        nanosleep(&ts, NULL);
        CHECK(mincore(m, bytes, vec) == 0);
        resident = 0;
        for (int i = 0; i < 64; i++) resident += vec[i] & 1;
    }
    pdt_prefault_stop(pf);
    CHECK_MSG(resident == 64, "only %d of 64 pages resident after prefaulting", resident);
    CHECK(m[0] == 7 && m[pg] == 0 && m[bytes - 1] == 0);
    pdt_prefault_stop(pdt_prefault_start(&r, 1)); /* started and stopped at once */
    pdt_prefault_stop(NULL);
    munmap(m, bytes);
}

/* A helper thread of a caller bound to one CPU runs on the other CPUs, and
 * the caller stays bound to its own, even when the helper ends before
 * pthread_create has returned (a helper's CPUs set on its handle after the
 * thread has ended would set the caller's: a rank's main thread then moved
 * onto the other rank's CPU). */
static void *note_cpus(void *arg)
{
    cpu_set_t *got = arg;
    if (sched_getaffinity(0, sizeof *got, got) != 0) CPU_ZERO(got);
    return NULL;
}

TEST(helper_keeps_caller_cpu)
{
    cpu_set_t saved, one, now, helper;
    if (sysconf(_SC_NPROCESSORS_ONLN) < 2 || sched_getaffinity(0, sizeof saved, &saved) != 0 ||
        !CPU_ISSET(0, &saved) || CPU_COUNT(&saved) < 2)
        return; /* (one CPU: nothing to keep apart) */
    CPU_ZERO(&one);
    CPU_SET(0, &one);
    CHECK(sched_setaffinity(0, sizeof one, &one) == 0);
    for (int i = 0; i < 200; i++) {
        pthread_t th;
        CPU_ZERO(&helper);
        CHECK(pdt_helper_start(&th, note_cpus, &helper) == 0);
        struct timespec ts = { 0, 20 * 1000 }; /* the helper has ended by now, mostly */
        nanosleep(&ts, NULL);
        CHECK(pthread_join(th, NULL) == 0);
        CHECK(sched_getaffinity(0, sizeof now, &now) == 0);
        CHECK_MSG(CPU_EQUAL(&now, &one), "round %d: the caller was moved off CPU 0", i);
        CHECK_MSG(CPU_COUNT(&helper) > 0 && !CPU_ISSET(0, &helper),
                  "round %d: the helper ran on the caller's CPU", i);
        if (!CPU_EQUAL(&now, &one)) break;
    }
    CHECK(sched_setaffinity(0, sizeof saved, &saved) == 0);
}

/* Whether the mapping that holds p asks for transparent huge pages (the
 * "hg" flag in /proc/self/smaps): 1 or 0, -1 if it cannot be read. */
static int asks_huge(const void *p)
{
    FILE *f = fopen("/proc/self/smaps", "r");
    if (!f) return -1;
    char line[512];
    int inside = 0, got = -1;
    while (got < 0 && fgets(line, sizeof line, f)) {
        unsigned long lo, hi;
        if (sscanf(line, "%lx-%lx ", &lo, &hi) == 2 && strchr(line, '-') < strchr(line, ' '))
            inside = (uintptr_t)p >= lo && (uintptr_t)p < hi;
        else if (inside && strncmp(line, "VmFlags:", 8) == 0)
            got = strstr(line, " hg") != NULL;
    }
    fclose(f);
    return got;
}

/* Re-run of this program with PDT_HUGEPAGES=1 (pdt_big_advise reads the
 * variable once per process): exit 0 if a big array asks for huge pages. */
static int huge_child(void)
{
    size_t bytes = (size_t)8 << 20;
    void *p = pdt_big_alloc(bytes);
    int got = p ? asks_huge((char *)p + bytes / 2) : -1;
    pdt_big_free(p, bytes);
    return got == 1 ? 0 : 1;
}

/* Big arrays ask for no huge pages unless PDT_HUGEPAGES=1 says so. */
TEST(huge_pages_only_when_asked)
{
    if (getenv("PDT_HUGEPAGES")) return; /* the default cannot be seen here */
    size_t bytes = (size_t)8 << 20;
    void *p = pdt_big_alloc(bytes);
    CHECK(p != NULL);
    CHECK_MSG(asks_huge((char *)p + bytes / 2) == 0, "a big array asked for huge pages by default");
    pdt_big_free(p, bytes);
    if (access("/sys/kernel/mm/transparent_hugepage", F_OK) != 0) return; /* no THP here */
    pid_t pid = fork();
    CHECK(pid >= 0);
    if (pid == 0) {
        setenv("PDT_HUGEPAGES", "1", 1);
        execl("/proc/self/exe", "test_delaunay", "--huge-child", (char *)NULL);
        _exit(2);
    }
    int st = 0;
    CHECK(waitpid(pid, &st, 0) == pid);
    CHECK_MSG(WIFEXITED(st) && WEXITSTATUS(st) == 0, "with PDT_HUGEPAGES=1 a big array asked for none");
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--huge-child") == 0) return huge_child();
    RUN(oracle_every_gen_family);
    RUN(oracle_random_small_ranges);
    RUN(tiny_inputs);
    RUN(all_collinear);
    RUN(vertical_line);
    RUN(line_plus_one_point);
    RUN(four_cocircular);
    RUN(grid_cocircular);
    RUN(lattice_circle_65);
    RUN(duplicate_points);
    RUN(int32_extreme_coordinates);
    RUN(sort_unique_keeps_smallest_index);
    RUN(kernel_rejects_unsorted_or_duplicate_points);
    RUN(canonical_order);
    RUN(bucket_order_is_canonical);
    RUN(bucket_order_flat_is_canonical);
    RUN(bucket_scatter_split_rounds);
    RUN(trace_events);
    RUN(symmetric_parabola_and_circle_large);
    RUN(high_degree_vertex);
    RUN(inplace_restores_points);
    RUN(prefault_same_triangles);
    RUN(prefault_makes_pages_resident);
    RUN(helper_keeps_caller_cpu);
    RUN(huge_pages_only_when_asked);
    return test_summary();
}
