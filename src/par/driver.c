/* pdt — the SRM driver: moves the data between the phases of docs/algorithm.md §3
 * with the pdt_comm wrappers.  pdt_par_triangulate reads as its phases:
 *
 *   partition  every rank's input block is sample-sorted by key (equal keys
 *              to one rank); duplicates removed (smallest index kept); strip
 *              descriptors allgathered.
 *   local      pdt_srm_local: lift-up, kernel, strip hull, classification.
 *   merge      for each level: every rank of a pair sends one message (its
 *              pending triangles for that level, and the hull if it holds
 *              one) to the merge rank, which runs pdt_srm_merge.
 *   order      the final triangles go to the rank of their smallest index's
 *              range (ranges balanced by a histogram) and are put in
 *              canonical order there: rank q ends with a consecutive block.
 *
 * With one rank the sequential pipeline does all of it: pdt_triangulate_inplace,
 * or for a large untraced .tri run the same SRM on two strips one after the
 * other in one process (pdt_srm_plain, plain.c), to hold less memory.  By the
 * same rule a rank of a large untraced .tri run holds two strips (rank_strips):
 * the SRM then runs on 2P strips, rank r holding strips 2r and 2r + 1, which
 * it triangulates one after the other in its block and merges first, at
 * level 0, with no message; the levels above are the P ranks' own. */
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "pdt/delaunay.h"
#include "pdt/testhook.h"
#include "srm.h"

enum {
    TAG_SAMPLES = 2,
    TAG_COUNTS = 3,
    TAG_RECORDS = 4,
    TAG_STRIPS = 5,
    TAG_GATHER = 6,
    TAG_STATS = 7,
    TAG_ORDER = 8,
    TAG_MERGE = 100 /* + level */
};

/* Per-rank state of the driver through the phases. */
typedef struct drv {
    pdt_comm *c;
    int rank, p;
    pdt_trace *tr;
    uint32_t *seq_send, *seq_recv; /* per-peer message sequence numbers */
    uint64_t bytes_sent, bytes_recv, merge_sent, merge_recv;
    unsigned char *blk;            /* this rank's one block (see block_bytes) */
    size_t blk_cap, blk_bytes;     /* room for blk_cap points; its size */
    size_t m;
    uint64_t nrecv;
    uint64_t local_dups;           /* copies dropped before the exchange */
    uint64_t n_total;              /* points in the whole input */
    int k;                         /* strips this rank holds (every rank the same) */
    size_t first[PDT_RANK_MAX_STRIPS + 1]; /* strip j: the block's points [first[j], first[j+1]) */
    srm_strip *strip;              /* p * k strip descriptors */
    srm_tree tree;                 /* a bisection run's regions (tree.cut NULL: strips) */
    srm_rank s[PDT_RANK_MAX_STRIPS];  /* strip k * rank + j */
    int s_init[PDT_RANK_MAX_STRIPS];
    pdt_tri *more;                 /* the order phase's finals besides the block's */
    size_t nmore;
    pdt_par_rank_stats *me;
    pdt_err *err;
} drv;

/* Trace one message (or one pair's share of a collective) and count it. */
static void note_send(drv *d, int tag, int peer, size_t bytes)
{
    d->bytes_sent += bytes;
    if (tag >= TAG_MERGE) d->merge_sent += bytes;
    PDT_TRACE(d->tr, 1, PDT_EV_SEND, tag, peer, (uint32_t)bytes, (uint32_t)((uint64_t)bytes >> 32),
              d->seq_send[peer]);
    d->seq_send[peer]++;
}

static void note_recv(drv *d, int tag, int peer, size_t bytes)
{
    d->bytes_recv += bytes;
    if (tag >= TAG_MERGE) d->merge_recv += bytes;
    PDT_TRACE(d->tr, 1, PDT_EV_RECV, tag, peer, (uint32_t)bytes, (uint32_t)((uint64_t)bytes >> 32),
              d->seq_recv[peer]);
    d->seq_recv[peer]++;
}

/* Collective with uniform block size: every pair exchanges `bytes`. */
static void note_all(drv *d, int tag, size_t bytes)
{
    for (int q = 0; q < d->p; q++)
        if (q != d->rank && bytes) {
            note_send(d, tag, q, bytes);
            note_recv(d, tag, q, bytes);
        }
}

/* An alltoallv: count what went to and came from each peer. */
static void note_v(drv *d, int tag, const size_t *sent, const size_t *recvd)
{
    for (int q = 0; q < d->p; q++) {
        if (q == d->rank) continue;
        if (sent[q]) note_send(d, tag, q, sent[q]);
        if (recvd[q]) note_recv(d, tag, q, recvd[q]);
    }
}

static double wclock(void *user)
{
    return pdt_comm_wtime(user);
}

static pdt_status nomem(drv *d, const char *phase)
{
    return pdt_err_set(d->err, PDT_ERR_NOMEM, "rank %d: %s: out of memory", d->rank, phase);
}

/* Test-only: PDT_TEST_SLEEP_BEFORE_MERGE="RANK:SECONDS" makes RANK sleep
 * before its first merge step (to kill it there in a test); PDT_TEST_MARK=FILE
 * is created when the sleep begins. */
static void test_sleep(int rank)
{
    const char *e = pdt_test_hook("PDT_TEST_SLEEP_BEFORE_MERGE");
    int r;
    double sec;
    if (e && sscanf(e, "%d:%lf", &r, &sec) == 2 && r == rank && sec > 0) {
        pdt_par_test_mark();
        struct timespec ts = {(time_t)sec, (long)((sec - (double)(time_t)sec) * 1e9)};
        nanosleep(&ts, NULL);
    }
}

void pdt_par_stats_free(pdt_par_stats *s)
{
    if (!s) return;
    free(s->rank);
    s->rank = NULL;
}

void pdt_par_output_free(pdt_par_output *out)
{
    free(out->tris);
    memset(out, 0, sizeof *out);
}

/* ---- partition -------------------------------------------------------------- */

/* The p - 1 splitters, exact: split[q-1] is the key of rank q * N / p
 * (0-based, N records in all, every rank's sorted rec[0..n) together), so
 * that the keys below it number q N / p but for copies of that key, which
 * all go with it (a key goes to the rank of the number of splitters <= it).
 * A distributed search: each round cuts every splitter's key interval into
 * SEL_WAYS parts, counts the keys up to each cut (binary searches), sums the
 * counts over the ranks (one allreduce) and keeps the part holding the
 * splitter; 64-bit keys take at most 8 rounds. */
enum { SEL_WAYS = 256 };

static uint64_t sel_cut(uint64_t lo, uint64_t hi, uint64_t step, int j)
{
    uint64_t off = (uint64_t)(j + 1) * step - 1;
    return off >= hi - lo ? hi : lo + off;
}

/* The exact selection behind the splitters and the bisection's cuts: for
 * each of ns searches, the smallest key v with more than t[i] keys <= v
 * among the key-sorted runs arr[i][0..len[i]) of all ranks, known to lie in
 * [lo[i], hi[i]] (every rank the same bounds); the answer in lo[i]. */
