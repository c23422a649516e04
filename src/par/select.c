/* pdt — exact selection across the ranks: the strips' splitters (driver.h;
 * the bisection's cuts come from a sample, bisect.c).
 *
 * A search looks for the smallest key v with more than t keys <= v among
 * the key-sorted runs of all ranks, known to lie in [lo, hi].  Many
 * searches share each round, and a round costs two small allreduces
 * whatever the number of ranks:
 *
 *   tighten  lo becomes the smallest key >= lo of any rank, hi the largest
 *            <= hi (one MIN allreduce): the answer is a key, so a search
 *            whose bounds meet is done -- after a round or two for keys
 *            that are dense where the answer lies;
 *   count    the open searches with the same bounds and runs (all p - 1
 *            splitters at first) form a group; each group's interval is
 *            cut into W parts, the keys up to each cut counted (binary
 *            searches) and summed over the ranks (one SUM allreduce), and
 *            each search keeps the part holding its answer.  W shares a
 *            budget of 256 + 16 ns counters among the groups, at least 16
 *            each: the first round of the p - 1 splitters cuts the whole
 *            key range in 16 p + 240 parts, the later ones each splitter's
 *            part in 16 or more.
 *
 * (The first version cut every splitter's interval in 256 parts every
 * round: (p - 1) x 255 counts and binary searches per rank and round, the
 * largest phase of a 256-rank run.) */
#include <stdlib.h>
#include <string.h>

#include "driver.h"

/* Counters per round: SEL_BASE + SEL_MIN_WAYS per search, at least
 * SEL_MIN_WAYS per group (each costs a binary search on every rank, and 8
 * bytes in the allreduce). */
enum { SEL_BASE = 256, SEL_MIN_WAYS = 16 };

/* The j-th of the W - 1 cuts of [lo, hi] (parts of `step` keys). */
static uint64_t sel_cut(uint64_t lo, uint64_t hi, uint64_t step, size_t j)
{
    uint64_t off = (uint64_t)(j + 1) * step - 1;
    return off >= hi - lo ? hi : lo + off;
}

/* Keys <= v in r[0..n). */
static size_t count_le(const srm_rec *r, size_t n, uint64_t v)
{
    return v == UINT64_MAX ? n : pdt_srm_count_lt(r, n, v + 1);
}

/* out[j] = keys <= the j-th cut of [lo, hi] in r[0..n), j < w - 1: the cuts
 * increase, so each search gallops on from the last count and ends in a
 * short binary search near it, in memory the last one touched (a binary
 * search of the whole run per cut risks a cache miss at every step). */
static void count_cuts(const srm_rec *r, size_t n, uint64_t lo, uint64_t hi, uint64_t step,
                       size_t w, uint64_t *out)
{
    size_t at = 0; /* every key before r[at] is <= the last cut */
    for (size_t j = 0; j + 1 < w; j++) {
        uint64_t v = sel_cut(lo, hi, step, j);
        size_t g = 1;
        while (at + g <= n && r[at + g - 1].key <= v) {
            at += g;
            g *= 2;
        }
        size_t e = at + g - 1 < n ? at + g - 1 : n; /* the first key > v is in [at, e] */
        while (at < e) {
            size_t mid = at + (e - at) / 2;
            if (r[mid].key <= v) at = mid + 1;
            else e = mid;
        }
        out[j] = at;
    }
}

static uint64_t sel_step(uint64_t lo, uint64_t hi, size_t ways)
{
    return (hi - lo) / ways + 1;
}

/* The searches' state: bounds, runs, targets; g[q] the first search of q's
 * group, w[q] its ways, at[q] its first counter. */
typedef struct sel {
    int ns;
    const srm_rec *const *arr;
    const size_t *len;
    const uint64_t *t;
    uint64_t *lo, *hi;
    uint64_t *v;    /* 2 ns for the tightening, then the counters */
    size_t *g, *w, *at;
} sel;

static int sel_open(const sel *s, int q)
{
    return s->lo[q] < s->hi[q];
}

/* Tighten every open search's bounds to keys of some rank; 1 when one is
 * still open. */
static pdt_status sel_tighten(drv *d, sel *s, int *open, pdt_err *err)
{
    size_t z = (size_t)s->ns;
    uint64_t *a = s->v, *b = s->v + z; /* b: ~ of the largest key <= hi */
    for (size_t q = 0; q < z; q++) {
        a[q] = b[q] = UINT64_MAX;
        if (!sel_open(s, (int)q)) continue;
        size_t i = pdt_srm_count_lt(s->arr[q], s->len[q], s->lo[q]);
        size_t e = count_le(s->arr[q], s->len[q], s->hi[q]);
        if (i < s->len[q]) a[q] = s->arr[q][i].key;
        if (e > 0) b[q] = ~s->arr[q][e - 1].key;
    }
    pdt_status st = pdt_comm_allreduce_u64(d->c, s->v, 2 * z, PDT_COMM_MIN, err);
    if (st != PDT_OK) return st;
    pdt_drv_note_reduce(d, TAG_SAMPLES, 2 * z * sizeof *s->v);
    *open = 0;
    for (size_t q = 0; q < z; q++) {
        if (!sel_open(s, (int)q)) continue;
        if (a[q] > s->lo[q]) s->lo[q] = a[q];
        if (~b[q] < s->hi[q]) s->hi[q] = ~b[q];
        if (s->hi[q] < s->lo[q]) s->hi[q] = s->lo[q]; /* (no key: cannot happen for t < N) */
        *open |= sel_open(s, (int)q);
    }
    return PDT_OK;
}

