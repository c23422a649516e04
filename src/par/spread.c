/* pdt — the partition phase (driver.h).  Strips: every rank's input block
 * sorted by key, cut by the exact splitters, exchanged, and the runs
 * received merged into the rank's strip.  Bisection: the cuts from a sample
 * (bisect.c), every rank's points sent unsorted to their regions, and each
 * region sorted once where it arrives.  Then the strip descriptors
 * allgathered. */
#include <stdlib.h>
#include <string.h>

#include "driver.h"

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
    if (st != PDT_OK) return pdt_drv_nomem(d, "partition");
    for (size_t i = 0; i < *nu; i++)
        rec[i] = (srm_rec){pdt_key(q[i]), (uint32_t)(in->first + pos[i]), 0};
    return PDT_OK;
}

/* The partition's buffers: the block (rec and tmp, its two record arrays),
 * the counts of the exchange and where it sends from and receives into. */
typedef struct part {
    unsigned char *blk, *more;  /* the block; a larger one when more arrive */
    size_t cap;                 /* its room, in points */
    srm_rec *rec, *tmp;
    const srm_rec *send;        /* rec: the records grouped by destination */
    srm_rec *got, *scratch;
    uint64_t *sc, *rc;          /* records to / from each rank */
    size_t *cnt, *rcnt, *start; /* bytes to / from each rank; runs received */
    uint64_t *split;
    size_t total;               /* records received */
} part;

static void part_free(part *x)
{
    free(x->cnt);
    free(x->rcnt);
    free(x->start);
    free(x->split);
    free(x->sc);
    free(x->rc);
    free(x->blk);
    free(x->more);
}

/* The block: room for this rank's input block or its share of the whole
 * plus 1/16, touched only as far as used. */
static pdt_status part_alloc(drv *d, const pdt_par_input *in, part *x)
{
    size_t p = (size_t)d->p, n = in->n;
    size_t share = (size_t)(d->n_total / (uint64_t)p), cap = n > share ? n : share;
    cap += cap / 16 + 64;
    x->cap = cap;
    x->blk = srm_big(block_bytes(cap));
    x->rec = (srm_rec *)(void *)x->blk;
    x->tmp = x->rec + cap;
    x->cnt = calloc(p, sizeof *x->cnt);
    x->rcnt = calloc(p, sizeof *x->rcnt);
    x->start = calloc(p + 1, sizeof *x->start);
    x->split = malloc(p * sizeof *x->split);
    x->sc = calloc(p, sizeof *x->sc);
    x->rc = calloc(p, sizeof *x->rc);
    if (!x->blk || !x->cnt || !x->rcnt || !x->start || !x->split || !x->sc || !x->rc)
        return pdt_drv_nomem(d, "partition");
    return PDT_OK;
}

/* This rank's records sorted, *n of them (in->pts freed as soon as the
 * records hold it if in->release_pts). */
static pdt_status part_sort(drv *d, pdt_par_input *in, part *x, size_t *n)
{
    d->blk = x->blk;
    d->blk_cap = x->cap;
    pdt_status st = sort_block(d, in, x->rec, n);
    d->blk = NULL;
    if (st != PDT_OK) return st;
    d->local_dups = in->n - *n;
    if (in->release_pts) {
        free(in->pts);
        in->pts = NULL;
    }
    return PDT_OK;
}

/* The strips: how many records go to each rank (x->sc), the splitters
 * cutting the sorted records in consecutive blocks. */
static pdt_status part_cut(drv *d, part *x, size_t n, pdt_err *err)
{
    size_t p = (size_t)d->p;
    x->send = x->rec;
    pdt_status st = pdt_drv_splitters(d, x->rec, n, x->split, err);
    for (size_t q = 0, at = 0; st == PDT_OK && q < p; q++) {
        size_t end = q < p - 1 ? pdt_srm_count_lt(x->rec, n, x->split[q]) : n;
        if (end < at) end = at;
        x->sc[q] = end - at;
        at = end;
    }
    return st;
}

/* The bisection: the cuts from a sample, and this rank's points, unsorted,
 * grouped by region into rec (x->sc of them for each rank; through tmp);
 * in->pts freed once the records hold it if in->release_pts. */
