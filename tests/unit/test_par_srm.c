/* Whole runs of the SRM parallel triangulation without MPI: p simulated
 * ranks (their messages moved in-process) on adversarial families with
 * random strip cuts (empty, 1- and 2-point strips included), compared with
 * one kernel run on all points.  Also: dropping the hull-vertex rule of the
 * Merge Lemma must break it (the test can fail).

 * The code under test comes from libpdtpar.a (src/par without MPI). */
#include "../harness.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../src/par/srm.h"
#include "pdt/delaunay.h"
#include "pdt/gen.h"

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static uint64_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}
static int32_t rndi(int32_t lo, int32_t hi) { return lo + (int32_t)(rnd() % (uint64_t)(hi - lo + 1)); }

/* ---- whole runs, simulated ----------------------------------------------------- */

enum { FAMILIES = 14 };
static const char *const fam_name[FAMILIES] = {
    "uniform", "grid", "lattice-circle", "rounded-circle", "parabola", "parabola-sym",
    "column", "row", "diagonal", "line+1", "two-lines", "duplicates", "clusters", "tiny"};

static pdt_point *family(int f, size_t n, size_t *outn)
{
    pdt_point *p = malloc((n + 64) * sizeof *p);
    size_t k = 0;
    switch (f) {
    case 0: for (; k < n; k++) p[k] = (pdt_point){rndi(0, 1000), rndi(0, 1000)}; break;
    case 1: for (; k < n; k++) p[k] = (pdt_point){(int32_t)(k % 8), (int32_t)(k / 8)}; break;
    case 2: /* all lattice points on x^2 + y^2 = 65^2 (36 of them) */
        for (int x = -65; x <= 65; x++)
            for (int y = -65; y <= 65; y++)
                if (x * x + y * y == 65 * 65) p[k++] = (pdt_point){x, y};
        break;
    case 3:
        for (; k < n; k++) {
            double a = 6.283185307179586 * (double)k / (double)n;
            p[k] = (pdt_point){(int32_t)lround(1000 * cos(a)), (int32_t)lround(1000 * sin(a))};
        }
        break;
    case 4: for (; k < n; k++) p[k] = (pdt_point){(int32_t)k, (int32_t)(k * k)}; break;
    case 5:
        for (; k < n; k++) {
            int32_t x = (int32_t)k - (int32_t)n / 2;
            p[k] = (pdt_point){x, x * x};
        }
        break;
    case 6: for (; k < n; k++) p[k] = (pdt_point){7, (int32_t)(rnd() % 1000)}; break;
    case 7: for (; k < n; k++) p[k] = (pdt_point){(int32_t)(rnd() % 1000), -3}; break;
    case 8: for (; k < n; k++) p[k] = (pdt_point){(int32_t)k, 2 * (int32_t)k}; break;
    case 9:
        for (; k + 1 < n; k++) p[k] = (pdt_point){(int32_t)k, 0};
        p[k++] = (pdt_point){(int32_t)n / 2, 5};
        break;
    case 10: for (; k < n; k++) p[k] = (pdt_point){(int32_t)(k / 2), k % 2 ? 10 : 0}; break;
    case 11: for (; k < n; k++) p[k] = (pdt_point){rndi(0, 4), rndi(0, 4)}; break;
    case 12:
        for (; k < n; k++) {
            int cl = (int)(k % 3);
            p[k] = (pdt_point){cl * 5000 + rndi(0, 40), cl * 700 + rndi(0, 40)};
        }
        break;
    default: /* 0..3 points */
        for (; k < n % 4; k++) p[k] = (pdt_point){(int32_t)k * 3, (int32_t)(k * k)};
        break;
    }
    *outn = k;
    return p;
}

static int cmp_tri(const void *x, const void *y)
{
    const pdt_tri *a = x, *b = y;
    for (int k = 0; k < 3; k++)
        if (a->v[k] != b->v[k]) return a->v[k] < b->v[k] ? -1 : 1;
    return 0;
}

/* One simulated run: the sorted distinct records cut into p blocks at the
 * given positions.  Returns the canonical triangles (malloc'd). */
