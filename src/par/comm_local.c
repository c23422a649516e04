/* pdt — the communication layer's local backend: P ranks as P threads of one
 * process.  Every collective publishes each rank's pointers in a shared table,
 * meets at a barrier, copies straight from the other ranks' buffers, and
 * meets again (so no buffer is reused before every reader is done).
 * Point-to-point messages are copied into the receiver's mailbox.  With one
 * rank and no thread this is the serial context of a plain run.
 *
 * A rank whose function returns an error breaks the world: every rank then
 * waiting (or later arriving) at a barrier or a receive gets PDT_ERR_MPI
 * instead of waiting forever. */
#include "comm_int.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct local_msg {
    struct local_msg *next;
    int from, tag;
    size_t bytes;
    char *data;
} local_msg;

typedef struct local_pub { /* what one rank shows the others in a collective */
    const void *a;
    const size_t *counts;
    size_t n;
    int fd, err;
} local_pub;

typedef struct local_world {
    int P;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int arrived;
    unsigned long gen;
    int broken;          /* a rank failed: -1 none, else the rank */
    local_pub *pub;      /* P entries */
    local_msg **box;     /* P mailboxes, oldest first */
} local_world;

typedef struct local_be {
    local_world *w;
    int owns_world; /* the serial context: its world goes with it */
} local_be;

static local_world *world_of(const pdt_comm *c) { return ((const local_be *)c->be)->w; }

static pdt_status broken_err(const pdt_comm *c, int who, pdt_err *err)
{
    return pdt_err_set(err, PDT_ERR_MPI, "rank %d: rank %d failed, the job cannot go on", c->rank,
                       who);
}

static pdt_status local_barrier(pdt_comm *c, pdt_err *err)
{
    local_world *w = world_of(c);
    pthread_mutex_lock(&w->mu);
    unsigned long gen = w->gen;
    if (++w->arrived == w->P) {
        w->arrived = 0;
        w->gen++;
        pthread_cond_broadcast(&w->cv);
    }
    while (w->gen == gen && w->broken < 0) pthread_cond_wait(&w->cv, &w->mu);
    int who = w->gen == gen ? w->broken : -1;
    pthread_mutex_unlock(&w->mu);
    return who >= 0 ? broken_err(c, who, err) : PDT_OK;
}

/* Show p to the others and wait until every rank has shown its own. */
static pdt_status publish(pdt_comm *c, local_pub p, pdt_err *err)
{
    world_of(c)->pub[c->rank] = p;
    return local_barrier(c, err);
}

static const local_pub *pub_of(const pdt_comm *c, int rank) { return &world_of(c)->pub[rank]; }

/* The second meeting of a collective: keeps the first error. */
static pdt_status done(pdt_comm *c, pdt_status s, pdt_err *err)
{
    pdt_err e2 = {0};
    pdt_status b = local_barrier(c, s == PDT_OK ? err : &e2);
    return s != PDT_OK ? s : b;
}

static double local_wtime(const pdt_comm *c)
{
    (void)c;
    return pdt_seconds();
}

static pdt_status local_bcast(pdt_comm *c, void *buf, size_t bytes, int root, pdt_err *err)
{
    pdt_status s = publish(c, (local_pub){.a = buf, .n = bytes}, err);
    if (s != PDT_OK) return s;
    if (c->rank != root && bytes) {
        if (pub_of(c, root)->n != bytes)
            s = pdt_err_set(err, PDT_ERR_MPI, "rank %d: bcast: size mismatch", c->rank);
        else
            memcpy(buf, pub_of(c, root)->a, bytes);
    }
    return done(c, s, err);
}

static pdt_status local_allgather(pdt_comm *c, const void *send, size_t bytes, void *recv,
                                  pdt_err *err)
{
    pdt_status s = publish(c, (local_pub){.a = send, .n = bytes}, err);
    if (s != PDT_OK) return s;
    for (int i = 0; i < c->size && bytes; i++)
        memmove((char *)recv + (size_t)i * bytes, pub_of(c, i)->a, bytes);
    return done(c, s, err);
}

