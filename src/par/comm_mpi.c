/* pdt — the communication layer's MPI backend: the only file that includes
 * mpi.h.  pdt_comm_init lives here: it starts MPI when a launcher started the
 * process, and otherwise returns the serial context (src/par/comm_local.c).
 *
 * Small wrappers over the MPI calls the parallel driver needs.  Every call
 * goes to the context's private communicator (a duplicate of the world one,
 * with MPI_ERRORS_RETURN), every return code is checked and turned into
 * PDT_ERR_MPI with MPI's own error string.
 *
 * No 32-bit limit: MPI counts are ints (Open MPI 4.1 has no MPI-4 "_c"
 * calls), so every transfer goes in chunks of at most c->chunk bytes.  The
 * v-collectives and the large uniform ones run on point-to-point messages of
 * a second private communicator (xcomm_of(c)), chunk by chunk in rounds, so no
 * int displacement is ever needed.
 *
 * Under SimGrid's SMPI (bin/smpi/pdt: this file compiled by smpicc with
 * PDT_SMPI=1) a few things differ, each marked PDT_SMPI below, none in what
 * is computed: waiting ranks block in MPI instead of polling (a poll there
 * is a step of the simulator for every waiting rank, and nanosleep is
 * simulated time); the world communicator is used as it is (SMPI sets up a
 * new one with O(P^2) simulated messages); exscan and waitall avoid SMPI's
 * O(P^2)-per-rank versions; an exchange posts its requests a window of
 * peers at a time, with synchronous sends (SimGrid walks lists of every
 * pending request); the output file is written with pwrite, through to
 * the disk (SMPI's MPI-IO opens files on simulated disks only); the heap
 * the ranks share with SimGrid has no fast bins and no trimming
 * (pdt_comm_heap_shared) and the process no huge pages
 * (pdt_comm_small_pages); the launcher tweaks for Open MPI are skipped
 * (docs/simulation.md). */
#include "comm_int.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <mpi.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#ifndef PDT_SMPI
#define PDT_SMPI 0 /* 1: compiled by smpicc for SimGrid (Makefile, bin/smpi/pdt) */
#endif

typedef struct mpi_be {
    MPI_Comm comm;  /* collectives and the caller's point-to-point messages */
    MPI_Comm xcomm; /* the chunked exchanges (no tag clash with comm) */
} mpi_be;

static MPI_Comm comm_of(const pdt_comm *c) { return ((const mpi_be *)c->be)->comm; }
static MPI_Comm xcomm_of(const pdt_comm *c) { return ((const mpi_be *)c->be)->xcomm; }

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

static const pdt_comm_ops mpi_ops;

/* When mpirun placed every rank on this one node (Open MPI says so in the
 * environment it gives each rank), ask for the shared-memory point-to-point
 * layer (pml ob1, which uses the vader BTL) unless the user chose a pml or an
 * mtl: by default Open MPI 4.1 also opens its network MTLs (PSM, PSM2) to
 * find none, which is most of MPI_Init's time on a small machine.  Likewise
 * only the BTLs a node needs (self, vader: no TCP, which sets up its sockets
 * in every rank) unless the user chose BTLs.  On several nodes nothing
 * changes. */
static void one_node_defaults(void)
{
    const char *size = getenv("OMPI_COMM_WORLD_SIZE");
    const char *local = getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
    if (!size || !local || strcmp(size, local) != 0) return;
    if (!getenv("OMPI_MCA_btl")) setenv("OMPI_MCA_btl", "self,vader", 0);
    if (getenv("OMPI_MCA_pml") || getenv("OMPI_MCA_mtl")) return;
    setenv("OMPI_MCA_pml", "ob1", 0);
}

/* The connection to the node's launcher daemon (PMIx over TCP on the
 * loopback with Open MPI 4.1) without Nagle's algorithm.  MPI_Finalize ends
 * with a fence through the daemon; with Nagle's algorithm its small request
 * waits for the daemon's delayed acknowledgement of the previous message,
 * tens of milliseconds of every run spent idle.  Our sockets are
 * PMIx's, made inside MPI_Init: every TCP socket of this process connected
 * to a loopback address gets the option; nothing else is touched, and a
 * failure changes nothing but the delay. */
