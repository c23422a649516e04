/* pdt — the communication layer: the only file that includes mpi.h.
 *
 * Small wrappers over the MPI calls the parallel driver needs.  Every call
 * goes to the context's private communicator (a duplicate of the world one,
 * with MPI_ERRORS_RETURN), every return code is checked and turned into
 * PDT_ERR_MPI with MPI's own error string.  A context created without a
 * launcher is "serial": size 1, no MPI call at all. */
#include "pdt/par.h"

#include <limits.h>
#include <mpi.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

struct pdt_comm {
    int mpi;        /* 1 if MPI was initialised by us */
    int rank, size;
    MPI_Comm comm;
    char host[256];
};

int pdt_comm_launched(void)
{
    const char *force = getenv("PDT_MPI");
    if (force && *force) return strcmp(force, "0") != 0;
    static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE",
                                       "PMI_RANK", "MPI_LOCALNRANKS", "MV2_COMM_WORLD_SIZE"};
    for (size_t i = 0; i < sizeof vars / sizeof *vars; i++)
        if (getenv(vars[i])) return 1;
    return 0;
}

/* Turn an MPI return code into a pdt status (the first error sticks). */
static pdt_status mpi_check(int rc, const char *what, const pdt_comm *c, pdt_err *err)
{
    if (rc == MPI_SUCCESS) return PDT_OK;
    char msg[MPI_MAX_ERROR_STRING + 1];
    int len = 0;
    if (MPI_Error_string(rc, msg, &len) != MPI_SUCCESS) len = 0;
    msg[len] = '\0';
    return pdt_err_set(err, PDT_ERR_MPI, "rank %d: %s failed: %s", c ? c->rank : -1, what,
                       len ? msg : "unknown MPI error");
}

static pdt_status to_int(const pdt_comm *c, size_t v, int *out, const char *what, pdt_err *err)
{
    *out = 0;
    if (v > (size_t)INT_MAX)
        return pdt_err_set(err, PDT_ERR_MPI, "rank %d: %s: message too large (%zu bytes)",
                           c->rank, what, v);
    *out = (int)v;
    return PDT_OK;
}

/* counts/displacements as ints for the v-collectives (malloc'd pair). */
static pdt_status int_counts(const pdt_comm *c, const size_t *count, int **cnt, int **dsp,
                             const char *what, pdt_err *err)
{
    *cnt = malloc((size_t)c->size * sizeof **cnt);
    *dsp = malloc((size_t)c->size * sizeof **dsp);
    if (!*cnt || !*dsp) {
        free(*cnt);
        free(*dsp);
        *cnt = *dsp = NULL;
        return pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: %s: out of memory", c->rank, what);
    }
    size_t off = 0;
    for (int i = 0; i < c->size; i++) {
        pdt_status s = to_int(c, count[i], &(*cnt)[i], what, err);
        if (s == PDT_OK) s = to_int(c, off, &(*dsp)[i], what, err);
        if (s != PDT_OK) {
            free(*cnt);
            free(*dsp);
            *cnt = *dsp = NULL;
            return s;
        }
        off += count[i];
    }
    return to_int(c, off, &(int){0}, what, err);
}

pdt_status pdt_comm_init(int *argc, char ***argv, int force_mpi, pdt_comm **out, pdt_err *err)
{
    *out = NULL;
    pdt_comm *c = calloc(1, sizeof *c);
    if (!c) return pdt_err_set(err, PDT_ERR_NOMEM, "comm: out of memory");
    c->size = 1;
    if (gethostname(c->host, sizeof c->host - 1) != 0) strcpy(c->host, "?");
    if (!force_mpi && !pdt_comm_launched()) {
        *out = c;
        return PDT_OK;
    }
    int rc = MPI_Init(argc, argv);
    if (rc != MPI_SUCCESS) {
        free(c);
        return pdt_err_set(err, PDT_ERR_MPI, "MPI_Init failed (code %d)", rc);
    }
    c->mpi = 1;
    /* From here on errors come back as codes instead of aborting. */
    pdt_status s = mpi_check(MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN),
                             "MPI_Comm_set_errhandler", c, err);
    if (s == PDT_OK) s = mpi_check(MPI_Comm_dup(MPI_COMM_WORLD, &c->comm), "MPI_Comm_dup", c, err);
    if (s == PDT_OK)
        s = mpi_check(MPI_Comm_set_errhandler(c->comm, MPI_ERRORS_RETURN),
                      "MPI_Comm_set_errhandler", c, err);
    if (s == PDT_OK) s = mpi_check(MPI_Comm_rank(c->comm, &c->rank), "MPI_Comm_rank", c, err);
    if (s == PDT_OK) s = mpi_check(MPI_Comm_size(c->comm, &c->size), "MPI_Comm_size", c, err);
    if (s != PDT_OK) {
        MPI_Finalize();
        free(c);
        return s;
    }
    *out = c;
    return PDT_OK;
}