static pdt_status select_keys(drv *d, int ns, const srm_rec *const *arr, const size_t *len,
                              const uint64_t *t, uint64_t *lo, uint64_t *hi, pdt_err *err)
{
    int nc = SEL_WAYS - 1;
    pdt_status st = PDT_OK;
    uint64_t *cnt = malloc(((size_t)ns * (size_t)nc + 1) * sizeof *cnt);
    if (!cnt) return nomem(d, "partition");
    for (;;) {
        int open = 0;
        for (int q = 0; q < ns; q++) {
            uint64_t step = (hi[q] - lo[q]) / SEL_WAYS + 1;
            for (int j = 0; j < nc; j++) {
                uint64_t *c = &cnt[(size_t)q * (size_t)nc + (size_t)j];
                if (lo[q] == hi[q]) *c = 0;
                else *c = pdt_srm_count_lt(arr[q], len[q], sel_cut(lo[q], hi[q], step, j) + 1);
            }
            open |= lo[q] != hi[q];
        }
        if (!open) break;
        st = pdt_comm_allreduce_u64(d->c, cnt, (size_t)ns * (size_t)nc, PDT_COMM_SUM, err);
        if (st != PDT_OK) break;
        note_all(d, TAG_SAMPLES, (size_t)ns * (size_t)nc * sizeof *cnt);
        for (int q = 0; q < ns; q++) {
            if (lo[q] == hi[q]) continue;
            /* the key: the smallest v with more than t keys <= v */
            uint64_t step = (hi[q] - lo[q]) / SEL_WAYS + 1;
            int j = 0;
            while (j < nc && cnt[(size_t)q * (size_t)nc + (size_t)j] <= t[q]) j++;
            uint64_t nlo = j ? sel_cut(lo[q], hi[q], step, j - 1) + 1 : lo[q];
            if (j < nc) hi[q] = sel_cut(lo[q], hi[q], step, j);
            lo[q] = nlo;
        }
    }
    free(cnt);
    return st;
}

static pdt_status splitters(drv *d, const srm_rec *rec, size_t n, uint64_t *split, pdt_err *err)
{
    int p = d->p, q1 = p - 1;
    uint64_t ext[2] = {n ? rec[0].key : UINT64_MAX, n ? ~rec[n - 1].key : UINT64_MAX};
    pdt_status st = pdt_comm_allreduce_u64(d->c, ext, 2, PDT_COMM_MIN, err);
    if (st != PDT_OK) return st;
    note_all(d, TAG_SAMPLES, sizeof ext);
    uint64_t N = d->n_total;
    uint64_t *hi = malloc(((size_t)q1 + 1) * sizeof *hi), *t = malloc(((size_t)q1 + 1) * sizeof *t);
    size_t *len = malloc(((size_t)q1 + 1) * sizeof *len);
    const srm_rec **arr = malloc(((size_t)q1 + 1) * sizeof *arr);
    if (!hi || !t || !len || !arr) st = nomem(d, "partition");
    for (int q = 0; st == PDT_OK && q < q1; q++) { /* an empty input: every key to rank 0 */
        split[q] = N ? ext[0] : UINT64_MAX;
        hi[q] = N ? ~ext[1] : UINT64_MAX;
        t[q] = N * (uint64_t)(q + 1) / (uint64_t)p;
        arr[q] = rec;
        len[q] = n;
    }
    if (st == PDT_OK) st = select_keys(d, q1, arr, len, t, split, hi, err);
    free(hi);
    free(t);
    free(len);
    free((void *)arr);
    return st;
}

/* ---- the bisection partition (algorithm.md §3.12) -------------------------------
 *
 * Every rank range of the tree cuts its points at the exact key that leaves
 * ceil(s/2)/s of them (s ranks) on the left, along the longer side of its
 * cell.  The ranges of one depth are cut together: each rank holds its
 * records of a range as one run of w (sorted by the range's axis key, its
 * index in rec alongside), the searches share the rounds of select_keys,
 * and a cut splits each run in two in place. */
typedef struct bis_range {
    int lo, hi, at;          /* ranks [lo, hi), the preorder number of its cut */
    int64_t x0, x1, y0, y1;  /* its cell (closed; the input's box at the root), in
                              * coordinates biased by 2^31 as in the key */
    size_t s, e;             /* its records here: w[s, e) */
    int inorder;             /* w[s, e) is in rec's order (the (x, y) key's) */
} bis_range;

/* The input's box, (x0, y0) and (x1, y1), over all ranks (rec key-sorted). */
static pdt_status bis_root(drv *d, const srm_rec *rec, size_t n, bis_range *root, pdt_err *err)
{
    uint64_t v[4] = {UINT64_MAX, UINT64_MAX, UINT64_MAX, UINT64_MAX};
    for (size_t i = 0; i < n; i++) {
        uint64_t x = rec[i].key >> 32, y = rec[i].key & 0xffffffffu;
        if (x < v[0]) v[0] = x;
        if (~x < v[1]) v[1] = ~x;
        if (y < v[2]) v[2] = y;
        if (~y < v[3]) v[3] = ~y;
    }
    pdt_status st = pdt_comm_allreduce_u64(d->c, v, 4, PDT_COMM_MIN, err);
    if (st != PDT_OK) return st;
    note_all(d, TAG_SAMPLES, sizeof v);
    *root = (bis_range){0, d->p, 0, (int64_t)v[0], (int64_t)(uint32_t)~v[1], (int64_t)v[2],
                        (int64_t)(uint32_t)~v[3], 0, n, 1};
    return PDT_OK;
}

/* The axis of every range (its cell's longer side; x on a tie) and its run
 * of w sorted by that axis' key (a run already in rec's order needs no sort
 * for an x-cut: the first cut of a wide input, every cut of strips-like
 * ones).  *scratch: n records, allocated at the first sort. */
static pdt_status bis_sort(drv *d, const srm_rec *rec, srm_rec *w, size_t n, srm_rec **scratch,
                           bis_range *r, int nr)
{
    for (int i = 0; i < nr; i++) {
        int axis = r[i].x1 - r[i].x0 >= r[i].y1 - r[i].y0 ? 0 : 1;
        d->tree.cut[r[i].at].axis = axis;
        if (axis == 0 && r[i].inorder) continue;
        if (!*scratch && !(*scratch = srm_big((n + 1) * sizeof **scratch)))
            return nomem(d, "partition");
        for (size_t k = r[i].s; k < r[i].e; k++) {
            pdt_point q = srm_key_point(rec[w[k].idx].key);
            w[k].key = srm_axis_key(axis, q.x, q.y);
        }
        pdt_srm_radix_sort(w + r[i].s, *scratch, r[i].e - r[i].s);
        r[i].inorder = axis == 0; /* (rec's keys are distinct: x order is rec's) */
    }
    return PDT_OK;
}

/* The cuts of the nr ranges of one depth (every rank the same). */
static pdt_status bis_select(drv *d, const srm_rec *w, const bis_range *r, int nr, pdt_err *err)
{
    size_t z = (size_t)nr; /* (lo and hi side by side: one allreduce) */
    uint64_t *v = malloc(3 * z * sizeof *v), *t = malloc(z * sizeof *t);
    const srm_rec **arr = malloc(z * sizeof *arr);
    size_t *len = malloc(z * sizeof *len);
    pdt_status st = v && t && arr && len ? PDT_OK : nomem(d, "partition");
    uint64_t *cntr = v, *lo = v + z, *hi = v + 2 * z; /* hi: ~ of the largest key first */
    for (int i = 0; st == PDT_OK && i < nr; i++) {
        arr[i] = w + r[i].s;
        len[i] = r[i].e - r[i].s;
        cntr[i] = len[i];
        lo[i] = len[i] ? arr[i][0].key : UINT64_MAX;
        hi[i] = len[i] ? ~arr[i][len[i] - 1].key : UINT64_MAX;
    }
    if (st == PDT_OK) st = pdt_comm_allreduce_u64(d->c, cntr, (size_t)nr, PDT_COMM_SUM, err);
    if (st == PDT_OK) st = pdt_comm_allreduce_u64(d->c, lo, 2 * (size_t)nr, PDT_COMM_MIN, err);
    if (st == PDT_OK) {
        note_all(d, TAG_SAMPLES, 3 * (size_t)nr * sizeof *v);
        for (int i = 0; i < nr; i++) {
            uint64_t s = (uint64_t)(r[i].hi - r[i].lo), left = (uint64_t)(srm_bis_mid(r[i].lo, r[i].hi) - r[i].lo);
            t[i] = cntr[i] * left / s;
            hi[i] = cntr[i] ? ~hi[i] : 0;
            if (!cntr[i]) lo[i] = 0; /* no points: any cut */
        }
        st = select_keys(d, nr, arr, len, t, lo, hi, err);
    }
    for (int i = 0; st == PDT_OK && i < nr; i++) d->tree.cut[r[i].at].split = lo[i];
    free(v);
    free(t);
    free((void *)arr);
    free(len);
    return st;
}

