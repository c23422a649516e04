/* pdt — an external sort of (key, value) pairs in bounded memory: sorted
 * runs on disk, merged by a small heap.  See xsort.h. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pdt/xsort.h"
#include "pdt/tmpfile.h"

#define MAX_RUNS 128               /* open runs before they are merged into one */

typedef struct run_src {
    FILE *f;                       /* NULL: the memory buffer */
    const pdt_kv *mem;
    size_t nmem, imem;
    pdt_kv head;
    int has;
} run_src;

struct pdt_xsort {
    pdt_kv *buf, *tmp;             /* the buffer and the radix sort's scratch */
    size_t n, alloc, cap;          /* pairs held, allocated, at most (budget) */
    FILE *runs[MAX_RUNS];
    size_t nruns;
    uint64_t spilled;
    size_t run_buffer;             /* stdio buffer of each run read back */
    /* the merge (after pdt_xsort_done) */
    run_src src[MAX_RUNS + 1];
    size_t heap[MAX_RUNS + 1], nheap;
    int failed;                    /* a read failed: errno saved here */
};

/* ---- the sort of one buffer ------------------------------------------------ */

/* Stable LSD radix sort by key, a byte at a time; a byte that is the same in
 * every key costs nothing but its count.  The result ends in *a. */
static void radix_sort(pdt_kv **a, pdt_kv **t, size_t n)
{
    size_t cnt[8][256];
    memset(cnt, 0, sizeof cnt);
    for (size_t i = 0; i < n; i++) {
        uint64_t k = (*a)[i].key;
        for (int d = 0; d < 8; d++) cnt[d][(k >> (8 * d)) & 255]++;
    }
    for (int d = 0; d < 8; d++) {
        uint64_t k0 = n ? ((*a)[0].key >> (8 * d)) & 255 : 0;
        if (cnt[d][k0] == n) continue;   /* one value: the order stands */
        size_t pos = 0;
        for (int b = 0; b < 256; b++) {
            size_t c = cnt[d][b];
            cnt[d][b] = pos;
            pos += c;
        }
        pdt_kv *src = *a, *dst = *t;
        for (size_t i = 0; i < n; i++) dst[cnt[d][(src[i].key >> (8 * d)) & 255]++] = src[i];
        *a = dst;
        *t = src;
    }
}

/* ---- runs on disk ------------------------------------------------------------ */

static void src_advance(run_src *s, int *failed)
{
    if (s->f) {
        s->has = fread(&s->head, sizeof s->head, 1, s->f) == 1;
        if (!s->has && ferror(s->f)) *failed = errno ? errno : EIO;
    } else if ((s->has = s->imem < s->nmem)) {
        s->head = s->mem[s->imem++];
    }
}

void pdt_heap_sift(size_t *heap, size_t n, size_t i, int (*less)(const void *ctx, size_t a, size_t b),
                   const void *ctx)
{
    for (;;) {
        size_t l = 2 * i + 1, k = i;
        if (l < n && less(ctx, heap[l], heap[k])) k = l;
        if (l + 1 < n && less(ctx, heap[l + 1], heap[k])) k = l + 1;
        if (k == i) return;
        size_t t = heap[i];
        heap[i] = heap[k];
        heap[k] = t;
        i = k;
    }
}

static int src_less(const void *ctx, size_t a, size_t b)
{
    const pdt_xsort *x = ctx;
    return x->src[a].head.key < x->src[b].head.key;
}

static void heap_sift(pdt_xsort *x, size_t i)
{
    pdt_heap_sift(x->heap, x->nheap, i, src_less, x);
}

/* Open the merge of the runs on disk and buf[0..nmem) (sorted). */
static void merge_open(pdt_xsort *x, const pdt_kv *mem, size_t nmem)
{
    x->nheap = 0;
    for (size_t i = 0; i <= x->nruns; i++) {
        run_src *s = &x->src[i];
        memset(s, 0, sizeof *s);
        if (i < x->nruns) {
            s->f = x->runs[i];
            rewind(s->f);
        } else {
            s->mem = mem;
            s->nmem = nmem;
        }
        src_advance(s, &x->failed);
        if (s->has) x->heap[x->nheap++] = i;
    }
    for (size_t i = x->nheap / 2; i-- > 0;) heap_sift(x, i);
}