static void launcher_nodelay(void)
{
    DIR *dir = opendir("/proc/self/fd");
    if (!dir) return;
    for (struct dirent *e; (e = readdir(dir)) != NULL;) {
        char *end;
        long fd = strtol(e->d_name, &end, 10);
        if (*end || fd < 0 || fd == dirfd(dir)) continue;
        struct sockaddr_storage peer;
        socklen_t len = sizeof peer;
        int type = 0, one = 1;
        socklen_t tlen = sizeof type;
        if (getsockopt((int)fd, SOL_SOCKET, SO_TYPE, &type, &tlen) != 0 || type != SOCK_STREAM ||
            getpeername((int)fd, (struct sockaddr *)&peer, &len) != 0)
            continue;
        int loop = (peer.ss_family == AF_INET &&
                    (ntohl(((struct sockaddr_in *)&peer)->sin_addr.s_addr) >> 24) == 127) ||
                   (peer.ss_family == AF_INET6 &&
                    IN6_IS_ADDR_LOOPBACK(&((struct sockaddr_in6 *)&peer)->sin6_addr));
        if (loop) (void)setsockopt((int)fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    }
    closedir(dir);
}

/* The context's communicators: duplicates of the world one (the caller's
 * messages and the exchanges' cannot meet anybody else's), and the ranks on
 * this rank's node.  Under SMPI the world communicator itself and one rank
 * per node: SMPI sets up a new communicator with O(P^2) simulated messages
 * (at P = 1024 the start-up alone ran for over 20 minutes); the exchanges'
 * tag 0 is one the driver's messages never use. */
static pdt_status private_comms(pdt_comm *c, mpi_be *m, pdt_err *err)
{
    pdt_status s = PDT_OK;
    if (PDT_SMPI) {
        m->comm = m->xcomm = MPI_COMM_WORLD;
    } else {
        s = mpi_check(MPI_Comm_dup(MPI_COMM_WORLD, &m->comm), "MPI_Comm_dup", c, err);
        if (s == PDT_OK)
            s = mpi_check(MPI_Comm_set_errhandler(m->comm, MPI_ERRORS_RETURN),
                          "MPI_Comm_set_errhandler", c, err);
        if (s == PDT_OK) s = mpi_check(MPI_Comm_dup(m->comm, &m->xcomm), "MPI_Comm_dup", c, err);
    }
    if (s == PDT_OK) s = mpi_check(MPI_Comm_rank(m->comm, &c->rank), "MPI_Comm_rank", c, err);
    if (s == PDT_OK) s = mpi_check(MPI_Comm_size(m->comm, &c->size), "MPI_Comm_size", c, err);
    c->node_size = PDT_SMPI ? 1 : c->size;
    if (PDT_SMPI || s != PDT_OK) return s;
    MPI_Comm node = MPI_COMM_NULL;
    s = mpi_check(MPI_Comm_split_type(m->comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node),
                  "MPI_Comm_split_type", c, err);
    if (s == PDT_OK) s = mpi_check(MPI_Comm_size(node, &c->node_size), "MPI_Comm_size", c, err);
    if (node != MPI_COMM_NULL) MPI_Comm_free(&node);
    return s;
}

pdt_status pdt_comm_init(int *argc, char ***argv, int force_mpi, pdt_comm **out, pdt_err *err)
{
    *out = NULL;
    if (!force_mpi && !pdt_comm_launched()) return pdt_comm_serial_new(out, err);
    pdt_comm *c = calloc(1, sizeof *c);
    mpi_be *m = calloc(1, sizeof *m);
    if (!c || !m) {
        free(c);
        free(m);
        return pdt_err_set(err, PDT_ERR_NOMEM, "comm: out of memory");
    }
    c->ops = &mpi_ops;
    c->be = m;
    c->size = 1;
    c->node_size = 1;
    c->chunk = pdt_comm_chunk_from_env();
    if (gethostname(c->host, sizeof c->host - 1) != 0) strcpy(c->host, "?");
    if (!PDT_SMPI) one_node_defaults();
    int rc = MPI_Init(argc, argv);
    if (rc != MPI_SUCCESS) {
        free(m);
        free(c);
        return pdt_err_set(err, PDT_ERR_MPI, "MPI_Init failed (code %d)", rc);
    }
    if (!PDT_SMPI) launcher_nodelay();
    /* From here on errors come back as codes instead of aborting. */
    pdt_status s = mpi_check(MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN),
                             "MPI_Comm_set_errhandler", c, err);
    if (s == PDT_OK) s = private_comms(c, m, err);
    if (PDT_SMPI && c->size > 1) pdt_comm_heap_shared(); /* (comm.c: smpicc wraps malloc.h) */
    if (PDT_SMPI) pdt_comm_small_pages();
    /* Every rank must cut transfers the same way: rank 0's chunk size wins. */
    unsigned long long chunk = c->chunk;
    if (s == PDT_OK)
        s = mpi_check(MPI_Bcast(&chunk, 1, MPI_UNSIGNED_LONG_LONG, 0, m->comm), "MPI_Bcast", c,
                      err);
    c->chunk = (size_t)chunk;
    if (s != PDT_OK) {
        MPI_Finalize();
        free(m);
        free(c);
        return s;
    }
    *out = c;
    return PDT_OK;
}