/* Each range cut in two at its split: halves of two ranks or more into
 * next[] (their number returned), a single rank's run counted in sc[] (and
 * whether it is in rec's order in inorder[]). */
static int bis_split(drv *d, const srm_rec *w, const bis_range *r, int nr, bis_range *next,
                     uint64_t *sc, unsigned char *inorder)
{
    int nn = 0;
    for (int i = 0; i < nr; i++) {
        srm_cut c = d->tree.cut[r[i].at];
        int mid = srm_bis_mid(r[i].lo, r[i].hi);
        size_t at = r[i].s + pdt_srm_count_lt(w + r[i].s, r[i].e - r[i].s, c.split);
        int64_t v = (int64_t)(c.split >> 32); /* the cut's own coordinate (biased) */
        bis_range h[2] = {r[i], r[i]};
        h[0].hi = h[1].lo = mid;
        h[0].at = r[i].at + 1;
        h[1].at = r[i].at + mid - r[i].lo;
        h[0].e = h[1].s = at;
        if (c.axis) h[0].y1 = h[1].y0 = v;
        else h[0].x1 = h[1].x0 = v;
        for (int k = 0; k < 2; k++) {
            if (h[k].hi - h[k].lo >= 2) next[nn++] = h[k];
            else {
                sc[h[k].lo] = h[k].e - h[k].s;
                inorder[h[k].lo] = (unsigned char)h[k].inorder;
            }
        }
    }
    return nn;
}

/* The bisection of the key-sorted rec[0..n) into the ranks' regions: the
 * cuts in d->tree (every rank the same), sc[q] the records for rank q, and
 * w[0..n) the records grouped by rank, key-sorted within each group (the
 * send buffer).  scratch: n records. */
static pdt_status bisect(drv *d, const srm_rec *rec, srm_rec *w, size_t n, uint64_t *sc,
                         pdt_err *err)
{
    int p = d->p;
    d->tree.p = p;
    d->tree.k = 1;
    d->tree.levels_p = pdt_srm_ceil_log2(p);
    d->tree.cut = calloc((size_t)p, sizeof *d->tree.cut);
    bis_range *cur = malloc((size_t)p * sizeof *cur), *next = malloc((size_t)p * sizeof *next);
    unsigned char *inorder = malloc((size_t)p);
    srm_rec *scratch = NULL;
    pdt_status st = d->tree.cut && cur && next && inorder ? PDT_OK : nomem(d, "partition");
    for (size_t i = 0; i < n; i++) w[i] = (srm_rec){rec[i].key, (uint32_t)i, 0};
    int nr = 1;
    if (st == PDT_OK) st = bis_root(d, rec, n, &cur[0], err);
    while (st == PDT_OK && nr > 0) {
        st = bis_sort(d, rec, w, n, &scratch, cur, nr);
        if (st == PDT_OK) st = bis_select(d, w, cur, nr, err);
        if (st != PDT_OK) break;
        nr = bis_split(d, w, cur, nr, next, sc, inorder);
        bis_range *t = cur;
        cur = next;
        next = t;
    }
    /* each rank's run back in key order (if a y-cut moved it), as records */
    for (size_t q = 0, at = 0; st == PDT_OK && q < (size_t)p; at += sc[q++]) {
        if (!inorder[q]) {
            for (size_t i = at; i < at + sc[q]; i++) w[i].key = w[i].idx;
            pdt_srm_radix_sort(w + at, scratch, sc[q]);
        }
        for (size_t i = at; i < at + sc[q]; i++) w[i] = rec[w[i].idx];
    }
    free(cur);
    free(next);
    free(inorder);
    free(scratch);
    return st;
}

/* This rank's one block, for up to M points (fresh pages are costly on
 * this kind of machine, reused ones cheap, so every phase from the
 * partition to the order works in it):
 *   [0, PDT_DELAUNAY_WORK(M))  the partition's two record arrays (32 bytes
 *                              per point), then the kernel's edges (72), the
 *                              final triangles at its front, the order's
 *                              receive buffer and canonical scratch;
 *   then the strip's points (8 bytes each), global indices (4) and the
 *   kernel's scratch ids (4), M + 1 of each. */
static size_t block_bytes(size_t M)
{
    return PDT_DELAUNAY_WORK(M) + (M + 1) * (sizeof(pdt_point) + 2 * sizeof(uint32_t));
}

static pdt_point *block_pts(const drv *d)
{
    return (pdt_point *)(void *)(d->blk + PDT_DELAUNAY_WORK(d->blk_cap));
}

static uint32_t *block_gid(const drv *d)
{
    return (uint32_t *)(void *)(block_pts(d) + d->blk_cap + 1);
}

static uint32_t *block_id(const drv *d)
{
    return block_gid(d) + d->blk_cap + 1;
}

/* This rank's input block sorted by the plain run's sort (pdt_sort_unique_on:
 * one counting pass by the top bits into buckets, each finished in the
 * cache; the first of equal points kept, and input order is index order) on
 * the block's front, the distinct points and their positions written where
 * the strip's points and indices go later: rec[0, *nu), key-sorted, the
 * records of the distinct points with their global indices.  A block too
 * small for the sort's counters (a tiny input) gets scratch of its own. */
static pdt_status sort_block(drv *d, const pdt_par_input *in, srm_rec *rec, size_t *nu)
{
    size_t n = in->n, need = PDT_SORT_WORK(n);
    void *work = need <= PDT_DELAUNAY_WORK(d->blk_cap) ? (void *)d->blk : malloc(need);
    pdt_point *q = block_pts(d);
    uint32_t *pos = block_gid(d);
    pdt_status st = work ? pdt_sort_unique_on(in->pts, n, work, pos, q, nu) : PDT_ERR_NOMEM;
    if (work != d->blk) free(work);
    if (st != PDT_OK) return nomem(d, "partition");
    for (size_t i = 0; i < *nu; i++)
        rec[i] = (srm_rec){pdt_key(q[i]), (uint32_t)(in->first + pos[i]), 0};
    return PDT_OK;
}

/* Sample sort of this rank's input block by key, with exact splitters:
 * the strip's d->m distinct points in lexicographic order and their global
 * indices end in d->blk (block_pts, block_gid; room for this rank's input
 * block or its share of the whole plus 1/16, touched only as far as used; a
 * larger one when more records arrive).  in->pts is freed as soon as the
 * records hold it if in->release_pts. */
