/* pdt — Phase 0 of SRM: sorting keys, splitters, duplicates (algorithm.md §3.2).
 *
 * The collective part (scatter, sample exchange, all-to-all) is in driver.c;
 * here are the local building blocks. */
#include "srm.h"

#include <stdlib.h>
#include <string.h>

/* Stable bottom-up merge sort using tmp: the path when no counters can be
 * had (rare). */
static void merge_sort(srm_rec *r, srm_rec *tmp, size_t n)
{
    srm_rec *src = r, *dst = tmp;
    for (size_t w = 1; w < n; w *= 2) {
        for (size_t lo = 0; lo < n; lo += 2 * w) {
            size_t mid = lo + w < n ? lo + w : n, hi = lo + 2 * w < n ? lo + 2 * w : n;
            size_t i = lo, j = mid, k = lo;
            while (i < mid && j < hi) dst[k++] = src[j].key < src[i].key ? src[j++] : src[i++];
            while (i < mid) dst[k++] = src[i++];
            while (j < hi) dst[k++] = src[j++];
        }
        srm_rec *t = src;
        src = dst;
        dst = t;
    }
    if (src != r) memcpy(r, src, n * sizeof *r);
}

/* The compact key of a record: (x - xlo) << ybits | (y - ylo) orders like the
 * key and needs only the bits the coordinates span (40 for points in
 * [0, 2^20)^2). */
typedef struct compact {
    uint32_t xlo, ylo;
    int ybits, bits;
} compact;

static inline uint64_t ckey(const compact *c, uint64_t key)
{
    return ((uint64_t)((uint32_t)(key >> 32) - c->xlo) << c->ybits) |
           (uint64_t)((uint32_t)key - c->ylo);
}

static compact compact_of(const srm_rec *r, size_t n)
{
    uint32_t xlo = UINT32_MAX, xhi = 0, ylo = UINT32_MAX, yhi = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t x = (uint32_t)(r[i].key >> 32), y = (uint32_t)r[i].key;
        xlo = x < xlo ? x : xlo;
        xhi = x > xhi ? x : xhi;
        ylo = y < ylo ? y : ylo;
        yhi = y > yhi ? y : yhi;
    }
    compact c = {xlo, ylo, 0, 0};
    int xbits = 0;
    while (c.ybits < 32 && ((uint64_t)(yhi - ylo) >> c.ybits)) c.ybits++;
    while (xbits < 32 && ((uint64_t)(xhi - xlo) >> xbits)) xbits++;
    c.bits = xbits + c.ybits;
    return c;
}

/* Stable LSD passes over one bucket src[0, m) (in the cache) by the compact
 * key's bits [0, bits), digits of at most 11 bits, those on which every key
 * agrees skipped; the result ends in src or dst: returns which. */
static srm_rec *bucket_lsd(const compact *c, srm_rec *src, srm_rec *dst, size_t m, int bits,
                           size_t *cnt)
{
    if (m < 2 || bits == 0) return src;
    if (m <= 32) { /* stable insertion sort */
        for (size_t i = 1; i < m; i++) {
            srm_rec v = src[i];
            size_t j = i;
            while (j > 0 && src[j - 1].key > v.key) {
                src[j] = src[j - 1];
                j--;
            }
            src[j] = v;
        }
        return src;
    }
    uint64_t all_or = 0, all_and = ~UINT64_C(0);
    for (size_t i = 0; i < m; i++) {
        uint64_t k = ckey(c, src[i].key);
        all_or |= k;
        all_and &= k;
    }
    int passes = (bits + 10) / 11, d = (bits + passes - 1) / passes;
    uint64_t mask = (UINT64_C(1) << d) - 1;
    for (int shift = 0; shift < bits; shift += d) {
        if ((((all_or ^ all_and) >> shift) & mask) == 0) continue;
        memset(cnt, 0, ((size_t)mask + 1) * sizeof *cnt);
        for (size_t i = 0; i < m; i++) cnt[(ckey(c, src[i].key) >> shift) & mask]++;
        size_t sum = 0;
        for (size_t k = 0; k <= mask; k++) {
            size_t v = cnt[k];
            cnt[k] = sum;
            sum += v;
        }
        for (size_t i = 0; i < m; i++) dst[cnt[(ckey(c, src[i].key) >> shift) & mask]++] = src[i];
        srm_rec *t = src;
        src = dst;
        dst = t;
    }
    return src;
}

/* Stable radix sort on the key: one counting pass by the compact key's top
 * 11 bits puts the records in about 2048 buckets (in tmp), each small enough
 * for the cache at a few million records, then LSD passes finish each bucket
 * there and it goes back to r.  (Four LSD passes over the whole array, as
 * before, scattered each record four times into 2048 streams far past the
 * cache and the TLB.) */