static void mpi_finalize(pdt_comm *c)
{
    mpi_be *m = c->be;
    if (!PDT_SMPI) { /* (under SMPI both are the world communicator) */
        MPI_Comm_free(&m->xcomm);
        MPI_Comm_free(&m->comm);
    }
    MPI_Finalize();
    free(m);
}

void pdt_comm_abort(pdt_comm *c, int code)
{
    if (c && c->ops->is_mpi) MPI_Abort(comm_of(c), code);
    exit(code);
}

static double mpi_wtime(const pdt_comm *c)
{
    (void)c;
    return MPI_Wtime();
}

static pdt_status mpi_barrier(pdt_comm *c, pdt_err *err)
{
    return mpi_check(MPI_Barrier(comm_of(c)), "MPI_Barrier", c, err);
}

/* Waiting ranks sleep between polls instead of spinning in MPI's progress
 * loop, so that they leave the cores to the ranks still computing (matters
 * when ranks outnumber cores or the machine is busy). */
static void nap(void)
{
    struct timespec ts = {0, 100000}; /* 0.1 ms */
    nanosleep(&ts, NULL);
}

static pdt_status mpi_quiet_barrier(pdt_comm *c, pdt_err *err)
{
    if (PDT_SMPI) /* a blocked simulated rank costs nothing */
        return mpi_check(MPI_Barrier(comm_of(c)), "MPI_Barrier", c, err);
    MPI_Request rq;
    pdt_status s = mpi_check(MPI_Ibarrier(comm_of(c), &rq), "MPI_Ibarrier", c, err);
    int done = 0;
    while (s == PDT_OK && !done) {
        s = mpi_check(MPI_Test(&rq, &done, MPI_STATUS_IGNORE), "MPI_Test", c, err);
        if (s == PDT_OK && !done) nap();
    }
    return s;
}

/* ---- the chunked exchange ------------------------------------------------ */

/* One exchange: rank i gets sn[i] bytes from sp[i], and rn[i] bytes from
 * rank i land at rp[i] (sn at rank j == rn[j's peer] by the caller's
 * contract).  Round r moves chunk r of every pair that still has one; each
 * side knows its own pair's sizes, so the ranks need not agree on the number
 * of rounds.  The self block is a plain copy. */
typedef struct xchg {
    const char **sp;
    size_t *sn;
    char **rp;
    size_t *rn;
} xchg;

static pdt_status xchg_new(const pdt_comm *c, xchg *x, const char *what, pdt_err *err)
{
    size_t P = (size_t)c->size;
    x->sp = calloc(P, sizeof *x->sp);
    x->sn = calloc(P, sizeof *x->sn);
    x->rp = calloc(P, sizeof *x->rp);
    x->rn = calloc(P, sizeof *x->rn);
    if (x->sp && x->sn && x->rp && x->rn) return PDT_OK;
    return pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: %s: out of memory", c->rank, what);
}

static void xchg_free(xchg *x)
{
    free(x->sp);
    free(x->sn);
    free(x->rp);
    free(x->rn);
}

static size_t min_size(size_t a, size_t b) { return a < b ? a : b; }

/* SMPI's MPI_Waitall is a loop of MPI_Waitany, each a pass over all the
 * requests: O(P^2) steps of the simulator per rank in an exchange with
 * every rank.  Under SMPI the requests are waited for one by one instead
 * (the same completion, in linear time). */
static pdt_status wait_all(pdt_comm *c, int nrq, MPI_Request *rq, pdt_err *err)
{
    if (!PDT_SMPI)
        return mpi_check(MPI_Waitall(nrq, rq, MPI_STATUSES_IGNORE), "MPI_Waitall", c, err);
    pdt_status s = PDT_OK;
    for (int i = 0; i < nrq; i++) {
        pdt_status w = mpi_check(MPI_Wait(&rq[i], MPI_STATUS_IGNORE), "MPI_Wait", c, err);
        if (s == PDT_OK) s = w;
    }
    return s;
}

