/* pdt — the bisection partition's cuts (algorithm.md §3.12, driver.h).
 *
 * The cuts come from a sample, not from exact medians: the output is T*(P)
 * for every choice of cuts (algorithm.md §3.8), so a cut only has to
 * balance the regions well enough, and to be the same on every rank and in
 * every run.  Each rank draws a fixed share of its input block (one point
 * from each of s equal stretches of it, at a place a hash of the stretch's
 * global position chooses: a regular sample that no periodic input order
 * aliases; all the block's points when it has at most s), rank 0 gathers
 * the samples (bis_gather), and the cuts are made down the tree (bis_down):
 * each rank range across its cell's longer side, at the key that leaves
 * ceil(s/2)/s of the range's sample on the left.  With many points a rank
 * the cuts are then moved by counts of the points (bis_count).  Every rank
 * then sends each of its points to the region the cuts put it in,
 * unsorted: the receiver sorts its region once (spread.c).
 *
 * Exact medians would need every rank's block sorted and rounds of counts
 * and allreduces at every depth of the tree.  A sample of 2^17 points in
 * all puts a region within about 1/sqrt(2s) of n / p, s = 2^17 / p sample
 * points a region (at p = 64 the largest of 10^7 uniform points' regions
 * held 4.3 % more than n / p; at p = 1024 the largest of 10^8, 31 %); the
 * counts, a share of every rank's points at each cut's window, within a
 * few bins of the windows (docs/parallel.md, "Cuts moved by counts").
 * Uncounted cuts take half the sample (bis_share). */
#include <stdlib.h>
#include <string.h>

#include "driver.h"

#include "pdt/testhook.h"

/* Sample points over all ranks (a rank draws BIS_SAMPLE / p of its block,
 * at least BIS_MIN_SHARE), half as many when the cuts are not counted
 * (bis_share). */
enum { BIS_SAMPLE = 1 << 17, BIS_MIN_SHARE = 64 };

/* The ranks from which the samples go to rank 0 up a tree (bis_gather).
 * A test build's PDT_TEST_BIS_GATHER=1 or 2 forces the gather or the tree. */
enum { BIS_TREE_FROM = 64 };

