/* pdt — the parallel triangulation (SRM: strips, restricted areas, merge
 * tree; design in docs/algorithm.md §3) and the thin
 * communication layer it runs on.
 *
 * Only src/par/comm_mpi.c includes mpi.h.  Everything else talks to a
 * pdt_comm context through the pdt_comm_* wrappers below; every wrapper
 * checks MPI's return code (the communicator uses MPI_ERRORS_RETURN) and turns
 * a failure into PDT_ERR_MPI with a message.
 *
 * A process that was not started by a launcher (mpirun, srun, ...) gets a
 * "serial" context of size 1 without initialising MPI, so a plain run stays
 * fast and works on machines where MPI cannot start. */
#ifndef PDT_PAR_H
#define PDT_PAR_H

#include <stdio.h>

#include "pdt/common.h"
#include "pdt/io.h"
#include "pdt/trace.h"

/* ---- communication layer (src/par/comm.c: the front; backends MPI
 * (src/par/comm_mpi.c) and local (src/par/comm_local.c: threads) --------- */

typedef struct pdt_comm pdt_comm;

/* 1 if the environment says this process was started by an MPI launcher
 * (Open MPI's OMPI_COMM_WORLD_SIZE, PMIx's PMIX_RANK, PMI's PMI_SIZE/PMI_RANK,
 * Slurm's srun with an MPI plugin).  PDT_MPI=0 / PDT_MPI=1 overrides. */
int pdt_comm_launched(void);

/* Create the context: MPI_Init and a private duplicate of the world
 * communicator if launched (or if force_mpi), otherwise a serial context of
 * size 1 (the local backend with one rank; no MPI call at all).  *c is owned by the caller (pdt_comm_finalize frees it). */
pdt_status pdt_comm_init(int *argc, char ***argv, int force_mpi, pdt_comm **c, pdt_err *err);
/* Free the context; MPI_Finalize if MPI was initialised.  c may be NULL. */
pdt_status pdt_comm_finalize(pdt_comm *c, pdt_err *err);
/* End the whole job at once (MPI_Abort on every rank; exit in serial mode).
 * For the program's main only, after an unrecoverable error on one rank. */
void pdt_comm_abort(pdt_comm *c, int code);

/* ---- stopping a job before it commits ----------------------------------------
 * The library never catches a signal; the program does, and tells the
 * library through a query it sets here: 1 when the job is being stopped
 * (interrupted, terminated, its launcher gone), else 0.  The query may
 * wait (a program that is told of a stop in two steps, as mpirun's SIGCONT
 * and, a second later, SIGTERM).  A commit point (the rename of a parallel
 * run's output) asks it of every rank just before it acts. */
typedef int (*pdt_stop_query)(void *ctx);
void pdt_comm_set_stop_query(pdt_comm *c, pdt_stop_query q, void *ctx);
/* Collective, at a commit point: every rank asks its query, then rank 0,
 * which renames, asks again after the others have answered.  PDT_OK when
 * no rank is being stopped; else PDT_ERR_IO "PATH: not written: the job
 * was stopped" at the ranks that were (rank 0's is its own status: the
 * caller agrees on it with the others after it has decided not to act). */
pdt_status pdt_comm_commit_ok(pdt_comm *c, const char *path, pdt_err *err);

int pdt_comm_rank(const pdt_comm *c);
int pdt_comm_size(const pdt_comm *c);
int pdt_comm_is_mpi(const pdt_comm *c);
/* 1 when the ranks are simulated (bin/smpi/pdt under SimGrid's smpirun: all
 * ranks are threads of one process, pdt_comm_wtime is the simulated clock and
 * a rank's computing time is measured on its own thread's CPU clock, so a
 * rank must not start helper threads), 0 otherwise. */
int pdt_comm_is_simulated(const pdt_comm *c);
/* How many ranks of the job run on this rank's machine (this one included). */
int pdt_comm_node_size(const pdt_comm *c);
/* Name of the host this rank runs on (owned by c). */
const char *pdt_comm_host(const pdt_comm *c);
/* Wall clock in seconds (MPI_Wtime, or CLOCK_MONOTONIC in serial mode;
 * simulated seconds under SMPI). */
