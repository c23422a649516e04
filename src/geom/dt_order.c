/* pdt — the canonical order of the triangles (docs/geometry.md): each
 * rotated to start at its smallest index, then sorted by its three indices.
 * Alone (pdt_tri_canonical), or in buckets of first indices spread over ranks
 * (pdt_tri_bucket_*).  dt_int.h lists the kernel's other files. */
#include "dt_int.h"

#include "pdt/bigmem.h"

#include <stdlib.h>
#include <string.h>

static int tri_cmp(const pdt_tri *a, const pdt_tri *b)
{
    for (int k = 0; k < 3; k++)
        if (a->v[k] != b->v[k]) return a->v[k] < b->v[k] ? -1 : 1;
    return 0;
}

static int tri_qcmp(const void *a, const void *b)
{
    return tri_cmp(a, b);
}

static void tri_rotate(pdt_tri *t)
{
    *t = pdt_tri_smallest_first(*t);
}

/* a before b in the canonical order */
static inline int tri_less(const pdt_tri *a, const pdt_tri *b)
{
    uint64_t ka = (uint64_t)a->v[0] << 32 | a->v[1], kb = (uint64_t)b->v[0] << 32 | b->v[1];
    return ka < kb || (ka == kb && a->v[2] < b->v[2]);
}

/* Sort tris[lo, hi), all with the same first index, by (v[1], v[2]):
 * insertion sort for short runs, qsort for long ones (a vertex of huge degree
 * must not make this quadratic). */
static void sort_run(pdt_tri *t, size_t lo, size_t hi)
{
    if (hi - lo > 32) {
        qsort(t + lo, hi - lo, sizeof *t, tri_qcmp);
        return;
    }
    for (size_t i = lo + 1; i < hi; i++) {
        pdt_tri v = t[i];
        size_t j = i;
        while (j > lo && tri_cmp(&t[j - 1], &v) > 0) {
            t[j] = t[j - 1];
            j--;
        }
        t[j] = v;
    }
}

/* t[lo, hi) is in order by first index: put each run of one first index in
 * order by the other two.  One insertion pass over the whole range (a
 * triangle moves only within its run; runs are two triangles long on
 * average, so a check per triangle and few moves, where finding each run's
 * end first mispredicted once a run); when the moves pass 8 per triangle (a
 * vertex of huge degree), the rest goes run by run with sort_run. */
static void order_first_runs(pdt_tri *t, size_t lo, size_t hi)
{
    size_t budget = 8 * (hi - lo) + 64;
    for (size_t i = lo + 1; i < hi; i++) {
        if (!tri_less(&t[i], &t[i - 1])) continue;
        pdt_tri v = t[i];
        size_t j = i;
        do {
            t[j] = t[j - 1];
            j--;
        } while (j > lo && tri_less(&v, &t[j - 1]));
        t[j] = v;
        if (i - j >= budget) {
            for (size_t a = lo; a < hi;) {
                size_t b = a + 1;
                while (b < hi && t[b].v[0] == t[a].v[0]) b++;
                if (b - a > 1) sort_run(t, a, b);
                a = b;
            }
            return;
        }
        budget -= i - j;
    }
}

/* One bucket of first indices [base, base + nlo) whose triangles lie in ns
 * places seg[k][0, len[k]) and have been counted by first index into
 * lc[v - base + 1] (lc: nlo + 1 counters): written to out in canonical order
 * (a counting pass by first index, then the runs of one first index by the
 * other two). */
static void bucket_place(const pdt_tri *const *seg, const size_t *len, size_t ns, uint32_t base,
                         size_t nlo, size_t *lc, pdt_tri *out)
{
    lc[0] = 0;
    for (size_t l = 1; l <= nlo; l++) lc[l] += lc[l - 1];
    for (size_t k = 0; k < ns; k++)
        for (size_t i = 0; i < len[k]; i++) out[lc[seg[k][i].v[0] - base]++] = seg[k][i];
    order_first_runs(out, 0, lc[nlo]);
}

/* The triangles are put in order by their first (smallest) index with two
 * counting passes: first by its high bits into at most 2048 buckets (2048
 * output streams: cache lines enough for all), then each
 * bucket, now small enough for the cache, by its low bits; equal first
 * indices (two triangles per vertex on average) are then sorted by the other
 * two.  A random scatter of all triangles in one pass, as before, missed the
 * cache and the TLB on every triangle at 10^7 points.  (dt_int.h: the
 * contract.) */