static int bis_by_tree(int p)
{
    const char *t = pdt_test_hook("PDT_TEST_BIS_GATHER");
    if (t && (*t == '1' || *t == '2')) return *t == '2';
    return p >= BIS_TREE_FROM;
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

/* The t-th smallest of a[0..n) (t < n), a left as it is: a radix
 * selection, 11 bits at a time from the top, each pass counting the keys
 * that are still candidates and keeping those of the digit holding the
 * t-th in `keep` (n keys and 2048 counters of room).  No branch on a key
 * (a quickselect's compares go either way half the time, each mispredicted
 * one some 15 cycles); exact, so the cuts are those of any selection. */
static uint64_t bis_radix_kth(const uint64_t *a, size_t n, size_t t, uint64_t *keep)
{
    static const int shift[6] = {53, 42, 31, 20, 9, 0}, width[6] = {11, 11, 11, 11, 11, 9};
    const uint64_t *cur = a;
    size_t *cnt = (size_t *)(void *)(keep + n); /* (2048 counters past keep) */
    for (int d = 0;; d++) {
        uint64_t mask = ((uint64_t)1 << width[d]) - 1;
        memset(cnt, 0, ((size_t)mask + 1) * sizeof *cnt);
        for (size_t i = 0; i < n; i++) cnt[(cur[i] >> shift[d]) & mask]++;
        uint64_t b = 0;
        while (t >= cnt[b]) t -= cnt[b++];
        size_t k = 0; /* (in place from the second pass: k <= i) */
        for (size_t i = 0; i < n; i++) {
            keep[k] = cur[i];
            k += ((cur[i] >> shift[d]) & mask) == b;
        }
        cur = keep;
        n = k;
        if (d == 5 || n == 1) return cur[d == 5 ? 0 : t];
    }
}

/* Where a cut's true place lies, almost surely: keys [lo, hi) on the
 * cut's axis, between the sample's points 2 sqrt(m) + 2 ranks either side
 * of the one the cut is at (the sample's rank of the true place is off by
 * about sqrt(m) / 2: four standard deviations).  Every rank counts its
 * points there in BIS_BINS equal bins (bis_count), and the counts move the
 * cut (bis_refined).  Empty (lo == hi): no sample, the cut stays. */
typedef struct bis_window {
    uint64_t lo, hi;
    int shift; /* a key's bin: (key - lo) >> shift */
} bis_window;

/* The bins of a window; the points a rank counts in them; the first depth
 * whose cuts are counted (above it a cut's sample has at least
 * BIS_SAMPLE / 8 points, which put it within a fraction of a per cent). */
enum { BIS_BINS = 16, BIS_COUNTED = 8192, BIS_COUNT_FROM = 3 };

/* Whether the cuts are counted: from 2^15 points a rank, where the local
 * phase is long enough for a region's excess to cost more than the rounds
 * of counts (4-6 ms of the partition on 1024 simulated ranks).  A test
 * build's PDT_TEST_BIS_COUNT=0 or 1 decides. */
static int bis_counted(const drv *d)
{
    const char *t = pdt_test_hook("PDT_TEST_BIS_COUNT");
    if (t && (*t == '0' || *t == '1')) return *t == '1';
    return d->n_total / (uint64_t)d->p >= (uint64_t)1 << 15;
}

/* A rank's share of the sample.  Uncounted cuts (below 2^15 points a
 * rank) take half the sample: on 1024 simulated ranks its gather and cuts
 * are most of the partition's fixed cost (10^7 uniform points: 9.1 ms with
 * 2^17 points, 7.0-7.2 with 2^16), while the largest region grew from
 * 12,587 to 13,812 points (n / p = 9,766), a local phase of a few
 * milliseconds.  Counted cuts keep it all: their windows come from the
 * sample, and the depths above the counted ones are its alone. */
static size_t bis_share(const drv *d)
{
    size_t s = (size_t)BIS_SAMPLE / (bis_counted(d) ? 1 : 2) / (size_t)d->p;
    return s < BIS_MIN_SHARE ? BIS_MIN_SHARE : s;
}

/* Words of the cuts' allreduce a cut: split and axis, and its window when
 * counted. */
static size_t bis_words(const drv *d)
{
    return bis_counted(d) ? 4 : 2;
}

static size_t isqrt(size_t m)
{
    size_t r = 0;
    while ((r + 1) * (r + 1) <= m) r++;
    return r;
}

/* A sample key on a cut's axis: as it is across x (axis 0), its halves
 * swapped across y (am: all ones for axis 1), without a branch. */
static inline uint64_t bis_axis_key(uint64_t k, uint64_t am)
{
    return (swap_key(k) & am) | (k & ~am);
}

/* The keys of ranks r[0] <= r[1] <= r[2] among the axis keys of a[0..m)
 * (r[2] < m) into at[0..3).  One pass finds the keys' span, one counts
 * them in 2048 bins of the top 11 bits in which they differ, one keeps
 * those of the bins from r[0]'s to r[2]'s, and the radix selection finds
 * the three among them: four passes over the sample, where a selection for
 * each rank would take two or more each.  Exact, so the keys are those of
 * any selection.  0 without memory. */
static int bis_ranks(const uint64_t *a, size_t m, uint64_t am, const size_t r[3], uint64_t at[3])
{
    uint64_t lo = UINT64_MAX, hi = 0;
    for (size_t i = 0; i < m; i++) {
        uint64_t k = bis_axis_key(a[i], am);
        lo = k < lo ? k : lo;
        hi = k > hi ? k : hi;
    }
    if (lo == hi) {
        at[0] = at[1] = at[2] = lo;
        return 1;
    }
    int top = 63 - __builtin_clzll(lo ^ hi), shift = top > 10 ? top - 10 : 0;
    size_t cnt[2048] = {0}; /* ((k - lo) >> shift < 2^11: k - lo < 2^(top + 1)) */
    for (size_t i = 0; i < m; i++) cnt[(bis_axis_key(a[i], am) - lo) >> shift]++;
    size_t b0 = 0, base = 0;
    while (base + cnt[b0] <= r[0]) base += cnt[b0++];
    size_t b2 = b0, upto = base + cnt[b0];
    while (upto <= r[2]) upto += cnt[++b2];
    size_t n = upto - base, k = 0;
    uint64_t *keep = malloc((2 * n + 1) * sizeof *keep + 2048 * sizeof(size_t));
    if (!keep) return 0;
    for (size_t i = 0; i < m; i++) { /* (keep[k] written before k moves: room n + 1) */
        uint64_t v = bis_axis_key(a[i], am);
        keep[k] = v;
        k += ((v - lo) >> shift) - b0 <= b2 - b0;
    }
    for (int j = 0; j < 3; j++) at[j] = bis_radix_kth(keep, n, r[j] - base, keep + n + 1);
    free(keep);
    return 1;
}

/* The cut of a range of s = hi - lo ranks from its sample a[0..m), (x, y)
 * keys, in its cell c: across the longer side, at the key of the sample's
 * point of rank m ceil(s/2)/s along that axis (copies of it go right), and
 * its window (w not NULL); a reordered, the left side's *left keys first.
 * No sample: any cut, an empty window.  0 without memory. */
static int bis_cut_of(int lo, int hi, uint64_t *a, size_t m, bis_cell c, srm_cut *cut,
                      bis_window *w, size_t *left)
{
    *cut = (srm_cut){0, c.x1 - c.x0 >= c.y1 - c.y0 ? 0 : 1};
    if (w) *w = (bis_window){0, 0, 0};
    *left = 0;
    if (!m) return 1;
    uint64_t am = (uint64_t)0 - (uint64_t)(cut->axis != 0), key[3];
    size_t t = (size_t)((uint64_t)m * (uint64_t)(srm_bis_mid(lo, hi) - lo) / (uint64_t)(hi - lo));
    size_t span = w ? 2 * isqrt(m) + 2 : 0, r[3] = {t > span ? t - span : 0, t,
                                                   t + span < m ? t + span : m - 1};
    if (!bis_ranks(a, m, am, r, key)) return 0;
    cut->split = key[1];
    if (w) {
        w->lo = key[0];
        w->hi = key[2] == UINT64_MAX ? key[2] : key[2] + 1;
    }
    size_t l = 0; /* a[0, l) below the split, a[l, i) not; without a branch */
    for (size_t i = 0; i < m; i++) {
        uint64_t v = a[i];
        a[i] = a[l];
        a[l] = v;
        l += bis_axis_key(v, am) < cut->split;
    }
    *left = l;
    return 1;
}

/* A range's sample on its way to the range's first rank: its cell (4
 * words) and its keys. */
static pdt_status bis_send(drv *d, int to, const uint64_t *a, size_t m, bis_cell c,
                           pdt_err *err)
{
    uint64_t *b = malloc((m + 4) * sizeof *b);
    if (!b) return pdt_drv_nomem(d, "partition");
    b[0] = (uint64_t)c.x0;
    b[1] = (uint64_t)c.x1;
    b[2] = (uint64_t)c.y0;
    b[3] = (uint64_t)c.y1;
    if (m) memcpy(b + 4, a, m * sizeof *a);
    size_t bytes = (m + 4) * sizeof *b;
    pdt_status st = pdt_comm_send(d->c, to, TAG_CUTS, b, bytes, err);
    if (st == PDT_OK) pdt_drv_note_send(d, TAG_CUTS, to, bytes);
    free(b);
    return st;
}

/* The same received: *buf holds it (the keys from *buf + 4). */
static pdt_status bis_recv(drv *d, int from, uint64_t **buf, size_t *m, bis_cell *c,
                           pdt_err *err)
{
    void *b = NULL;
    size_t bytes = 0;
    pdt_status st = pdt_comm_recv(d->c, from, TAG_CUTS, &b, &bytes, err);
    if (st != PDT_OK) return st;
    pdt_drv_note_recv(d, TAG_CUTS, from, bytes);
    *buf = b;
    if (bytes < 4 * sizeof **buf)
        return pdt_err_set(err, PDT_ERR_CHECK, "rank %d: partition: a sample of %zu bytes",
                           d->rank, bytes);
    *m = bytes / sizeof **buf - 4;
    *c = (bis_cell){(int64_t)(*buf)[0], (int64_t)(*buf)[1], (int64_t)(*buf)[2],
                    (int64_t)(*buf)[3]};
    return PDT_OK;
}

/* The cuts, computed down the tree by the ranges' first ranks: rank 0
 * holds the whole sample (buf, keys from a, m of them, cell c); the first
 * rank of a range cuts its sample, keeps the left side's and sends the
 * right side's to the right half's first rank, which goes on there.  So
 * the work on the critical path is about twice the sample, not once per
 * depth, and the messages follow the tree.  v[w at .. w at + w) (w =
 * bis_words): the split, axis and window of each cut this rank made (zero
 * elsewhere). */
static pdt_status bis_down(drv *d, uint64_t *buf, uint64_t *a, size_t m, bis_cell c,
                           uint64_t *v, pdt_err *err)
{
    int lo = 0, hi = d->p, at = 0, r = d->rank, lead = r == 0;
    size_t vw = bis_words(d);
    pdt_status st = PDT_OK;
    while (st == PDT_OK && hi - lo >= 2) {
        int mid = srm_bis_mid(lo, hi);
        if (lead) { /* r == lo */
            size_t left;
            srm_cut cut;
            bis_window w = {0, 0, 0};
            if (!bis_cut_of(lo, hi, a, m, c, &cut, vw == 4 ? &w : NULL, &left)) {
                st = pdt_drv_nomem(d, "partition");
                break;
            }
            uint64_t *mine = v + vw * (size_t)at;
            mine[0] = cut.split;
            mine[1] = (uint64_t)cut.axis;
            if (vw == 4) {
                mine[2] = w.lo;
                mine[3] = w.hi;
            }
            bis_cell l = c, rc = c;
            int64_t x = (int64_t)(cut.split >> 32); /* the cut's own coordinate (biased) */
            if (cut.axis) l.y1 = rc.y0 = x;
            else l.x1 = rc.x0 = x;
            st = bis_send(d, mid, a + left, m - left, rc, err);
            m = left;
            c = l;
        } else if (r == mid) {
            free(buf);
            st = bis_recv(d, lo, &buf, &m, &c, err);
            a = buf + 4;
            lead = 1;
        }
        if (r < mid) {
            hi = mid;
            at += 1;
        } else {
            at += mid - lo;
            lo = mid;
        }
    }
    free(buf);
    return st;
}

/* Rank 0: the samples of every rank (slots of `slot` words) packed to the
 * front of all, their number and box. */
static size_t bis_pack(uint64_t *all, int p, size_t slot, bis_cell *c)
{
    size_t m = 0;
    for (int q = 0; q < p; q++) {
        const uint64_t *s = all + (size_t)q * slot;
        size_t k = (size_t)s[0]; /* (before the move: s[0] may be all[m]) */
        memmove(all + m, s + 1, k * sizeof *all);
        m += k;
    }
    *c = (bis_cell){INT64_MAX, INT64_MIN, INT64_MAX, INT64_MIN};
    for (size_t i = 0; i < m; i++) {
        int64_t x = (int64_t)(all[i] >> 32), y = (int64_t)(all[i] & 0xffffffffu);
        c->x0 = x < c->x0 ? x : c->x0;
        c->x1 = x > c->x1 ? x : c->x1;
        c->y0 = y < c->y0 ? y : c->y0;
        c->y1 = y > c->y1 ? y : c->y1;
    }
    if (!m) *c = (bis_cell){0, 0, 0, 0};
    return m;
}

/* Every rank's sample slot (`slot` words, mine) at rank 0 in rank order,
 * *all (p * slot words; NULL at the other ranks).  Below BIS_TREE_FROM
 * ranks one gather; from there up a binomial tree, the slots of ranks
 * [r + s, r + 2s) going to rank r at step s = 1, 2, 4 ..., so that rank 0
 * gets log2 p messages, not p - 1 (on 1024 simulated ranks the gather took
 * 2.8 ms of a partition of 10 ms). */
static pdt_status bis_gather(drv *d, const uint64_t *mine, size_t slot, uint64_t **all,
                             pdt_err *err)
{
    int p = d->p, r = d->rank;
    size_t bytes = slot * sizeof *mine;
    *all = NULL;
    if (!bis_by_tree(p)) {
        size_t *cnt = malloc((size_t)p * sizeof *cnt);
        uint64_t *buf = r == 0 ? malloc((size_t)p * bytes) : NULL;
        pdt_status st = cnt && (r || buf) ? PDT_OK : pdt_drv_nomem(d, "partition");
        for (int q = 0; st == PDT_OK && q < p; q++) cnt[q] = bytes;
        if (st == PDT_OK) st = pdt_comm_gatherv(d->c, mine, bytes, buf, cnt, 0, err);
        if (st == PDT_OK) /* (uniform: the checker pairs them) */
            pdt_drv_note_gather(d, TAG_SAMPLES, bytes, 0);
        free(cnt);
        if (st == PDT_OK) *all = buf;
        else free(buf);
        return st;
    }
    size_t span = r ? (size_t)(r & -r) : (size_t)p, have = 1; /* [r, r + have) held */
    if (span > (size_t)(p - r)) span = (size_t)(p - r);
    uint64_t *buf = malloc(span * bytes);
    if (!buf) return pdt_drv_nomem(d, "partition");
    memcpy(buf, mine, bytes);
    pdt_status st = PDT_OK;
    for (int s = 1; s < p && st == PDT_OK; s <<= 1) {
        if (r & s) {
            st = pdt_comm_send(d->c, r - s, TAG_SAMPLES, buf, have * bytes, err);
            if (st == PDT_OK) pdt_drv_note_send(d, TAG_SAMPLES, r - s, have * bytes);
            break;
        }
        if (r + s >= p) continue;
        void *got = NULL;
        size_t len = 0;
        st = pdt_comm_recv(d->c, r + s, TAG_SAMPLES, &got, &len, err);
        if (st == PDT_OK) pdt_drv_note_recv(d, TAG_SAMPLES, r + s, len);
        if (st == PDT_OK && (len % bytes || have + len / bytes > span))
            st = pdt_err_set(err, PDT_ERR_CHECK, "rank %d: partition: %zu bytes of samples from "
                             "rank %d", r, len, r + s);
        if (st == PDT_OK) {
            memcpy(buf + have * slot, got, len);
            have += len / bytes;
        }
        free(got);
    }
    if (st == PDT_OK && r == 0) *all = buf;
    else free(buf);
    return st;
}

/* The cuts in d->tree and their windows in win[0 .. p - 1), the same on
 * every rank: the samples gathered at rank 0, cut down the tree
 * (bis_down), every cut summed into every rank by one allreduce (each made
 * by one rank, zero elsewhere). */
static pdt_status bis_tree(drv *d, const pdt_point *pts, size_t n, uint64_t first,
                           bis_window *win, pdt_err *err)
{
    int p = d->p;
    size_t share = bis_share(d), slot = share + 1, vw = bis_words(d), nv = vw * (size_t)p;
    d->tree.p = p;
    d->tree.k = 1;
    d->tree.levels_p = pdt_srm_ceil_log2(p);
    d->tree.cut = calloc((size_t)p, sizeof *d->tree.cut);
    uint64_t *mine = malloc(slot * sizeof *mine), *v = calloc(nv, sizeof *v), *all = NULL;
    pdt_status st = d->tree.cut && mine && v ? PDT_OK : pdt_drv_nomem(d, "partition");
    if (st == PDT_OK) {
        bis_sample(pts, n, first, share, mine);
        st = bis_gather(d, mine, slot, &all, err);
    }
    if (st == PDT_OK) {
        bis_cell c = {0, 0, 0, 0};
        size_t m = d->rank == 0 ? bis_pack(all, p, slot, &c) : 0;
        st = bis_down(d, all, all, m, c, v, err); /* (all is bis_down's: freed there) */
        all = NULL;
    }
    if (st == PDT_OK) st = pdt_comm_allreduce_u64(d->c, v, nv, PDT_COMM_SUM, err);
    if (st == PDT_OK) {
        pdt_drv_note_reduce(d, TAG_SAMPLES, nv * sizeof *v);
        for (int i = 0; i + 1 < p; i++) {
            const uint64_t *x = v + vw * (size_t)i;
            d->tree.cut[i] = (srm_cut){x[0], (int)x[1]};
            win[i] = vw == 4 ? (bis_window){x[2], x[3], 0} : (bis_window){0, 0, 0};
            while (win[i].hi > win[i].lo && (win[i].hi - win[i].lo - 1) >> win[i].shift >= BIS_BINS)
                win[i].shift++;
        }
    }
    free(mine);
    free(v);
    free(all);
    return st;
}

/* The tree as the points walk it: nodes 0 .. p - 2 are the cuts (in
 * d->tree.cut's order), node p - 1 + q is region q, a leaf whose split (0)
 * sends every key right, to itself.  am: all ones for a cut across y (its
 * key's halves swapped). */
typedef struct bis_walk {
    uint64_t split, am;
    uint32_t left, right;
} bis_walk;

/* The nodes of cut `at` of ranks [lo, hi) (hi - lo >= 2) and below. */
static void bis_walk_cuts(bis_walk *w, const srm_cut *cut, int p, int lo, int hi, int at)
{
    int mid = srm_bis_mid(lo, hi);
    uint32_t leaf = (uint32_t)(p - 1);
    w[at] = (bis_walk){cut[at].split, (uint64_t)0 - (uint64_t)(cut[at].axis != 0),
                       mid - lo >= 2 ? (uint32_t)(at + 1) : leaf + (uint32_t)lo,
                       hi - mid >= 2 ? (uint32_t)(at + (mid - lo)) : leaf + (uint32_t)mid};
    if (mid - lo >= 2) bis_walk_cuts(w, cut, p, lo, mid, at + 1);
    if (hi - mid >= 2) bis_walk_cuts(w, cut, p, mid, hi, at + (mid - lo));
}

/* The walk's 2p - 1 nodes for the cuts `cut`, or NULL (no memory). */
static bis_walk *bis_walk_new(const srm_cut *cut, int p)
{
    bis_walk *w = malloc((size_t)(2 * p - 1) * sizeof *w);
    if (!w) return NULL;
    if (p >= 2) bis_walk_cuts(w, cut, p, 0, p, 0);
    for (int q = 0; q < p; q++) {
        uint32_t me = (uint32_t)(p - 1 + q);
        w[me] = (bis_walk){0, 0, me, me};
    }
    return w;
}

/* The node after `at` for the point of key `key` (swapped: its halves
 * swapped): left when the key on the cut's axis is below the cut, by a
 * conditional move, not a branch (half of them would be mispredicted, some
 * 15 cycles each at every depth). */
static inline uint32_t bis_step(const bis_walk *w, uint32_t at, uint64_t key, uint64_t swapped)
{
    const bis_walk *c = &w[at];
    uint64_t k = (swapped & c->am) | (key & ~c->am);
    return k < c->split ? c->left : c->right;
}

/* The region of each of pts[0..n) into dst: every point steps down the
 * tree w of p regions as many times as it is deep (a region steps to
 * itself), eight points at a time in lockstep, so that their chains of
 * loads and compares overlap (one point's steps depend on each other; at
 * 10^5 points a rank on 1024 simulated ranks the walk of one point at a
 * time took 7-12 ms on the median rank, eight at a time 1.3-2.2 ms). */
static void bis_dests(const bis_walk *w, int p, const pdt_point *pts, size_t n, uint32_t *dst)
{
    enum { W = 8 };
    int depth = pdt_srm_ceil_log2(p);
    for (size_t i = 0; i < n; i += W) {
        size_t m = n - i < W ? n - i : W;
        uint64_t key[W], sw[W];
        uint32_t at[W];
        for (size_t k = 0; k < W; k++) {
            key[k] = pdt_key(pts[i + (k < m ? k : 0)]);
            sw[k] = swap_key(key[k]);
            at[k] = 0;
        }
        for (int s = 0; s < depth; s++)
            for (size_t k = 0; k < W; k++) at[k] = bis_step(w, at[k], key[k], sw[k]);
        for (size_t k = 0; k < m; k++) dst[i + k] = at[k] - (uint32_t)(p - 1);
    }
}

/* A cut of the tree: its ranks [lo, hi), its depth, its place among the
 * cuts of that depth. */
typedef struct bis_node {
    int lo, hi, depth, slot;
} bis_node;

/* The cuts below `at` (ranks [lo, hi), depth `depth`) into node, each
 * given the next slot of its depth (per: cuts so far at each depth). */
static void bis_nodes(bis_node *node, int *per, int lo, int hi, int at, int depth)
{
    if (hi - lo < 2) return;
    int mid = srm_bis_mid(lo, hi);
    node[at] = (bis_node){lo, hi, depth, per[depth]++};
    bis_nodes(node, per, lo, mid, at + 1, depth + 1);
    bis_nodes(node, per, mid, hi, at + (mid - lo), depth + 1);
}

/* A cut's counters: its window's bins, then the points above the window,
 * below it, and left of the cut as it is. */
enum { BIS_ABOVE = BIS_BINS, BIS_BELOW = BIS_BINS + 1, BIS_LEFT = BIS_BINS + 2,
       BIS_ROWLEN = BIS_BINS + 3 };

/* The point of key `key` counted in the row of the cut it is at. */
static inline void bis_tally(srm_cut c, const bis_window *w, uint64_t key, uint64_t *row)
{
    uint64_t k = c.axis ? swap_key(key) : key;
    size_t below = k < w->lo, in = !below & (k < w->hi);
    row[in ? (size_t)((k - w->lo) >> w->shift) : BIS_ABOVE + below]++;
    row[BIS_LEFT] += k < c.split;
}

/* The split of a cut of ranks [lo, hi) that leaves the left side nearest
 * its share of the cell's points, from the counts of every rank (row): the
 * cut as it is, or a bin's edge of its window (ties: as it is, then the
 * lower edge). */
static uint64_t bis_refined(srm_cut c, bis_window w, const uint64_t *row, int lo, int hi)
{
    int mid = srm_bis_mid(lo, hi);
    uint64_t cell = row[BIS_ABOVE] + row[BIS_BELOW], left = row[BIS_LEFT];
    for (int b = 0; b < BIS_BINS; b++) cell += row[b];
    uint64_t want = cell * (uint64_t)(mid - lo) / (uint64_t)(hi - lo);
    if (w.hi <= w.lo) return c.split;
    uint64_t best = c.split, gap = left > want ? left - want : want - left;
    uint64_t below = row[BIS_BELOW], bins = ((w.hi - w.lo - 1) >> w.shift) + 1;
    for (uint64_t b = 0; b <= bins; b++) { /* (b << shift: at most hi - lo - 1) */
        uint64_t edge = b == bins ? w.hi : w.lo + (b << w.shift);
        uint64_t g = below > want ? below - want : want - below;
        if (g < gap) {
            gap = g;
            best = edge;
        }
        if (b < bins) below += row[b];
    }
    return best;
}

/* The counted points (pts[j * stride]) whose walk has reached a cut of
 * depth `depth` (at[j], nc of them) counted at it, summed over the ranks
 * (rows: a row a cut of the depth, ncut of them), and those cuts moved, in
 * d->tree.cut and in the walk w. */
static pdt_status bis_count_depth(drv *d, const pdt_point *pts, size_t stride, const uint32_t *at,
                                  size_t nc, const bis_node *node, int depth, int ncut,
                                  const bis_window *win, uint64_t *rows, bis_walk *w, pdt_err *err)
{
    srm_cut *cut = d->tree.cut;
    size_t len = (size_t)ncut * BIS_ROWLEN;
    uint32_t cuts = (uint32_t)(d->p - 1);
    memset(rows, 0, len * sizeof *rows);
    for (size_t j = 0; j < nc; j++)
        if (at[j] < cuts)
            bis_tally(cut[at[j]], &win[at[j]], pdt_key(pts[j * stride]),
                      rows + (size_t)node[at[j]].slot * BIS_ROWLEN);
    pdt_status st = pdt_comm_allreduce_u64(d->c, rows, len, PDT_COMM_SUM, err);
    if (st != PDT_OK) return st;
    pdt_drv_note_reduce(d, TAG_SAMPLES, len * sizeof *rows);
    for (uint32_t c = 0; c < cuts; c++)
        if (node[c].depth == depth)
            w[c].split = cut[c].split =
                bis_refined(cut[c], win[c], rows + (size_t)node[c].slot * BIS_ROWLEN, node[c].lo,
                            node[c].hi);
    return PDT_OK;
}

/* The sample's cuts moved by what the points say (algorithm.md §3.12),
 * depth by depth from the root: every rank counts a share of its points
 * (every n / BIS_COUNTED-th) at the cuts of the depth they have reached, in
 * each cut's window, one allreduce sums the counts, every rank moves those
 * cuts the same way (in d->tree.cut and the walk w), and the points step
 * past them.  A cut is moved in its cell as its ancestors left it, so the
 * cells below see its final place.  The sample alone leaves a region within
 * about 1/sqrt(2s) of n / p, s sample points a region (at p = 1024 on 10^8
 * points the largest held 31 % more than n / p). */
static pdt_status bis_count(drv *d, const pdt_point *pts, size_t n, const bis_window *win,
                            bis_walk *w, pdt_err *err)
{
    int p = d->p, depths = pdt_srm_ceil_log2(p);
    size_t stride = n / BIS_COUNTED > 1 ? n / BIS_COUNTED : 1, nc = (n + stride - 1) / stride;
    int *per = calloc((size_t)depths + 1, sizeof *per);
    bis_node *node = malloc((size_t)p * sizeof *node);
    uint32_t *at = calloc(nc + 1, sizeof *at); /* (all at the root) */
    uint64_t *rows = malloc(((size_t)p * BIS_ROWLEN + 1) * sizeof *rows);
    pdt_status st = per && node && at && rows ? PDT_OK : pdt_drv_nomem(d, "partition");
    if (st == PDT_OK) bis_nodes(node, per, 0, p, 0, 0);
    for (int depth = 0; depth < depths && st == PDT_OK; depth++) {
        if (depth >= BIS_COUNT_FROM)
            st = bis_count_depth(d, pts, stride, at, nc, node, depth, per[depth], win, rows, w,
                                 err);
        for (size_t j = 0; st == PDT_OK && j < nc; j++) {
            uint64_t key = pdt_key(pts[j * stride]);
            at[j] = bis_step(w, at[j], key, swap_key(key));
        }
    }
    free(per);
    free(node);
    free(at);
    free(rows);
    return st;
}

/* Each point's region (in dst, counted in sc), then the records grouped by
 * region into send. */
pdt_status pdt_drv_bisect(drv *d, const pdt_point *pts, size_t n, uint64_t first, srm_rec *send,
                          srm_rec *tmp, uint64_t *sc, pdt_err *err)
{
    int p = d->p;
    bis_window *win = malloc((size_t)p * sizeof *win);
    bis_walk *w = NULL;
    uint64_t *at = calloc((size_t)p, sizeof *at);
    pdt_status st = win && at ? bis_tree(d, pts, n, first, win, err) : pdt_drv_nomem(d, "partition");
    if (st == PDT_OK && !(w = bis_walk_new(d->tree.cut, p))) st = pdt_drv_nomem(d, "partition");
    if (st == PDT_OK && bis_counted(d)) st = bis_count(d, pts, n, win, w, err);
    free(win);
    if (st != PDT_OK) {
        free(w);
        free(at);
        return st;
    }
    uint32_t *dst = (uint32_t *)(void *)tmp; /* (4 bytes a point of tmp's 16) */
    bis_dests(w, p, pts, n, dst);
    free(w);
    for (size_t i = 0; i < n; i++) sc[dst[i]]++;
    uint64_t sum = 0;
    for (int q = 0; q < p; q++) {
        at[q] = sum;
        sum += sc[q];
    }
    for (size_t i = 0; i < n; i++) /* (the region in the record's spare word) */
        send[at[dst[i]]++] = (srm_rec){pdt_key(pts[i]), (uint32_t)(first + i), dst[i]};
    free(at);
    return PDT_OK;
}