void pdt_srm_radix_sort(srm_rec *r, srm_rec *tmp, size_t n)
{
    if (n < 2) return;
    enum { HB = 11, DB = 1 << HB };
    size_t *hc = calloc(DB + 1, sizeof *hc), *cnt = malloc(DB * sizeof *cnt);
    if (!hc || !cnt) {
        free(hc);
        free(cnt);
        merge_sort(r, tmp, n);
        return;
    }
    compact c = compact_of(r, n);
    int hb = c.bits < HB ? c.bits : HB, shift = c.bits - hb;
    size_t nb = (size_t)1 << hb;
    for (size_t i = 0; i < n; i++) hc[(ckey(&c, r[i].key) >> shift) + 1]++;
    for (size_t h = 1; h <= nb; h++) hc[h] += hc[h - 1];
    for (size_t i = 0; i < n; i++) tmp[hc[ckey(&c, r[i].key) >> shift]++] = r[i];
    /* hc[h] is now the end of bucket h, in tmp */
    for (size_t h = 0, start = 0; h < nb; h++) {
        size_t end = hc[h];
        srm_rec *done = bucket_lsd(&c, tmp + start, r + start, end - start, shift, cnt);
        if (done != r + start) memcpy(r + start, done, (end - start) * sizeof *r);
        start = end;
    }
    free(hc);
    free(cnt);
}

size_t pdt_srm_dedupe(srm_rec *r, size_t n)
{
    if (n == 0) return 0;
    size_t k = 1;
    for (size_t i = 1; i < n; i++)
        if (r[i].key != r[k - 1].key) r[k++] = r[i];
    return k;
}

size_t pdt_srm_count_lt(const srm_rec *r, size_t n, uint64_t key)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (r[mid].key < key) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* One stable merge of the sorted runs a[0..na) and b[0..nb) into out
 * (ties: a first). */
static void merge2(const srm_rec *a, size_t na, const srm_rec *b, size_t nb, srm_rec *out)
{
    size_t i = 0, j = 0, k = 0;
    while (i < na && j < nb) out[k++] = b[j].key < a[i].key ? b[j++] : a[i++];
    while (i < na) out[k++] = a[i++];
    while (j < nb) out[k++] = b[j++];
}

/* One round of merge_runs: neighbouring runs merged pairwise from src into
 * dst (run order kept on ties); returns the new number of runs. */
static int merge_round(const srm_rec *src, srm_rec *dst, size_t *start, int k)
{
    int nk = 0;
    for (int i = 0; i < k; i += 2) {
        size_t lo = start[i], mid = start[i + 1], hi = i + 2 <= k ? start[i + 2] : mid;
        if (i + 1 < k) merge2(src + lo, mid - lo, src + mid, hi - mid, dst + lo);
        else memcpy(dst + lo, src + lo, (mid - lo) * sizeof *src);
        start[nk++] = lo;
    }
    start[nk] = start[k];
    return nk;
}

/* Merge rounds until at most `keep` runs are left; returns the array that
 * holds them (r or tmp), *k their number. */
static srm_rec *merge_down_to(srm_rec *r, srm_rec *tmp, size_t *start, int *k, int keep)
{
    srm_rec *src = r, *dst = tmp;
    while (*k > keep) {
        *k = merge_round(src, dst, start, *k);
        srm_rec *t = src;
        src = dst;
        dst = t;
    }
    return src;
}

srm_rec *pdt_srm_merge_runs(srm_rec *r, srm_rec *tmp, size_t *start, int k)
{
    return merge_down_to(r, tmp, start, &k, 1);
}

/* The strip's point i: the record's point and global index, if its key is
 * not the one before (the first of equal keys is kept). */
static inline void emit(const srm_rec *x, pdt_point *pt, uint32_t *g, size_t *m)
{
    if (*m && pdt_key(pt[*m - 1]) == x->key) return;
    pt[*m] = srm_key_point(x->key);
    g[*m] = x->idx;
    (*m)++;
}

size_t pdt_srm_runs_to_strip(srm_rec *r, srm_rec *tmp, size_t *start, int k, pdt_point *pt,
                             uint32_t *g)
{
    const srm_rec *src = merge_down_to(r, tmp, start, &k, 2);
    size_t na = k >= 1 ? start[1] - start[0] : 0, nb = k == 2 ? start[2] - start[1] : 0;
    const srm_rec *a = src + (k >= 1 ? start[0] : 0), *b = a + na;
    size_t i = 0, j = 0, m = 0;
    while (i < na && j < nb) emit(b[j].key < a[i].key ? &b[j++] : &a[i++], pt, g, &m);
    while (i < na) emit(&a[i++], pt, g, &m);
    while (j < nb) emit(&b[j++], pt, g, &m);
    return m;
}