static pdt_status local_alltoall(pdt_comm *c, const void *send, size_t bytes, void *recv,
                                 pdt_err *err)
{
    pdt_status s = publish(c, (local_pub){.a = send, .n = bytes}, err);
    if (s != PDT_OK) return s;
    for (int i = 0; i < c->size && bytes; i++)
        memmove((char *)recv + (size_t)i * bytes,
                (const char *)pub_of(c, i)->a + (size_t)c->rank * bytes, bytes);
    return done(c, s, err);
}

/* Where rank `me`'s block starts in a sender's contiguous blocks. */
static size_t block_start(const size_t *count, int me)
{
    size_t off = 0;
    for (int k = 0; k < me; k++) off += count[k];
    return off;
}

static pdt_status local_alltoallv(pdt_comm *c, const void *send, const size_t *scount,
                                  void *recv, const size_t *rcount, pdt_err *err)
{
    pdt_status s = publish(c, (local_pub){.a = send, .counts = scount}, err);
    if (s != PDT_OK) return s;
    size_t ro = 0;
    for (int i = 0; i < c->size && s == PDT_OK; i++) {
        const local_pub *p = pub_of(c, i);
        if (p->counts[c->rank] != rcount[i])
            s = pdt_err_set(err, PDT_ERR_MPI, "rank %d: alltoallv: count mismatch with rank %d",
                            c->rank, i);
        else if (rcount[i])
            memmove((char *)recv + ro,
                    (const char *)p->a + block_start(p->counts, c->rank), rcount[i]);
        ro += rcount[i];
    }
    return done(c, s, err);
}

static pdt_status local_scatterv(pdt_comm *c, const void *send, const size_t *count, void *recv,
                                 size_t rbytes, int root, pdt_err *err)
{
    pdt_status s = publish(c, (local_pub){.a = send, .counts = count}, err);
    if (s != PDT_OK) return s;
    const local_pub *p = pub_of(c, root);
    if (p->counts[c->rank] != rbytes)
        s = pdt_err_set(err, PDT_ERR_MPI, "rank %d: scatterv: count mismatch", c->rank);
    else if (rbytes)
        memmove(recv, (const char *)p->a + block_start(p->counts, c->rank), rbytes);
    return done(c, s, err);
}

static pdt_status local_gatherv(pdt_comm *c, const void *send, size_t bytes, void *recv,
                                const size_t *count, int root, pdt_err *err)
{
    pdt_status s = publish(c, (local_pub){.a = send, .n = bytes}, err);
    if (s != PDT_OK) return s;
    size_t off = 0;
    for (int i = 0; c->rank == root && i < c->size && s == PDT_OK; i++) {
        const local_pub *p = pub_of(c, i);
        if (p->n != count[i])
            s = pdt_err_set(err, PDT_ERR_MPI, "rank %d: gatherv: count mismatch with rank %d",
                            c->rank, i);
        else if (count[i])
            memmove((char *)recv + off, p->a, count[i]);
        off += count[i];
    }
    return done(c, s, err);
}

static pdt_status local_allmax(pdt_comm *c, double *v, int n, pdt_err *err)
{
    double *r = malloc((n > 0 ? (size_t)n : 1) * sizeof *r);
    pdt_status s = publish(c, (local_pub){.a = v}, err);
    if (s != PDT_OK) {
        free(r);
        return s;
    }
    if (!r) s = pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: allmax: out of memory", c->rank);
    for (int j = 0; s == PDT_OK && j < n; j++) {
        r[j] = v[j];
        for (int i = 0; i < c->size; i++) {
            double x = ((const double *)pub_of(c, i)->a)[j];
            if (x > r[j]) r[j] = x;
        }
    }
    s = done(c, s, err);
    if (s == PDT_OK && n > 0) memcpy(v, r, (size_t)n * sizeof *r);
    free(r);
    return s;
}

