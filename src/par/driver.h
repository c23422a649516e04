/* pdt — private interface of the SRM driver's files (src/par): the state a
 * rank carries through the phases of pdt_par_triangulate and the phases
 * themselves, one file each:
 *
 *   driver.c   the run (pdt_par_triangulate), its figures, the one-rank run
 *   select.c   the exact splitters of the strips (a few rounds of counts)
 *   bisect.c   the bisection partition's cuts, from a sample (algorithm.md §3.12)
 *   spread.c   the partition: sort, cut, exchange, strip descriptors
 *   steps.c    the local phase and the merge tree
 *   order.c    the final triangles in canonical order across the ranks */
#ifndef PDT_DRIVER_H
#define PDT_DRIVER_H

#include "srm.h"

enum {
    TAG_SAMPLES = 2,
    TAG_COUNTS = 3,
    TAG_RECORDS = 4,
    TAG_STRIPS = 5,
    TAG_GATHER = 6,
    TAG_STATS = 7,
    TAG_ORDER = 8,
    TAG_CUTS = 9,
    TAG_MERGE = 100,       /* + level (the shared merge's too: merge bytes) */
    TAG_SHARE = 100 + 32,  /* + level: a piece of a shared merge */
    TAG_SHARE_BACK = 100 + 64, /* + level: its reply */
    TAG_VERDICT = 100 + 96 /* + level: whether the pieces held the selection */
};

/* Per-rank state of the driver through the phases. */
typedef struct drv {
    pdt_comm *c;
    int rank, p;
    pdt_trace *tr;
    uint32_t *seq_send, *seq_recv; /* per-peer message sequence numbers */
    uint64_t bytes_sent, bytes_recv, merge_sent, merge_recv;
    unsigned char *blk;            /* this rank's one block (see block_bytes) */
    size_t blk_cap, blk_bytes;     /* room for blk_cap points; its size */
    size_t m;
    uint64_t nrecv;
    uint64_t local_dups;           /* copies dropped before the exchange */
    uint64_t n_total;              /* points in the whole input */
    int k;                         /* strips this rank holds (every rank the same) */
    size_t first[PDT_RANK_MAX_STRIPS + 1]; /* strip j: the block's points [first[j], first[j+1]) */
    srm_strip *strip;              /* p * k strip descriptors */
    srm_tree tree;                 /* a bisection run's regions (tree.cut NULL: strips) */
    srm_rank s[PDT_RANK_MAX_STRIPS];  /* strip k * rank + j */
    int s_init[PDT_RANK_MAX_STRIPS];
    pdt_tri *more;                 /* the order phase's finals besides the block's */
    size_t nmore;
    uint64_t *order_hist;          /* the local finals counted by bucket (order.c) */
    size_t more_counted;           /* more[0, more_counted) are among them */
    pdt_par_rank_stats *me;
    pdt_err *err;
} drv;

/* order.c: the order phase's histogram, for the local phase to fill
 * (srm_rank.order_hist of each strip). */
pdt_status pdt_drv_order_hist(drv *d);

/* Collectives are traced peer by peer up to this many ranks (the lessons'
 * runs: the viewer draws every message); beyond, a collective adds no event
 * (O(P^2) events a collective at 1024 ranks) and only its bytes are counted.
 * Point-to-point messages (the merge tree's) are always traced. */
#define PDT_DRV_TRACE_PEERS 16

/* Trace one message and count it (driver.c). */
void pdt_drv_note_send(drv *d, int tag, int peer, size_t bytes);
void pdt_drv_note_recv(drv *d, int tag, int peer, size_t bytes);
/* The collectives (traced as every pair exchanging `bytes`, the viewer's
 * picture of one; counted as below).  An alltoall or allgather of `bytes`
 * blocks: `bytes` to and from every other rank. */
void pdt_drv_note_all(drv *d, int tag, size_t bytes);
/* An allreduce of a `bytes` vector: the vector out and the result back,
 * once each, however the library routes it (counted to every rank, a
 * 1024-rank run's counts would be a thousand times its traffic). */
void pdt_drv_note_reduce(drv *d, int tag, size_t bytes);
/* A gather of `bytes` from every rank at root. */
void pdt_drv_note_gather(drv *d, int tag, size_t bytes, int root);
/* An alltoallv: what went to and came from each peer. */
void pdt_drv_note_v(drv *d, int tag, const size_t *sent, const size_t *recvd);
/* PDT_ERR_NOMEM with the rank and phase in the message. */
pdt_status pdt_drv_nomem(drv *d, const char *phase);

/* select.c: the p - 1 exact splitters of the strips partition. */
pdt_status pdt_drv_splitters(drv *d, const srm_rec *rec, size_t n, uint64_t *split, pdt_err *err);
/* bisect.c: the bisection's cuts (into d->tree, the same on every rank, from
 * a sample of every rank's block) and this rank's points pts[0..n) (global
 * indices from `first`, in input order) as records grouped by the rank of
 * their region into send[0..n), input order kept within each group; sc[q]
 * (zeroed by the caller) gets the records for rank q; tmp: n records of
 * scratch. */
pdt_status pdt_drv_bisect(drv *d, const pdt_point *pts, size_t n, uint64_t first, srm_rec *send,
                          srm_rec *tmp, uint64_t *sc, pdt_err *err);
/* spread.c: the partition phase's three steps. */
pdt_status pdt_drv_partition(drv *d, pdt_par_input *in, pdt_err *err);
pdt_status pdt_drv_rank_strips(drv *d, const pdt_par_input *in, pdt_err *err);
pdt_status pdt_drv_strips(drv *d, pdt_err *err);
/* steps.c: the local phase, the merge tree and what follows it. */
pdt_status pdt_drv_local(drv *d, int prefault, pdt_err *err);
pdt_status pdt_drv_merge_tree(drv *d, pdt_err *err);
pdt_status pdt_drv_gather_more(drv *d);
void pdt_drv_release_points(drv *d);
const srm_tree *pdt_drv_sched(const drv *d);
/* order.c: the order phase. */
pdt_status pdt_drv_order(drv *d, pdt_par_output *out, pdt_err *err);

/* This rank's one block, for up to M points (fresh pages are costly on
 * this kind of machine, reused ones cheap, so every phase from the
 * partition to the order works in it):
 *   [0, PDT_DELAUNAY_WORK(M))  the partition's two record arrays (32 bytes
 *                              per point), then the kernel's edges (72), the
 *                              final triangles at its front, the order's
 *                              receive buffer and canonical scratch;
 *   then the strip's points (8 bytes each), global indices (4) and the
 *   kernel's scratch ids (4), M + 1 of each. */
static inline size_t block_bytes(size_t M)
{
    return PDT_DELAUNAY_WORK(M) + (M + 1) * (sizeof(pdt_point) + 2 * sizeof(uint32_t));
}

static inline pdt_point *block_pts(const drv *d)
{
    return (pdt_point *)(void *)(d->blk + PDT_DELAUNAY_WORK(d->blk_cap));
}

static inline uint32_t *block_gid(const drv *d)
{
    return (uint32_t *)(void *)(block_pts(d) + d->blk_cap + 1);
}

static inline uint32_t *block_id(const drv *d)
{
    return block_gid(d) + d->blk_cap + 1;
}

#endif