static pdt_status part_regions(drv *d, pdt_par_input *in, part *x, pdt_err *err)
{
    x->send = x->rec;
    pdt_status st = pdt_drv_bisect(d, in->pts, in->n, in->first, x->rec, x->tmp, x->sc, err);
    d->local_dups = 0;
    if (st == PDT_OK && in->release_pts) {
        free(in->pts);
        in->pts = NULL;
    }
    return st;
}

/* The counts exchanged, and the room to receive: over the scratch the send
 * leaves (merged back there), or a larger block (many equal keys). */
static pdt_status part_room(drv *d, part *x, pdt_err *err)
{
    int p = d->p;
    pdt_status st = pdt_comm_alltoall(d->c, x->sc, sizeof *x->sc, x->rc, err);
    if (st != PDT_OK) return st;
    pdt_drv_note_all(d, TAG_COUNTS, sizeof *x->sc);
    size_t total = 0;
    for (int q = 0; q < p; q++) {
        x->cnt[q] = (size_t)x->sc[q] * sizeof(srm_rec);
        x->rcnt[q] = (size_t)x->rc[q] * sizeof(srm_rec);
        x->start[q] = total;
        total += (size_t)x->rc[q];
    }
    x->start[p] = x->total = total;
    if (total < x->cap) {
        x->got = x->tmp;
        x->scratch = x->rec;
        return PDT_OK;
    }
    size_t M = total + 1;
    if (!(x->more = srm_big(block_bytes(M)))) return pdt_drv_nomem(d, "partition");
    x->got = (srm_rec *)(void *)x->more;
    x->scratch = x->got + M;
    x->cap = M;
    return PDT_OK;
}

/* The bisection's region: the records received -- in global index order
 * (from the ranks in rank order, each in input order) -- sorted by the plain
 * run's sort, the first of equal keys kept (the smallest index), into the
 * strip's points and global indices.  The block (cap M) holds the records
 * at 0 or 16 M (bytes); their points and indices (12 M) go in the other of
 * [0, 16 M) and [16 M, 32 M).  The sort's scratch follows them when the
 * records were at 16 M (the usual case: the records are spent by then, and
 * the scratch reuses their pages, which the exchange touched), else it
 * starts at 32 M. */
static pdt_status part_sort_region(drv *d, part *x)
{
    size_t T = x->total, M = d->blk_cap, nu = 0;
    unsigned char *b = d->blk;
    size_t half = M * sizeof(srm_rec), goff = (size_t)((unsigned char *)x->got - b);
    pdt_point *pt = (pdt_point *)(void *)(b + (goff ? 0 : half));
    uint32_t *idx = (uint32_t *)(void *)(pt + M);
    for (size_t i = 0; i < T; i++) {
        pt[i] = srm_key_point(x->got[i].key);
        idx[i] = x->got[i].idx;
    }
    size_t past = (M * (sizeof *pt + sizeof *idx) + 7) & ~(size_t)7;
    size_t need = PDT_SORT_WORK(T), at = goff ? past : 2 * half;
    void *work = at + need <= PDT_DELAUNAY_WORK(M) ? (void *)(b + at) : malloc(need);
    uint32_t *g = block_gid(d);
    pdt_status st = work ? pdt_sort_unique_on(pt, T, work, g, block_pts(d), &nu) : PDT_ERR_NOMEM;
    if (work != b + at) free(work);
    if (st != PDT_OK) return pdt_drv_nomem(d, "partition");
    for (size_t i = 0; i < nu; i++) g[i] = idx[g[i]];
    d->m = nu;
    return PDT_OK;
}

/* The exchange, and the runs received merged into the strip: blocks arrive
 * in rank order, each key-sorted with equal keys in index order, and rank
 * q's indices are all below rank q+1's: the stable merge puts the smallest
 * index first among equal keys, and its last pass writes the strip's points
 * and global indices, duplicates dropped.  The block is d's from here. */