static pdt_status local_allreduce_u64(pdt_comm *c, uint64_t *v, size_t n, pdt_comm_op op,
                                      pdt_err *err)
{
    uint64_t *r = malloc((n ? n : 1) * sizeof *r);
    pdt_status s = publish(c, (local_pub){.a = v, .n = n}, err);
    if (s != PDT_OK) {
        free(r);
        return s;
    }
    if (!r) s = pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: allreduce: out of memory", c->rank);
    for (size_t j = 0; s == PDT_OK && j < n; j++) {
        uint64_t acc = ((const uint64_t *)pub_of(c, 0)->a)[j];
        for (int i = 1; i < c->size; i++) {
            uint64_t x = ((const uint64_t *)pub_of(c, i)->a)[j];
            acc = op == PDT_COMM_SUM ? acc + x
                : op == PDT_COMM_MAX ? (x > acc ? x : acc)
                                     : (x < acc ? x : acc);
        }
        r[j] = acc;
    }
    s = done(c, s, err);
    if (s == PDT_OK && n) memcpy(v, r, n * sizeof *r);
    free(r);
    return s;
}

static pdt_status local_exscan_u64(pdt_comm *c, uint64_t v, uint64_t *out, pdt_err *err)
{
    *out = 0;
    pdt_status s = publish(c, (local_pub){.a = &v}, err);
    if (s != PDT_OK) return s;
    uint64_t acc = 0;
    for (int i = 0; i < c->rank; i++) acc += *(const uint64_t *)pub_of(c, i)->a;
    s = done(c, s, err);
    if (s == PDT_OK) *out = acc;
    return s;
}

static pdt_status local_send(pdt_comm *c, int peer, int tag, const void *buf, size_t bytes,
                             pdt_err *err)
{
    local_msg *m = malloc(sizeof *m);
    char *d = malloc(bytes ? bytes : 1);
    if (!m || !d) {
        free(m);
        free(d);
        return pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: send: out of memory", c->rank);
    }
    if (bytes) memcpy(d, buf, bytes);
    *m = (local_msg){.from = c->rank, .tag = tag, .bytes = bytes, .data = d};
    local_world *w = world_of(c);
    pthread_mutex_lock(&w->mu);
    local_msg **end = &w->box[peer];
    while (*end) end = &(*end)->next;
    *end = m;
    pthread_cond_broadcast(&w->cv);
    pthread_mutex_unlock(&w->mu);
    return PDT_OK;
}

static pdt_status local_recv(pdt_comm *c, int peer, int tag, void **buf, size_t *bytes,
                             pdt_err *err)
{
    local_world *w = world_of(c);
    pthread_mutex_lock(&w->mu);
    local_msg *m = NULL;
    for (;;) {
        local_msg **p = &w->box[c->rank];
        while (*p && ((*p)->from != peer || (*p)->tag != tag)) p = &(*p)->next;
        if (*p) {
            m = *p;
            *p = m->next;
            break;
        }
        if (w->broken >= 0) break;
        pthread_cond_wait(&w->cv, &w->mu);
    }
    int who = w->broken;
    pthread_mutex_unlock(&w->mu);
    if (!m) return broken_err(c, who, err);
    *buf = m->data;
    *bytes = m->bytes;
    free(m);
    return PDT_OK;
}

/* ---- one file: rank 0 opens it, every rank writes with pwrite ---------------- */