static pdt_status partition(drv *d, pdt_par_input *in, pdt_err *err)
{
    int p = d->p, r = d->rank;
    pdt_status st = PDT_OK;
    size_t n = in->n;
    size_t *cnt = calloc((size_t)p, sizeof *cnt), *rcnt = calloc((size_t)p, sizeof *rcnt);
    size_t *start = calloc((size_t)p + 1, sizeof *start);
    uint64_t *split = malloc((size_t)p * sizeof *split), *sc = NULL, *rc = NULL;
    size_t share = (size_t)(d->n_total / (uint64_t)p), cap = n > share ? n : share;
    cap += cap / 16 + 64;
    unsigned char *blk = srm_big(block_bytes(cap)), *more = NULL;
    srm_rec *rec = (srm_rec *)(void *)blk, *tmp = rec + cap, *got = NULL, *scratch = NULL;
    sc = malloc((size_t)p * sizeof *sc);
    rc = malloc((size_t)p * sizeof *rc);
    if (!cnt || !rcnt || !start || !split || !sc || !rc || !blk) goto nomem;
    d->blk = blk;
    d->blk_cap = cap;
    size_t nu = 0;
    st = sort_block(d, in, rec, &nu);
    d->blk = NULL;
    if (st != PDT_OK) goto done;
    d->local_dups = n - nu;
    n = nu;
    if (in->release_pts) {
        free(in->pts);
        in->pts = NULL;
    }
    const srm_rec *send = rec;
    if (in->partition == PDT_PART_BISECT) { /* the records regrouped by rank, in tmp */
        st = bisect(d, rec, tmp, n, sc, err);
        send = tmp;
    } else {
        st = splitters(d, rec, n, split, err);
        /* rank q's records are a consecutive block of the sorted ones */
        for (size_t q = 0, at = 0; st == PDT_OK && q < (size_t)p; q++) {
            size_t end = q < (size_t)p - 1 ? pdt_srm_count_lt(rec, n, split[q]) : n;
            if (end < at) end = at;
            sc[q] = end - at;
            at = end;
        }
    }
    if (st != PDT_OK) goto done;
    st = pdt_comm_alltoall(d->c, sc, sizeof *sc, rc, err);
    if (st != PDT_OK) goto done;
    note_all(d, TAG_COUNTS, sizeof *sc);
    size_t total = 0;
    for (int q = 0; q < p; q++) {
        cnt[q] = (size_t)sc[q] * sizeof(srm_rec);
        rcnt[q] = (size_t)rc[q] * sizeof(srm_rec);
        start[q] = total;
        total += (size_t)rc[q];
    }
    start[p] = total;
    if (total < cap) { /* received over the scratch the send leaves; merged back */
        got = send == rec ? tmp : rec;
        scratch = send == rec ? rec : tmp;
    } else { /* more than the room (many equal keys): a larger block */
        size_t M = total + 1;
        more = srm_big(block_bytes(M));
        if (!more) goto nomem;
        got = (srm_rec *)(void *)more;
        scratch = got + M;
        cap = M;
    }
    st = pdt_comm_alltoallv(d->c, send, cnt, got, rcnt, err);
    if (st != PDT_OK) goto done;
    note_v(d, TAG_RECORDS, cnt, rcnt);
    if (more) {
        free(blk);
        blk = more;
        more = NULL;
    }
    /* blocks arrive in rank order, each key-sorted with equal keys in index
     * order, and rank q's indices are all below rank q+1's: the stable merge
     * puts the smallest index first among equal keys, and its last pass
     * writes the strip's points and global indices, duplicates dropped */
    d->blk = blk;
    d->blk_cap = cap;
    d->blk_bytes = block_bytes(cap);
    blk = NULL;
    d->nrecv = total;
    d->m = pdt_srm_runs_to_strip(got, scratch, start, p, block_pts(d), block_gid(d));
    goto done;
nomem:
    st = pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: partition: out of memory", r);
done:
    free(cnt);
    free(rcnt);
    free(start);
    free(split);
    free(sc);
    free(rc);
    free(blk);
    free(more);
    return st;
}

/* The strip descriptor of this rank's points (in the block, from the
 * partition), allgathered into d->strip. */
static pdt_status strips(drv *d, pdt_err *err)
{
    size_t m = d->m;
    int k = d->k;
    d->strip = malloc((size_t)d->p * (size_t)k * sizeof *d->strip);
    if (!d->strip) return nomem(d, "partition");
    srm_strip mine[PDT_RANK_MAX_STRIPS];
    for (int j = 0; j <= k; j++) d->first[j] = m * (size_t)j / (size_t)k;
    for (int j = 0; j < k; j++)
        mine[j] = pdt_srm_strip_of(block_pts(d) + d->first[j], d->first[j + 1] - d->first[j]);
    size_t bytes = (size_t)k * sizeof *mine;
    pdt_status st = pdt_comm_allgather(d->c, mine, bytes, d->strip, err);
    if (st == PDT_OK) note_all(d, TAG_STRIPS, bytes);
    return st;
}

/* How many strips each rank holds: 2 for an untraced run of at least 2^21
 * points whose points may be spent (a .tri output), as a plain run's
 * (strips_for), when every rank's sample says the merge pays
 * (pdt_srm_plain_pays: one vote each, summed); else 1.
 * $PDT_RANK_STRIPS=1|2 decides for every size and output format of an
 * untraced run (tests). */
static pdt_status rank_strips(drv *d, const pdt_par_input *in, pdt_err *err)
{
    const char *t = getenv("PDT_RANK_STRIPS");
    int want = t && *t ? atoi(t) : 0;
    int k = d->tr ? 1 /* (a traced run's events are the lessons': one strip a rank) */
            : want ? want : in->release_pts && d->n_total >= ((uint64_t)1 << 21) ? 2 : 1;
    k = k >= 2 ? 2 : 1;
    if (!want && k == 2) {
        uint64_t votes = (uint64_t)pdt_srm_plain_pays(block_pts(d), d->m);
        pdt_status st = pdt_comm_allreduce_u64(d->c, &votes, 1, PDT_COMM_SUM, err);
        if (st != PDT_OK) return st;
        note_all(d, TAG_STRIPS, sizeof votes);
        if (votes < (uint64_t)d->p) k = 1;
    }
    d->k = k;
    return PDT_OK;
}

/* Phases 1 and 2 on this rank's strip, in its block (which the SRM state
 * owns from here on, as the array of final triangles); with `prefault` a
 * second thread faults the kernel's part of the block in ahead of it. */
static pdt_status local(drv *d, int prefault, pdt_err *err)
{
    int k = d->k;
    pdt_status st = PDT_OK;
    for (int j = 0; j < k; j++) {
        srm_rank *s = &d->s[j];
        st = pdt_srm_init(s, d->rank * k + j, d->p * k, d->strip, d->tr, err);
        if (st != PDT_OK) return st;
        d->s_init[j] = 1;
        pdt_srm_per_rank(s, k);
        if (d->tree.cut) {
            d->tree.k = k;
            st = pdt_srm_use_tree(s, &d->tree, err);
            if (st != PDT_OK) return st;
        }
        s->clock = wclock;
        s->clock_user = d->c;
    }
    pdt_point *pts = block_pts(d);
    uint32_t *gid = block_gid(d), *id = block_id(d);
    unsigned char *blk = d->blk;
    d->blk = NULL;
    /* strip j's kernel right behind the final triangles of the strips before
     * it (an even number: the edges stay 8-byte aligned; an odd one is set
     * aside in d->more) */
    size_t off = 0, need = 0;
    for (int j = 0; j < k; j++) {
        size_t mj = d->first[j + 1] - d->first[j];
        size_t end = (j ? 24 * d->first[j] : 0) + PDT_DELAUNAY_WORK(mj);
        need = end > need ? end : need;
    }
    pdt_prefault *pf = NULL;
    if (prefault) { /* the kernel's edges grow past the partition's records, up to its
                     * bound for this strip's points (the block has room for more) */
        size_t front = 2 * d->blk_cap * sizeof(srm_rec);
        pdt_range edges = {blk + front, need > front ? need - front : 0};
        pf = pdt_prefault_start(&edges, 1);
        d->me->prefault = pf != NULL;
    }
    size_t nfin = 0;
    for (int j = 0; j < k && st == PDT_OK; j++) {
        size_t a = d->first[j], mj = d->first[j + 1] - a;
        srm_rank *s = &d->s[j];
        st = pdt_srm_local(s, blk + off, pts + a, gid + a, id, mj, err);
        if (st != PDT_OK) break;
        if (j + 1 < k && s->nfin % 2) {
            pdt_tri *more = realloc(d->more, (d->nmore + 1) * sizeof *more);
            if (!more) {
                st = nomem(d, "local");
                break;
            }
            d->more = more;
            d->more[d->nmore++] = s->fin[--s->nfin];
        }
        off += s->nfin * sizeof(pdt_tri);
        nfin += s->nfin;
        if (j) { /* (the block is strip 0's: its finals hold every strip's, in order) */
            s->fin = NULL;
            s->nfin = s->capfin = 0;
        }
    }
    if (st == PDT_OK) {
        d->s[0].nfin = nfin;
        d->s[0].capfin = nfin;
    }
    pdt_prefault_stop(pf); /* every page of the block has been touched */
    return st;
}

