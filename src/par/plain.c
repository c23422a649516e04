/* pdt — the plain run on strips, one after the other (pdt_srm_plain in
 * srm.h): the memory of the sequential pipeline cut by the thesis' own
 * algorithm.
 *
 * The kernel on all n points holds 72 bytes of edge records per point at
 * its end (docs/geometry.md); with the points (8) and their input indices
 * (4) the plain run peaked at 84 bytes per point.  Here the sorted points
 * are cut into k strips by count, as k ranks would hold them, and SRM
 * (docs/algorithm.md §3) runs on one strip after the other in one block R:
 *
 *   R[0, 48n)   the sort's records and sorted points (pdt_sort_unique_on);
 *   then        strip 0's kernel at R's front: its final triangles stay at
 *               the front (12 bytes each, about 24 bytes per point of the
 *               strip), strip 1's kernel right after them, and so on: R
 *               holds the edges of one strip and the triangles of the strips
 *               before it (k = 2: 12 + 36 bytes per point);
 *   then        the merges (border sets only: the SRM's own small arrays),
 *               their triangles appended, the canonical order with the room
 *               that is left as scratch.
 *
 * Peak: the points (8), their indices (4), R (48) and one strip's kernel
 * scratch (4 per point of the strip): about 62 bytes per point with k = 2.
 * The output is the same triangles in the same order: the SRM's final
 * triangles are T* for any number of strips (tests/sh/plain_strips.sh). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pdt/delaunay.h"
#include "srm.h"

static double mono(void *user)
{
    (void)user;
    return pdt_seconds();
}

/* The plan: strip s is pts[first[s], first[s + 1]). */
typedef struct plan {
    int k;
    size_t first[PDT_PLAIN_MAX_STRIPS + 1];
    srm_strip strip[PDT_PLAIN_MAX_STRIPS];
    srm_rank rk[PDT_PLAIN_MAX_STRIPS];
    int init[PDT_PLAIN_MAX_STRIPS];
} plan;

/* R's size for n input points on k strips, the most of: the sort's records
 * and sorted points; for each strip s, the triangles of the strips before it
 * (at most 2 per point: 24 bytes) and its kernel (with the n' <= n distinct
 * points a strip may hold one point more); all triangles and the canonical
 * order's scratch as many again (48 bytes per point). */
static size_t block_bytes(size_t n, int k)
{
    size_t need = PDT_SORT_WORK(n) + n * sizeof(pdt_point);
    for (int s = 0; s < k; s++) {
        size_t a = n * (size_t)s / (size_t)k, b = n * (size_t)(s + 1) / (size_t)k;
        size_t strip = 24 * a + PDT_DELAUNAY_WORK(b - a + 1);
        if (strip > need) need = strip;
    }
    if (48 * n > need) need = 48 * n;
    return need + 256;
}

/* Sort and dedupe: pts[0, nu) the distinct points in lexicographic order,
 * order[i] the input index of pts[i] (the smallest among equal points). */
static pdt_status sort_points(pdt_point *pts, size_t n, unsigned char *R, uint32_t *order,
                              size_t *nu)
{
    pdt_point *q = (pdt_point *)(void *)(R + PDT_SORT_WORK(n));
    pdt_status st = pdt_sort_unique_on(pts, n, R, order, q, nu);
    if (st == PDT_OK) memcpy(pts, q, *nu * sizeof *pts);
    return st;
}

/* Strip s's local phase in R at *off: its final triangles end at R + *off
 * (advanced past them, an odd one set aside in *spare so the next strip's
 * block stays 8-byte aligned). */
static pdt_status strip_local(plan *P, int s, pdt_point *pts, uint32_t *order, uint32_t *id,
                              unsigned char *R, size_t *off, pdt_tri *spare, size_t *nspare,
                              pdt_err *err)
{
    srm_rank *S = &P->rk[s];
    pdt_status st = pdt_srm_init(S, s, P->k, P->strip, NULL, err);
    if (st != PDT_OK) /* (its message names a rank) */
        return pdt_err_set(err, st, "strip %d of %d: %s", s + 1, P->k, pdt_status_str(st));
    P->init[s] = 1;
    pdt_srm_as_strips(S);
    S->clock = mono;
    size_t a = P->first[s], m = P->first[s + 1] - a;
    pdt_tri *fin = (pdt_tri *)(void *)(R + *off);
    st = pdt_srm_local(S, fin, pts + a, order + a, id, m, err);
    size_t nf = S->nfin;
    S->fin = NULL; /* R's, not the state's */
    S->nfin = 0;
    if (st != PDT_OK) return st;
    if (nf % 2) spare[(*nspare)++] = fin[--nf];
    *off += nf * sizeof *fin;
    return PDT_OK;
}