double pdt_comm_wtime(const pdt_comm *c);

/* Collectives.  Byte counts are size_t with no 32-bit limit: a transfer
 * larger than the chunk size (1 GiB, or PDT_COMM_CHUNK=bytes in the
 * environment — rank 0's value, read at pdt_comm_init) goes as several
 * messages of at most one chunk each.  Receive buffers are the caller's. */
pdt_status pdt_comm_barrier(pdt_comm *c, pdt_err *err);
/* A barrier during which waiting ranks sleep (0.1 ms polls) instead of
 * spinning: call it before a collective that some ranks reach much later. */
pdt_status pdt_comm_quiet_barrier(pdt_comm *c, pdt_err *err);
pdt_status pdt_comm_bcast(pdt_comm *c, void *buf, size_t bytes, int root, pdt_err *err);
/* Every rank sends `bytes` bytes; recv gets size * bytes, rank order. */
pdt_status pdt_comm_allgather(pdt_comm *c, const void *send, size_t bytes, void *recv,
                              pdt_err *err);
/* Every rank sends `bytes` bytes to each rank (send holds size blocks). */
pdt_status pdt_comm_alltoall(pdt_comm *c, const void *send, size_t bytes, void *recv,
                             pdt_err *err);
/* Block i of send (scount[i] bytes, blocks contiguous in rank order) goes to
 * rank i; block j of recv (rcount[j] bytes, contiguous) comes from rank j.
 * Requires rcount[j] at rank i == scount[i] at rank j. */
pdt_status pdt_comm_alltoallv(pdt_comm *c, const void *send, const size_t *scount, void *recv,
                              const size_t *rcount, pdt_err *err);
/* Root sends count[i] bytes (contiguous blocks) to rank i; every rank
 * receives `rbytes` into recv.  send/count matter at the root only. */
pdt_status pdt_comm_scatterv(pdt_comm *c, const void *send, const size_t *count, void *recv,
                             size_t rbytes, int root, pdt_err *err);
/* Every rank sends `bytes`; the root receives count[i] bytes from rank i,
 * contiguous in rank order.  recv/count matter at the root only. */
pdt_status pdt_comm_gatherv(pdt_comm *c, const void *send, size_t bytes, void *recv,
                            const size_t *count, int root, pdt_err *err);
/* Element-wise maximum / sum of n doubles over all ranks, result everywhere. */
pdt_status pdt_comm_allmax(pdt_comm *c, double *v, int n, pdt_err *err);

typedef enum pdt_comm_op { PDT_COMM_SUM, PDT_COMM_MAX, PDT_COMM_MIN } pdt_comm_op;
/* In place: v[0..n) becomes, at every rank, the element-wise op over all
 * ranks' v (sums wrap modulo 2^64).  Requires the same n and op everywhere. */
pdt_status pdt_comm_allreduce_u64(pdt_comm *c, uint64_t *v, size_t n, pdt_comm_op op,
                                  pdt_err *err);
/* Exclusive prefix sum: *out = sum of v over ranks 0..rank-1 (0 at rank 0). */
pdt_status pdt_comm_exscan_u64(pdt_comm *c, uint64_t v, uint64_t *out, pdt_err *err);

/* ---- one file written by all ranks together ---- */
typedef struct pdt_comm_file pdt_comm_file;
/* Collective: create `path` for writing by every rank (MPI-IO in an MPI
 * job; open(2) in serial mode) and give it its final size, `size` bytes
 * (same at every rank): a longer file left under that name is cut, and no
 * truncation to 0 happens (on ext4 that makes the close start writing the
 * whole file back: 0.16 s for 480 MB).  All ranks return the same status: if
 * any rank failed, every rank gets PDT_ERR_IO naming the path and *f = NULL.
 * On success *f is owned by the caller (pdt_comm_file_close). */