/* ---- merge --------------------------------------------------------------------- */

/* The merge tree's schedule: the bisection tree, or NULL for strips. */
static const srm_tree *sched(const drv *d)
{
    return d->tree.cut ? &d->tree : NULL;
}

/* At the merge strip g of a level (this rank's strip j): the messages of the
 * pair's strips [gl, ge): this rank's own (in own[], taken: freed here), the
 * others received from their ranks, in strip order (a rank sends its strips'
 * messages in that order, and messages from one rank with one tag arrive in
 * the order sent); merged. */
static pdt_status merge_at(drv *d, int level, int j, int gl, int ge, void **own, size_t *own_len,
                           pdt_err *err)
{
    int k = d->k, nm = ge - gl;
    test_sleep(d->rank);
    void **msg = calloc((size_t)nm, sizeof *msg);
    size_t *lens = calloc((size_t)nm, sizeof *lens);
    pdt_status st = msg && lens ? PDT_OK : nomem(d, "merge");
    for (int q = gl; q < ge && st == PDT_OK; q++) {
        int from = q / k;
        if (from == d->rank) {
            msg[q - gl] = own[q % k];
            lens[q - gl] = own_len[q % k];
            own[q % k] = NULL;
            continue;
        }
        st = pdt_comm_recv(d->c, from, TAG_MERGE + level, &msg[q - gl], &lens[q - gl], err);
        if (st == PDT_OK) note_recv(d, TAG_MERGE + level, from, lens[q - gl]);
    }
    if (st == PDT_OK) st = pdt_srm_merge(&d->s[j], level, msg, lens, err);
    for (int i = 0; msg && i < nm; i++) free(msg[i]);
    free(msg);
    free(lens);
    return st;
}

/* One level of the merge tree on this rank: each of its strips whose group
 * has a partner packs its message (in strip order) and sends it to the rank
 * of the pair's merge strip, or keeps it when that strip is its own; then
 * the merges at its own merge strips. */
static pdt_status merge_level(drv *d, int level, pdt_err *err)
{
    int k = d->k, np = d->p * k;
    void *own[PDT_RANK_MAX_STRIPS] = {0};
    size_t own_len[PDT_RANK_MAX_STRIPS] = {0};
    pdt_status st = PDT_OK;
    for (int j = 0; j < k && st == PDT_OK; j++) {
        int g = d->rank * k + j, gl, gr, ge;
        if (!pdt_srm_pair_of(sched(d), g, np, level, &gl, &gr, &ge)) continue;
        st = pdt_srm_pack(&d->s[j], level, &own[j], &own_len[j], err);
        if (st != PDT_OK || gr / k == d->rank) continue;
        st = pdt_comm_send(d->c, gr / k, TAG_MERGE + level, own[j], own_len[j], err);
        if (st == PDT_OK) note_send(d, TAG_MERGE + level, gr / k, own_len[j]);
        free(own[j]);
        own[j] = NULL;
    }
    for (int j = 0; j < k && st == PDT_OK; j++) {
        int g = d->rank * k + j, gl, gr, ge;
        if (pdt_srm_pair_of(sched(d), g, np, level, &gl, &gr, &ge) && gr == g)
            st = merge_at(d, level, j, gl, ge, own, own_len, err);
    }
    for (int j = 0; j < k; j++) free(own[j]);
    return st;
}

/* Phase 3: the merge tree, level by level; this rank takes part in the
 * levels where one of its strips' groups has a partner. */
static pdt_status merge_tree(drv *d, pdt_err *err)
{
    pdt_status st = PDT_OK;
    int k = d->k, np = d->p * k;
    for (int level = 0; level < d->s[0].levels && st == PDT_OK; level++) {
        int gl, gr, ge, any = 0;
        for (int j = 0; j < k; j++)
            any |= pdt_srm_pair_of(sched(d), d->rank * k + j, np, level, &gl, &gr, &ge);
        if (!any) continue;
        PDT_TRACE(d->tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_MERGE, level, 0, 0, 0);
        st = merge_level(d, level, err);
        if (st == PDT_OK) PDT_TRACE(d->tr, 1, PDT_EV_PHASE_END, PDT_PH_MERGE, level, 0, 0, 0);
    }
    for (int j = 0; j < k && st == PDT_OK; j++)
        if (d->s[j].npend)
            st = pdt_err_set(err, PDT_ERR_CHECK, "%s: %zu triangles still pending after the "
                             "last merge", d->s[j].who, d->s[j].npend);
    return st;
}

/* After the merges: the finals besides the block's (the strips' merges' and
 * those set aside) in one array, d->more. */
static pdt_status gather_more(drv *d)
{
    size_t n = d->nmore;
    for (int j = 0; j < d->k; j++) n += d->s[j].nmore;
    pdt_tri *all = realloc(d->more, (n + 1) * sizeof *all);
    if (!all) return nomem(d, "order");
    for (int j = 0; j < d->k; j++) {
        if (d->s[j].nmore) memcpy(all + d->nmore, d->s[j].more, d->s[j].nmore * sizeof *all);
        d->nmore += d->s[j].nmore;
        free(d->s[j].more);
        d->s[j].more = NULL;
        d->s[j].nmore = d->s[j].capmore = 0;
    }
    d->more = all;
    return PDT_OK;
}

/* After the merges the strip's points and their names in the block are done
 * with: their pages go back before the order phase (which may take that room
 * again: it is the block's far end) -- 16 bytes a point of the peak. */
static void release_points(drv *d)
{
    if (!d->s[0].fin) return;
    unsigned char *blk = (unsigned char *)d->s[0].fin;
    size_t at = PDT_DELAUNAY_WORK(d->blk_cap);
    pdt_release_pages(blk + at, d->blk_bytes - at);
}

/* ---- canonical order across ranks ------------------------------------------------ */

/* The canonical order sorts by smallest index first, so the output splits
 * into ranges of smallest index: rank q writes the triangles whose smallest
 * index lies in its range.  The ranges are made of buckets of 2^shift
 * consecutive indices, the same on every rank (pdt_tri_bucket_*): each rank
 * counts its final triangles by bucket, the counts summed over the ranks
 * (one allreduce) give each rank a range of buckets holding about T / p
 * triangles, each rank groups its triangles by bucket (one pass: the runs
 * for the ranks are then consecutive), one exchange of 12-byte records, and
 * each rank puts what it got in order bucket by bucket -- the counting sort
 * of the plain run, split at the exchange, with no sorted runs to merge. */

/* The final triangles of a rank: the local phase's and the merges'. */
typedef struct finals {
    pdt_tri *t[2];
    size_t n[2];
} finals;

/* The buckets: 2^shift consecutive smallest indices each, as many over
 * [0, n_total) as fit in max(2048, 256 p), at most 2^16: about 256 per rank
 * (a bucket is never split between ranks), and narrow enough that one
 * bucket's counters (8 bytes an index) stay a third of its triangles. */
static int order_shift(const drv *d)
{
    uint64_t top = d->n_total ? d->n_total - 1 : 0;
    uint64_t want = (uint64_t)256 * (uint64_t)d->p;
    if (want < 2048) want = 2048;
    if (want > ((uint64_t)1 << 16)) want = (uint64_t)1 << 16;
    int sh = 0;
    while ((top >> sh) + 1 > want) sh++;
    return sh;
}