/* The groups of the open searches and their ways; the number of counters. */
static size_t sel_groups(sel *s)
{
    size_t ng = 0;
    for (int q = 0; q < s->ns; q++) {
        if (!sel_open(s, q)) continue;
        int p = q - 1;
        while (p >= 0 && !sel_open(s, p)) p--;
        int same = p >= 0 && s->lo[p] == s->lo[q] && s->hi[p] == s->hi[q] &&
                   s->arr[p] == s->arr[q] && s->len[p] == s->len[q];
        s->g[q] = same ? s->g[p] : (size_t)q;
        ng += !same;
    }
    size_t budget = SEL_BASE + SEL_MIN_WAYS * (size_t)s->ns;
    size_t ways = ng ? budget / ng : 0, nc = 0;
    if (ways < SEL_MIN_WAYS) ways = SEL_MIN_WAYS;
    for (int q = 0; q < s->ns; q++) {
        if (!sel_open(s, q) || s->g[q] != (size_t)q) continue;
        uint64_t span = s->hi[q] - s->lo[q];
        s->w[q] = span < ways ? (size_t)span + 1 : ways; /* (every part one key or more) */
        s->at[q] = nc;
        nc += s->w[q] - 1;
    }
    return nc;
}

/* One counting round: every open search keeps the part holding its answer. */
static pdt_status sel_count(drv *d, sel *s, pdt_err *err)
{
    size_t nc = sel_groups(s);
    uint64_t *cnt = s->v;
    for (int q = 0; q < s->ns; q++) {
        if (!sel_open(s, q) || s->g[q] != (size_t)q) continue;
        uint64_t step = sel_step(s->lo[q], s->hi[q], s->w[q]);
        count_cuts(s->arr[q], s->len[q], s->lo[q], s->hi[q], step, s->w[q], &cnt[s->at[q]]);
    }
    pdt_status st = pdt_comm_allreduce_u64(d->c, cnt, nc, PDT_COMM_SUM, err);
    if (st != PDT_OK) return st;
    pdt_drv_note_reduce(d, TAG_SAMPLES, nc * sizeof *cnt);
    for (int q = 0; q < s->ns; q++) {
        if (!sel_open(s, q)) continue;
        size_t g = s->g[q], nw = s->w[g] - 1, j = 0;
        uint64_t lo = s->lo[q], hi = s->hi[q], step = sel_step(lo, hi, s->w[g]);
        const uint64_t *c = &cnt[s->at[g]];
        while (j < nw && c[j] <= s->t[q]) j++; /* the answer: the first part past t */
        s->lo[q] = j ? sel_cut(lo, hi, step, j - 1) + 1 : lo;
        if (j < nw) s->hi[q] = sel_cut(lo, hi, step, j);
    }
    return PDT_OK;
}

/* For each of ns searches, the smallest key v with more than t[i] keys <= v
 * among the key-sorted runs arr[i][0..len[i]) of all ranks, known to lie in
 * [lo[i], hi[i]] (every rank the same bounds); the answer in lo[i]. */
static pdt_status select_keys(drv *d, int ns, const srm_rec *const *arr, const size_t *len,
                              const uint64_t *t, uint64_t *lo, uint64_t *hi, pdt_err *err)
{
    size_t z = (size_t)ns + 1, nv = SEL_BASE + 2 * SEL_MIN_WAYS * z;
    sel s = {ns, arr, len, t, lo, hi, malloc(nv * sizeof *s.v), malloc(z * sizeof *s.g),
             malloc(z * sizeof *s.w), malloc(z * sizeof *s.at)};
    pdt_status st = s.v && s.g && s.w && s.at ? PDT_OK : pdt_drv_nomem(d, "partition");
    int open = 1;
    while (st == PDT_OK) {
        st = sel_tighten(d, &s, &open, err);
        if (st != PDT_OK || !open) break;
        st = sel_count(d, &s, err);
    }
    free(s.v);
    free(s.g);
    free(s.w);
    free(s.at);
    return st;
}

/* The p - 1 splitters, exact: split[q-1] is the key of rank q * N / p
 * (0-based, N records in all, every rank's sorted rec[0..n) together), so
 * that the keys below it number q N / p but for copies of that key, which
 * all go with it (a key goes to the rank of the number of splitters <= it). */
pdt_status pdt_drv_splitters(drv *d, const srm_rec *rec, size_t n, uint64_t *split, pdt_err *err)
{
    int p = d->p, q1 = p - 1;
    uint64_t ext[2] = {n ? rec[0].key : UINT64_MAX, n ? ~rec[n - 1].key : UINT64_MAX};
    pdt_status st = pdt_comm_allreduce_u64(d->c, ext, 2, PDT_COMM_MIN, err);
    if (st != PDT_OK) return st;
    pdt_drv_note_reduce(d, TAG_SAMPLES, sizeof ext);
    uint64_t N = d->n_total;
    uint64_t *hi = malloc(((size_t)q1 + 1) * sizeof *hi), *t = malloc(((size_t)q1 + 1) * sizeof *t);
    size_t *len = malloc(((size_t)q1 + 1) * sizeof *len);
    const srm_rec **arr = malloc(((size_t)q1 + 1) * sizeof *arr);
    if (!hi || !t || !len || !arr) st = pdt_drv_nomem(d, "partition");
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