pdt_status pdt_comm_file_open(pdt_comm *c, const char *path, uint64_t size, pdt_comm_file **f,
                              pdt_err *err);
/* Not collective: write `bytes` bytes of buf at byte `offset` of the file
 * (any number of calls per rank, none included; ranges of different ranks
 * must not overlap).  MPI_File_write_at in chunks, pwrite(2) in the local
 * backend.  Returns this rank's status; after a failure every later write
 * fails the same way, and pdt_comm_file_close reports it to every rank. */
pdt_status pdt_comm_file_write_at(pdt_comm_file *f, uint64_t offset, const void *buf,
                                  size_t bytes, pdt_err *err);
/* Not collective: this rank's share of the file failed for a reason of its
 * own (e, as its writes would have): later writes fail the same way, and
 * the close reports it to every rank. */
void pdt_comm_file_failed(pdt_comm_file *f, const pdt_err *e);
/* Collective: close and free f (f may be NULL on every rank).  Same status
 * at every rank: PDT_ERR_IO if a write or the close failed at any rank (the
 * failing rank keeps its own message; the others get "PATH: write failed
 * at rank R").  Does not remove the file, even after a failed write. */
pdt_status pdt_comm_file_close(pdt_comm_file *f, pdt_err *err);
/* Collective: pdt_comm_file_close and, unless path is NULL, the commit
 * point of `path` (pdt_comm_commit_ok) in one agreement: each rank asks its
 * stop query as it closes, rank 0 again once all have answered.  A rank
 * that did not fail gets the failing rank's status with no message (the
 * failing rank's own is the one to print, as pdt_par_agree).  f may be
 * NULL on every rank (the commit point alone). */
pdt_status pdt_comm_file_close_commit(pdt_comm *c, pdt_comm_file *f, const char *path,
                                      pdt_err *err);

/* Point to point, blocking.  recv: waits (sleeping between polls) for the
 * message, *buf is malloc'd (caller frees; may be non-NULL even for 0
 * bytes). */
pdt_status pdt_comm_send(pdt_comm *c, int peer, int tag, const void *buf, size_t bytes,
                         pdt_err *err);
pdt_status pdt_comm_recv(pdt_comm *c, int peer, int tag, void **buf, size_t *bytes,
                         pdt_err *err);

/* ---- the local backend (src/par/comm_local.c) ---- */
/* One rank's work in a local run: returns a status, message in *err. */
typedef pdt_status (*pdt_comm_rank_fn)(pdt_comm *c, void *arg, pdt_err *err);
/* Run fn on nranks ranks, each a thread of this process with its own context
 * (pdt_comm_is_mpi 0, size nranks), messages moved in memory; every
 * collective and the file API work as under MPI.  Returns when every rank
 * has returned: PDT_OK, or the status and message of the first rank that
 * failed (the others then get PDT_ERR_MPI from any collective or receive
 * instead of waiting forever).  pdt_comm_abort must not be called inside. */
pdt_status pdt_comm_local_run(int nranks, pdt_comm_rank_fn fn, void *arg, pdt_err *err);

/* ---- the parallel triangulation (src/par: libpdtpar) ---------------------- */
/*
 * One `pdt triangulate` run on P ranks, as the cli drives it:
 *   pdt_par_read          every rank gets a consecutive block of the input
 *   pdt_par_triangulate   sample sort, local kernels, merges, canonical order:
 *                         every rank ends with a consecutive block of T*
 *   pdt_par_write         all ranks write the one output file together
 *   pdt_par_stats_collect the per-rank figures, at rank 0
 * With P = 1 (a plain run, or mpirun -np 1) the same calls run the
 * sequential kernel.  None of these functions prints or exits: each returns a
 * status, and err holds the message of this rank's failure. */

/* This rank's share of the input: the points of global input indices
 * first .. first + n - 1 (rank q's block comes before rank q+1's). */