/* The plan of the exchange, in `rounds` rounds (bucket b goes in round
 * b % rounds: a round's grouped array holds about 1/rounds of the finals):
 * hist[b], this rank's triangles in bucket b; the buckets' owners from the
 * sum over the ranks (the rank whose share holds a bucket's middle:
 * nondecreasing in b); sc[q * rounds + r], how many this rank sends rank q in
 * round r, rc the same received; at[b], where bucket b starts in its round's
 * grouped array; most, the largest round's count. */
typedef struct order_plan {
    int shift, rounds;
    size_t nb, most;
    uint64_t *hist, *at, *sc, *rc;
} order_plan;

static void order_plan_free(order_plan *o)
{
    free(o->hist);
    free(o->at);
    free(o->sc);
    free(o->rc);
}

static pdt_status order_plan_make(drv *d, finals *f, order_plan *o, pdt_err *err)
{
    int p = d->p;
    int R = o->rounds = d->k > 1 ? 2 : 1; /* (two when the strips are, for memory) */
    o->shift = order_shift(d);
    o->nb = (size_t)((d->n_total ? d->n_total - 1 : 0) >> o->shift) + 1;
    o->hist = calloc(o->nb, sizeof *o->hist);
    o->at = calloc(o->nb, sizeof *o->at);
    o->sc = calloc((size_t)p * (size_t)R, sizeof *o->sc);
    o->rc = calloc((size_t)p * (size_t)R, sizeof *o->rc);
    uint64_t *sum = calloc(o->nb, sizeof *sum);
    if (!o->hist || !o->at || !o->sc || !o->rc || !sum) {
        free(sum);
        return nomem(d, "order");
    }
    for (int k = 0; k < 2; k++) pdt_tri_bucket_count(f->t[k], f->n[k], o->shift, o->hist);
    memcpy(sum, o->hist, o->nb * sizeof *sum);
    pdt_status st = pdt_comm_allreduce_u64(d->c, sum, o->nb, PDT_COMM_SUM, err);
    if (st == PDT_OK) {
        note_all(d, TAG_ORDER, o->nb * sizeof *sum);
        uint64_t total = 0, before = 0, pos[2] = {0, 0};
        for (size_t b = 0; b < o->nb; b++) total += sum[b];
        for (size_t b = 0; b < o->nb; b++) {
            uint64_t q = total ? (before + sum[b] / 2) * (uint64_t)p / total : 0;
            int r = (int)(b % (size_t)R);
            before += sum[b];
            o->sc[(q < (uint64_t)p ? q : (uint64_t)p - 1) * (uint64_t)R + (uint64_t)r] += o->hist[b];
            o->at[b] = pos[r];
            pos[r] += o->hist[b];
        }
        o->most = (size_t)(pos[0] > pos[1] ? pos[0] : pos[1]);
        st = pdt_comm_alltoall(d->c, o->sc, (size_t)R * sizeof *o->sc, o->rc, err);
        if (st == PDT_OK) note_all(d, TAG_COUNTS, (size_t)R * sizeof *o->sc);
    }
    free(sum);
    return st;
}

/* Where the order phase groups, receives and orders: in the rank's block
 * (room for cap triangles, the local finals at its front) when each fits,
 * else in arrays of their own, and each as low in the block as it fits, so
 * that the phase touches about the pages the kernel did (finals, grp and got
 * take some 6 triangles per point, the kernel's edges 72 bytes), not the
 * block's far end (room for 1/16 more points than the strip holds):
 *   grp  the grouped triangles, behind the finals;
 *   got  the received ones, right past grp (sent before anything arrives)
 *        or past out, whichever ends later;
 *   out  the ordered output at the front (the finals and grp have been read
 *        by then). */
typedef struct order_room {
    pdt_tri *blk;
    size_t cap;
    pdt_tri *grp, *got, *out;
    int grp_own, got_own, out_own;
} order_room;

static void order_room_free(order_room *o)
{
    if (o->grp_own) free(o->grp);
    if (o->got_own) free(o->got);
    if (o->out_own) free(o->out);
}

/* PDT_TEST_ORDER_ROOM=N: the order phase sees at most N triangles of room
 * in the block (tests: every choice of room below runs on small inputs). */
static size_t test_order_room(size_t cap)
{
    const char *e = pdt_test_hook("PDT_TEST_ORDER_ROOM");
    char *end;
    unsigned long long v = e && *e ? strtoull(e, &end, 10) : 0;
    return e && *e && !*end && v < cap ? (size_t)v : cap;
}

static pdt_status order_room_grp(drv *d, order_room *o, const finals *f, size_t mine)
{
    o->blk = d->s[0].fin;
    o->cap = o->blk ? test_order_room(d->blk_bytes / sizeof(pdt_tri)) : 0; /* (the strip's
                                                                              points are done) */
    if (o->blk && f->n[0] + mine + 1 <= o->cap) { /* (+ 1: a round's spare place) */
        o->grp = o->blk + f->n[0];
        return PDT_OK;
    }
    o->grp = srm_big((mine + 1) * sizeof *o->grp);
    o->grp_own = 1;
    return o->grp ? PDT_OK : nomem(d, "order");
}

static pdt_status order_room_out(drv *d, order_room *o, const finals *f, size_t grp,
                                 size_t total)
{
    size_t busy = o->grp_own ? 0 : f->n[0] + grp + 1; /* grp, until it has been sent */
    size_t got_at = busy > total ? busy : total;
    if (o->blk && got_at <= o->cap && o->cap - got_at >= total) {
        o->got = o->blk + got_at;
    } else {
        o->got = srm_big((total + 1) * sizeof *o->got);
        o->got_own = 1;
    }
    if (o->blk && total <= o->cap) { /* below got, if got is in the block */
        o->out = o->blk;
    } else {
        o->out = srm_big((total + 1) * sizeof *o->out);
        o->out_own = 1;
    }
    return o->got && o->out ? PDT_OK : nomem(d, "order");
}

/* Phase 4: the final triangles go to the rank of their smallest index's
 * range, which puts them in canonical order: rank q ends with the q-th block
 * of the canonical output in out (and its place in the whole output). */