/* The merge tree over the strips, level by level: every strip of a pair
 * packs its message, the pair's merge strip merges them. */
static pdt_status merge_tree(plan *P, pdt_err *err)
{
    pdt_status st = PDT_OK;
    int levels = pdt_srm_ceil_log2(P->k);
    void *msg[PDT_PLAIN_MAX_STRIPS];
    size_t len[PDT_PLAIN_MAX_STRIPS];
    for (int level = 0; level < levels && st == PDT_OK; level++) {
        for (int gl = 0; gl < P->k && st == PDT_OK;) {
            int l, gr, ge;
            if (!pdt_srm_pair(gl, P->k, level, &l, &gr, &ge) || l != gl) {
                gl++; /* alone at this level (a pair starts at its first strip) */
                continue;
            }
            memset(msg, 0, sizeof msg);
            for (int r = gl; r < ge && st == PDT_OK; r++)
                st = pdt_srm_pack(&P->rk[r], level, &msg[r - gl], &len[r - gl], err);
            if (st == PDT_OK) st = pdt_srm_merge(&P->rk[gr], level, msg, len, err);
            for (int r = gl; r < ge; r++) free(msg[r - gl]);
            gl = ge;
        }
    }
    for (int s = 0; s < P->k && st == PDT_OK; s++)
        if (P->rk[s].npend)
            st = pdt_err_set(err, PDT_ERR_CHECK, "strip %d of %d: %zu triangles still pending "
                             "after the last merge", s + 1, P->k, P->rk[s].npend);
    return st;
}

/* The triangles the merges made, and those set aside, after the strips'
 * ones at t[nt]: the new count. */
static size_t append_rest(plan *P, pdt_tri *t, size_t nt, const pdt_tri *spare, size_t nspare)
{
    memcpy(t + nt, spare, nspare * sizeof *t);
    nt += nspare;
    for (int s = 0; s < P->k; s++) {
        if (P->rk[s].nmore) memcpy(t + nt, P->rk[s].more, P->rk[s].nmore * sizeof *t);
        nt += P->rk[s].nmore;
    }
    return nt;
}

/* ---- whether the strips pay ---------------------------------------------------- */

static int key_cmp(const void *a, const void *b)
{
    uint64_t x = pdt_key(*(const pdt_point *)a), y = pdt_key(*(const pdt_point *)b);
    return x < y ? -1 : x > y;
}

int pdt_srm_plain_pays(const pdt_point *pts, size_t n)
{
    enum { SAMPLE = 4096 };
    if (n < 4 * (size_t)SAMPLE) return 1;
    pdt_point *s = malloc(SAMPLE * sizeof *s);
    if (!s) return 1;
    for (size_t i = 0; i < SAMPLE; i++) s[i] = pts[i * (n / SAMPLE)];
    qsort(s, SAMPLE, sizeof *s, key_cmp);
    size_t m = 0;
    for (size_t i = 0; i < SAMPLE; i++)
        if (m == 0 || s[i].x != s[m - 1].x || s[i].y != s[m - 1].y) s[m++] = s[i];
    pdt_tri *t = NULL;
    size_t nt = 0, open = 0;
    int pays = 1;
    if (m >= 64 && pdt_delaunay(s, m, &t, &nt, 0, NULL) == PDT_OK && nt > 0) {
        /* the two strips' slabs, as pdt_srm_slab_of makes them */
        srm_slab left = {-INFINITY, (double)s[m / 2].x, -INFINITY, INFINITY},
                 right = {(double)s[m / 2 - 1].x, INFINITY, -INFINITY, INFINITY};
        for (size_t i = 0; i < nt; i++) {
            srm_pt v[3];
            for (int e = 0; e < 3; e++) v[e] = (srm_pt){s[t[i].v[e]].x, s[t[i].v[e]].y, 0};
            open += !srm_disk_in_slab(&left, v[0], v[1], v[2]) &&
                    !srm_disk_in_slab(&right, v[0], v[1], v[2]);
        }
        pays = open * 4 <= nt;
    }
    free(t);
    free(s);
    return pays;
}

/* A failure worded for a plain run, as the whole kernel's are
 * ("triangulation failed: ..."; the SRM names the strip: srm_rank.who). */
static pdt_status plain_failure(pdt_status st, pdt_err *err)
{
    if (!err) return st;
    char was[sizeof err->msg];
    snprintf(was, sizeof was, "%s", err->msg[0] ? err->msg : pdt_status_str(st));
    pdt_err_clear(err);
    return pdt_err_set(err, st, "triangulation failed: %s", was);
}

/* The pipeline's arrays: R (block_bytes), the index list, the kernel's
 * scratch ids for the largest strip, the plan; and the prefault thread. */
