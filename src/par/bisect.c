/* pdt — the bisection partition's cuts (algorithm.md §3.12, driver.h).
 *
 * Every rank range of the tree cuts its points at the exact key that leaves
 * ceil(s/2)/s of them (s ranks) on the left, along the longer side of its
 * cell.  The ranges of one depth are cut together: each rank holds its
 * records of a range as one run in each of two orders (bis_ord), the
 * searches share the rounds of select_keys on the run of the range's axis,
 * and a cut splits both runs in two in place. */
#include <stdlib.h>
#include <string.h>

#include "driver.h"

typedef struct bis_range {
    int lo, hi, at;          /* ranks [lo, hi), the preorder number of its cut */
    int64_t x0, x1, y0, y1;  /* its cell (closed; the input's box at the root), in
                              * coordinates biased by 2^31 as in the key */
    size_t s, e;             /* its records here: w[s, e) */
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
    pdt_drv_note_all(d, TAG_SAMPLES, sizeof v);
    *root = (bis_range){0, d->p, 0, (int64_t)v[0], (int64_t)(uint32_t)~v[1], (int64_t)v[2],
                        (int64_t)(uint32_t)~v[3], 0, n};
    return PDT_OK;
}

/* A record's key on the other axis: (x, y) <-> (y, x), the key's halves
 * swapped (srm_axis_key). */
static inline uint64_t swap_key(uint64_t k)
{
    return k << 32 | k >> 32;
}

/* The bisection's two orders of this rank's records: x[] by the (x, y) key
 * (rec's order), y[] the same records keyed and sorted by (y, x) -- built at
 * the first y-cut.  A range's records are x[s, e) and y[s, e) alike; a cut
 * splits the array of its axis where it falls and stably partitions the
 * other (one pass), so both stay sorted and no range is ever sorted again.
 * tmp: scratch of n records. */
typedef struct bis_ord {
    srm_rec *x, *y, *tmp;
} bis_ord;

/* The axis of every range (its cell's longer side; x on a tie); at the
 * first y-cut, y[] of every range built (swapped keys, radix-sorted). */
static pdt_status bis_axes(drv *d, bis_ord *o, size_t n, bis_range *r, int nr)
{
    int any_y = 0;
    for (int i = 0; i < nr; i++) {
        int axis = r[i].x1 - r[i].x0 >= r[i].y1 - r[i].y0 ? 0 : 1;
        d->tree.cut[r[i].at].axis = axis;
        any_y |= axis;
    }
    if (!any_y || o->y) return PDT_OK;
    if (!(o->y = srm_big((n + 1) * sizeof *o->y))) return pdt_drv_nomem(d, "partition");
    for (size_t k = 0; k < n; k++) o->y[k] = (srm_rec){swap_key(o->x[k].key), o->x[k].idx, 0};
    for (int i = 0; i < nr; i++) pdt_srm_radix_sort(o->y + r[i].s, o->tmp, r[i].e - r[i].s);
    return PDT_OK;
}

/* The cuts of the nr ranges of one depth (every rank the same). */
static pdt_status bis_select(drv *d, const bis_ord *o, const bis_range *r, int nr, pdt_err *err)
{
    size_t z = (size_t)nr; /* (lo and hi side by side: one allreduce) */
    uint64_t *v = malloc(3 * z * sizeof *v), *t = malloc(z * sizeof *t);
    const srm_rec **arr = malloc(z * sizeof *arr);
    size_t *len = malloc(z * sizeof *len);
    pdt_status st = v && t && arr && len ? PDT_OK : pdt_drv_nomem(d, "partition");
    uint64_t *cntr = v, *lo = v + z, *hi = v + 2 * z; /* hi: ~ of the largest key first */
    for (int i = 0; st == PDT_OK && i < nr; i++) {
        arr[i] = (d->tree.cut[r[i].at].axis ? o->y : o->x) + r[i].s;
        len[i] = r[i].e - r[i].s;
        cntr[i] = len[i];
        lo[i] = len[i] ? arr[i][0].key : UINT64_MAX;
        hi[i] = len[i] ? ~arr[i][len[i] - 1].key : UINT64_MAX;
    }
    if (st == PDT_OK) st = pdt_comm_allreduce_u64(d->c, cntr, (size_t)nr, PDT_COMM_SUM, err);
    if (st == PDT_OK) st = pdt_comm_allreduce_u64(d->c, lo, 2 * (size_t)nr, PDT_COMM_MIN, err);
    if (st == PDT_OK) {
        pdt_drv_note_all(d, TAG_SAMPLES, 3 * (size_t)nr * sizeof *v);
        for (int i = 0; i < nr; i++) {
            uint64_t s = (uint64_t)(r[i].hi - r[i].lo), left = (uint64_t)(srm_bis_mid(r[i].lo, r[i].hi) - r[i].lo);
            t[i] = cntr[i] * left / s;
            hi[i] = cntr[i] ? ~hi[i] : 0;
            if (!cntr[i]) lo[i] = 0; /* no points: any cut */
        }
        st = pdt_drv_select_keys(d, nr, arr, len, t, lo, hi, err);
    }
    for (int i = 0; st == PDT_OK && i < nr; i++) d->tree.cut[r[i].at].split = lo[i];
    free(v);
    free(t);
    free((void *)arr);
    free(len);
    return st;
}

