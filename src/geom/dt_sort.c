/* pdt — the points sorted lexicographically and their copies dropped, the
 * first step of the kernel's pipeline (dt_int.h lists the kernel's files).
 *
 * The points are keyed by (x - min x) * 2^by + (y - min y), which orders
 * them lexicographically with as few bits as the data need (40 for points in
 * [0, 2^20)^2).  One counting pass by the top 11 bits splits them into
 * buckets small enough for the cache (about n / 2048 points each), then each
 * bucket is finished by LSD passes in the cache.  Stable throughout, so equal
 * points stay in input order and the first is kept.  (Full-width digits over
 * the whole array would have tens of thousands of output streams: far past
 * the cache and the TLB at 10^7 points.)
 *
 * Two record layouts, one radix sort (lsd_sort, specialized by record size
 * and key): when a key without its top bits and an input index fit one word
 * (10^7 points of [0, 2^20)^2 need 29 + 24 bits) the records are those
 * 8-byte words, built by the counting pass straight from the points;
 * otherwise 16-byte records (key, index). */
#include "dt_int.h"

#include "pdt/bigmem.h"

#include <stdlib.h>
#include <string.h>

typedef struct keyed {
    uint64_t key;
    uint32_t idx;
} keyed;

typedef pdt_dt_sorted sorted;

static int bit_length(uint64_t v)
{
    return v ? 64 - __builtin_clzll(v) : 0;
}

/* ---- one LSD radix sort for both layouts ---- */

/* The digit width for m records: about as many counters as records, from
 * 2^4 to 2^11 (2048 counters: they and the output streams stay in the
 * cache); bits split into equal digits of at most that width. */
static int digit_bits(size_t m, int bits)
{
    int dmax = bit_length(m) - 1;
    if (dmax > 11) dmax = 11;
    if (dmax < 4) dmax = 4;
    int passes = (bits + dmax - 1) / dmax;
    return (bits + passes - 1) / passes;
}

/* Stable LSD radix sort of the m records of `size` bytes at src by the bits
 * [lo, lo + bits) of key(record), digits of digit_bits; digits on which all
 * keys agree are skipped; up to 32 records, a stable insertion sort by the
 * whole key.  cnt: 2048 counters.  The sorted records end in src or dst:
 * returns the one that holds them.  Always inlined into its callers, where
 * size and key are constants, so each layout gets its own plain loops. */
static inline __attribute__((always_inline)) void *lsd_sort(void *src_, void *dst_, size_t m,
                                                           size_t size,
                                                           uint64_t (*key)(const void *),
                                                           int lo, int bits, size_t *cnt)
{
    char *src = src_, *dst = dst_;
    if (m < 2 || bits == 0) return src;
    if (m <= 32) {
        char v[16];
        for (size_t i = 1; i < m; i++) {
            memcpy(v, src + i * size, size);
            uint64_t kv = key(v);
            size_t j = i;
            while (j > 0 && key(src + (j - 1) * size) > kv) {
                memcpy(src + j * size, src + (j - 1) * size, size);
                j--;
            }
            memcpy(src + j * size, v, size);
        }
        return src;
    }
    uint64_t all_or = 0, all_and = ~UINT64_C(0);
    for (size_t i = 0; i < m; i++) {
        uint64_t k = key(src + i * size);
        all_or |= k;
        all_and &= k;
    }
    int d = digit_bits(m, bits);
    uint64_t mask = (UINT64_C(1) << d) - 1;
    for (int shift = lo; shift < lo + bits; shift += d) {
        if ((((all_or ^ all_and) >> shift) & mask) == 0) continue;
        memset(cnt, 0, ((size_t)mask + 1) * sizeof *cnt);
        for (size_t i = 0; i < m; i++) cnt[(key(src + i * size) >> shift) & mask]++;
        size_t sum = 0;
        for (size_t k = 0; k <= mask; k++) {
            size_t c = cnt[k];
            cnt[k] = sum;
            sum += c;
        }
        for (size_t i = 0; i < m; i++)
            memcpy(dst + cnt[(key(src + i * size) >> shift) & mask]++ * size, src + i * size, size);
        char *t = src;
        src = dst;
        dst = t;
    }
    return src;
}

static inline uint64_t keyed_key(const void *r)
{
    return ((const keyed *)r)->key;
}