pdt_status pdt_comm_finalize(pdt_comm *c, pdt_err *err)
{
    if (!c) return PDT_OK;
    pdt_status s = PDT_OK;
    if (c->mpi) {
        s = mpi_check(MPI_Comm_free(&c->comm), "MPI_Comm_free", c, err);
        pdt_status s2 = mpi_check(MPI_Finalize(), "MPI_Finalize", c, err);
        if (s == PDT_OK) s = s2;
    }
    free(c);
    return s;
}

void pdt_comm_abort(pdt_comm *c, int code)
{
    if (c && c->mpi) MPI_Abort(c->comm, code);
    exit(code);
}

int pdt_comm_rank(const pdt_comm *c) { return c->rank; }
int pdt_comm_size(const pdt_comm *c) { return c->size; }
int pdt_comm_is_mpi(const pdt_comm *c) { return c->mpi; }
const char *pdt_comm_host(const pdt_comm *c) { return c->host; }

double pdt_comm_wtime(const pdt_comm *c)
{
    if (c && c->mpi) return MPI_Wtime();
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

pdt_status pdt_comm_barrier(pdt_comm *c, pdt_err *err)
{
    if (!c->mpi) return PDT_OK;
    return mpi_check(MPI_Barrier(c->comm), "MPI_Barrier", c, err);
}

/* Waiting ranks sleep between polls instead of spinning in MPI's progress
 * loop, so that they leave the cores to the ranks still computing (matters
 * when ranks outnumber cores or the machine is busy). */
static void nap(void)
{
    struct timespec ts = {0, 100000}; /* 0.1 ms */
    nanosleep(&ts, NULL);
}

pdt_status pdt_comm_quiet_barrier(pdt_comm *c, pdt_err *err)
{
    if (!c->mpi) return PDT_OK;
    MPI_Request rq;
    pdt_status s = mpi_check(MPI_Ibarrier(c->comm, &rq), "MPI_Ibarrier", c, err);
    int done = 0;
    while (s == PDT_OK && !done) {
        s = mpi_check(MPI_Test(&rq, &done, MPI_STATUS_IGNORE), "MPI_Test", c, err);
        if (s == PDT_OK && !done) nap();
    }
    return s;
}

pdt_status pdt_comm_bcast(pdt_comm *c, void *buf, size_t bytes, int root, pdt_err *err)
{
    if (!c->mpi) return PDT_OK;
    int nb = 0;
    pdt_status s = to_int(c, bytes, &nb, "bcast", err);
    if (s != PDT_OK) return s;
    return mpi_check(MPI_Bcast(buf, nb, MPI_BYTE, root, c->comm), "MPI_Bcast", c, err);
}

pdt_status pdt_comm_allgather(pdt_comm *c, const void *send, size_t bytes, void *recv,
                              pdt_err *err)
{
    if (!c->mpi) {
        if (bytes) memmove(recv, send, bytes);
        return PDT_OK;
    }
    int nb = 0;
    pdt_status s = to_int(c, bytes * (size_t)c->size, &nb, "allgather", err);
    if (s != PDT_OK) return s;
    return mpi_check(MPI_Allgather(send, (int)bytes, MPI_BYTE, recv, (int)bytes, MPI_BYTE, c->comm),
                     "MPI_Allgather", c, err);
}

pdt_status pdt_comm_alltoall(pdt_comm *c, const void *send, size_t bytes, void *recv,
                             pdt_err *err)
{
    if (!c->mpi) {
        if (bytes) memmove(recv, send, bytes);
        return PDT_OK;
    }
    int nb = 0;
    pdt_status s = to_int(c, bytes * (size_t)c->size, &nb, "alltoall", err);
    if (s != PDT_OK) return s;
    return mpi_check(MPI_Alltoall(send, (int)bytes, MPI_BYTE, recv, (int)bytes, MPI_BYTE, c->comm),
                     "MPI_Alltoall", c, err);
}

pdt_status pdt_comm_alltoallv(pdt_comm *c, const void *send, const size_t *scount, void *recv,
                              const size_t *rcount, pdt_err *err)
{
    if (!c->mpi) {
        if (scount[0] != rcount[0])
            return pdt_err_set(err, PDT_ERR_MPI, "alltoallv: count mismatch");
        if (scount[0]) memmove(recv, send, scount[0]);
        return PDT_OK;
    }
    int *sc, *sd, *rc, *rd;
    pdt_status s = int_counts(c, scount, &sc, &sd, "alltoallv", err);
    if (s != PDT_OK) return s;
    s = int_counts(c, rcount, &rc, &rd, "alltoallv", err);
    if (s == PDT_OK) {
        s = mpi_check(MPI_Alltoallv(send, sc, sd, MPI_BYTE, recv, rc, rd, MPI_BYTE, c->comm),
                      "MPI_Alltoallv", c, err);
        free(rc);
        free(rd);
    }
    free(sc);
    free(sd);
    return s;
}

pdt_status pdt_comm_scatterv(pdt_comm *c, const void *send, const size_t *count, void *recv,
                             size_t rbytes, int root, pdt_err *err)
{
    if (!c->mpi) {
        if (count[0] != rbytes) return pdt_err_set(err, PDT_ERR_MPI, "scatterv: count mismatch");
        if (rbytes) memmove(recv, send, rbytes);
        return PDT_OK;
    }
    int *sc = NULL, *sd = NULL, nr = 0;
    pdt_status s = to_int(c, rbytes, &nr, "scatterv", err);
    if (s == PDT_OK && c->rank == root) s = int_counts(c, count, &sc, &sd, "scatterv", err);
    if (s == PDT_OK)
        s = mpi_check(MPI_Scatterv(send, sc, sd, MPI_BYTE, recv, nr, MPI_BYTE, root, c->comm),
                      "MPI_Scatterv", c, err);
    free(sc);
    free(sd);
    return s;
}

pdt_status pdt_comm_gatherv(pdt_comm *c, const void *send, size_t bytes, void *recv,
                            const size_t *count, int root, pdt_err *err)
{
    if (!c->mpi) {
        if (count[0] != bytes) return pdt_err_set(err, PDT_ERR_MPI, "gatherv: count mismatch");
        if (bytes) memmove(recv, send, bytes);
        return PDT_OK;
    }
    int *rc = NULL, *rd = NULL, ns = 0;
    pdt_status s = to_int(c, bytes, &ns, "gatherv", err);
    if (s == PDT_OK && c->rank == root) s = int_counts(c, count, &rc, &rd, "gatherv", err);
    if (s == PDT_OK)
        s = mpi_check(MPI_Gatherv(send, ns, MPI_BYTE, recv, rc, rd, MPI_BYTE, root, c->comm),
                      "MPI_Gatherv", c, err);
    free(rc);
    free(rd);
    return s;
}

pdt_status pdt_comm_allmax(pdt_comm *c, double *v, int n, pdt_err *err)
{
    if (!c->mpi) return PDT_OK;
    return mpi_check(MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_DOUBLE, MPI_MAX, c->comm),
                     "MPI_Allreduce", c, err);
}

