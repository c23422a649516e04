/* pdt — the communication layer's inside: the context every backend shares
 * and the table of operations a backend provides (src/par/comm.c is the
 * front that dispatches; backends: src/par/comm_mpi.c, src/par/comm_local.c,
 * whose P = 1 case is the serial context). */
#ifndef PDT_COMM_INT_H
#define PDT_COMM_INT_H

#include "pdt/par.h"

typedef struct pdt_comm_ops {
    int is_mpi;
    int simulated; /* SMPI: see pdt_comm_is_simulated */
    void (*finalize)(pdt_comm *c); /* free c->be (not c) */
    double (*wtime)(const pdt_comm *c);
    pdt_status (*barrier)(pdt_comm *c, pdt_err *err);
    pdt_status (*quiet_barrier)(pdt_comm *c, pdt_err *err);
    pdt_status (*bcast)(pdt_comm *c, void *buf, size_t bytes, int root, pdt_err *err);
    pdt_status (*allgather)(pdt_comm *c, const void *send, size_t bytes, void *recv,
                            pdt_err *err);
    pdt_status (*alltoall)(pdt_comm *c, const void *send, size_t bytes, void *recv,
                           pdt_err *err);
    pdt_status (*alltoallv)(pdt_comm *c, const void *send, const size_t *scount, void *recv,
                            const size_t *rcount, pdt_err *err);
    pdt_status (*scatterv)(pdt_comm *c, const void *send, const size_t *count, void *recv,
                           size_t rbytes, int root, pdt_err *err);
    pdt_status (*gatherv)(pdt_comm *c, const void *send, size_t bytes, void *recv,
                          const size_t *count, int root, pdt_err *err);
    pdt_status (*allmax)(pdt_comm *c, double *v, int n, pdt_err *err);
    pdt_status (*allreduce_u64)(pdt_comm *c, uint64_t *v, size_t n, pdt_comm_op op,
                                pdt_err *err);
    pdt_status (*exscan_u64)(pdt_comm *c, uint64_t v, uint64_t *out, pdt_err *err);
    pdt_status (*send)(pdt_comm *c, int peer, int tag, const void *buf, size_t bytes,
                       pdt_err *err);
    pdt_status (*recv)(pdt_comm *c, int peer, int tag, void **buf, size_t *bytes, pdt_err *err);
    /* files: the backend allocates and frees f->be; open and close are
     * collective (the front agrees on their status), write_at is not */
    pdt_status (*file_open)(pdt_comm *c, pdt_comm_file *f, pdt_err *err);
    pdt_status (*file_write_at)(pdt_comm_file *f, uint64_t offset, const void *buf,
                                size_t bytes, pdt_err *err);
    pdt_status (*file_close)(pdt_comm_file *f, pdt_err *err);
} pdt_comm_ops;

struct pdt_comm {
    const pdt_comm_ops *ops;
    int rank, size;
    int node_size;  /* ranks of the job on this machine (threads of the local backend: all) */
    size_t chunk;   /* largest single message, bytes (<= INT_MAX) */
    char host[256];
    void *be;       /* the backend's state */
    pdt_stop_query stop; /* the program's "is the job being stopped?" (NULL: never) */
    void *stop_ctx;
};

struct pdt_comm_file {
    pdt_comm *c;
    char *path;
    uint64_t size;  /* the file's final size, set at the open */
    void *be;
    pdt_err first; /* this rank's first failed write (code PDT_OK: none) */
};

/* The chunk size from PDT_COMM_CHUNK (1 GiB if unset or invalid). */
size_t pdt_comm_chunk_from_env(void);
/* For a backend whose ranks share one heap with a simulator (SMPI): glibc
 * tuned so that no rank's malloc or free pays for the others' blocks. */
void pdt_comm_heap_shared(void);
/* For a backend timed on a virtual machine's first touches (SMPI): no
 * transparent huge pages in this process. */
void pdt_comm_small_pages(void);
/* A serial context (the local backend with one rank, no thread), *c owned by
 * the caller (pdt_comm_finalize). */
pdt_status pdt_comm_serial_new(pdt_comm **c, pdt_err *err);
/* An alltoallv through relays, about 6 sqrt(P) messages a rank instead of
 * P - 1 (src/par/comm_hops.c); pdt_comm_alltoallv takes it from
 * PDT_COMM_HOPS_MIN ranks on with MPI.  (Below, direct: on the simulated
 * cluster, 64 ranks exchanging 10^7 points' records took 3.1 ms direct
 * and 8.4-9.1 ms in two hops, the order's rounds 2.5-3.5 ms against 5.4-6.3;
 * from 128 ranks direct exchanges gained the simulated runs nothing
 * measurable and cost the simulator up to 17 times its wall time:
 * docs/simulation.md, "Two hops and the relay".) */
pdt_status pdt_comm_hops_alltoallv(pdt_comm *c, const void *send, const size_t *scount,
                                   void *recv, const size_t *rcount, pdt_err *err);
#define PDT_COMM_HOPS_MIN 128

/* Every rank learns whether any rank failed: a rank that did not fail itself
 * gets PDT_ERR_IO "PATH: WHAT failed at rank R" (R the lowest failing rank). */
pdt_status pdt_comm_agree(pdt_comm *c, pdt_status mine, const char *path, const char *what,
                          pdt_err *err);

#endif
