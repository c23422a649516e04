/* pdt — a run folder open for reading: what the reader (reader.c) and the
 * merge of the ranks' events (merge.c) share.  Private to src/trace. */
#ifndef PDT_TRACE_RUN_INT_H
#define PDT_TRACE_RUN_INT_H

#include <pthread.h>

#include "tf_internal.h"

typedef pdt_block_ref tf_block;  /* off: of the block header; first: its first event */
_Static_assert(PDT_BLOCK_HEADER_BYTES == TF_BLOCK_HEADER_SIZE, "tracefile.h says the header size");

typedef struct tf_rank {
    int present, complete, level;
    int absent;       /* the file does not exist (reported in ranges by pdt_run_open) */
    uint8_t *map;
    size_t size;
    tf_block *blk;
    size_t nblk;
    uint64_t nev;
    int64_t shift;    /* added to every time: offset - min(0, min offsets) */
    pdt_event *ev;    /* all events, decoded on demand */
} tf_rank;

struct pdt_run {
    char *dir;
    pdt_manifest m;
    pdt_point *pts;
    size_t npts;
    uint8_t *pts_map;  /* points.bin, when pts points into it (no copy) */
    size_t pts_map_size;
    int nranks;
    tf_rank *rk;
    char *warn;
    size_t wlen, wcap;
    struct {             /* the points' checksum, made while the ranks are scanned */
        pthread_t th;
        int started, done;
        uint64_t value;
        size_t warn_at;  /* its warning's place in warn */
    } sum;
    pdt_rec *merged;
    size_t nmerged;
    int merged_done;
};

/* Add a line to the run's warnings (a lost warning is better than a failed
 * open: nothing when memory runs out). */
void pdt_tf_warnf(pdt_run *run, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* bytes of memory (malloc'd, or in huge pages when big: fewer page
 * faults of filling them); NULL when out of memory; free with free(). */
void *pdt_tf_big_alloc(size_t bytes);

#endif
