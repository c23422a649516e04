/* pdt — the communication layer's front: every pdt_comm_* call goes to the
 * context's backend through its table of operations (src/par/comm_int.h).
 * Backends: MPI (src/par/comm_mpi.c, the only file that includes mpi.h) and
 * local (src/par/comm_local.c: ranks as threads of one process; with one
 * rank it is the serial context of a plain run). */
#include "comm_int.h"
#include "pdt/testhook.h"

#include <errno.h>
#include <limits.h>
#include <malloc.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>

int pdt_comm_launched(void)
{
    const char *force = getenv("PDT_MPI");
    if (force && *force) return strcmp(force, "0") != 0;
    /* SMPI_GLOBAL_SIZE: SimGrid's smpirun (bin/smpi/pdt) */
    static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE",
                                       "PMI_RANK", "MPI_LOCALNRANKS", "MV2_COMM_WORLD_SIZE",
                                       "SMPI_GLOBAL_SIZE"};
    for (size_t i = 0; i < sizeof vars / sizeof *vars; i++)
        if (getenv(vars[i])) return 1;
    return 0;
}

/* Under SMPI every rank is a thread of one process, whose heap SimGrid fills
 * with millions of small blocks of its own (requests, actions) and frees
 * again.  glibc keeps freed small blocks in "fast bins" and merges them all
 * the next time anybody asks for or frees a large block, and it gives the
 * heap's free top back to the system when a free leaves more than 128 KiB
 * there: both run on the clock of whichever rank happened to call malloc or
 * free, which then came out milliseconds late (measured at P = 1024: 10 ms
 * in three small allocations; 39 ms in an end of the order that frees large
 * blocks, with the fast bins already off), and every rank of an exchange
 * waited for it.
 * Neither is that rank's work on a real node.  No fast bins and no
 * trimming: the same blocks, reused without either.  (Only with several
 * ranks: setting the trim threshold also fixes glibc's mmap threshold,
 * which `pdt triangulate` sets to 4 MiB for P > 1 anyway, while a plain run
 * keeps the adaptive one; fixed at 128 KiB it made the simulated one-rank
 * run of 10^6 points take 0.86 s against 0.61-0.71 s.) */
void pdt_comm_heap_shared(void)
{
    (void)mallopt(M_MXFAST, 0);
    (void)mallopt(M_TRIM_THRESHOLD, -1);
}

/* Under SMPI a rank's code is timed on this machine, and on the virtual
 * machine the figures of docs/simulation.md come from, a 2 MiB page the
 * process touches for the first time (or again after a few seconds free)
 * was cleared at 0.35-0.8 GB/s, against 6.6 GB/s touched again at once, and
 * 4 KiB pages at 2.2-2.7 GB/s whatever their past: the partition, where a
 * rank first touches its block, took two to three times as long with huge
 * pages, and from run to run twice as long or not.  No transparent huge
 * pages for the whole simulation, one rank or many, whatever PDT_HUGEPAGES
 * or the system's setting ("always") says (docs/simulation.md). */
void pdt_comm_small_pages(void)
{
#ifdef PR_SET_THP_DISABLE
    (void)prctl(PR_SET_THP_DISABLE, 1, 0, 0, 0);
#endif
}

size_t pdt_comm_chunk_from_env(void)
{
    const char *e = getenv("PDT_COMM_CHUNK");
    if (e && *e) {
        char *end;
        errno = 0;
        unsigned long long v = strtoull(e, &end, 10);
        if (!errno && !*end && v >= 1 && v <= (unsigned long long)INT_MAX) return (size_t)v;
    }
    return (size_t)1 << 30;
}

pdt_status pdt_comm_finalize(pdt_comm *c, pdt_err *err)
{
    (void)err;
    if (!c) return PDT_OK;
    c->ops->finalize(c);
    free(c);
    return PDT_OK;
}

void pdt_comm_set_stop_query(pdt_comm *c, pdt_stop_query q, void *ctx)
{
    c->stop = q;
    c->stop_ctx = ctx;
}

static int stopping(pdt_comm *c)
{
    return c->stop && c->stop(c->stop_ctx);
}