typedef struct pdt_par_input {
    pdt_point *pts;      /* malloc'd; pdt_par_input_free */
    size_t n;
    uint64_t first;      /* global index of pts[0] */
    uint64_t n_total;    /* points in the whole input (every rank) */
    uint64_t collisions; /* --scale: points that became equal to a point written
                          * differently, over the whole input (every rank) */
    int release_pts;     /* 1: pdt_par_triangulate may free pts (see there) */
    int prefault;        /* 1: a second thread may fault this rank's working
                          * memory in ahead of use (PDT_TRI_PREFAULT with one
                          * rank, the partition's block with more): for
                          * ranks not sharing a CPU with another rank */
    int partition;       /* pdt_par_partition: how the ranks' regions are cut
                          * (0: strips; PDT_PART_AUTO is resolved in place) */
} pdt_par_input;

/* This rank's share of T*: triangles first .. first + ntri - 1 of the
 * canonical output (pdt_tri_canonical order across all ranks). */
typedef struct pdt_par_output {
    pdt_tri *tris;       /* malloc'd; pdt_par_output_free */
    size_t ntri;
    uint64_t first;      /* index of tris[0] in the whole output */
    uint64_t n_total;    /* triangles in the whole output (every rank) */
    int release_tris;    /* 1: pdt_par_write gives the pages of tris back as it
                          * writes them (pdt_write_tris_releasing): the caller
                          * frees tris next, whatever the status */
} pdt_par_output;

void pdt_par_input_free(pdt_par_input *in);
void pdt_par_output_free(pdt_par_output *out);

/* Merge levels the figures count one by one (2^24 ranks). */
#define PDT_PAR_MAX_LEVELS 24

/* How the ranks' regions are cut (algorithm.md §3.2, §3.12). */
typedef enum pdt_par_partition {
    PDT_PART_STRIPS = 0, /* lexicographic blocks: every seam as tall as the input */
    PDT_PART_BISECT = 1, /* boxes by recursive bisection across the longer side */
    PDT_PART_AUTO = 2    /* pdt_par_partition_for the run (the default) */
} pdt_par_partition;

/* The partition a run uses when none is asked for: PDT_PART_AUTO, which
 * pdt_par_triangulate resolves by pdt_par_partition_for. */
#define PDT_PART_DEFAULT PDT_PART_AUTO

/* From this many ranks a run is bisected (docs/simulation.md: on the
 * simulated 10 Gb/s cluster the bisection is faster from P = 16 at 10^7
 * uniform points, and its lead grows with P and n). */
#define PDT_PART_BISECT_FROM 16

/* The partition PDT_PART_AUTO stands for on p ranks: bisection from
 * PDT_PART_BISECT_FROM ranks on, strips below.  Tracing does not change it:
 * a trace shows the run as it is made (lessons that teach strips on many
 * ranks ask for them with --partition strips). */
static inline pdt_par_partition pdt_par_partition_for(int p)
{
    return p >= PDT_PART_BISECT_FROM ? PDT_PART_BISECT : PDT_PART_STRIPS;
}