static pdt_status part_move(drv *d, part *x, pdt_err *err)
{
    pdt_status st = pdt_comm_alltoallv(d->c, x->send, x->cnt, x->got, x->rcnt, err);
    if (st != PDT_OK) return st;
    pdt_drv_note_v(d, TAG_RECORDS, x->cnt, x->rcnt);
    if (x->more) {
        free(x->blk);
        x->blk = x->more;
        x->more = NULL;
    }
    d->blk = x->blk;
    d->blk_cap = x->cap;
    d->blk_bytes = block_bytes(x->cap);
    x->blk = NULL;
    d->nrecv = x->total;
    if (d->tree.cut) return part_sort_region(d, x);
    d->m = pdt_srm_runs_to_strip(x->got, x->scratch, x->start, d->p, block_pts(d), block_gid(d));
    return PDT_OK;
}

/* Sample sort of this rank's input block by key, with exact splitters (or
 * the bisection's cuts): the strip's d->m distinct points in lexicographic
 * order and their global indices end in d->blk (block_pts, block_gid). */
pdt_status pdt_drv_partition(drv *d, pdt_par_input *in, pdt_err *err)
{
    part x = {0};
    size_t n = 0;
    pdt_status st = part_alloc(d, in, &x);
    if (in->partition == PDT_PART_BISECT) {
        if (st == PDT_OK) st = part_regions(d, in, &x, err);
    } else {
        if (st == PDT_OK) st = part_sort(d, in, &x, &n);
        if (st == PDT_OK) st = part_cut(d, &x, n, err);
    }
    if (st == PDT_OK) st = part_room(d, &x, err);
    if (st == PDT_OK) st = part_move(d, &x, err);
    part_free(&x);
    return st;
}

/* The strip descriptor of this rank's points (in the block, from the
 * partition), allgathered into d->strip. */
pdt_status pdt_drv_strips(drv *d, pdt_err *err)
{
    size_t m = d->m;
    int k = d->k;
    d->strip = malloc((size_t)d->p * (size_t)k * sizeof *d->strip);
    if (!d->strip) return pdt_drv_nomem(d, "partition");
    srm_strip mine[PDT_RANK_MAX_STRIPS];
    for (int j = 0; j <= k; j++) d->first[j] = m * (size_t)j / (size_t)k;
    for (int j = 0; j < k; j++)
        mine[j] = pdt_srm_strip_of(block_pts(d) + d->first[j], d->first[j + 1] - d->first[j]);
    size_t bytes = (size_t)k * sizeof *mine;
    pdt_status st = pdt_comm_allgather(d->c, mine, bytes, d->strip, err);
    if (st == PDT_OK) pdt_drv_note_all(d, TAG_STRIPS, bytes);
    return st;
}

/* How many strips each rank holds: 2 for an untraced run of at least 2^21
 * points whose points may be spent (a .tri output), as a plain run's
 * (strips_for), with at least RANK_STRIPS_MIN_SHARE points a rank, when
 * every rank's sample says the merge pays (pdt_srm_plain_pays: one vote
 * each, summed); else 1.  (Simulated, 10^7 points on 1024 ranks, about 10^4
 * a rank: one strip took 0.098 s, two 0.112 s, the second order round and
 * the level-0 merges costing more than the smaller kernels save; 10^5 a
 * rank on 256 ranks: one strip 0.234 s, two 0.195 s.)
 * $PDT_RANK_STRIPS=1|2 decides for every size and output format of an
 * untraced run (tests). */
enum { RANK_STRIPS_MIN_SHARE = 1 << 15 };

pdt_status pdt_drv_rank_strips(drv *d, const pdt_par_input *in, pdt_err *err)
{
    const char *t = getenv("PDT_RANK_STRIPS");
    int want = t && *t ? atoi(t) : 0;
    int k = d->tr ? 1 /* (a traced run's events are the lessons': one strip a rank) */
            : want ? want
            : in->release_pts && d->n_total >= ((uint64_t)1 << 21) &&
                      d->n_total / (uint64_t)d->p >= RANK_STRIPS_MIN_SHARE
                ? 2
                : 1;
    k = k >= 2 ? 2 : 1;
    if (!want && k == 2) {
        uint64_t votes = (uint64_t)pdt_srm_plain_pays(block_pts(d), d->m);
        pdt_status st = pdt_comm_allreduce_u64(d->c, &votes, 1, PDT_COMM_SUM, err);
        if (st != PDT_OK) return st;
        pdt_drv_note_reduce(d, TAG_STRIPS, sizeof votes);
        if (votes < (uint64_t)d->p) k = 1;
    }
    d->k = k;
    return PDT_OK;
}