static pdt_status simulate(const srm_rec *u, int p, const size_t *cut, pdt_tri **out,
                           size_t *nout, uint64_t *bmax)
{
    srm_strip *strip = calloc((size_t)p, sizeof *strip);
    srm_rank *rk = calloc((size_t)p, sizeof *rk);
    pdt_err err;
    pdt_err_clear(&err);
    pdt_status st = PDT_OK;
    for (int r = 0; r < p; r++) {
        size_t lo = cut[r], hi = cut[r + 1];
        srm_strip *s = &strip[r];
        s->count = hi - lo;
        for (size_t i = lo; i < hi; i++) {
            pdt_point q = srm_key_point(u[i].key);
            if (i == lo || q.y < s->ymin) s->ymin = q.y;
            if (i == lo || q.y > s->ymax) s->ymax = q.y;
        }
        if (hi > lo) {
            s->first_key = u[lo].key;
            s->last_key = u[hi - 1].key;
            s->xmin = srm_key_point(u[lo].key).x;
            s->xmax = srm_key_point(u[hi - 1].key).x;
        }
    }
    for (int r = 0; r < p && st == PDT_OK; r++) {
        size_t lo = cut[r], hi = cut[r + 1];
        pdt_point *pts = malloc((hi - lo + 1) * sizeof *pts);
        uint32_t *gid = malloc((hi - lo + 1) * sizeof *gid), *id = malloc((hi - lo + 1) * sizeof *id);
        void *block = malloc(PDT_DELAUNAY_WORK(hi - lo));
        for (size_t i = lo; i < hi; i++) {
            pts[i - lo] = srm_key_point(u[i].key);
            gid[i - lo] = u[i].idx;
        }
        st = pdt_srm_init(&rk[r], r, p, strip, NULL, &err);
        if (st == PDT_OK) st = pdt_srm_local(&rk[r], block, pts, gid, id, hi - lo, &err);
        else free(block);
        free(pts);
        free(gid);
        free(id);
    }
    int L = pdt_srm_ceil_log2(p);
    for (int level = 0; level < L && st == PDT_OK; level++)
        for (int r = 0; r < p && st == PDT_OK; r++) {
            int gl, gr, ge;
            if (!pdt_srm_pair(r, p, level, &gl, &gr, &ge) || r != gr) continue;
            void *msg[64];
            size_t len[64];
            for (int q = gl; q < ge; q++) pdt_srm_pack(&rk[q], level, &msg[q - gl], &len[q - gl], &err);
            st = pdt_srm_merge(&rk[r], level, msg, len, &err);
            for (int q = gl; q < ge; q++) free(msg[q - gl]);
        }
    size_t total = 0;
    *bmax = 0;
    for (int r = 0; r < p; r++) {
        total += rk[r].nfin + rk[r].nmore;
        if (rk[r].npend) st = PDT_ERR_CHECK;
        if (rk[r].cnt.border_max > *bmax) *bmax = rk[r].cnt.border_max;
    }
    pdt_tri *t = malloc((total + 1) * sizeof *t);
    size_t k = 0;
    for (int r = 0; r < p; r++) {
        if (rk[r].nfin) memcpy(t + k, rk[r].fin, rk[r].nfin * sizeof *t);
        k += rk[r].nfin;
        if (rk[r].nmore) memcpy(t + k, rk[r].more, rk[r].nmore * sizeof *t);
        k += rk[r].nmore;
        pdt_srm_free(&rk[r]);
    }
    pdt_tri_canonical(t, total);
    *out = t;
    *nout = total;
    free(strip);
    free(rk);
    if (st != PDT_OK && err.code) printf("#   %s\n", err.msg);
    return st;
}