pdt_status pdt_comm_send(pdt_comm *c, int peer, int tag, const void *buf, size_t bytes,
                         pdt_err *err)
{
    if (!c->mpi || peer == c->rank)
        return pdt_err_set(err, PDT_ERR_MPI, "rank %d: send to itself", c->rank);
    int nb = 0;
    pdt_status s = to_int(c, bytes, &nb, "send", err);
    if (s != PDT_OK) return s;
    return mpi_check(MPI_Send(buf, nb, MPI_BYTE, peer, tag, c->comm), "MPI_Send", c, err);
}

pdt_status pdt_comm_recv(pdt_comm *c, int peer, int tag, void **buf, size_t *bytes, pdt_err *err)
{
    *buf = NULL;
    *bytes = 0;
    if (!c->mpi || peer == c->rank)
        return pdt_err_set(err, PDT_ERR_MPI, "rank %d: receive from itself", c->rank);
    MPI_Status st;
    int flag = 0;
    pdt_status s = PDT_OK;
    while (s == PDT_OK && !flag) {
        s = mpi_check(MPI_Iprobe(peer, tag, c->comm, &flag, &st), "MPI_Iprobe", c, err);
        if (s == PDT_OK && !flag) nap();
    }
    int nb = 0;
    if (s == PDT_OK) s = mpi_check(MPI_Get_count(&st, MPI_BYTE, &nb), "MPI_Get_count", c, err);
    if (s != PDT_OK) return s;
    if (nb < 0) return pdt_err_set(err, PDT_ERR_MPI, "rank %d: bad message size", c->rank);
    void *b = malloc(nb ? (size_t)nb : 1);
    if (!b) return pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: recv: out of memory", c->rank);
    s = mpi_check(MPI_Recv(b, nb, MPI_BYTE, peer, tag, c->comm, MPI_STATUS_IGNORE), "MPI_Recv",
                  c, err);
    if (s != PDT_OK) {
        free(b);
        return s;
    }
    *buf = b;
    *bytes = (size_t)nb;
    return PDT_OK;
}
