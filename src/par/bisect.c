/* pdt — the bisection partition's cuts (algorithm.md §3.12, driver.h).
 *
 * The cuts come from a sample, not from exact medians: the output is T*(P)
 * for every choice of cuts (algorithm.md §3.8), so a cut only has to
 * balance the regions well enough, and to be the same on every rank and in
 * every run.  Each rank draws a fixed share of its input block (one point
 * from each of s equal stretches of it, at a place a hash of the stretch's
 * global number chooses: a regular sample that no periodic input order
 * aliases; all the block's points when it has at most s), rank 0 gathers
 * the samples, cuts them recursively -- each rank range across its cell's
 * longer side, at the key that leaves ceil(s/2)/s of the range's sample on
 * the left -- and broadcasts the p - 1 cuts.  Every rank then sends each of
 * its points to the region the cuts put it in, unsorted: the receiver sorts
 * its region once (spread.c).
 *
 * (The first version selected exact medians: every rank sorted its block,
 * kept it in two orders, (x, y) and (y, x), and ran rounds of counts and
 * allreduces for every depth of the tree; at 10^7 points and 64 ranks that
 * was most of the partition's time.)  A sample of 2^17 points in all puts a
 * region within a few per cent of n / p at p = 64 (one sample point in 1/s
 * of the region's count, s = 2^17 / p: about 2 % at p = 64). */
#include <stdlib.h>
#include <string.h>

#include "driver.h"

/* Sample points over all ranks (a rank draws BIS_SAMPLE / p of its block,
 * at least BIS_MIN_SHARE). */
enum { BIS_SAMPLE = 1 << 17, BIS_MIN_SHARE = 64 };

static size_t bis_share(int p)
{
    size_t s = (size_t)BIS_SAMPLE / (size_t)p;
    return s < BIS_MIN_SHARE ? BIS_MIN_SHARE : s;
}

/* A record's key on the other axis: (x, y) <-> (y, x), the key's halves
 * swapped (srm_axis_key). */
static inline uint64_t swap_key(uint64_t k)
{
    return k << 32 | k >> 32;
}

/* splitmix64's finaliser: a fixed hash of a stretch's number. */
static uint64_t bis_mix(uint64_t z)
{
    z += 0x9e3779b97f4a7c15u;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    return z ^ (z >> 31);
}

/* This rank's sample of pts[0..n) (global indices from `first`) into
 * slot[1..]: one point from each of s equal stretches, s = min(n, share);
 * slot[0] = s. */
static void bis_sample(const pdt_point *pts, size_t n, uint64_t first, size_t share,
                       uint64_t *slot)
{
    size_t s = n < share ? n : share;
    slot[0] = s;
    for (size_t j = 0; j < s; j++) {
        size_t a = n * j / s, b = n * (j + 1) / s; /* (b > a: s <= n) */
        size_t at = a + (size_t)(bis_mix(first + a) % (uint64_t)(b - a));
        slot[1 + j] = pdt_key(pts[at]);
    }
}

/* A rank range's cell (closed; the sample's box at the root), in
 * coordinates biased by 2^31 as in the key. */
typedef struct bis_cell {
    int64_t x0, x1, y0, y1;
} bis_cell;

/* The sample of a rank range in two orders: x[0..m) by the (x, y) key,
 * y[0..m) the same points keyed and sorted by (y, x); tmp: scratch. */
typedef struct bis_ord {
    srm_rec *x, *y, *tmp;
    size_t m;
} bis_ord;

/* The records of o[0..m) (the order across the cut's axis) whose key on the
 * cut's axis is below split first, each side in its order (through tmp). */
static void bis_partition(srm_rec *o, srm_rec *tmp, size_t m, uint64_t split)
{
    size_t l = 0, r = m;
    for (size_t k = 0; k < m; k++) { /* left from the front, right from the back */
        if (swap_key(o[k].key) < split) tmp[l++] = o[k];
        else tmp[--r] = o[k];
    }
    memcpy(o, tmp, l * sizeof *o);
    for (size_t k = l; k < m; k++) o[k] = tmp[m - 1 - (k - l)];
}

/* The cuts of the rank range [lo, hi) (the cut of the range at preorder
 * number `at` first) from its sample o: the key of the sample's point of
 * rank ceil(s/2)/s along the axis; the run of that axis splits where the
 * key falls, the other is partitioned stably, and each half recurses. */
static void bis_cut(srm_cut *cut, int lo, int hi, int at, bis_ord o, bis_cell c)
{
    if (hi - lo < 2) return;
    int axis = c.x1 - c.x0 >= c.y1 - c.y0 ? 0 : 1, mid = srm_bis_mid(lo, hi);
    uint64_t split = 0; /* (no sample: any cut) */
    size_t left = 0;
    if (o.m) {
        const srm_rec *a = axis ? o.y : o.x;
        left = (size_t)((uint64_t)o.m * (uint64_t)(mid - lo) / (uint64_t)(hi - lo));
        split = a[left].key;
        while (left > 0 && a[left - 1].key == split) left--; /* (copies go right) */
        bis_partition(axis ? o.x : o.y, o.tmp, o.m, split);
    }
    cut[at] = (srm_cut){split, axis};
    int64_t v = (int64_t)(split >> 32); /* the cut's own coordinate (biased) */
    bis_cell l = c, r = c;
    if (axis) l.y1 = r.y0 = v;
    else l.x1 = r.x0 = v;
    bis_ord ol = {o.x, o.y, o.tmp, left}, orr = {o.x + left, o.y + left, o.tmp, o.m - left};
    bis_cut(cut, lo, mid, at + 1, ol, l);
    bis_cut(cut, mid, hi, at + mid - lo, orr, r);
}