/* Figures of one rank. */
typedef struct pdt_par_rank_stats {
    uint64_t points;        /* distinct points in this rank's strip */
    uint64_t received;      /* points received in the partition (with duplicates) */
    uint64_t local_tris;    /* triangles of the local kernel run */
    uint64_t final_at_once; /* local triangles final after classification */
    uint64_t deferred;      /* local triangles deferred (restricted area touched a box) */
    uint64_t shipped;       /* pending triangles sent to a merge rank */
    uint64_t merges;        /* merge steps done at this rank */
    uint64_t border_max;    /* largest border set |B| of a merge done here */
    uint64_t border_level[PDT_PAR_MAX_LEVELS]; /* the same, per merge level */
    uint64_t kept;          /* triangles kept by merges done here */
    uint64_t discarded;     /* shipped triangles discarded (non-Delaunay) here */
    uint64_t final_merge;   /* triangles made final by merges done here */
    uint64_t shared;        /* merges done here planned as shared along their seams */
    uint64_t share_fallbacks; /* of those, the ones this merge rank finished alone */
    uint64_t emitted;       /* final triangles this rank found */
    uint64_t written;       /* triangles of the output this rank wrote */
    uint64_t bytes_sent, bytes_recv;          /* all traffic of this rank */
    uint64_t merge_bytes_sent, merge_bytes_recv; /* merge-step traffic only */
    uint64_t n_dup;         /* duplicates dropped in this rank's strip */
    uint64_t hull;          /* vertices of the hull this rank holds */
    int32_t holds_final_hull, hull_degenerate;
    int32_t levels;         /* merge levels of the run (0 with one rank) */
    int32_t partition;      /* pdt_par_partition of the run */
    int32_t prefault;       /* 1: a second thread faulted memory in ahead */
    int32_t strips;         /* strips triangulated one after the other to save
                             * memory: a plain run's, or each rank's of an MPI
                             * run (0: one kernel run on the rank's points) */
    /* seconds per phase of the pipeline */
    double t_read, t_partition, t_local, t_merge, t_order, t_write;
    double t_total;         /* seconds from the start to the output in place (the
                             * figures' own collection is not in it) */
    double critical_path;   /* seconds: longest chain of dependent compute ending here */
    double critical_cpu;    /* the same chain in CPU seconds */
    int64_t peak_rss_kib;   /* peak resident memory of this rank's process */
} pdt_par_rank_stats;

/* The figures of the whole run (rank 0). */
typedef struct pdt_par_stats {
    int nranks;
    uint64_t n_in, n_unique, n_dup, n_tri;
    int collinear;            /* 1 if < 3 distinct points or all collinear */
    uint64_t hull;            /* vertices of the final hull (collinear ones kept) */
    uint64_t border_max;      /* largest border set of any merge */
    uint64_t border_level[PDT_PAR_MAX_LEVELS]; /* the same, per merge level */
    int levels;               /* merge levels of the run */
    int partition;            /* pdt_par_partition of the run */
    uint64_t bytes_total;     /* sum of bytes sent by all ranks */
    uint64_t merge_bytes;     /* sum of merge-step bytes sent */
    double critical_path;     /* seconds, max over ranks */
    double critical_cpu;      /* CPU seconds, max over ranks */
    double t_compute;         /* seconds, max over ranks of partition .. order */
    pdt_par_rank_stats *rank; /* nranks entries (malloc'd; pdt_par_stats_free) */
} pdt_par_stats;

void pdt_par_stats_free(pdt_par_stats *s);

/* Collective: the status every rank agrees on after a step that may have
 * failed on some ranks only.  Returns PDT_OK if st is PDT_OK on every rank;
 * otherwise, at every rank, the status of the lowest failing rank, and *who
 * (if not NULL) = that rank (err at that rank holds the message; at a rank
 * whose own st was PDT_OK, err gets the status and an empty message).  Never blocks on a rank that already failed: call it from every
 * rank after the step. */
pdt_status pdt_par_agree(pdt_comm *c, pdt_status st, int *who, pdt_err *err);
/* Collective: a step only rank 0 takes (its status st, what it made in buf,
 * `bytes` long at every rank, at most PDT_PAR_OUTCOME_MAX) told to every rank
 * in one broadcast, where an agreement and a broadcast would be two.
 * Returns rank 0's status at every rank (err at rank 0 holds the message;
 * the others get the status and an empty message), and buf holds rank 0's
 * bytes. */
enum { PDT_PAR_OUTCOME_MAX = 16384 };
pdt_status pdt_par_bcast_outcome(pdt_comm *c, pdt_status st, void *buf, size_t bytes,
                                 pdt_err *err);

/* Collective: read the points of `path` ("-" = standard input; ".node" =
 * Triangle's format; else text), scaled by `scale` as pdt_read_points does.
 * Every rank gets its block in *in (pdt_par_input_free); the
 * collision count is the whole input's.  A regular file is read in parts:
 * every rank loads and parses about size/P bytes of whole lines (no rank
 * holds the whole input); standard input, a pipe or a device is read by
 * rank 0 and scattered.  The failure reported is the one pdt_read_points
 * gives on the whole file (its first bad line), whatever P.  Same status at every rank
 * (pdt_par_agree): a parse error is reported, at the rank that found it, as
 * "FILE:LINE: what".  prefault: a thread faults each rank's point array in
 * ahead of its parser (PDT_READ_PREFAULT). */
