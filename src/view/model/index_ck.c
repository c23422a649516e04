/* pdt — the kept index's checkpoints (S_CKPT), written while the other
 * tables are: a thread steps one state forwards through the run from
 * cursor 0 and, at every r->ick_every-th cursor, the state goes to the
 * index (each checkpoint holding the triangles born before its cursor).
 *
 * Stepping takes that thread a core; writing the states (hundreds of
 * megabytes for a run of 10^7 points) took it as long again while the
 * thread that writes the tables had finished and waited.  So when two
 * copies of a state fit a quarter of the budget, the stepping thread
 * copies each checkpoint into one of two buffers and goes on, and the
 * calling thread, its own tables written, writes the copies in order
 * (pdt_ix_ck_finish).  Otherwise the stepping thread writes each state
 * itself, as it goes (a paged state's pages given back behind it).
 * Private to src/view/model. */
#include "pdt/view/replay.h"
#include "replay_int.h"
#include "index_int.h"
#include "scratch_int.h"
#include "pdt/tmpfile.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

typedef struct ck_copy {
    uint8_t *buf;
    size_t cap, bytes;
    uint64_t at;  /* where in the index */
} ck_copy;

struct ck_job {
    pdt_replay *r;
    int fd;
    uint64_t off;     /* the section's place */
    crcacc crc;       /* its chunk checksums, fed in the order written */
    pthread_t th;
    int threaded;
    int handoff;      /* the stepping thread copies, the calling thread writes */
    pthread_mutex_t mu;
    pthread_cond_t cv;
    ck_copy copy[2];  /* checkpoint c in copy[c % 2] */
    size_t made;      /* checkpoints copied (handing off) */
    size_t written;   /* ... written */
    int done;         /* the stepping thread is done */
    int failed;       /* a step, a copy or a write failed (errno in err): both stop */
    int err;
};

static void fail(ck_job *j, int e)
{
    pthread_mutex_lock(&j->mu);
    if (!j->failed) j->err = e;
    j->failed = 1;
    pthread_cond_broadcast(&j->cv);
    pthread_mutex_unlock(&j->mu);
}

static int fd_get(void *ctx, uint64_t at, void *p, size_t bytes)
{
    return pdt_pread_all(*(const int *)ctx, at, p, bytes);
}

/* Write the state's blob (its parts, each followed by its zero padding) at
 * `at` as it is (the stepping thread, without a handoff). */
static int write_parts(ck_job *j, const pdt_rstate *s, const void *part[5], const size_t len[5],
                       const size_t pad[5], uint64_t at)
{
    static const uint8_t zeros[8];
    for (int p = 0; p < 5; p++) {
        for (size_t o = 0; o < len[p]; o += CHUNK_BYTES) { /* (a paged state's pages go back) */
            size_t k = len[p] - o < CHUNK_BYTES ? len[p] - o : CHUNK_BYTES;
            if (!pdt_pwrite_all(j->fd, (const char *)part[p] + o, k, at + o)) return 0;
            pdt_ix_crc_feed(&j->crc, (const char *)part[p] + o, k);
            pdt_replay_give_back(j->r, s);
        }
        if (!pdt_pwrite_all(j->fd, zeros, pad[p], at + len[p])) return 0;
        pdt_ix_crc_feed(&j->crc, zeros, pad[p]);
        at += len[p] + pad[p];
    }
    return 1;
}

/* Copy checkpoint c's blob into its buffer, once the calling thread has
 * written what that buffer held, and hand it over.  0 when either failed. */
static int hand_over(ck_job *j, size_t c, const void *part[5], const size_t len[5],
                     const size_t pad[5], size_t bytes, uint64_t at)
{
    pthread_mutex_lock(&j->mu);
    while (!j->failed && j->written + 2 <= c) pthread_cond_wait(&j->cv, &j->mu);
    int failed = j->failed;
    pthread_mutex_unlock(&j->mu);
    if (failed) return 0;
    ck_copy *cp = &j->copy[c % 2];
    if (cp->cap < bytes) {
        uint8_t *grown = realloc(cp->buf, bytes);
        if (!grown) return errno = ENOMEM, 0;
        cp->buf = grown;
        cp->cap = bytes;
    }
    size_t o = 0;
    for (int p = 0; p < 5; p++) {
        memcpy(cp->buf + o, part[p], len[p]);
        memset(cp->buf + o + len[p], 0, pad[p]);
        o += len[p] + pad[p];
    }
    cp->bytes = o;
    cp->at = at;
    pthread_mutex_lock(&j->mu);
    j->made = c + 1;
    pthread_cond_broadcast(&j->cv);
    pthread_mutex_unlock(&j->mu);
    return 1;
}