typedef struct arrays {
    unsigned char *R;
    size_t bytes, big;
    uint32_t *order, *id;
    plan *P;
    pdt_prefault *pf;
} arrays;

static pdt_status arrays_get(arrays *a, size_t n, int k, int prefault, pdt_err *err)
{
    memset(a, 0, sizeof *a);
    a->bytes = block_bytes(n, k);
    a->big = n / (size_t)k + 2;
    a->R = srm_big(a->bytes);
    a->order = srm_big((n + 1) * sizeof *a->order);
    a->id = malloc(a->big * sizeof *a->id);
    a->P = calloc(1, sizeof *a->P);
    if (!a->R || !a->order || !a->id || !a->P)
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    if (prefault && a->bytes >= (8u << 20)) {
        /* as the sort and the strips use them: the sort's bucket writes
         * (R[16n, 24n)), the index list, its other records, then the rest
         * where the strips' edges grow, and the kernel's scratch ids */
        pdt_range rr[5] = {{a->R + 16 * n, 8 * n}, {a->order, n * sizeof *a->order},
                           {a->R, 16 * n}, {a->R + 24 * n, a->bytes - 24 * n},
                           {a->id, a->big * sizeof *a->id}};
        a->pf = pdt_prefault_start(rr, 5);
    }
    return PDT_OK;
}

/* Everything but R (and the prefault thread, stopped before). */
static void arrays_put(arrays *a, int k)
{
    for (int s = 0; s < k; s++)
        if (a->P && a->P->init[s]) pdt_srm_free(&a->P->rk[s]);
    free(a->P);
    free(a->order);
    free(a->id);
    a->P = NULL;
    a->order = a->id = NULL;
}

/* The strips: k consecutive blocks of the nu sorted points, by count. */
static void plan_strips(plan *P, const pdt_point *pts, size_t nu, int k)
{
    P->k = k;
    for (int s = 0; s <= k; s++) P->first[s] = nu * (size_t)s / (size_t)k;
    for (int s = 0; s < k; s++)
        P->strip[s] = pdt_srm_strip_of(pts + P->first[s], P->first[s + 1] - P->first[s]);
}

/* R shrunk to the nt triangles at its front (freed if none). */
static pdt_tri *shrink(unsigned char *R, size_t nt)
{
    if (nt == 0) {
        free(R);
        return NULL;
    }
    pdt_tri *t = realloc(R, nt * sizeof *t);
    return t ? t : (pdt_tri *)(void *)R;
}

pdt_status pdt_srm_plain(pdt_point *pts, size_t n, int k, int prefault, pdt_tri **tris,
                         size_t *ntri, pdt_tri_stats *stats, pdt_err *err)
{
    *tris = NULL;
    *ntri = 0;
    memset(stats, 0, sizeof *stats);
    stats->n_in = n;
    if (k < 2 || k > PDT_PLAIN_MAX_STRIPS || n > PDT_KERNEL_MAX_POINTS)
        return pdt_err_set(err, PDT_ERR_ARG, "triangulation failed: %d strips of %zu points", k,
                           n);
    double t0 = mono(NULL);
    arrays a;
    pdt_status st = arrays_get(&a, n, k, prefault, err);
    stats->prefaulted = a.pf != NULL;
    size_t nu = 0, nt = 0, nspare = 0, off = 0;
    pdt_tri spare[PDT_PLAIN_MAX_STRIPS];
    if (st == PDT_OK) st = sort_points(pts, n, a.R, a.order, &nu);
    double t1 = mono(NULL);
    if (st == PDT_OK) plan_strips(a.P, pts, nu, k);
    for (int s = 0; s < k && st == PDT_OK; s++)
        st = strip_local(a.P, s, pts, a.order, a.id, a.R, &off, spare, &nspare, err);
    if (st == PDT_OK) st = merge_tree(a.P, err);
    pdt_prefault_stop(a.pf);
    double t2 = mono(NULL);
    pdt_tri *t = (pdt_tri *)(void *)a.R;
    if (st == PDT_OK) {
        nt = append_rest(a.P, t, off / sizeof *t, spare, nspare);
        pdt_tri_canonical_on(t, nt, t + nt);
    }
    double t3 = mono(NULL);
    arrays_put(&a, k);
    if (st != PDT_OK) {
        free(a.R);
        return plain_failure(st, err);
    }
    stats->n_unique = nu;
    stats->n_dup = n - nu;
    stats->n_tri = nt;
    stats->collinear = nt == 0;
    stats->n_hull = nt ? 2 * nu - 2 - nt : nu; /* Euler, as the plain pipeline counts it */
    stats->t_sort = t1 - t0;
    stats->t_kernel = t2 - t1;
    stats->t_canon = t3 - t2;
    *tris = shrink(a.R, nt);
    *ntri = nt;
    return PDT_OK;
}