void pdt_dt_canonical(pdt_tri *in, pdt_tri *out, size_t ntri, pdt_tri *scratch)
{
    if (ntri == 0) return;
    uint32_t minv = UINT32_MAX, maxv = 0;
    for (size_t i = 0; i < ntri; i++) {
        tri_rotate(&in[i]);
        if (in[i].v[0] > maxv) maxv = in[i].v[0];
        if (in[i].v[0] < minv) minv = in[i].v[0];
    }
    uint32_t span = maxv - minv;
    int bits = 32 - __builtin_clz(span | 1u), shift = bits > 11 ? bits - 11 : 0;
    size_t nhi = ((size_t)span >> shift) + 1, nlo = (size_t)1 << shift;
    pdt_tri *tmp = ntri <= 64 ? NULL : scratch ? scratch : pdt_big_alloc(ntri * sizeof *tmp);
    size_t *hc = tmp ? calloc(nhi + 1, sizeof *hc) : NULL;
    size_t *lc = hc ? malloc((nlo + 1) * sizeof *lc) : NULL;
    if (!lc) {
        if (tmp != scratch) pdt_big_free(tmp, ntri * sizeof *tmp);
        free(hc);
        qsort(in, ntri, sizeof *in, tri_qcmp);
        if (out != in) memmove(out, in, ntri * sizeof *out);
        return;
    }
    for (size_t i = 0; i < ntri; i++) hc[((in[i].v[0] - minv) >> shift) + 1]++;
    for (size_t h = 1; h <= nhi; h++) hc[h] += hc[h - 1];
    for (size_t i = 0; i < ntri; i++) tmp[hc[(in[i].v[0] - minv) >> shift]++] = in[i];
    /* hc[h] is now the end of high bucket h */
    size_t start = 0;
    for (size_t h = 0; h < nhi; h++) {
        size_t end = hc[h];
        if (end == start) continue; /* (no counters to clear for an empty bucket) */
        const pdt_tri *seg = tmp + start;
        size_t len = end - start;
        uint32_t base = minv + ((uint32_t)h << shift);
        memset(lc, 0, (nlo + 1) * sizeof *lc);
        for (size_t i = 0; i < len; i++) lc[seg[i].v[0] - base + 1]++;
        bucket_place(&seg, &len, 1, base, nlo, lc, out + start);
        start = end;
    }
    if (tmp != scratch) pdt_big_free(tmp, ntri * sizeof *tmp);
    free(hc);
    free(lc);
}

void pdt_tri_canonical(pdt_tri *tris, size_t ntri)
{
    pdt_dt_canonical(tris, tris, ntri, NULL);
}

void pdt_tri_canonical_on(pdt_tri *tris, size_t ntri, pdt_tri *scratch)
{
    pdt_dt_canonical(tris, tris, ntri, scratch);
}

/* ---- the canonical order in buckets (spread over ranks) ---- */

void pdt_tri_bucket_count(pdt_tri *t, size_t n, int shift, uint64_t *hist)
{
    for (size_t i = 0; i < n; i++) {
        tri_rotate(&t[i]);
        hist[t[i].v[0] >> shift]++;
    }
}

void pdt_tri_bucket_scatter(const pdt_tri *t, size_t n, int shift, uint64_t *at, pdt_tri *dst)
{
    for (size_t i = 0; i < n; i++) dst[at[t[i].v[0] >> shift]++] = t[i];
}

size_t pdt_tri_bucket_scatter_split(pdt_tri *t, size_t n, int shift, const uint8_t *in,
                                     uint64_t *at, pdt_tri *dst)
{
    size_t w = 0;
    for (size_t i = 0; i < n; i++) { /* (branch-free: which round is random) */
        pdt_tri x = t[i];
        uint32_t b = x.v[0] >> shift;
        uint64_t a = at[b];
        dst[a] = x;
        at[b] = a + in[b];
        t[w] = x; /* (w <= i: t[i] has been read) */
        w += 1u - in[b];
    }
    return w;
}

/* Past the segment of bucket b = t[i].v[0] >> shift in t[i, n) (grouped by
 * bucket in increasing order): galloping, then halving -- O(log length)
 * reads, where a scan would read every triangle's first index. */
static size_t seg_end(const pdt_tri *t, size_t i, size_t n, int shift)
{
    uint32_t b = t[i].v[0] >> shift;
    size_t lo = i, step = 1; /* t[lo] is in b; t[hi] (if hi < n) is not */
    while (step < n - lo && t[lo + step].v[0] >> shift == b) {
        lo += step;
        step *= 2;
    }
    size_t hi = step < n - lo ? lo + step : n;
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (t[mid].v[0] >> shift == b) lo = mid;
        else hi = mid;
    }
    return hi;
}

/* A range of first indices far wider than its triangles is ordered flat:
 * the runs' triangles sorted by first index over the range's span, a stable
 * radix sort of at most 12 bits a pass, least significant digit first, then
 * the runs of one first index by the other two.  Indices are in input order,
 * so a triangle's smallest one is rarely near the end: at 1024 ranks on 10^8
 * uniform points the last rank's range held some 1,200 buckets of 8,192
 * indices and a triangle or two per bucket and run, so the bucket by bucket
 * way took 14.8 ms on it (a segment for nearly every triangle, a bucket's
 * counters cleared and summed for a hundred of them), three times the
 * median rank's whole ordering. */
enum { FLAT_SPAN = 8, FLAT_BITS = 12 };

