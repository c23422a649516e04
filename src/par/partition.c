/* pdt — Phase 0 of SRM: sorting keys, splitters, duplicates (docs/algorithm.md §3.2).
 *
 * The collective part (scatter, sample exchange, all-to-all) is in driver.c;
 * here are the local building blocks. */
#include "srm.h"

#include <stdlib.h>
#include <string.h>

/* Stable LSD radix sort on the 64-bit key, 11 bits per pass over the bits
 * the records' coordinates actually span (see below); a few records by
 * insertion, a pass's counters costing more than their sort. */
void pdt_srm_radix_sort(srm_rec *r, srm_rec *tmp, size_t n)
{
    enum { DBITS = 11, DB = 1 << DBITS, FEW = 48 };
    if (n < 2) return;
    if (n <= FEW) {
        for (size_t i = 1; i < n; i++) {
            srm_rec v = r[i];
            size_t j = i;
            for (; j > 0 && r[j - 1].key > v.key; j--) r[j] = r[j - 1];
            r[j] = v;
        }
        return;
    }
    /* compact keys: (x - xmin) << ybits | (y - ymin) orders like the key
     * and needs only the bits the coordinates span (40 for points in
     * [0, 2^20)^2), so 11-bit digits (2048 counters, in L1) take 4 passes */
    uint32_t xlo = UINT32_MAX, xhi = 0, ylo = UINT32_MAX, yhi = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t x = (uint32_t)(r[i].key >> 32), y = (uint32_t)r[i].key;
        xlo = x < xlo ? x : xlo;
        xhi = x > xhi ? x : xhi;
        ylo = y < ylo ? y : ylo;
        yhi = y > yhi ? y : yhi;
    }
    int ybits = 0, xbits = 0;
    while (ybits < 32 && ((uint64_t)(yhi - ylo) >> ybits)) ybits++;
    while (xbits < 32 && ((uint64_t)(xhi - xlo) >> xbits)) xbits++;
    int passes = (xbits + ybits + DBITS - 1) / DBITS;
    if (passes == 0) return; /* one key */
    size_t *hist = calloc((size_t)passes * DB, sizeof *hist);
    if (!hist) { /* fall back to a stable bottom-up merge sort using tmp: rare path */
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
        return;
    }
#define CKEY(k) (((uint64_t)((uint32_t)((k) >> 32) - xlo) << ybits) | (uint64_t)((uint32_t)(k) - ylo))
    for (size_t i = 0; i < n; i++) {
        uint64_t ck = CKEY(r[i].key);
        for (int p = 0; p < passes; p++) hist[(size_t)p * DB + ((ck >> (p * DBITS)) & (DB - 1))]++;
    }
    srm_rec *src = r, *dst = tmp;
    for (int p = 0; p < passes; p++) {
        size_t *h = hist + (size_t)p * DB;
        size_t sum = 0;
        for (size_t d = 0; d < DB; d++) {
            size_t c = h[d];
            h[d] = sum;
            sum += c;
        }
        for (size_t i = 0; i < n; i++) dst[h[(CKEY(src[i].key) >> (p * DBITS)) & (DB - 1)]++] = src[i];
        srm_rec *t = src;
        src = dst;
        dst = t;
    }
#undef CKEY
    if (src != r) memcpy(r, src, n * sizeof *r);
    free(hist);
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