/* A packed record is its own key: (key bits << ib | input index). */
static inline uint64_t word_key(const void *r)
{
    return *(const uint64_t *)r;
}

/* The 16-byte records src[0, m) by the low `bits` bits of their keys. */
static keyed *lsd_keyed(keyed *src, keyed *dst, size_t m, int bits, size_t *cnt)
{
    return lsd_sort(src, dst, m, sizeof *src, keyed_key, 0, bits, cnt);
}

/* The packed records src[0, m) by their bits [lo, lo + bits), the bits
 * below lo (the input index) increasing within equal digits, so the result
 * is in (key, index) order. */
static uint64_t *lsd_packed(uint64_t *src, uint64_t *dst, size_t m, int lo, int bits, size_t *cnt)
{
    return lsd_sort(src, dst, m, sizeof *src, word_key, lo, bits, cnt);
}

/* ---- the keys and the distinct points ---- */

/* The key of p: (x - min x) * 2^by + (y - min y). */
static inline uint64_t point_key(pdt_point p, pdt_point mn, int by)
{
    return ((uint64_t)((int64_t)p.x - mn.x) << by) | (uint64_t)((int64_t)p.y - mn.y);
}

/* The distinct points found so far, and the last key seen. */
typedef struct uniq {
    size_t u, nd;
    uint64_t prev;
    int have_prev;
} uniq;

/* The next point in order, key k, input index idx: the u-th distinct point
 * (written to o->order and, decoded from k, o->q: the inverse of
 * point_key), or a copy of the last one (a pair in o->dup). */
static inline void take(sorted *o, uniq *s, uint64_t k, uint32_t idx, pdt_point mn, int by)
{
    if (!s->have_prev || k != s->prev) {
        if (o->q) {
            uint64_t ymask = by ? (~UINT64_C(0) >> (64 - by)) : 0;
            o->q[s->u].x = (int32_t)((int64_t)(k >> by) + mn.x);
            o->q[s->u].y = (int32_t)((int64_t)(k & ymask) + mn.y);
        }
        o->order[s->u++] = idx;
    } else if (o->dup) {
        o->dup[2 * s->nd] = idx;
        o->dup[2 * s->nd + 1] = o->order[s->u - 1];
        s->nd++;
    }
    s->prev = k;
    s->have_prev = 1;
}

/* The layout of a sort: keys of `bits` bits (by of them for y) above the
 * minima mn; a counting pass by the top hb bits, then `shift` bits left
 * below them; ib bits of an input index. */
typedef struct layout {
    pdt_point mn;
    int by, bits, hb, shift, ib;
} layout;

static layout layout_of(const pdt_point *pts, size_t n)
{
    int32_t minx = INT32_MAX, maxx = INT32_MIN, miny = INT32_MAX, maxy = INT32_MIN;
    for (size_t i = 0; i < n; i++) {
        if (pts[i].x < minx) minx = pts[i].x;
        if (pts[i].x > maxx) maxx = pts[i].x;
        if (pts[i].y < miny) miny = pts[i].y;
        if (pts[i].y > maxy) maxy = pts[i].y;
    }
    layout l;
    l.mn = (pdt_point){ minx, miny };
    l.by = bit_length((uint64_t)((int64_t)maxy - miny));
    l.bits = bit_length((uint64_t)((int64_t)maxx - minx)) + l.by; /* <= 64 */
    l.hb = l.bits < 11 ? l.bits : 11;
    l.shift = l.bits - l.hb;
    l.ib = bit_length(n - 1);
    return l;
}

/* ---- the two layouts ---- */

/* Packed: the counting pass by the top hb bits reads the points themselves
 * and writes words (low key bits << ib | index) into bucket order in b, so
 * the records are 8 bytes instead of 16 and there is no key array to write
 * first; each bucket is then finished in the cache by the bits of its keys
 * below the top.  a: scratch of the same size. */