pdt_status pdt_comm_commit_ok(pdt_comm *c, const char *path, pdt_err *err)
{
    pdt_status st = stopping(c) ? PDT_ERR_IO : PDT_OK;
    if (st != PDT_OK)
        pdt_err_set(err, st, "%s: not written: the job was stopped (rank %d)", path, c->rank);
    st = pdt_comm_agree(c, st, path, "the commit (the job was stopped)", err);
    if (st == PDT_OK && c->rank == 0 && stopping(c)) /* (the last word: rank 0 renames) */
        st = pdt_err_set(err, PDT_ERR_IO, "%s: not written: the job was stopped (rank 0)", path);
    return st;
}

int pdt_comm_rank(const pdt_comm *c) { return c->rank; }
int pdt_comm_size(const pdt_comm *c) { return c->size; }
int pdt_comm_is_mpi(const pdt_comm *c) { return c->ops->is_mpi; }
int pdt_comm_is_simulated(const pdt_comm *c) { return c->ops->simulated; }
int pdt_comm_node_size(const pdt_comm *c) { return c->node_size; }
const char *pdt_comm_host(const pdt_comm *c) { return c->host; }
double pdt_comm_wtime(const pdt_comm *c) { return c->ops->wtime(c); }

pdt_status pdt_comm_barrier(pdt_comm *c, pdt_err *err) { return c->ops->barrier(c, err); }

pdt_status pdt_comm_quiet_barrier(pdt_comm *c, pdt_err *err)
{
    return c->ops->quiet_barrier(c, err);
}

pdt_status pdt_comm_bcast(pdt_comm *c, void *buf, size_t bytes, int root, pdt_err *err)
{
    return c->ops->bcast(c, buf, bytes, root, err);
}

pdt_status pdt_comm_allgather(pdt_comm *c, const void *send, size_t bytes, void *recv,
                              pdt_err *err)
{
    return c->ops->allgather(c, send, bytes, recv, err);
}

pdt_status pdt_comm_alltoall(pdt_comm *c, const void *send, size_t bytes, void *recv,
                             pdt_err *err)
{
    return c->ops->alltoall(c, send, bytes, recv, err);
}

/* Two hops when the messages of a direct exchange would be many and small:
 * MPI from PDT_COMM_HOPS_MIN ranks on (the same choice at every rank); a
 * test build's PDT_TEST_COMM_HOPS=1 or 2 forces one or the other. */
static int two_hops(const pdt_comm *c)
{
    const char *t = pdt_test_hook("PDT_TEST_COMM_HOPS");
    if (t && (*t == '1' || *t == '2')) return *t == '2' && c->size > 1;
    return c->ops->is_mpi && c->size >= PDT_COMM_HOPS_MIN;
}

pdt_status pdt_comm_alltoallv(pdt_comm *c, const void *send, const size_t *scount, void *recv,
                              const size_t *rcount, pdt_err *err)
{
    if (two_hops(c)) return pdt_comm_hops_alltoallv(c, send, scount, recv, rcount, err);
    return c->ops->alltoallv(c, send, scount, recv, rcount, err);
}

pdt_status pdt_comm_scatterv(pdt_comm *c, const void *send, const size_t *count, void *recv,
                             size_t rbytes, int root, pdt_err *err)
{
    return c->ops->scatterv(c, send, count, recv, rbytes, root, err);
}

pdt_status pdt_comm_gatherv(pdt_comm *c, const void *send, size_t bytes, void *recv,
                            const size_t *count, int root, pdt_err *err)
{
    return c->ops->gatherv(c, send, bytes, recv, count, root, err);
}

pdt_status pdt_comm_allmax(pdt_comm *c, double *v, int n, pdt_err *err)
{
    return c->ops->allmax(c, v, n, err);
}

pdt_status pdt_comm_allreduce_u64(pdt_comm *c, uint64_t *v, size_t n, pdt_comm_op op,
                                  pdt_err *err)
{
    return c->ops->allreduce_u64(c, v, n, op, err);
}

pdt_status pdt_comm_exscan_u64(pdt_comm *c, uint64_t v, uint64_t *out, pdt_err *err)
{
    return c->ops->exscan_u64(c, v, out, err);
}

pdt_status pdt_comm_send(pdt_comm *c, int peer, int tag, const void *buf, size_t bytes,
                         pdt_err *err)
{
    if (peer == c->rank || peer < 0 || peer >= c->size)
        return pdt_err_set(err, PDT_ERR_MPI, "rank %d: send to rank %d", c->rank, peer);
    return c->ops->send(c, peer, tag, buf, bytes, err);
}