/* Post the receives then the sends of chunk `off` of every pair i whose
 * peer is listed in rfrom[0..n) (receive) and sto[0..n) (send); returns the
 * number of requests in *nrq.  Under SMPI a send is synchronous (see
 * xchg_run). */
static pdt_status xchg_post(pdt_comm *c, const xchg *x, const int *rfrom, const int *sto, int n,
                            size_t off, MPI_Request *rq, int *nrq, pdt_err *err)
{
    pdt_status s = PDT_OK;
    *nrq = 0;
    for (int j = 0; j < n && s == PDT_OK; j++) {
        int i = rfrom[j];
        if (off >= x->rn[i]) continue;
        int len = (int)min_size(c->chunk, x->rn[i] - off);
        s = mpi_check(MPI_Irecv(x->rp[i] + off, len, MPI_BYTE, i, 0, xcomm_of(c), &rq[(*nrq)++]),
                      "MPI_Irecv", c, err);
    }
    for (int j = 0; j < n && s == PDT_OK; j++) {
        int i = sto[j];
        if (off >= x->sn[i]) continue;
        int len = (int)min_size(c->chunk, x->sn[i] - off);
        const char *b = x->sp[i] + off;
        s = PDT_SMPI ? mpi_check(MPI_Issend(b, len, MPI_BYTE, i, 0, xcomm_of(c), &rq[(*nrq)++]),
                                 "MPI_Issend", c, err)
                     : mpi_check(MPI_Isend(b, len, MPI_BYTE, i, 0, xcomm_of(c), &rq[(*nrq)++]),
                                 "MPI_Isend", c, err);
    }
    return s;
}

/* The exchange: the peers in windows of the pairwise schedule (step k:
 * send to rank me + k, receive from me - k, mod P), all P - 1 steps in one
 * window for a real run (every request posted at once, MPI's progress
 * engine does the rest), SMPI_WINDOW steps at a time under SMPI.  There
 * every pending request of a rank, and every small send in flight of all
 * ranks (SMPI "detaches" sends under 64 KiB), sits in a list of SimGrid's
 * that each completion and each stretch of computation walks: with all
 * requests posted at once that was O(P) per request, O(P^3) per exchange
 * in all, most of a 1024-rank simulation's time.  In windows, with
 * synchronous sends (kept with their rank, never detached), a rank has at
 * most 2 * SMPI_WINDOW requests pending.  A pair's messages go in the one
 * window of its step, at both ends, chunk round by chunk round, so the
 * windows match and cannot deadlock: each rank posts a window's requests
 * before waiting for any. */
#define SMPI_WINDOW 32
static pdt_status xchg_run(pdt_comm *c, const xchg *x, const char *what, pdt_err *err)
{
    int P = c->size, me = c->rank;
    if (x->sn[me] != x->rn[me])
        return pdt_err_set(err, PDT_ERR_MPI, "rank %d: %s: count mismatch with itself", me, what);
    if (x->sn[me]) memmove(x->rp[me], x->sp[me], x->sn[me]);
    int win = PDT_SMPI && P - 1 > SMPI_WINDOW ? SMPI_WINDOW : (P > 1 ? P - 1 : 1);
    MPI_Request *rq = malloc(2 * (size_t)win * sizeof *rq);
    int *peer = malloc(2 * (size_t)win * sizeof *peer);
    pdt_status s = rq && peer ? PDT_OK
                              : pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: %s: out of memory", me,
                                            what);
    for (int k0 = 1; k0 < P && s == PDT_OK; k0 += win) {
        int n = P - k0 < win ? P - k0 : win;
        for (int j = 0; j < n; j++) {
            peer[j] = (me - (k0 + j) + P) % P;   /* receive from */
            peer[win + j] = (me + k0 + j) % P;   /* send to */
        }
        for (size_t off = 0; s == PDT_OK; off += c->chunk) {
            int nrq = 0;
            s = xchg_post(c, x, peer, peer + win, n, off, rq, &nrq, err);
            if (nrq == 0) break;
            pdt_status w = wait_all(c, nrq, rq, err);
            if (s == PDT_OK) s = w;
        }
    }
    free(peer);
    free(rq);
    return s;
}

/* ---- collectives ---------------------------------------------------------- */

static pdt_status mpi_bcast(pdt_comm *c, void *buf, size_t bytes, int root, pdt_err *err)
{
    pdt_status s = PDT_OK;
    for (size_t off = 0; off < bytes && s == PDT_OK; off += c->chunk)
        s = mpi_check(MPI_Bcast((char *)buf + off, (int)min_size(c->chunk, bytes - off), MPI_BYTE,
                                root, comm_of(c)),
                      "MPI_Bcast", c, err);
    return s;
}

