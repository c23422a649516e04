/* pdt — the parallel triangulation (SRM: strips, restricted areas, merge
 * tree; design in ../shared/design/algorithm.md §3) and the thin
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

int pdt_comm_rank(const pdt_comm *c);
int pdt_comm_size(const pdt_comm *c);
int pdt_comm_is_mpi(const pdt_comm *c);
/* Name of the host this rank runs on (owned by c). */
const char *pdt_comm_host(const pdt_comm *c);
/* Wall clock in seconds (MPI_Wtime, or CLOCK_MONOTONIC in serial mode). */
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
/* Collective: create `path` (or truncate it) for writing by every rank
 * (MPI-IO in an MPI job; open(2) in serial mode).  All ranks return the same
 * status: if any rank failed, every rank gets PDT_ERR_IO naming the path and
 * *f = NULL.  On success *f is owned by the caller (pdt_comm_file_close). */
pdt_status pdt_comm_file_open(pdt_comm *c, const char *path, pdt_comm_file **f, pdt_err *err);
/* Collective: every rank writes its own `bytes` bytes of buf at byte
 * `offset` of the file (ranges must not overlap; bytes may be 0, buf then
 * unused).  MPI_File_write_at_all in chunks, pwrite(2) in serial mode.  All
 * ranks return the same status (PDT_ERR_IO naming the path and the failing
 * rank). */
pdt_status pdt_comm_file_write_at(pdt_comm_file *f, uint64_t offset, const void *buf,
                                  size_t bytes, pdt_err *err);
/* Collective: close and free f (f may be NULL on every rank).  Same status
 * at every rank.  Does not remove the file, even after a failed write. */
pdt_status pdt_comm_file_close(pdt_comm_file *f, pdt_err *err);

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

/* ---- the parallel triangulation (src/par/driver.c) ----------------------- */

/* Per-rank figures of one run (collected at rank 0). */
typedef struct pdt_par_rank_stats {
    uint64_t points;        /* distinct points in this rank's strip */
    uint64_t received;      /* points received in the partition (with duplicates) */
    uint64_t local_tris;    /* triangles of the local kernel run */
    uint64_t final_at_once; /* local triangles final after classification */
    uint64_t deferred;      /* local triangles deferred (restricted area touched a box) */
    uint64_t shipped;       /* pending triangles sent to a merge rank */
    uint64_t merges;        /* merge steps done at this rank */
    uint64_t border_max;    /* largest border set |B| of a merge done here */
    uint64_t kept;          /* triangles kept by merges done here */
    uint64_t discarded;     /* shipped triangles discarded (non-Delaunay) here */
    uint64_t final_merge;   /* triangles made final by merges done here */
    uint64_t emitted;       /* triangles this rank contributed to the output */
    uint64_t bytes_sent, bytes_recv;          /* all traffic of this rank */
    uint64_t merge_bytes_sent, merge_bytes_recv; /* merge-step traffic only */
    double t_partition, t_local, t_classify, t_merge, t_gather; /* seconds */
    double critical_path;   /* seconds: longest chain of dependent compute ending here */
    double critical_cpu;    /* the same chain in CPU seconds */
    int64_t peak_rss_kib;   /* peak resident memory of this rank's process */
} pdt_par_rank_stats;

typedef struct pdt_par_stats {
    int nranks;
    uint64_t n_in, n_unique, n_dup, n_tri;
    int collinear;            /* 1 if < 3 distinct points or all collinear */
    uint64_t hull;            /* vertices of the final hull (collinear ones kept) */
    uint64_t border_max;      /* largest border set of any merge */
    uint64_t bytes_total;     /* sum of bytes sent by all ranks */
    uint64_t merge_bytes;     /* sum of merge-step bytes sent */
    double critical_path;     /* seconds, max over ranks */
    double critical_cpu;      /* CPU seconds, max over ranks */
    double t_total;           /* seconds, driver wall time at rank 0 */
    pdt_par_rank_stats *rank; /* nranks entries (malloc'd; pdt_par_stats_free) */
} pdt_par_stats;

void pdt_par_stats_free(pdt_par_stats *s);

/* Write the figures as one JSON object (no trailing newline) to f. */
void pdt_par_stats_json(const pdt_par_stats *s, FILE *f);

/* The SRM triangulation, collective over c.
 * Requires: at rank 0, pts[0..n) is the whole input (other ranks: pts
 * ignored, n ignored).  Returns at rank 0 *tris (malloc'd, caller frees) =
 * T*(P) as 0-based input indices in canonical order (pdt_tri_canonical),
 * *ntri their count; other ranks get *tris = NULL, *ntri = 0.  stats, if not
 * NULL, is filled at rank 0 (free with pdt_par_stats_free).  tr (may be
 * NULL) is this rank's trace hook; points are reported as global input
 * indices.  On error every rank returns as soon as it notices, but ranks that
 * wait for a failed peer may block: call pdt_comm_abort after reporting. */
pdt_status pdt_par_triangulate(pdt_comm *c, const pdt_point *pts, size_t n, pdt_tri **tris,
                               size_t *ntri, pdt_par_stats *stats, pdt_trace *tr,
                               pdt_err *err);

/* ---- the command (src/par/par_cmd.c) -------------------------------------- */

/* What `pdt triangulate` asks of a parallel run. */
typedef struct pdt_par_job {
    const char *input;     /* points file */
    const char *output;    /* NULL or "-" = standard output */
    double scale;          /* --scale (0 = integers only) */
    int stats;             /* --stats: print JSON to stderr at rank 0 */
    const char *trace_dir; /* --trace DIR, or NULL */
    int trace_level;       /* 1 or 2 */
    int argc;              /* the command's arguments, for the trace manifest */
    char **argv;           /* (argv may be NULL) */
} pdt_par_job;

/* Run `pdt triangulate` on every rank of an MPI job (initialises and
 * finalises MPI itself): rank 0 reads and writes (atomically), all ranks
 * compute.  Prints messages on standard error (rank 0, or the failing rank).
 * Returns the process exit status (0 ok, 2 bad input, 1 other errors); on an
 * error with several ranks the job is aborted. */
int pdt_par_cmd_triangulate(int *argc, char ***argv, const pdt_par_job *job);

#endif