pdt_status pdt_comm_recv(pdt_comm *c, int peer, int tag, void **buf, size_t *bytes, pdt_err *err)
{
    *buf = NULL;
    *bytes = 0;
    if (peer == c->rank || peer < 0 || peer >= c->size)
        return pdt_err_set(err, PDT_ERR_MPI, "rank %d: receive from rank %d", c->rank, peer);
    return c->ops->recv(c, peer, tag, buf, bytes, err);
}

pdt_status pdt_comm_agree(pdt_comm *c, pdt_status mine, const char *path, const char *what,
                          pdt_err *err)
{
    if (c->size == 1) return mine;
    /* one allreduce: the largest size - rank is the lowest failing rank */
    uint64_t v = mine != PDT_OK ? (uint64_t)(c->size - c->rank) : 0;
    pdt_err e2 = {0};
    pdt_status s = pdt_comm_allreduce_u64(c, &v, 1, PDT_COMM_MAX, &e2);
    if (mine != PDT_OK) return mine;
    if (s != PDT_OK) {
        *err = e2;
        return s;
    }
    if (v)
        return pdt_err_set(err, PDT_ERR_IO, "%s: %s failed at rank %llu", path, what,
                           (unsigned long long)((uint64_t)c->size - v));
    return PDT_OK;
}

pdt_status pdt_comm_file_open(pdt_comm *c, const char *path, uint64_t size, pdt_comm_file **out,
                              pdt_err *err)
{
    *out = NULL;
    pdt_comm_file *f = calloc(1, sizeof *f);
    char *p = strdup(path);
    if (!f || !p) {
        free(f);
        free(p);
        /* (a few bytes short: the other ranks may then wait in the open) */
        return pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: %s: out of memory", c->rank, path);
    }
    f->c = c;
    f->path = p;
    f->size = size;
    pdt_err_clear(&f->first);
    pdt_status s = c->ops->file_open(c, f, err);
    if (s != PDT_OK) {
        free(p);
        free(f);
        return s;
    }
    *out = f;
    return PDT_OK;
}

pdt_status pdt_comm_file_write_at(pdt_comm_file *f, uint64_t offset, const void *buf,
                                  size_t bytes, pdt_err *err)
{
    if (f->first.code != PDT_OK) return pdt_err_set(err, f->first.code, "%s", f->first.msg);
    pdt_status s = f->c->ops->file_write_at(f, offset, buf, bytes, &f->first);
    if (s != PDT_OK) pdt_err_set(err, s, "%s", f->first.msg);
    return s;
}

void pdt_comm_file_failed(pdt_comm_file *f, const pdt_err *e)
{
    if (f && f->first.code == PDT_OK) f->first = *e;
}

/* The close, and with `close_commit` and `commit` (the user's file) the
 * commit point's stop question in the same agreement (pdt_comm_commit_ok). */
static pdt_status file_close(pdt_comm_file *f, int close_commit, const char *commit,
                             pdt_err *err)
{
    pdt_comm *c = f->c;
    pdt_err cerr;
    pdt_err_clear(&cerr);
    pdt_status s = c->ops->file_close(f, &cerr);
    pdt_status mine = f->first.code != PDT_OK ? f->first.code : s;
    const char *what = f->first.code ? "write" : "close";
    if (mine != PDT_OK) {
        pdt_err_set(err, mine, "%s", f->first.code ? f->first.msg : cerr.msg);
    } else if (commit && stopping(c)) {
        mine = pdt_err_set(err, PDT_ERR_IO, "%s: not written: the job was stopped (rank %d)",
                           commit, c->rank);
        what = "the commit (the job was stopped)";
    }
    pdt_status own = mine;
    mine = pdt_comm_agree(c, mine, f->path, what, err);
    if (close_commit && own == PDT_OK && mine != PDT_OK) err->msg[0] = '\0';
    if (mine == PDT_OK && commit && c->rank == 0 && stopping(c))
        mine = pdt_err_set(err, PDT_ERR_IO, "%s: not written: the job was stopped (rank 0)", commit);
    free(f->path);
    free(f);
    return mine;
}

pdt_status pdt_comm_file_close(pdt_comm_file *f, pdt_err *err)
{
    return f ? file_close(f, 0, NULL, err) : PDT_OK;
}

pdt_status pdt_comm_file_close_commit(pdt_comm *c, pdt_comm_file *f, const char *path,
                                      pdt_err *err)
{
    if (f) return file_close(f, 1, path, err);
    return path ? pdt_comm_commit_ok(c, path, err) : PDT_OK;
}