/* Uniform collectives whose whole receive buffer fits in one chunk use MPI's
 * own call (same decision at every rank: bytes, size and chunk agree). */
static int one_chunk(const pdt_comm *c, size_t bytes)
{
    return bytes <= c->chunk / (size_t)c->size;
}

static pdt_status mpi_allgather(pdt_comm *c, const void *send, size_t bytes, void *recv,
                              pdt_err *err)
{
    if (one_chunk(c, bytes))
        return mpi_check(MPI_Allgather(send, (int)bytes, MPI_BYTE, recv, (int)bytes, MPI_BYTE,
                                       comm_of(c)),
                         "MPI_Allgather", c, err);
    xchg x;
    pdt_status s = xchg_new(c, &x, "allgather", err);
    for (int i = 0; s == PDT_OK && i < c->size; i++) {
        x.sp[i] = send;
        x.sn[i] = x.rn[i] = bytes;
        x.rp[i] = (char *)recv + (size_t)i * bytes;
    }
    if (s == PDT_OK) s = xchg_run(c, &x, "allgather", err);
    xchg_free(&x);
    return s;
}

static pdt_status mpi_alltoall(pdt_comm *c, const void *send, size_t bytes, void *recv,
                             pdt_err *err)
{
    if (one_chunk(c, bytes))
        return mpi_check(MPI_Alltoall(send, (int)bytes, MPI_BYTE, recv, (int)bytes, MPI_BYTE,
                                      comm_of(c)),
                         "MPI_Alltoall", c, err);
    xchg x;
    pdt_status s = xchg_new(c, &x, "alltoall", err);
    for (int i = 0; s == PDT_OK && i < c->size; i++) {
        x.sp[i] = (const char *)send + (size_t)i * bytes;
        x.rp[i] = (char *)recv + (size_t)i * bytes;
        x.sn[i] = x.rn[i] = bytes;
    }
    if (s == PDT_OK) s = xchg_run(c, &x, "alltoall", err);
    xchg_free(&x);
    return s;
}

static pdt_status mpi_alltoallv(pdt_comm *c, const void *send, const size_t *scount, void *recv,
                              const size_t *rcount, pdt_err *err)
{
    xchg x;
    pdt_status s = xchg_new(c, &x, "alltoallv", err);
    size_t so = 0, ro = 0;
    for (int i = 0; s == PDT_OK && i < c->size; i++) {
        x.sp[i] = (const char *)send + so;
        x.rp[i] = (char *)recv + ro;
        so += x.sn[i] = scount[i];
        ro += x.rn[i] = rcount[i];
    }
    if (s == PDT_OK) s = xchg_run(c, &x, "alltoallv", err);
    xchg_free(&x);
    return s;
}

static pdt_status mpi_scatterv(pdt_comm *c, const void *send, const size_t *count, void *recv,
                             size_t rbytes, int root, pdt_err *err)
{
    xchg x;
    pdt_status s = xchg_new(c, &x, "scatterv", err);
    if (s == PDT_OK) {
        x.rp[root] = recv;
        x.rn[root] = rbytes;
    }
    size_t off = 0;
    for (int i = 0; s == PDT_OK && c->rank == root && i < c->size; i++) {
        x.sp[i] = (const char *)send + off;
        off += x.sn[i] = count[i];
    }
    if (s == PDT_OK) s = xchg_run(c, &x, "scatterv", err);
    xchg_free(&x);
    return s;
}

static pdt_status mpi_gatherv(pdt_comm *c, const void *send, size_t bytes, void *recv,
                            const size_t *count, int root, pdt_err *err)
{
    xchg x;
    pdt_status s = xchg_new(c, &x, "gatherv", err);
    if (s == PDT_OK) {
        x.sp[root] = send;
        x.sn[root] = bytes;
    }
    size_t off = 0;
    for (int i = 0; s == PDT_OK && c->rank == root && i < c->size; i++) {
        x.rp[i] = (char *)recv + off;
        off += x.rn[i] = count[i];
    }
    if (s == PDT_OK) s = xchg_run(c, &x, "gatherv", err);
    xchg_free(&x);
    return s;
}

static pdt_status mpi_allmax(pdt_comm *c, double *v, int n, pdt_err *err)
{
    return mpi_check(MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_DOUBLE, MPI_MAX, comm_of(c)),
                     "MPI_Allreduce", c, err);
}