pdt_status pdt_par_read(pdt_comm *c, const char *path, double scale, int prefault,
                        pdt_par_input *in, pdt_err *err);

/* Collective: T* of the whole input (every rank passes its block).  *out is
 * this rank's block of the canonical output (pdt_par_output_free).  me gets
 * this rank's figures (partition .. order).  tr (may be NULL) is this rank's
 * trace hook; events name global input indices.  With in->release_pts set,
 * in->pts is freed (and set to NULL) as soon as the partition has its keys
 * (P = 1: used as the kernel's working memory, then freed): for a caller that does not need the points after
 * (a .tri output), the peak memory of the run is lower by 8 bytes per point.
 * On error ranks that wait for a failed peer may block: the caller reports
 * and calls pdt_comm_abort. */
pdt_status pdt_par_triangulate(pdt_comm *c, pdt_par_input *in, pdt_par_output *out,
                               pdt_par_rank_stats *me, pdt_trace *tr, pdt_err *err);

/* Collective: write the output to `path` (NULL or "-" = standard output,
 * a device or a pipe: gathered at rank 0) in format `fmt` (.ele also writes
 * the .node beside it; .off and .node take each rank's input block `in`,
 * the triangles its block `out`).  Every rank formats its blocks and writes
 * them at their offsets of a temporary name; rank 0 renames it once every
 * rank succeeded; on any failure nothing is left.  Same status at every
 * rank (pdt_par_agree). */
pdt_status pdt_par_write(pdt_comm *c, const char *path, pdt_tri_format fmt, const pdt_par_input *in,
                         const pdt_par_output *out, pdt_err *err);
/* pdt_par_write, the complete file(s) left at rank 0 in *defer (empty at
 * the other ranks) for pdt_pending_commit / pdt_pending_drop: a traced run
 * puts its output in place only once its run folder is complete. */
pdt_status pdt_par_write_deferred(pdt_comm *c, const char *path, pdt_tri_format fmt,
                                  const pdt_par_input *in, const pdt_par_output *out,
                                  pdt_pending_write *defer, pdt_err *err);

/* T* of n points (a pdt_tstar_fn for pdt_run_check_tstar): as a plain run
 * computes it for a .tri output, on two strips one after the other from 2^21
 * points on ($PDT_PLAIN_STRIPS as for the plain run), else the whole kernel;
 * on a copy of the points.  *strips: the strips (0: the whole kernel). */
pdt_status pdt_par_tstar(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri,
                         int *strips);

/* Remove the temporaries of a parallel write still in progress at this rank
 * (none: nothing happens).  Async-signal-safe (unlink only): for a handler
 * of the signal that ends the job when another rank died. */
void pdt_par_write_abandon(void);

/* The phase of pdt_par_triangulate this process is in: "partition",
 * "local", "merge" or "order", NULL outside it.  Async-signal-safe (an
 * atomic load of a string constant). */
const char *pdt_par_phase(void);

/* Test-only (a test build's hooks, include/pdt/testhook.h): when the hook
 * `var` is "RANK:SECONDS" and RANK is `rank`, create the file named by
 * PDT_TEST_MARK (if set), so that a test knows the rank got there, then sleep
 * SECONDS (PDT_TEST_SLEEP_BEFORE_MERGE, PDT_TEST_SLEEP_IN_WRITE). */
void pdt_par_test_sleep(const char *var, int rank);

/* Collective: gather every rank's figures at rank 0 into *all (other ranks:
 * *all zeroed).  Free with pdt_par_stats_free. */
pdt_status pdt_par_stats_collect(pdt_comm *c, const pdt_par_rank_stats *me, uint64_t n_in,
                                 pdt_par_stats *all, pdt_err *err);

#endif