/* Rank 0: the samples of every rank (slots of `slot` words) in two sorted
 * orders, their box, the cuts. */
static pdt_status bis_root(drv *d, const uint64_t *all, size_t slot)
{
    int p = d->p;
    size_t m = 0;
    for (int q = 0; q < p; q++) m += (size_t)all[(size_t)q * slot];
    srm_rec *buf = srm_big((3 * m + 3) * sizeof *buf);
    if (!buf) return pdt_drv_nomem(d, "partition");
    bis_ord o = {buf, buf + m + 1, buf + 2 * m + 2, m};
    bis_cell c = {INT64_MAX, INT64_MIN, INT64_MAX, INT64_MIN};
    size_t k = 0;
    for (int q = 0; q < p; q++) {
        const uint64_t *s = all + (size_t)q * slot;
        for (size_t i = 0; i < (size_t)s[0]; i++, k++) {
            uint64_t key = s[1 + i];
            int64_t x = (int64_t)(key >> 32), y = (int64_t)(key & 0xffffffffu);
            c.x0 = x < c.x0 ? x : c.x0;
            c.x1 = x > c.x1 ? x : c.x1;
            c.y0 = y < c.y0 ? y : c.y0;
            c.y1 = y > c.y1 ? y : c.y1;
            o.x[k] = (srm_rec){key, 0, 0};
            o.y[k] = (srm_rec){swap_key(key), 0, 0};
        }
    }
    if (!m) c = (bis_cell){0, 0, 0, 0};
    pdt_srm_radix_sort(o.x, o.tmp, m);
    pdt_srm_radix_sort(o.y, o.tmp, m);
    bis_cut(d->tree.cut, 0, p, 0, o, c);
    free(buf);
    return PDT_OK;
}

/* The cuts in d->tree, the same on every rank: samples gathered at rank 0,
 * cut there, broadcast. */
static pdt_status bis_tree(drv *d, const pdt_point *pts, size_t n, uint64_t first, pdt_err *err)
{
    int p = d->p;
    size_t share = bis_share(p), slot = share + 1;
    d->tree.p = p;
    d->tree.k = 1;
    d->tree.levels_p = pdt_srm_ceil_log2(p);
    d->tree.cut = calloc((size_t)p, sizeof *d->tree.cut);
    uint64_t *mine = malloc(slot * sizeof *mine);
    uint64_t *all = d->rank == 0 ? malloc((size_t)p * slot * sizeof *all) : NULL;
    size_t *cnt = malloc((size_t)p * sizeof *cnt);
    pdt_status st = d->tree.cut && mine && cnt && (d->rank || all) ? PDT_OK
                                                                    : pdt_drv_nomem(d, "partition");
    if (st == PDT_OK) {
        bis_sample(pts, n, first, share, mine);
        for (int q = 0; q < p; q++) cnt[q] = slot * sizeof *mine;
        st = pdt_comm_gatherv(d->c, mine, slot * sizeof *mine, all, cnt, 0, err);
    }
    if (st == PDT_OK) {
        pdt_drv_note_all(d, TAG_SAMPLES, (size_t)(mine[0] + 1) * sizeof *mine);
        if (d->rank == 0) st = bis_root(d, all, slot);
    }
    if (st == PDT_OK) { /* (a failure at rank 0 ends the job: no agreement here) */
        size_t bytes = (size_t)(p - 1) * sizeof *d->tree.cut;
        st = pdt_comm_bcast(d->c, d->tree.cut, bytes, 0, err);
        if (st == PDT_OK) pdt_drv_note_all(d, TAG_SAMPLES, bytes);
    }
    free(mine);
    free(all);
    free(cnt);
    return st;
}

/* The rank whose region holds the point of key `key`: down the tree from
 * the root, left when the key on the cut's axis is below the cut. */
static inline uint32_t bis_dest(const srm_cut *cut, int p, uint64_t key)
{
    int lo = 0, hi = p, at = 0;
    while (hi - lo >= 2) {
        int mid = srm_bis_mid(lo, hi);
        srm_cut c = cut[at];
        uint64_t k = c.axis ? swap_key(key) : key;
        int left = k < c.split;
        at = left ? at + 1 : at + (mid - lo);
        lo = left ? lo : mid;
        hi = left ? mid : hi;
    }
    return (uint32_t)lo;
}

pdt_status pdt_drv_bisect(drv *d, const pdt_point *pts, size_t n, uint64_t first, srm_rec *send,
                          srm_rec *tmp, uint64_t *sc, pdt_err *err)
{
    pdt_status st = bis_tree(d, pts, n, first, err);
    if (st != PDT_OK) return st;
    int p = d->p;
    const srm_cut *cut = d->tree.cut;
    uint64_t *at = calloc((size_t)p, sizeof *at);
    if (!at) return pdt_drv_nomem(d, "partition");
    for (size_t i = 0; i < n; i++) { /* (the region in the record's spare word) */
        uint64_t key = pdt_key(pts[i]);
        uint32_t q = bis_dest(cut, p, key);
        tmp[i] = (srm_rec){key, (uint32_t)(first + i), q};
        sc[q]++;
    }
    uint64_t sum = 0;
    for (int q = 0; q < p; q++) {
        at[q] = sum;
        sum += sc[q];
    }
    for (size_t i = 0; i < n; i++) send[at[tmp[i].pad]++] = tmp[i];
    free(at);
    return PDT_OK;
}