static void sort_packed(const pdt_point *pts, size_t n, uint64_t *a, uint64_t *b, size_t *cnt,
                        size_t *hc, sorted *o, layout l)
{
    size_t nb = (size_t)1 << l.hb;
    int shift = l.shift, ib = l.ib;
    uint64_t lmask = shift ? (~UINT64_C(0) >> (64 - shift)) : 0;
    uint64_t imask = ib ? (~UINT64_C(0) >> (64 - ib)) : 0;
    memset(hc, 0, (nb + 1) * sizeof *hc);
    for (size_t i = 0; i < n; i++) hc[(point_key(pts[i], l.mn, l.by) >> shift) + 1]++;
    for (size_t h = 1; h <= nb; h++) hc[h] += hc[h - 1];
    for (size_t i = 0; i < n; i++) {
        uint64_t k = point_key(pts[i], l.mn, l.by);
        b[hc[k >> shift]++] = ((k & lmask) << ib) | i;
    }
    /* hc[h] is the end of bucket h, in b */
    uniq s = { 0, 0, 0, 0 };
    size_t start = 0;
    for (size_t h = 0; h < nb; h++) {
        size_t end = hc[h];
        uint64_t *r = lsd_packed(b + start, a + start, end - start, ib, shift, cnt);
        uint64_t top = (uint64_t)h << shift;
        for (size_t i = 0; i < end - start; i++)
            take(o, &s, top | r[i] >> ib, (uint32_t)(r[i] & imask), l.mn, l.by);
        start = end;
    }
    o->nu = s.u;
    o->ndup = n - s.u;
}

/* Keyed: the 16-byte records (key, index) written to a, the counting pass by
 * the top hb bits into b, each bucket then finished in the cache. */
static void sort_keyed(const pdt_point *pts, size_t n, keyed *a, keyed *b, size_t *cnt,
                       size_t *hc, sorted *o, layout l)
{
    size_t nb = (size_t)1 << l.hb;
    int shift = l.shift;
    for (size_t i = 0; i < n; i++) a[i] = (keyed){ point_key(pts[i], l.mn, l.by), (uint32_t)i };
    memset(hc, 0, (nb + 1) * sizeof *hc);
    for (size_t i = 0; i < n; i++) hc[(a[i].key >> shift) + 1]++;
    for (size_t h = 1; h <= nb; h++) hc[h] += hc[h - 1];
    for (size_t i = 0; i < n; i++) b[hc[a[i].key >> shift]++] = a[i];
    /* hc[h] is the end of bucket h, in b */
    uniq s = { 0, 0, 0, 0 };
    size_t start = 0;
    for (size_t h = 0; h < nb; h++) {
        size_t end = hc[h];
        keyed *r = lsd_keyed(b + start, a + start, end - start, shift, cnt);
        for (size_t i = 0; i < end - start; i++) take(o, &s, r[i].key, r[i].idx, l.mn, l.by);
        start = end;
    }
    o->nu = s.u;
    o->ndup = n - s.u;
}

void pdt_dt_sort(const pdt_point *pts, size_t n, void *work, size_t *cnt, size_t *hc, sorted *o)
{
    keyed *a = work, *b = a + n;
    layout l = layout_of(pts, n);
    if (l.shift + l.ib <= 64)
        sort_packed(pts, n, (uint64_t *)(void *)a, (uint64_t *)(void *)b, cnt, hc, o, l);
    else
        sort_keyed(pts, n, a, b, cnt, hc, o, l);
}

pdt_status pdt_sort_unique_on(const pdt_point *pts, size_t n, void *work, uint32_t *order,
                              pdt_point *q, size_t *nu)
{
    *nu = 0;
    if (n == 0) return PDT_OK;
    if (n > UINT32_MAX) return PDT_ERR_ARG;
    _Static_assert(sizeof(keyed) == 16, "PDT_SORT_WORK counts 16 bytes a record");
    size_t *cnt = (size_t *)(void *)((keyed *)work + 2 * n), *hc = cnt + PDT_DT_SORT_COUNTERS;
    sorted o = { order, q, NULL, 0, 0 };
    pdt_dt_sort(pts, n, work, cnt, hc, &o);
    *nu = o.nu;
    return PDT_OK;
}

pdt_status pdt_sort_unique(const pdt_point *pts, size_t n, uint32_t *order, size_t *nu)
{
    *nu = 0;
    if (n == 0) return PDT_OK;
    if (n > UINT32_MAX) return PDT_ERR_ARG;
    size_t bytes = PDT_SORT_WORK(n);
    void *work = pdt_big_alloc(bytes);
    if (!work) return PDT_ERR_NOMEM;
    pdt_status st = pdt_sort_unique_on(pts, n, work, order, NULL, nu);
    pdt_big_free(work, bytes);
    return st;
}