static pdt_status mpi_allreduce_u64(pdt_comm *c, uint64_t *v, size_t n, pdt_comm_op op,
                                  pdt_err *err)
{
    MPI_Op mop = op == PDT_COMM_SUM ? MPI_SUM : op == PDT_COMM_MAX ? MPI_MAX : MPI_MIN;
    size_t step = c->chunk / sizeof *v ? c->chunk / sizeof *v : 1;
    pdt_status s = PDT_OK;
    for (size_t i = 0; i < n && s == PDT_OK; i += step)
        s = mpi_check(MPI_Allreduce(MPI_IN_PLACE, v + i, (int)min_size(step, n - i), MPI_UINT64_T,
                                    mop, comm_of(c)),
                      "MPI_Allreduce", c, err);
    return s;
}

/* SMPI's MPI_Exscan is linear: every rank sends to every later rank and
 * waits on them one MPI_Waitany at a time, O(P^3) steps of the simulator (at
 * P = 256 a single call ran for minutes); an allgather of the P values
 * instead is still P^2 messages.  Under SMPI the prefix comes from
 * recursive doubling (as MPI libraries do it): in round d every rank sends
 * its sum of ranks (me - 2d, me] to me + d and adds what me - d sends it,
 * log2 P rounds of one message each.  Tag 0 is the exchanges': every rank
 * has finished the previous collective's receives from a peer before that
 * peer can send it anything here, and a pair meets in one round only. */
static pdt_status smpi_exscan_u64(pdt_comm *c, uint64_t v, uint64_t *out, pdt_err *err)
{
    uint64_t incl = v;
    pdt_status s = PDT_OK;
    for (int d = 1; d < c->size && s == PDT_OK; d *= 2) {
        int to = c->rank + d < c->size ? c->rank + d : MPI_PROC_NULL;
        int from = c->rank >= d ? c->rank - d : MPI_PROC_NULL;
        uint64_t mine = incl, got = 0;
        s = mpi_check(MPI_Sendrecv(&mine, 1, MPI_UINT64_T, to, 0, &got, 1, MPI_UINT64_T, from, 0,
                                   comm_of(c), MPI_STATUS_IGNORE),
                      "MPI_Sendrecv", c, err);
        if (from != MPI_PROC_NULL) incl += got;
    }
    *out = incl - v;
    return s;
}

static pdt_status mpi_exscan_u64(pdt_comm *c, uint64_t v, uint64_t *out, pdt_err *err)
{
    *out = 0;
    if (PDT_SMPI) return smpi_exscan_u64(c, v, out, err);
    uint64_t r = 0;
    pdt_status s = mpi_check(MPI_Exscan(&v, &r, 1, MPI_UINT64_T, MPI_SUM, comm_of(c)), "MPI_Exscan",
                             c, err);
    if (s == PDT_OK && c->rank > 0) *out = r; /* MPI leaves rank 0's result undefined */
    return s;
}

/* ---- point to point --------------------------------------------------------
 * A message is a header (its size, one uint64) then the bytes in chunks, all
 * with the caller's tag: MPI keeps messages of one sender, tag and
 * communicator in order. */

static pdt_status mpi_send(pdt_comm *c, int peer, int tag, const void *buf, size_t bytes,
                         pdt_err *err)
{
    uint64_t head = bytes;
    pdt_status s = mpi_check(MPI_Send(&head, 1, MPI_UINT64_T, peer, tag, comm_of(c)), "MPI_Send", c,
                             err);
    for (size_t off = 0; off < bytes && s == PDT_OK; off += c->chunk)
        s = mpi_check(MPI_Send((const char *)buf + off, (int)min_size(c->chunk, bytes - off),
                               MPI_BYTE, peer, tag, comm_of(c)),
                      "MPI_Send", c, err);
    return s;
}