TEST(srm_equals_sequential)
{
    static const int ps[] = {1, 2, 3, 4, 5, 7, 8, 11};
    static const size_t ns[] = {0, 1, 2, 3, 5, 17, 40, 90};
    int runs = 0, bad = 0;
    for (int f = 0; f < FAMILIES; f++)
        for (size_t ni = 0; ni < sizeof ns / sizeof *ns; ni++) {
            size_t n;
            pdt_point *pts = family(f, ns[ni], &n);
            srm_rec *u = malloc((n + 1) * sizeof *u), *tmp = malloc((n + 1) * sizeof *tmp);
            for (size_t i = 0; i < n; i++) u[i] = (srm_rec){pdt_key(pts[i]), (uint32_t)i, 0};
            pdt_srm_radix_sort(u, tmp, n);
            size_t m = pdt_srm_dedupe(u, n);
            /* reference: one kernel run on everything */
            pdt_point *up = malloc((m + 1) * sizeof *up);
            for (size_t i = 0; i < m; i++) up[i] = srm_key_point(u[i].key);
            pdt_tri *ref = NULL;
            size_t nref = 0;
            pdt_delaunay(up, m, &ref, &nref, 0, NULL);
            for (size_t i = 0; i < nref; i++)
                for (int k = 0; k < 3; k++) ref[i].v[k] = u[ref[i].v[k]].idx;
            pdt_tri_canonical(ref, nref);
            for (size_t pi = 0; pi < sizeof ps / sizeof *ps; pi++)
                for (int rep = 0; rep < 3; rep++) {
                    int p = ps[pi];
                    size_t cut[65];
                    cut[0] = 0;
                    cut[p] = m;
                    for (int r = 1; r < p; r++) cut[r] = m ? (size_t)(rnd() % (m + 1)) : 0;
                    if (rep == 0) /* balanced */
                        for (int r = 1; r < p; r++) cut[r] = m * (size_t)r / (size_t)p;
                    for (int a = 1; a < p; a++) /* sort the cuts */
                        for (int b = a + 1; b < p; b++)
                            if (cut[b] < cut[a]) {
                                size_t t = cut[a];
                                cut[a] = cut[b];
                                cut[b] = t;
                            }
                    pdt_tri *got = NULL;
                    size_t ngot = 0;
                    uint64_t bmax;
                    pdt_status st = simulate(u, p, cut, &got, &ngot, &bmax);
                    runs++;
                    int same = st == PDT_OK && ngot == nref &&
                               (nref == 0 || memcmp(got, ref, nref * sizeof *ref) == 0);
                    if (!same) {
                        bad++;
                        if (bad <= 5)
                            printf("#   %s n=%zu p=%d rep=%d: %zu triangles, expected %zu\n",
                                   fam_name[f], n, p, rep, ngot, nref);
                    }
                    free(got);
                }
            free(ref);
            free(up);
            free(u);
            free(tmp);
            free(pts);
        }
    CHECK_MSG(bad == 0, "%d of %d simulated runs differ from the sequential kernel", bad, runs);
    printf("# %d simulated runs\n", runs);
}

/* The project's generators at larger sizes, against the sequential
 * pipeline, with random cuts (empty strips included). */
TEST(srm_gen_families)
{
    static const int ps[] = {2, 3, 5, 8, 13};
    static const size_t ns[] = {600, 3000};
    int runs = 0, bad = 0;
    for (const char *const *k = pdt_gen_kinds(); *k; k++)
        for (size_t ni = 0; ni < sizeof ns / sizeof *ns; ni++) {
            pdt_point *pts = NULL;
            pdt_err err;
            pdt_err_clear(&err);
            size_t n = ns[ni];
            if (pdt_gen(*k, n, 11, &pts, &err) != PDT_OK) {
                CHECK_MSG(0, "gen %s: %s", *k, err.msg);
                continue;
            }
            pdt_tri *ref = NULL;
            size_t nref = 0;
            CHECK(pdt_triangulate(pts, n, &ref, &nref, NULL, NULL) == PDT_OK);
            srm_rec *u = malloc((n + 1) * sizeof *u), *tmp = malloc((n + 1) * sizeof *tmp);
            for (size_t i = 0; i < n; i++) u[i] = (srm_rec){pdt_key(pts[i]), (uint32_t)i, 0};
            pdt_srm_radix_sort(u, tmp, n);
            size_t m = pdt_srm_dedupe(u, n);
            for (size_t pi = 0; pi < sizeof ps / sizeof *ps; pi++)
                for (int rep = 0; rep < 2; rep++) {
                    int p = ps[pi];
                    size_t cut[65];
                    cut[0] = 0;
                    cut[p] = m;
                    for (int r = 1; r < p; r++)
                        cut[r] = rep == 0 ? m * (size_t)r / (size_t)p : (size_t)(rnd() % (m + 1));
                    for (int a = 1; a < p; a++)
                        for (int b = a + 1; b < p; b++)
                            if (cut[b] < cut[a]) {
                                size_t t = cut[a];
                                cut[a] = cut[b];
                                cut[b] = t;
                            }
                    pdt_tri *got = NULL;
                    size_t ngot = 0;
                    uint64_t bmax;
                    pdt_status st = simulate(u, p, cut, &got, &ngot, &bmax);
                    runs++;
                    if (!(st == PDT_OK && ngot == nref &&
                          (nref == 0 || memcmp(got, ref, nref * sizeof *ref) == 0))) {
                        bad++;
                        if (bad <= 5)
                            printf("#   %s n=%zu p=%d rep=%d: %zu triangles, expected %zu\n", *k,
                                   n, p, rep, ngot, nref);
                    }
                    free(got);
                }
            free(u);
            free(tmp);
            free(ref);
            free(pts);
        }
    CHECK_MSG(bad == 0, "%d of %d simulated runs differ from pdt_triangulate", bad, runs);
    printf("# %d simulated runs on the generators\n", runs);
}