static int merge_next(pdt_xsort *x, pdt_kv *kv)
{
    if (x->failed) {
        errno = x->failed;
        return -1;
    }
    if (!x->nheap) return 0;
    run_src *s = &x->src[x->heap[0]];
    *kv = s->head;
    src_advance(s, &x->failed);
    if (!s->has) x->heap[0] = x->heap[--x->nheap];
    heap_sift(x, 0);
    return 1;
}

/* Merge every run on disk into one (when MAX_RUNS piled up). */
static int compact(pdt_xsort *x)
{
    FILE *out = pdt_tmp_file("pdt-sort", x->run_buffer);
    if (!out) return -1;
    merge_open(x, NULL, 0);
    pdt_kv kv;
    int r;
    while ((r = merge_next(x, &kv)) == 1)
        if (fwrite(&kv, sizeof kv, 1, out) != 1) break;
    if (r != 0 || fflush(out) != 0) {
        int e = errno ? errno : EIO;
        fclose(out);
        errno = e;
        return -1;
    }
    for (size_t i = 0; i < x->nruns; i++) fclose(x->runs[i]);
    x->runs[0] = out;
    x->nruns = 1;
    return 0;
}

/* Sort the buffer and write it out as one run; empties the buffer. */
static int spill(pdt_xsort *x)
{
    if (!x->n) return 0;
    if (x->nruns == MAX_RUNS && compact(x)) return -1;
    radix_sort(&x->buf, &x->tmp, x->n);
    FILE *f = pdt_tmp_file("pdt-sort", x->run_buffer);
    if (!f) return -1;
    x->runs[x->nruns++] = f;
    x->spilled++;
    if (fwrite(x->buf, sizeof *x->buf, x->n, f) != x->n || fflush(f) != 0) {
        if (!errno) errno = EIO;
        return -1;
    }
    x->n = 0;
    return 0;
}

/* ---- the interface ------------------------------------------------------------ */

pdt_xsort *pdt_xsort_new(uint64_t budget)
{
    pdt_xsort *x = calloc(1, sizeof *x);
    if (!x) return NULL;
    uint64_t cap = budget / 4 * 3 / (2 * sizeof(pdt_kv));  /* pairs and scratch: 3/4 */
    if (cap < 256) cap = 256;
    if (cap > SIZE_MAX / (2 * sizeof(pdt_kv))) cap = SIZE_MAX / (2 * sizeof(pdt_kv));
    x->cap = (size_t)cap;  /* the buffer grows on demand up to it */
    /* the runs' buffers take at most a quarter of the budget besides: from
     * 4 KiB to 64 KiB each */
    uint64_t rb = budget / 4 / MAX_RUNS;
    x->run_buffer = rb < 4096 ? 4096 : rb > (64u << 10) ? (64u << 10) : (size_t)rb;
    return x;
}

/* Room for one more pair: the buffer doubles up to its cap, then spills. */
static int make_room(pdt_xsort *x)
{
    if (x->n < x->alloc) return 0;
    if (x->alloc == x->cap) return spill(x);
    size_t want = x->alloc ? 2 * x->alloc : 1024;
    if (want > x->cap) want = x->cap;
    pdt_kv *b = realloc(x->buf, want * sizeof *b);
    if (!b) return -1;
    x->buf = b;
    pdt_kv *t = realloc(x->tmp, want * sizeof *t);
    if (!t) return -1;
    x->tmp = t;
    x->alloc = want;
    return 0;
}

int pdt_xsort_put(pdt_xsort *x, uint64_t key, uint64_t val)
{
    if (make_room(x)) return -1;
    x->buf[x->n].key = key;
    x->buf[x->n].val = val;
    x->n++;
    return 0;
}

int pdt_xsort_done(pdt_xsort *x)
{
    radix_sort(&x->buf, &x->tmp, x->n);
    merge_open(x, x->buf, x->n);
    if (x->failed) {
        errno = x->failed;
        return -1;
    }
    return 0;
}

int pdt_xsort_get(pdt_xsort *x, pdt_kv *kv)
{
    return merge_next(x, kv);
}

uint64_t pdt_xsort_runs(const pdt_xsort *x)
{
    return x->spilled;
}

void pdt_xsort_free(pdt_xsort *x)
{
    if (!x) return;
    for (size_t i = 0; i < x->nruns; i++) fclose(x->runs[i]);
    free(x->buf);
    free(x->tmp);
    free(x);
}