static pdt_status local_file_open(pdt_comm *c, pdt_comm_file *f, pdt_err *err)
{
    int *fd = malloc(sizeof *fd);
    pdt_status s = PDT_OK;
    local_pub me = {.fd = -1};
    if (c->rank == 0) {
        me.fd = open(f->path, O_WRONLY | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (me.fd >= 0 && ftruncate(me.fd, (off_t)f->size) != 0) {
            int e = errno;
            close(me.fd);
            me.fd = -1;
            errno = e;
        }
        me.err = me.fd < 0 ? errno : 0;
    }
    s = publish(c, me, err);
    if (s != PDT_OK) {
        if (me.fd >= 0) close(me.fd);
        free(fd);
        return s;
    }
    const local_pub *p0 = pub_of(c, 0);
    int shared = p0->fd, e = p0->err;
    s = done(c, s, err);
    if (s == PDT_OK && shared < 0)
        s = pdt_err_set(err, PDT_ERR_IO, "%s: cannot create: %s", f->path, strerror(e));
    if (s == PDT_OK && !fd)
        s = pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: %s: out of memory", c->rank, f->path);
    s = pdt_comm_agree(c, s, f->path, "create", err);
    if (s != PDT_OK) {
        if (c->rank == 0 && shared >= 0) close(shared);
        free(fd);
        return s;
    }
    *fd = shared;
    f->be = fd;
    return PDT_OK;
}

static pdt_status local_file_write_at(pdt_comm_file *f, uint64_t offset, const void *buf,
                                      size_t bytes, pdt_err *err)
{
    int fd = *(int *)f->be;
    const char *b = buf;
    size_t n = 0;
    pdt_status s = PDT_OK;
    while (n < bytes && s == PDT_OK) {
        size_t len = bytes - n < f->c->chunk ? bytes - n : f->c->chunk;
        ssize_t w = pwrite(fd, b + n, len, (off_t)(offset + n));
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0)
            s = pdt_err_set(err, PDT_ERR_IO, "%s: write failed: %s", f->path,
                            w < 0 ? strerror(errno) : "no progress");
        else
            n += (size_t)w;
    }
    return s;
}

static pdt_status local_file_close(pdt_comm_file *f, pdt_err *err)
{
    pdt_comm *c = f->c;
    int fd = *(int *)f->be;
    free(f->be);
    pdt_status s = local_barrier(c, err); /* every rank has written */
    if (s == PDT_OK && c->rank == 0 && close(fd) != 0)
        s = pdt_err_set(err, PDT_ERR_IO, "%s: close failed: %s", f->path, strerror(errno));
    return s;
}

static void world_free(local_world *w);

static void local_finalize(pdt_comm *c)
{
    local_be *b = c->be;
    if (b->owns_world) world_free(b->w);
    free(b);
}

static const pdt_comm_ops local_ops = {
    .is_mpi = 0,
    .finalize = local_finalize,
    .wtime = local_wtime,
    .barrier = local_barrier,
    .quiet_barrier = local_barrier, /* waiting threads sleep on the condition */
    .bcast = local_bcast,
    .allgather = local_allgather,
    .alltoall = local_alltoall,
    .alltoallv = local_alltoallv,
    .scatterv = local_scatterv,
    .gatherv = local_gatherv,
    .allmax = local_allmax,
    .allreduce_u64 = local_allreduce_u64,
    .exscan_u64 = local_exscan_u64,
    .send = local_send,
    .recv = local_recv,
    .file_open = local_file_open,
    .file_write_at = local_file_write_at,
    .file_close = local_file_close,
};

/* ---- worlds ------------------------------------------------------------------ */

static void world_free(local_world *w)
{
    if (!w) return;
    for (int i = 0; w->box && i < w->P; i++)
        while (w->box[i]) {
            local_msg *m = w->box[i];
            w->box[i] = m->next;
            free(m->data);
            free(m);
        }
    pthread_mutex_destroy(&w->mu);
    pthread_cond_destroy(&w->cv);
    free(w->pub);
    free(w->box);
    free(w);
}

static local_world *world_new(int P)
{
    local_world *w = calloc(1, sizeof *w);
    if (!w) return NULL;
    w->P = P;
    w->broken = -1;
    pthread_mutex_init(&w->mu, NULL);
    pthread_cond_init(&w->cv, NULL);
    w->pub = calloc((size_t)P, sizeof *w->pub);
    w->box = calloc((size_t)P, sizeof *w->box);
    if (!w->pub || !w->box) {
        world_free(w);
        return NULL;
    }
    return w;
}