/* The stepping thread: every checkpoint's state, written or handed over;
 * r->ick_off and r->ick_born set.  Memory: one state (and the copies). */
static void *ck_step(void *arg)
{
    ck_job *j = arg;
    pdt_replay *r = j->r;
    pdt_rstate *s = r->nick ? pdt_rstate_new(r) : NULL;
    pdt_fwd *fw = r->nick ? pdt_fwd_new(r, fd_get, &j->fd) : NULL;
    int ok = !r->nick || (s && fw);
    if (!ok) errno = ENOMEM;
    r->ick_off[0] = 0;
    for (size_t c = 0; ok && c < r->nick; c++) {
        ok = pdt_fwd_to(fw, s, c * r->ick_every);
        size_t born = pdt_rstate_born(r, s), bytes = pdt_rstate_blob_bytes(r, born);
        const void *part[5];
        size_t len[5], pad[5];
        uint64_t at = j->off + r->ick_off[c];
        pdt_rstate_blob_parts(r, s, born, part, len, pad);
        ok = ok && (j->handoff ? hand_over(j, c, part, len, pad, bytes, at)
                               : write_parts(j, s, part, len, pad, at));
        r->ick_born[c] = born;
        r->ick_off[c + 1] = r->ick_off[c] + bytes;
    }
    if (!ok) fail(j, errno ? errno : EIO);
    pdt_fwd_free(fw);
    pdt_rstate_free(s);
    pthread_mutex_lock(&j->mu);
    j->done = 1;
    pthread_cond_broadcast(&j->cv);
    pthread_mutex_unlock(&j->mu);
    return NULL;
}

ck_job *pdt_ix_ck_start(pdt_replay *r, int fd, uint64_t off)
{
    ck_job *j = calloc(1, sizeof *j);
    if (!j) return NULL;
    j->r = r;
    j->fd = fd;
    j->off = off;
    pthread_mutex_init(&j->mu, NULL);
    pthread_cond_init(&j->cv, NULL);
    size_t most = pdt_rstate_blob_bytes(r, r->ntri);  /* (a checkpoint's most) */
    j->handoff = r->nick && !r->state_paged &&
                 (!r->mem_budget || 2 * (uint64_t)most <= r->mem_budget / 4);
    j->threaded = pthread_create(&j->th, NULL, ck_step, j) == 0;
    if (!j->threaded) j->handoff = 0;  /* (the calling thread steps: pdt_ix_ck_finish) */
    return j;
}

/* The calling thread's part of a handoff: each copy written in turn, its
 * checksums fed, until the stepping thread is done or either failed. */
static void write_copies(ck_job *j)
{
    for (size_t c = 0;; c++) {
        pthread_mutex_lock(&j->mu);
        while (!j->failed && !j->done && j->made <= c) pthread_cond_wait(&j->cv, &j->mu);
        int more = !j->failed && j->made > c;
        pthread_mutex_unlock(&j->mu);
        if (!more) return;
        const ck_copy *cp = &j->copy[c % 2];
        if (!pdt_pwrite_all(j->fd, cp->buf, cp->bytes, cp->at)) {
            fail(j, errno);
            return;
        }
        pdt_ix_crc_feed(&j->crc, cp->buf, cp->bytes);
        pthread_mutex_lock(&j->mu);
        j->written = c + 1;
        pthread_cond_broadcast(&j->cv);
        pthread_mutex_unlock(&j->mu);
    }
}

int pdt_ix_ck_finish(ck_job *j, crcacc *crc, uint64_t *copy_bytes)
{
    if (!j) return errno = ENOMEM, 0;
    if (j->threaded) {
        if (j->handoff) write_copies(j);
        pthread_join(j->th, NULL);
    } else {
        ck_step(j);
    }
    *crc = j->crc;
    *copy_bytes = j->copy[0].cap + j->copy[1].cap;
    int ok = !j->failed;
    if (!ok) errno = j->err;
    free(j->copy[0].buf);
    free(j->copy[1].buf);
    pthread_mutex_destroy(&j->mu);
    pthread_cond_destroy(&j->cv);
    free(j);
    return ok;
}
