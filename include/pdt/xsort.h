/* pdt — an external sort of (key, value) pairs in bounded memory (private to
 * src/trace).
 *
 * Pairs are put one at a time into a buffer taken from the budget; a full
 * buffer is sorted by key (a stable radix sort, so pairs of equal keys keep
 * the order they were put in within a run) and written to an anonymous
 * temporary file in $TMPDIR (else /tmp) as one sorted run.  After the last
 * put they come back by key, merged from the runs and what is left in the
 * buffer.  The files are unlinked at once, so nothing is left behind, even
 * when the process is killed.  Pairs of equal keys from different runs come
 * back in no particular order: callers compare keys only. */
#ifndef PDT_XSORT_H
#define PDT_XSORT_H

#include <stddef.h>
#include <stdint.h>

typedef struct pdt_kv {
    uint64_t key, val;
} pdt_kv;

typedef struct pdt_xsort pdt_xsort;

/* A new sort using at most about `budget` bytes (at least a few KiB), or
 * NULL (no memory). */
pdt_xsort *pdt_xsort_new(uint64_t budget);

/* 0, or -1 with errno set (ENOMEM, or the temporary file's error). */
int pdt_xsort_put(pdt_xsort *x, uint64_t key, uint64_t val);

/* After the last put: start giving the pairs back.  0 or -1 (errno). */
int pdt_xsort_done(pdt_xsort *x);

/* The next pair by key: 1, 0 at the end, -1 (errno: a read failed). */
int pdt_xsort_get(pdt_xsort *x, pdt_kv *kv);

/* Sorted runs written to disk. */
uint64_t pdt_xsort_runs(const pdt_xsort *x);

void pdt_xsort_free(pdt_xsort *x);

/* Sift entry i of a binary min-heap heap[0..n) of source numbers down into
 * place; less(ctx, a, b) orders sources a and b.  (The merges of sorted
 * runs here and in check.c share it.) */
void pdt_heap_sift(size_t *heap, size_t n, size_t i, int (*less)(const void *ctx, size_t a, size_t b),
                   const void *ctx);

#endif