/* A rank's context in world w (c->be owned by c; the world is not). */
static pdt_comm *rank_new(local_world *w, int rank)
{
    pdt_comm *c = calloc(1, sizeof *c);
    local_be *b = calloc(1, sizeof *b);
    if (!c || !b) {
        free(c);
        free(b);
        return NULL;
    }
    b->w = w;
    c->ops = &local_ops;
    c->be = b;
    c->rank = rank;
    c->size = w->P;
    c->node_size = w->P; /* the ranks are threads of this process */
    c->chunk = pdt_comm_chunk_from_env();
    if (gethostname(c->host, sizeof c->host - 1) != 0) strcpy(c->host, "?");
    return c;
}

pdt_status pdt_comm_serial_new(pdt_comm **out, pdt_err *err)
{
    *out = NULL;
    local_world *w = world_new(1);
    pdt_comm *c = w ? rank_new(w, 0) : NULL;
    if (!c) {
        world_free(w);
        return pdt_err_set(err, PDT_ERR_NOMEM, "comm: out of memory");
    }
    ((local_be *)c->be)->owns_world = 1;
    *out = c;
    return PDT_OK;
}

typedef struct local_job {
    pdt_comm *c;
    pdt_comm_rank_fn fn;
    void *arg;
    pdt_err err;
    pdt_status status;
} local_job;

static void *rank_main(void *p)
{
    local_job *j = p;
    j->status = j->fn(j->c, j->arg, &j->err);
    if (j->status != PDT_OK) {
        local_world *w = world_of(j->c);
        pthread_mutex_lock(&w->mu);
        if (w->broken < 0) w->broken = j->c->rank;
        pthread_cond_broadcast(&w->cv);
        pthread_mutex_unlock(&w->mu);
    }
    return NULL;
}

pdt_status pdt_comm_local_run(int nranks, pdt_comm_rank_fn fn, void *arg, pdt_err *err)
{
    if (nranks < 1) return pdt_err_set(err, PDT_ERR_ARG, "local run: %d ranks", nranks);
    local_world *w = world_new(nranks);
    local_job *jobs = calloc((size_t)nranks, sizeof *jobs);
    pthread_t *th = calloc((size_t)nranks, sizeof *th);
    int made = 0;
    pdt_status s = w && jobs && th ? PDT_OK : PDT_ERR_NOMEM;
    for (int r = 0; s == PDT_OK && r < nranks; r++) {
        jobs[r] = (local_job){.c = rank_new(w, r), .fn = fn, .arg = arg};
        if (!jobs[r].c) s = PDT_ERR_NOMEM;
    }
    int rc = 0;
    for (; s == PDT_OK && made < nranks; made++)
        if ((rc = pthread_create(&th[made], NULL, rank_main, &jobs[made])) != 0) s = PDT_ERR_MPI;
    if (s != PDT_OK && made > 0) { /* the started ranks wait for the missing ones: break */
        pthread_mutex_lock(&w->mu);
        w->broken = made;
        pthread_cond_broadcast(&w->cv);
        pthread_mutex_unlock(&w->mu);
    }
    for (int r = 0; r < made; r++) pthread_join(th[r], NULL);
    if (s == PDT_ERR_NOMEM) pdt_err_set(err, s, "local run: out of memory");
    if (s == PDT_ERR_MPI) pdt_err_set(err, s, "local run: cannot start rank %d: %s", made,
                                      strerror(rc));
    /* the failing rank's own message, lowest rank first */
    for (int r = 0; s == PDT_OK && r < nranks; r++)
        if (jobs[r].status != PDT_OK && w->broken == r) {
            s = jobs[r].status;
            *err = jobs[r].err;
        }
    for (int r = 0; s == PDT_OK && r < nranks; r++)
        if (jobs[r].status != PDT_OK) {
            s = jobs[r].status;
            *err = jobs[r].err;
        }
    for (int r = 0; jobs && r < nranks; r++)
        if (jobs[r].c) pdt_comm_finalize(jobs[r].c, NULL);
    free(jobs);
    free(th);
    world_free(w);
    return s;
}