/* Merge messages: every count and the payload size are 64-bit fields, and
 * a header whose counts or size disagree with the bytes is refused, also
 * when they differ only above bit 32 (where a 32-bit field would wrap and
 * match). */
TEST(merge_message_header)
{
    size_t n;
    pdt_point *pts = family(0, 200, &n);
    srm_rec *u = malloc((n + 1) * sizeof *u), *tmp = malloc((n + 1) * sizeof *tmp);
    for (size_t i = 0; i < n; i++) u[i] = (srm_rec){pdt_key(pts[i]), (uint32_t)i, 0};
    pdt_srm_radix_sort(u, tmp, n);
    size_t m = pdt_srm_dedupe(u, n), cut[3] = {0, m / 2, m};
    srm_strip strip[2];
    memset(strip, 0, sizeof strip);
    srm_rank rk[2];
    pdt_err err;
    pdt_err_clear(&err);
    for (int r = 0; r < 2; r++) {
        size_t lo = cut[r], hi = cut[r + 1];
        strip[r] = (srm_strip){hi - lo, u[lo].key, u[hi - 1].key, srm_key_point(u[lo].key).x,
                               srm_key_point(u[hi - 1].key).x, INT32_MAX, INT32_MIN};
        for (size_t i = lo; i < hi; i++) {
            pdt_point q = srm_key_point(u[i].key);
            if (q.y < strip[r].ymin) strip[r].ymin = q.y;
            if (q.y > strip[r].ymax) strip[r].ymax = q.y;
        }
    }
    for (int r = 0; r < 2; r++) {
        size_t lo = cut[r], hi = cut[r + 1];
        pdt_point *lp = malloc((hi - lo + 1) * sizeof *lp);
        uint32_t *gid = malloc((hi - lo + 1) * sizeof *gid), *id = malloc((hi - lo + 1) * sizeof *id);
        for (size_t i = lo; i < hi; i++) {
            lp[i - lo] = srm_key_point(u[i].key);
            gid[i - lo] = u[i].idx;
        }
        CHECK(pdt_srm_init(&rk[r], r, 2, strip, NULL, &err) == PDT_OK);
        CHECK(pdt_srm_local(&rk[r], malloc(PDT_DELAUNAY_WORK(hi - lo)), lp, gid, id, hi - lo,
                            &err) == PDT_OK);
        free(lp);
        free(gid);
        free(id);
    }
    void *msg[2];
    size_t len[2];
    for (int r = 0; r < 2; r++) CHECK(pdt_srm_pack(&rk[r], 0, &msg[r], &len[r], &err) == PDT_OK);
    srm_msg_head h;
    memcpy(&h, msg[0], sizeof h);
    CHECK(sizeof h.payload == 8 && sizeof h.npts == 8 && sizeof h.ntri == 8 && sizeof h.nhull == 8);
    CHECK(h.magic == SRM_MSG_MAGIC && h.payload == len[0] - sizeof h && h.ntri > 0 && h.nhull > 0);
    /* damaged headers, each refused with the sender named */
    const uint64_t wrap = (uint64_t)1 << 32;
    for (int k = 0; k < 5; k++) {
        srm_msg_head bad = h;
        if (k == 0) bad.payload += wrap;
        if (k == 1) bad.ntri += wrap;
        if (k == 2) bad.npts += wrap;
        if (k == 3) bad.nhull += wrap;
        if (k == 4) bad.ntri = UINT64_MAX / 2; /* 3 * ntri would wrap in 64 bits */
        unsigned char *c = malloc(len[0]);
        memcpy(c, msg[0], len[0]);
        memcpy(c, &bad, sizeof bad);
        void *mm[2] = {c, msg[1]};
        pdt_err_clear(&err);
        CHECK_MSG(pdt_srm_merge(&rk[1], 0, mm, len, &err) == PDT_ERR_CORRUPT, "damage %d", k);
        CHECK_MSG(strstr(err.msg, "from rank 0") != NULL, "damage %d: %s", k, err.msg);
        CHECK_MSG(strstr(err.msg, k == 0 ? "bad header" : "bad counts") != NULL, "damage %d: %s", k,
                  err.msg);
        free(c);
    }
    /* a point table out of key order (the merge merges the tables as runs),
     * or with a point twice, is refused */
    for (int k = 0; k < 2; k++) {
        unsigned char c[sizeof h + 64], *w = c + sizeof h;
        w += pdt_srm_put_varint(w, 0x80000000u + 10); /* (10, 0), gid 1 */
        w += pdt_srm_put_varint(w, pdt_srm_zigzag(0));
        w += pdt_srm_put_varint(w, 1);
        w += pdt_srm_put_varint(w, 0); /* (10, -5) or (10, 0) again, gid 2 */
        w += pdt_srm_put_varint(w, pdt_srm_zigzag(k == 0 ? -5 : 0));
        w += pdt_srm_put_varint(w, 2);
        srm_msg_head two = {SRM_MSG_MAGIC, 0, 0, 0, 2, 0, 0, (uint64_t)(w - c - sizeof h), 0, 0};
        memcpy(c, &two, sizeof two);
        srm_msg_view v;
        pdt_err_clear(&err);
        CHECK_MSG(pdt_srm_msg_decode(c, (size_t)(w - c), 0, "rank 0", &v, &err) == PDT_ERR_CORRUPT,
                  "order %d", k);
        CHECK_MSG(strstr(err.msg, "from rank 0: damaged payload") != NULL, "order %d: %s", k,
                  err.msg);
        /* in order, the same two points are read back */
        if (k == 0) {
            unsigned char *y = c + sizeof h;
            y += pdt_srm_put_varint(y, 0x80000000u + 10);
            y += pdt_srm_put_varint(y, pdt_srm_zigzag(-5));
            y += pdt_srm_put_varint(y, 2);
            y += pdt_srm_put_varint(y, 0);
            y += pdt_srm_put_varint(y, pdt_srm_zigzag(0));
            y += pdt_srm_put_varint(y, 1);
            two.payload = (uint64_t)(y - c - sizeof h);
            memcpy(c, &two, sizeof two);
            CHECK(pdt_srm_msg_decode(c, (size_t)(y - c), 0, "rank 0", &v, &err) == PDT_OK);
            CHECK(v.pts[0].x == 10 && v.pts[0].y == -5 && v.pts[0].gid == 2);
            CHECK(v.pts[1].x == 10 && v.pts[1].y == 0 && v.pts[1].gid == 1);
            pdt_srm_msg_free(&v);
        }
    }
    /* the same among the strips of a plain run: the sender named as a strip */
    pdt_srm_as_strips(&rk[1]);
    CHECK_MSG(strcmp(rk[1].who, "strip 2 of 2") == 0, "%s", rk[1].who);
    {
        unsigned char *c = malloc(len[0]);
        memcpy(c, msg[0], len[0]);
        srm_msg_head bad = h;
        bad.payload += wrap;
        memcpy(c, &bad, sizeof bad);
        void *mm[2] = {c, msg[1]};
        pdt_err_clear(&err);
        CHECK(pdt_srm_merge(&rk[1], 0, mm, len, &err) == PDT_ERR_CORRUPT);
        CHECK_MSG(strstr(err.msg, "merge message from strip 1 of 2: bad header") != NULL, "%s",
                  err.msg);
        free(c);
    }
    /* with relay a message is a sequence of blobs: a cut-off blob after the
     * first, or a blob for a level past the last, is refused */
    rk[1].relay = 1;
    for (int k = 0; k < 2; k++) {
        size_t extra = k == 0 ? 10 : len[0];
        unsigned char *c = malloc(len[0] + extra);
        memcpy(c, msg[0], len[0]);
        memcpy(c + len[0], msg[0], extra);
        if (k == 1) {
            srm_msg_head later = h;
            later.level = 5;
            memcpy(c + len[0], &later, sizeof later);
        }
        void *mm[2] = {c, msg[1]};
        size_t ll[2] = {len[0] + extra, len[1]};
        pdt_err_clear(&err);
        CHECK_MSG(pdt_srm_merge(&rk[1], 0, mm, ll, &err) == PDT_ERR_CORRUPT, "relay %d", k);
        CHECK_MSG(strstr(err.msg, "bad header") != NULL, "relay %d: %s", k, err.msg);
        CHECK(rk[1].nfwd == 0);
        free(c);
    }
    rk[1].relay = 0;
    /* the undamaged messages merge: every triangle final, none pending */
    pdt_err_clear(&err);
    CHECK(pdt_srm_merge(&rk[1], 0, msg, len, &err) == PDT_OK);
    CHECK(rk[0].npend == 0 && rk[1].npend == 0 && rk[1].holds_hull);
    for (int r = 0; r < 2; r++) {
        free(msg[r]);
        pdt_srm_free(&rk[r]);
    }
    free(u);
    free(tmp);
    free(pts);
}

int main(void)
{
    RUN(srm_equals_sequential);
    RUN(srm_gen_families);
    RUN(merge_message_header);
    (void)cmp_tri;
    return test_summary();
}