static pdt_status order_flat(const pdt_tri *const *src, const size_t *len, size_t ns,
                             size_t total, pdt_tri *out)
{
    uint32_t lo = UINT32_MAX, hi = 0;
    for (size_t k = 0; k < ns; k++)
        for (size_t i = 0; i < len[k]; i++) {
            uint32_t v = src[k][i].v[0];
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
        }
    int bits = 32 - __builtin_clz((hi - lo) | 1u);
    int passes = (bits + FLAT_BITS - 1) / FLAT_BITS, dbits = (bits + passes - 1) / passes;
    size_t nd = (size_t)1 << dbits;
    pdt_tri *tmp = malloc(total * sizeof *tmp);
    size_t *cnt = malloc(nd * sizeof *cnt);
    if (!tmp || !cnt) {
        free(tmp);
        free(cnt);
        return PDT_ERR_NOMEM;
    }
    const pdt_tri *from = NULL; /* (the first pass reads the runs) */
    for (int pass = 0; pass < passes; pass++) {
        int sh = pass * dbits;
        pdt_tri *to = (passes - 1 - pass) % 2 ? tmp : out; /* (the last pass writes out) */
        memset(cnt, 0, nd * sizeof *cnt);
        for (size_t k = 0; k < (from ? 1 : ns); k++) {
            const pdt_tri *t = from ? from : src[k];
            for (size_t i = 0, m = from ? total : len[k]; i < m; i++)
                cnt[((t[i].v[0] - lo) >> sh) & (nd - 1)]++;
        }
        for (size_t d = 0, sum = 0; d < nd; d++) {
            size_t c = cnt[d];
            cnt[d] = sum;
            sum += c;
        }
        for (size_t k = 0; k < (from ? 1 : ns); k++) {
            const pdt_tri *t = from ? from : src[k];
            for (size_t i = 0, m = from ? total : len[k]; i < m; i++)
                to[cnt[((t[i].v[0] - lo) >> sh) & (nd - 1)]++] = t[i];
        }
        from = to;
    }
    order_first_runs(out, 0, total);
    free(tmp);
    free(cnt);
    return PDT_OK;
}

/* The runs cut into segments, one per run and bucket with triangles, the
 * segments grouped by bucket (a counting sort over the buckets present, in
 * run order within one), then each bucket counted by first index and placed
 * from its own segments: O(triangles + segments) in all.  (Finding each
 * bucket's part of every run in turn was O(buckets x runs): at 1024 ranks
 * the rank with the sparse last buckets took ten times the others.) */
pdt_status pdt_tri_bucket_order(const pdt_tri *const *src, const size_t *len, size_t ns, int shift,
                                pdt_tri *out)
{
    size_t nseg = 0, total = 0;
    uint64_t bmin = UINT64_MAX, bmax = 0;
    for (size_t k = 0; k < ns; k++)
        if (len[k]) { /* (a run's buckets increase) */
            total += len[k];
            uint64_t b0 = src[k][0].v[0] >> shift, b1 = src[k][len[k] - 1].v[0] >> shift;
            bmin = b0 < bmin ? b0 : bmin;
            bmax = b1 > bmax ? b1 : bmax;
        }
    if (total && total * FLAT_SPAN < (bmax - bmin + 1) << shift)
        return order_flat(src, len, ns, total, out);
    if (total == 0) return PDT_OK;
    for (size_t k = 0; k < ns; k++) /* (the buckets' span is the runs' ends', above) */
        for (size_t i = 0; i < len[k]; nseg++) i = seg_end(src[k], i, len[k], shift);
    size_t nlo = (size_t)1 << shift, nb = (size_t)(bmax - bmin) + 1;
    size_t *lc = malloc((nlo + 1) * sizeof *lc), *first = calloc(nb + 1, sizeof *first),
           *sl = malloc(nseg * sizeof *sl);
    const pdt_tri **seg = malloc(nseg * sizeof *seg);
    pdt_status st = lc && first && sl && seg ? PDT_OK : PDT_ERR_NOMEM;
    for (int pass = 0; pass < 2 && st == PDT_OK; pass++) {
        for (size_t k = 0; k < ns; k++)
            for (size_t i = 0; i < len[k];) {
                size_t e = seg_end(src[k], i, len[k], shift);
                uint64_t b = src[k][i].v[0] >> shift;
                if (pass == 0) {
                    first[b - bmin + 1]++;
                } else {
                    size_t at = first[b - bmin]++;
                    seg[at] = src[k] + i;
                    sl[at] = e - i;
                }
                i = e;
            }
        if (pass == 0)
            for (size_t b = 0; b < nb; b++) first[b + 1] += first[b];
    }
    for (size_t b = 0, s0 = 0; b < nb && st == PDT_OK; b++) { /* first[b]: past bucket b's */
        size_t s1 = first[b];
        if (s1 == s0) continue;
        uint32_t base = (uint32_t)((bmin + b) << shift);
        memset(lc, 0, (nlo + 1) * sizeof *lc);
        for (size_t q = s0; q < s1; q++)
            for (size_t i = 0; i < sl[q]; i++) lc[seg[q][i].v[0] - base + 1]++;
        bucket_place(seg + s0, sl + s0, s1 - s0, base, nlo, lc, out);
        out += lc[nlo];
        s0 = s1;
    }
    free(lc);
    free(first);
    free(sl);
    free((void *)seg);
    return st;
}