static pdt_status mpi_recv(pdt_comm *c, int peer, int tag, void **buf, size_t *bytes, pdt_err *err)
{
    *buf = NULL;
    *bytes = 0;
    int flag = PDT_SMPI; /* a simulated rank blocks in MPI_Recv: that costs nothing */
    pdt_status s = PDT_OK;
    while (s == PDT_OK && !flag) {
        s = mpi_check(MPI_Iprobe(peer, tag, comm_of(c), &flag, MPI_STATUS_IGNORE), "MPI_Iprobe", c,
                      err);
        if (s == PDT_OK && !flag) nap();
    }
    uint64_t head = 0;
    if (s == PDT_OK)
        s = mpi_check(MPI_Recv(&head, 1, MPI_UINT64_T, peer, tag, comm_of(c), MPI_STATUS_IGNORE),
                      "MPI_Recv", c, err);
    if (s != PDT_OK) return s;
    if (head > SIZE_MAX - 1) return pdt_err_set(err, PDT_ERR_MPI, "rank %d: bad message size", c->rank);
    size_t n = (size_t)head;
    char *b = malloc(n ? n : 1);
    if (!b) return pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: recv: out of memory", c->rank);
    for (size_t off = 0; off < n && s == PDT_OK; off += c->chunk)
        s = mpi_check(MPI_Recv(b + off, (int)min_size(c->chunk, n - off), MPI_BYTE, peer, tag,
                               comm_of(c), MPI_STATUS_IGNORE),
                      "MPI_Recv", c, err);
    if (s != PDT_OK) {
        free(b);
        return s;
    }
    *buf = b;
    *bytes = n;
    return PDT_OK;
}

/* ---- one file written by all ranks (MPI-IO) --------------------------------- */

#if !PDT_SMPI
static pdt_status mpi_io_check(int rc, const pdt_comm *c, const char *path, const char *what,
                               pdt_err *err)
{
    if (rc == MPI_SUCCESS) return PDT_OK;
    char msg[MPI_MAX_ERROR_STRING + 1];
    int len = 0;
    if (MPI_Error_string(rc, msg, &len) != MPI_SUCCESS) len = 0;
    msg[len] = '\0';
    return pdt_err_set(err, PDT_ERR_IO, "%s: %s failed at rank %d: %s", path, what, c->rank,
                       len ? msg : "unknown MPI-IO error");
}

static pdt_status mpi_file_open(pdt_comm *c, pdt_comm_file *f, pdt_err *err)
{
    MPI_File *fh = malloc(sizeof *fh);
    pdt_status s = PDT_OK;
    if (!fh) s = pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: %s: out of memory", c->rank, f->path);
    /* every rank takes part in the collective open, even one short of memory */
    MPI_File h = MPI_FILE_NULL;
    int rc = MPI_File_open(comm_of(c), f->path, MPI_MODE_WRONLY | MPI_MODE_CREATE, MPI_INFO_NULL,
                           &h);
    pdt_status o = mpi_io_check(rc, c, f->path, "create", err);
    if (s == PDT_OK) s = o;
    if (rc == MPI_SUCCESS) { /* the open is collective: it succeeded at every rank */
        pdt_status t = mpi_io_check(MPI_File_set_size(h, (MPI_Offset)f->size), c, f->path,
                                    "truncate", err);
        if (s == PDT_OK) s = t;
    }
    s = pdt_comm_agree(c, s, f->path, "create", err);
    if (s != PDT_OK) {
        if (rc == MPI_SUCCESS) MPI_File_close(&h);
        free(fh);
        return s;
    }
    *fh = h;
    f->be = fh;
    return PDT_OK;
}

/* Independent writes (MPI_File_write_at, a chunk at a time): every rank's
 * range is one contiguous run of the file, so a collective write (two-phase
 * aggregation through a few ranks) would only move the bytes once more. */
static pdt_status mpi_file_write_at(pdt_comm_file *f, uint64_t offset, const void *buf,
                                    size_t bytes, pdt_err *err)
{
    pdt_comm *c = f->c;
    MPI_File *fh = f->be;
    pdt_status s = PDT_OK;
    for (size_t off = 0; off < bytes && s == PDT_OK; off += c->chunk) {
        int len = (int)min_size(c->chunk, bytes - off);
        MPI_Status st;
        int rc = MPI_File_write_at(*fh, (MPI_Offset)(offset + off), (const char *)buf + off, len,
                                   MPI_BYTE, &st);
        s = mpi_io_check(rc, c, f->path, "write", err);
        int got = 0;
        if (s == PDT_OK && (MPI_Get_count(&st, MPI_BYTE, &got) != MPI_SUCCESS || got != len))
            s = pdt_err_set(err, PDT_ERR_IO, "%s: short write at rank %d", f->path, c->rank);
    }
    return s;
}

static pdt_status mpi_file_close(pdt_comm_file *f, pdt_err *err)
{
    MPI_File *fh = f->be;
    pdt_status s = mpi_io_check(MPI_File_close(fh), f->c, f->path, "close", err);
    free(fh);
    return s;
}

#endif