static pdt_status order(drv *d, pdt_par_output *out, pdt_err *err)
{
    int p = d->p;
    finals f = {{d->s[0].fin, d->more}, {d->s[0].nfin, d->nmore}};
    order_plan o = {0};
    order_room room = {0};
    size_t *cnt = calloc((size_t)p, sizeof *cnt), *rcnt = calloc((size_t)p, sizeof *rcnt);
    size_t *len = calloc(2 * (size_t)p, sizeof *len);
    const pdt_tri **src = calloc(2 * (size_t)p, sizeof *src);
    pdt_status st = cnt && rcnt && len && src ? PDT_OK : nomem(d, "order");
    if (st == PDT_OK) st = order_plan_make(d, &f, &o, err);
    if (st == PDT_OK) st = order_room_grp(d, &room, &f, o.most);
    if (st != PDT_OK) goto done;
    size_t total = 0;
    for (size_t i = 0; i < (size_t)p * (size_t)o.rounds; i++) total += (size_t)o.rc[i];
    st = order_room_out(d, &room, &f, o.most, total);
    /* round r: the triangles of its buckets grouped, sent, received behind
     * the rounds before; each source's run of a round is in bucket order */
    size_t off = 0;
    uint8_t *in = o.rounds > 1 ? malloc(o.nb) : NULL;
    uint64_t *at = o.rounds > 1 ? malloc(o.nb * sizeof *at) : NULL;
    if (o.rounds > 1 && (!in || !at)) st = nomem(d, "order");
    for (int r = 0; r < o.rounds && st == PDT_OK; r++) {
        if (o.rounds == 1) {
            for (int k = 0; k < 2; k++) pdt_tri_bucket_scatter(f.t[k], f.n[k], o.shift, o.at, room.grp);
        } else {
            for (size_t b = 0; b < o.nb; b++) { /* (the others: to the spare place) */
                in[b] = b % (size_t)o.rounds == (size_t)r;
                at[b] = in[b] ? o.at[b] : o.most;
            }
            for (int k = 0; k < 2; k++)
                pdt_tri_bucket_scatter_round(f.t[k], f.n[k], o.shift, in, at, room.grp);
        }
        pdt_tri *into = room.got + off;
        for (int q = 0; q < p; q++) {
            size_t i = (size_t)q * (size_t)o.rounds + (size_t)r, j = (size_t)r * (size_t)p + (size_t)q;
            cnt[q] = (size_t)o.sc[i] * sizeof(pdt_tri);
            rcnt[q] = (size_t)o.rc[i] * sizeof(pdt_tri);
            src[j] = room.got + off;
            len[j] = (size_t)o.rc[i];
            off += len[j];
        }
        st = pdt_comm_alltoallv(d->c, room.grp, cnt, into, rcnt, err);
        if (st == PDT_OK) note_v(d, TAG_ORDER, cnt, rcnt);
    }
    free(in);
    free(at);
    if (st != PDT_OK) goto done;
    if (pdt_tri_bucket_order(src, len, (size_t)p * (size_t)o.rounds, o.shift, room.out) != PDT_OK) {
        st = nomem(d, "order");
        goto done;
    }
    free(d->more); /* every triangle went somewhere (itself included) */
    d->more = NULL;
    d->nmore = 0;
    d->s[0].fin = NULL; /* the block is room.blk */
    d->s[0].nfin = d->s[0].capfin = 0;
    if (room.out == room.blk) {
        pdt_tri *shrunk = realloc(room.out, (total + 1) * sizeof *room.out);
        room.out = shrunk ? shrunk : room.out;
    } else {
        free(room.blk);
    }
    room.blk = NULL;
    room.out_own = 0;
    uint64_t first = 0, all = total;
    st = pdt_comm_exscan_u64(d->c, total, &first, err); /* place in the whole output */
    if (st == PDT_OK) st = pdt_comm_allreduce_u64(d->c, &all, 1, PDT_COMM_SUM, err);
    out->tris = room.out;
    out->ntri = total;
    out->first = first;
    out->n_total = all;
    room.out = NULL;
    if (st == PDT_OK) note_all(d, TAG_ORDER, sizeof all);
done:
    order_room_free(&room);
    order_plan_free(&o);
    free(cnt);
    free(rcnt);
    free(len);
    free((void *)src);
    return st;
}

/* ---- figures -------------------------------------------------------------------- */

static void figures(drv *d)
{
    pdt_par_rank_stats *me = d->me;
    me->points = d->m;
    me->received = d->nrecv + d->local_dups;
    me->n_dup = me->received - d->m;
    me->bytes_sent = d->bytes_sent;
    me->bytes_recv = d->bytes_recv;
    me->merge_bytes_sent = d->merge_sent;
    me->merge_bytes_recv = d->merge_recv;
    me->strips = d->k > 1 ? d->k : 0;
    me->levels = d->s[0].levels;
    me->partition = d->tree.cut ? PDT_PART_BISECT : PDT_PART_STRIPS;
    for (int j = 0; j < d->k; j++) { /* the strips' counts summed; the longest chain */
        const srm_rank *s = &d->s[j];
        me->local_tris += s->cnt.local_tris;
        me->final_at_once += s->cnt.final_at_once;
        me->deferred += s->cnt.deferred;
        me->shipped += s->cnt.shipped;
        me->merges += s->cnt.merges;
        if (s->cnt.border_max > me->border_max) me->border_max = s->cnt.border_max;
        for (int l = 0; l < PDT_PAR_MAX_LEVELS; l++)
            if (s->cnt.border_level[l] > me->border_level[l])
                me->border_level[l] = s->cnt.border_level[l];
        me->kept += s->cnt.kept;
        me->discarded += s->cnt.discarded;
        me->final_merge += s->cnt.final_merge;
        if (s->cnt.critical_path > me->critical_path) me->critical_path = s->cnt.critical_path;
        if (s->cnt.critical_cpu > me->critical_cpu) me->critical_cpu = s->cnt.critical_cpu;
        int g = d->rank * d->k + j;
        if (s->holds_hull && pdt_srm_holder_of(sched(d), g, d->p * d->k, s->levels) == g) {
            me->holds_final_hull = 1;
            me->hull = s->nhull;
            me->hull_degenerate = s->hull_degenerate;
        }
    }
}

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* How many strips a plain run works on one after the other (pdt_srm_plain):
 * 2 for an untraced run of at least 2^21 points whose points may be spent
 * (a .tri output), else 0 (the whole kernel at once: traces keep the events
 * of one kernel run, the lessons count them; below 2^21 points, some 180 MB,
 * the 22 bytes per point saved are worth less than the 8-12 % of time), or
 * when a sample says the merge would redo most of the work (pdt_srm_plain_pays).
 * $PDT_PLAIN_STRIPS=K decides for every size: 0 the whole kernel (about 8 %
 * faster at 10^7 points, 84 bytes per point instead of 62), 2..16 strips. */
static int strips_for(const pdt_point *pts, size_t n)
{
    const char *t = getenv("PDT_PLAIN_STRIPS");
    if (t && *t) {
        int k = atoi(t);
        return k >= 2 && k <= PDT_PLAIN_MAX_STRIPS ? k : 0;
    }
    return n >= ((size_t)1 << 21) && pdt_srm_plain_pays(pts, n) ? 2 : 0;
}

static int plain_strips(const pdt_par_input *in, const pdt_trace *tr)
{
    return tr || !in->release_pts ? 0 : strips_for(in->pts, in->n);
}

/* T* of the points (pdt/par.h): on a copy the pipeline may spend, on
 * strips_for strips like a plain run's .tri output. */
pdt_status pdt_par_tstar(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri,
                         int *strips)
{
    *tris = NULL;
    *ntri = 0;
    *strips = strips_for(pts, n);
    pdt_point *copy = malloc(n ? n * sizeof *copy : 1);
    if (!copy) return PDT_ERR_NOMEM;
    memcpy(copy, pts, n * sizeof *copy);
    pdt_tri_stats ts;
    pdt_err err = {0};
    pdt_status st = *strips ? pdt_srm_plain(copy, n, *strips, 0, tris, ntri, &ts, &err)
                            : pdt_triangulate_inplace(copy, n, PDT_PTS_SPEND, tris, ntri, &ts, NULL);
    free(copy);
    return st;
}

/* Under SMPI the kernel's own phase clock is this machine's, not the
 * simulated one: its three phases are scaled to the simulated span they
 * fill (critical_path, which then holds nothing else). */
static void simulated_phases(pdt_par_rank_stats *me)
{
    double sum = me->t_partition + me->t_local + me->t_order;
    double f = sum > 0 ? me->critical_path / sum : 0;
    me->t_partition *= f;
    me->t_local *= f;
    me->t_order *= f;
}

/* One rank: the sequential pipeline on the whole input (the whole kernel, or
 * plain_strips strips one after the other), its figures in the same shape;
 * the trace gets the final triangles as a parallel run does. */