/* The records of the other axis' array o[s, e) whose key on the cut's axis
 * is below split first, each side in its order (through tmp). */
static void bis_partition(srm_rec *o, srm_rec *tmp, size_t s, size_t e, uint64_t split)
{
    size_t l = s, r = e;
    for (size_t k = s; k < e; k++) { /* left from the front, right from the back */
        if (swap_key(o[k].key) < split) tmp[l++] = o[k];
        else tmp[--r] = o[k];
    }
    memcpy(o + s, tmp + s, (l - s) * sizeof *o);
    for (size_t k = l; k < e; k++) o[k] = tmp[e - 1 - (k - l)];
}

/* Each range cut in two at its split: halves of two ranks or more into
 * next[] (their number returned), a single rank's run counted in sc[]. */
static int bis_split(drv *d, bis_ord *o, const bis_range *r, int nr, bis_range *next,
                     uint64_t *sc)
{
    int nn = 0;
    for (int i = 0; i < nr; i++) {
        srm_cut c = d->tree.cut[r[i].at];
        int mid = srm_bis_mid(r[i].lo, r[i].hi);
        const srm_rec *a = (c.axis ? o->y : o->x) + r[i].s;
        size_t at = r[i].s + pdt_srm_count_lt(a, r[i].e - r[i].s, c.split);
        if (o->y) bis_partition(c.axis ? o->x : o->y, o->tmp, r[i].s, r[i].e, c.split);
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
            else sc[h[k].lo] = h[k].e - h[k].s;
        }
    }
    return nn;
}

/* The bisection of the key-sorted rec[0..n) into the ranks' regions: the
 * cuts in d->tree (every rank the same), sc[q] the records for rank q, and
 * w[0..n) the records grouped by rank, key-sorted within each group (the
 * send buffer).  rec is scratch afterwards. */
pdt_status pdt_drv_bisect(drv *d, srm_rec *rec, srm_rec *w, size_t n, uint64_t *sc,
                          pdt_err *err)
{
    int p = d->p;
    d->tree.p = p;
    d->tree.k = 1;
    d->tree.levels_p = pdt_srm_ceil_log2(p);
    d->tree.cut = calloc((size_t)p, sizeof *d->tree.cut);
    bis_range *cur = malloc((size_t)p * sizeof *cur), *next = malloc((size_t)p * sizeof *next);
    pdt_status st = d->tree.cut && cur && next ? PDT_OK : pdt_drv_nomem(d, "partition");
    if (n) memcpy(w, rec, n * sizeof *w);
    bis_ord o = {w, NULL, rec};
    int nr = 1;
    if (st == PDT_OK) st = bis_root(d, w, n, &cur[0], err);
    while (st == PDT_OK && nr > 0) {
        st = bis_axes(d, &o, n, cur, nr);
        if (st == PDT_OK) st = bis_select(d, &o, cur, nr, err);
        if (st != PDT_OK) break;
        nr = bis_split(d, &o, cur, nr, next, sc);
        bis_range *t = cur;
        cur = next;
        next = t;
    }
    free(cur);
    free(next);
    free(o.y);
    return st;
}