/* ---- one file written by all ranks (SMPI: pwrite) ---------------------------
 * SMPI's MPI-IO writes to the simulated hosts' disks only.  Under it every
 * rank is a thread of this one process: every rank opens the file (creating
 * it if it is not there yet) and writes its range with pwrite at the same
 * offsets MPI-IO would use; rank 0 also gives it its final size, which no
 * write reaches past, so its ftruncate may come before or after any of them.
 * One agreement, on the opens.  The write's simulated time is the
 * formatting and the system calls, with no disk or file-system model.
 * Each piece is written through to the disk and dropped from the page
 * cache before the rank goes on: a thousand ranks' output would otherwise
 * take that much fresh memory from this one machine, which on a virtual
 * machine whose host has taken its free memory back costs about ten
 * times a warm page (docs/simulation.md, "What differs from a real run").  A
 * rank's clock is its CPU time, so the disk's own time is not counted. */
#if PDT_SMPI
static pdt_status smpi_file_open(pdt_comm *c, pdt_comm_file *f, pdt_err *err)
{
    int *fd = malloc(sizeof *fd);
    pdt_status s = fd ? PDT_OK
                      : pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: %s: out of memory", c->rank,
                                    f->path);
    if (s == PDT_OK) {
        *fd = open(f->path, O_WRONLY | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (*fd < 0 || (c->rank == 0 && ftruncate(*fd, (off_t)f->size) != 0))
            s = pdt_err_set(err, PDT_ERR_IO, "%s: cannot %s at rank %d: %s", f->path,
                            *fd < 0 ? "open" : "truncate", c->rank, strerror(errno));
    }
    s = pdt_comm_agree(c, s, f->path, "open", err);
    if (s != PDT_OK) {
        if (fd && *fd >= 0) close(*fd);
        free(fd);
        return s;
    }
    f->be = fd;
    return PDT_OK;
}

static pdt_status smpi_file_write_at(pdt_comm_file *f, uint64_t offset, const void *buf,
                                     size_t bytes, pdt_err *err)
{
    int fd = *(int *)f->be;
    for (size_t off = 0; off < bytes;) {
        ssize_t k = pwrite(fd, (const char *)buf + off, bytes - off, (off_t)(offset + off));
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0)
            return pdt_err_set(err, PDT_ERR_IO, "%s: write failed at rank %d: %s", f->path,
                               f->c->rank, k < 0 ? strerror(errno) : "no progress");
        off += (size_t)k;
    }
    /* written through and dropped: the next piece, and the next rank's,
     * reuse these pages */
    unsigned how = SYNC_FILE_RANGE_WAIT_BEFORE | SYNC_FILE_RANGE_WRITE |
                   SYNC_FILE_RANGE_WAIT_AFTER;
    if (sync_file_range(fd, (off_t)offset, (off_t)bytes, how) != 0 &&
        (errno == EIO || errno == ENOSPC)) /* (not EINVAL: a file system without it) */
        return pdt_err_set(err, PDT_ERR_IO, "%s: write failed at rank %d: %s", f->path,
                           f->c->rank, strerror(errno));
    (void)posix_fadvise(fd, (off_t)offset, (off_t)bytes, POSIX_FADV_DONTNEED);
    return PDT_OK;
}

static pdt_status smpi_file_close(pdt_comm_file *f, pdt_err *err)
{
    int *fd = f->be;
    pdt_status s = PDT_OK;
    if (close(*fd) != 0)
        s = pdt_err_set(err, PDT_ERR_IO, "%s: close failed at rank %d: %s", f->path, f->c->rank,
                        strerror(errno));
    free(fd);
    return s;
}
#endif

static const pdt_comm_ops mpi_ops = {
    .is_mpi = 1,
    .simulated = PDT_SMPI,
    .finalize = mpi_finalize,
    .wtime = mpi_wtime,
    .barrier = mpi_barrier,
    .quiet_barrier = mpi_quiet_barrier,
    .bcast = mpi_bcast,
    .allgather = mpi_allgather,
    .alltoall = mpi_alltoall,
    .alltoallv = mpi_alltoallv,
    .scatterv = mpi_scatterv,
    .gatherv = mpi_gatherv,
    .allmax = mpi_allmax,
    .allreduce_u64 = mpi_allreduce_u64,
    .exscan_u64 = mpi_exscan_u64,
    .send = mpi_send,
    .recv = mpi_recv,
#if PDT_SMPI
    .file_open = smpi_file_open,
    .file_write_at = smpi_file_write_at,
    .file_close = smpi_file_close,
#else
    .file_open = mpi_file_open,
    .file_write_at = mpi_file_write_at,
    .file_close = mpi_file_close,
#endif
};