static pdt_status sequential(pdt_comm *c, pdt_par_input *in, pdt_par_output *out,
                             pdt_par_rank_stats *me, pdt_trace *tr, pdt_err *err)
{
    pdt_tri_stats ts;
    double c0 = cpu_seconds(), w0 = pdt_comm_wtime(c);
    int how = (in->release_pts ? PDT_PTS_SPEND : PDT_PTS_RESTORE) |
              (in->prefault ? PDT_TRI_PREFAULT : 0);
    int k = plain_strips(in, tr);
    pdt_status st;
    if (k) {
        st = pdt_srm_plain(in->pts, in->n, k, in->prefault, &out->tris, &out->ntri, &ts, err);
    } else {
        st = pdt_triangulate_inplace(in->pts, in->n, how, &out->tris, &out->ntri, &ts, tr);
        if (st != PDT_OK)
            pdt_err_set(err, st, "triangulation failed: %s", pdt_status_str(st));
    }
    if (in->release_pts) {
        free(in->pts);
        in->pts = NULL;
    }
    if (st != PDT_OK) return st;
    out->first = 0;
    out->n_total = out->ntri;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_OUTPUT, 0, 0, 0, 0);
    for (size_t i = 0; i < out->ntri && PDT_TRACING(tr, 1); i++)
        PDT_TRACE(tr, 1, PDT_EV_TRI_FINAL, 0, out->tris[i].v[0], out->tris[i].v[1],
                  out->tris[i].v[2], 0);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_OUTPUT, 0, 0, 0, 0);
    me->points = ts.n_unique;
    me->received = ts.n_in;
    me->n_dup = ts.n_dup;
    me->local_tris = me->final_at_once = me->emitted = ts.n_tri;
    me->hull = ts.n_hull;
    me->holds_final_hull = 1;
    me->prefault = ts.prefaulted;
    me->strips = k;
    me->hull_degenerate = ts.collinear;
    me->t_partition = ts.t_sort;
    me->t_local = ts.t_kernel;
    me->t_order = ts.t_canon;
    me->critical_path = pdt_comm_wtime(c) - w0;
    if (pdt_comm_is_simulated(c)) simulated_phases(me);
    me->critical_cpu = cpu_seconds() - c0;
    return PDT_OK;
}

/* The phase of pdt_par_triangulate this process is in (NULL outside it), for
 * a message when the job is ended from outside (pdt_par_phase). */
static _Atomic(const char *) cur_phase;

const char *pdt_par_phase(void)
{
    return atomic_load_explicit(&cur_phase, memory_order_relaxed);
}

static void enter(const char *phase)
{
    atomic_store_explicit(&cur_phase, phase, memory_order_relaxed);
}

/* ---- the whole run ------------------------------------------------------------ */

pdt_status pdt_par_triangulate(pdt_comm *c, pdt_par_input *in, pdt_par_output *out,
                               pdt_par_rank_stats *me, pdt_trace *tr, pdt_err *err)
{
    memset(out, 0, sizeof *out);
    if (in->n_total > UINT32_MAX - 1)
        return pdt_err_set(err, PDT_ERR_ARG, "%llu points: more than 2^32 - 2",
                           (unsigned long long)in->n_total);
    const uint32_t *saved_gid = tr ? tr->gid : NULL;
    if (tr) tr->gid = NULL; /* the driver reports global indices itself */
    if (pdt_comm_size(c) == 1) {
        pdt_status st = sequential(c, in, out, me, tr, err);
        if (tr) tr->gid = saved_gid;
        return st;
    }
    drv d;
    memset(&d, 0, sizeof d);
    d.c = c;
    d.rank = pdt_comm_rank(c);
    d.p = pdt_comm_size(c);
    d.tr = tr;
    d.n_total = in->n_total;
    d.me = me;
    d.err = err;
    pdt_status st = PDT_OK;
    d.seq_send = calloc((size_t)d.p, sizeof *d.seq_send);
    d.seq_recv = calloc((size_t)d.p, sizeof *d.seq_recv);
    if (!d.seq_send || !d.seq_recv) {
        st = nomem(&d, "start");
        goto done;
    }
    double t0 = pdt_comm_wtime(c);
    enter("partition");
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_PARTITION, 0, 0, 0, 0);
    st = partition(&d, in, err);
    if (st == PDT_OK) st = rank_strips(&d, in, err);
    if (st == PDT_OK) st = strips(&d, err);
    if (st != PDT_OK) goto done;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_PARTITION, 0, 0, 0, 0);
    double t1 = pdt_comm_wtime(c);
    enter("local");
    st = local(&d, in->prefault, err);
    if (st != PDT_OK) goto done;
    double t2 = pdt_comm_wtime(c);
    enter("merge");
    st = merge_tree(&d, err);
    /* the merge phase ends when the last merge does: ranks done early sleep
     * here (counted as merge time, not as order time) */
    if (st == PDT_OK) st = pdt_comm_quiet_barrier(c, err);
    if (st != PDT_OK) goto done;
    double t3 = pdt_comm_wtime(c);
    st = gather_more(&d);
    if (st != PDT_OK) goto done;
    me->emitted = d.s[0].nfin + d.nmore;
    release_points(&d);
    enter("order");
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_ORDER, 0, 0, 0, 0);
    st = order(&d, out, err);
    if (st != PDT_OK) goto done;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_ORDER, 0, 0, 0, 0);
    double t4 = pdt_comm_wtime(c);
    me->t_partition = t1 - t0;
    me->t_local = t2 - t1;
    me->t_merge = t3 - t2;
    me->t_order = t4 - t3;
    figures(&d);
done:
    enter(NULL);
    if (tr) tr->gid = saved_gid;
    for (int j = 0; j < PDT_RANK_MAX_STRIPS; j++)
        if (d.s_init[j]) pdt_srm_free(&d.s[j]);
    free(d.more);
    free(d.blk);
    free(d.strip);
    free(d.tree.cut);
    free(d.seq_send);
    free(d.seq_recv);
    return st;
}

/* ---- figures of the whole run ------------------------------------------------------ */

pdt_status pdt_par_stats_collect(pdt_comm *c, const pdt_par_rank_stats *me, uint64_t n_in,
                                 pdt_par_stats *all, pdt_err *err)
{
    memset(all, 0, sizeof *all);
    int p = pdt_comm_size(c), r = pdt_comm_rank(c);
    pdt_par_rank_stats *reps = r == 0 ? malloc((size_t)p * sizeof *reps) : NULL;
    size_t *counts = malloc((size_t)p * sizeof *counts);
    if ((r == 0 && !reps) || !counts) {
        free(reps);
        free(counts);
        return pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: out of memory", r);
    }
    for (int q = 0; q < p; q++) counts[q] = sizeof *me;
    pdt_status st = pdt_comm_gatherv(c, me, sizeof *me, reps, counts, 0, err);
    free(counts);
    if (st != PDT_OK || r != 0) {
        free(reps);
        return st;
    }
    all->nranks = p;
    all->rank = reps;
    all->n_in = n_in;
    for (int q = 0; q < p; q++) {
        const pdt_par_rank_stats *rp = &reps[q];
        all->n_unique += rp->points;
        all->n_dup += rp->n_dup;
        all->n_tri += rp->written;
        all->bytes_total += rp->bytes_sent;
        all->merge_bytes += rp->merge_bytes_sent;
        if (rp->critical_path > all->critical_path) all->critical_path = rp->critical_path;
        if (rp->critical_cpu > all->critical_cpu) all->critical_cpu = rp->critical_cpu;
        if (rp->border_max > all->border_max) all->border_max = rp->border_max;
        for (int l = 0; l < PDT_PAR_MAX_LEVELS; l++)
            if (rp->border_level[l] > all->border_level[l])
                all->border_level[l] = rp->border_level[l];
        if (rp->levels > all->levels) all->levels = rp->levels;
        all->partition = rp->partition;
        double tc = rp->t_partition + rp->t_local + rp->t_merge + rp->t_order;
        if (tc > all->t_compute) all->t_compute = tc;
        if (rp->holds_final_hull) {
            all->hull = rp->hull;
            all->collinear = rp->hull_degenerate || all->n_unique < 3;
        }
    }
    if (all->n_unique < 3) all->collinear = 1;
    return PDT_OK;
}
