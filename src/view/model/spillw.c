/* pdt — the streamed build's spill writer: pass 1's full bucket buffers
 * written to the spill by a thread of its own.
 *
 * Pass 1 hands each fine bucket's records to the spill a buffer at a time
 * (pdt_rp_fine_flush).  The pass is paced by the thread that handles the
 * events; the thread that decodes them waits for it part of the time.  So
 * the writes (system calls copying gigabytes into the page cache) go to a
 * writer thread: a full buffer is queued and the bucket goes on in a spare
 * one, which the writer gives back once it has written it.  The writer
 * takes the queue in order, so the spill and its chunk log are what the
 * handler would have written itself; nothing reads them before
 * pdt_rp_sw_stop.  Private to src/view/model. */
#include "pdt/view/replay.h"
#include "replay_int.h"
#include "build_int.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>

#define SW_SPARE 32u /* buffers besides the buckets' own: the most queued at once */

typedef struct sw_item {
    tri_xrec *buf;
    size_t f, n;
} sw_item;

struct spill_writer {
    builder *b;
    pthread_t th;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    sw_item q[SW_SPARE];   /* queued buffers, from head (a ring) */
    size_t head, nq;
    tri_xrec *spare[SW_SPARE];  /* buffers free for a bucket */
    size_t nspare;
    tri_xrec *block;       /* the spares' memory */
    int stop;
    int err;               /* errno of a failed write */
};

static void *sw_thread(void *arg)
{
    spill_writer *w = arg;
    builder *b = w->b;
    for (;;) {
        pthread_mutex_lock(&w->mu);
        while (!w->nq && !w->stop) pthread_cond_wait(&w->cv, &w->mu);
        if (!w->nq) {
            pthread_mutex_unlock(&w->mu);
            return NULL;
        }
        sw_item it = w->q[w->head];
        pthread_mutex_unlock(&w->mu);
        if (!b->failed &&
            !pdt_rp_spill_put(b, PDT_SCR_SPILL, &b->tlog, it.buf, it.n, sizeof(tri_xrec), it.f))
        {
            b->failed = 1; /* (the handler sees it at its next buffer) */
            w->err = errno;
        }
        pthread_mutex_lock(&w->mu);
        w->head = (w->head + 1) % SW_SPARE;
        w->nq--;
        w->spare[w->nspare++] = it.buf;
        pthread_cond_broadcast(&w->cv);
        pthread_mutex_unlock(&w->mu);
    }
}

/* The writer for builder b (streamed, its buckets' buffers made): each
 * bucket's buffer is then b->fcur[f].  1, or 0 when out of memory.  When no
 * thread can be made, b->sw stays NULL and pdt_rp_fine_flush writes itself. */
int pdt_rp_sw_start(builder *b)
{
    b->fcur = malloc(b->nfine * sizeof *b->fcur);
    if (!b->fcur) return 0;
    for (size_t f = 0; f < b->nfine; f++) b->fcur[f] = b->fbuf + f * b->fbuf_recs;
    spill_writer *w = calloc(1, sizeof *w);
    if (!w) return 0;
    w->b = b;
    w->block = pdt_rp_bmalloc(b, SW_SPARE * b->fbuf_recs * sizeof *w->block);
    if (!w->block) {
        free(w);
        return 0;
    }
    for (size_t k = 0; k < SW_SPARE; k++) w->spare[w->nspare++] = w->block + k * b->fbuf_recs;
    pthread_mutex_init(&w->mu, NULL);
    pthread_cond_init(&w->cv, NULL);
    if (pthread_create(&w->th, NULL, sw_thread, w) != 0) {
        pthread_mutex_destroy(&w->mu);
        pthread_cond_destroy(&w->cv);
        pdt_rp_bfree(b, w->block, SW_SPARE * b->fbuf_recs * sizeof *w->block);
        free(w);
        return 1;
    }
    b->sw = w;
    b->sw_live = 1;
    return 1;
}

/* Bucket f's full buffer (n records) to the writer's queue, and a spare
 * one for the bucket (waiting for the writer when none is free). */
void pdt_rp_sw_queue(builder *b, size_t f, size_t n)
{
    spill_writer *w = b->sw;
    pthread_mutex_lock(&w->mu);
    while (!w->nspare) pthread_cond_wait(&w->cv, &w->mu);
    w->q[(w->head + w->nq++) % SW_SPARE] = (sw_item){b->fcur[f], f, n};
    b->fcur[f] = w->spare[--w->nspare];
    pthread_cond_broadcast(&w->cv);
    pthread_mutex_unlock(&w->mu);
}

/* Everything queued written, the writer ended (the buckets' buffers stay
 * where b->fcur says, until pdt_rp_sw_free). */
void pdt_rp_sw_stop(builder *b)
{
    spill_writer *w = b->sw;
    if (!w || !b->sw_live) return;
    b->sw_live = 0;
    pthread_mutex_lock(&w->mu);
    w->stop = 1;
    pthread_cond_broadcast(&w->cv);
    pthread_mutex_unlock(&w->mu);
    pthread_join(w->th, NULL);
    if (w->err) errno = w->err; /* (for the build's message) */
}

/* The writer stopped (if it runs) and its buffers freed, with b->fcur. */
void pdt_rp_sw_free(builder *b)
{
    spill_writer *w = b->sw;
    if (w) {
        pdt_rp_sw_stop(b);
        pthread_mutex_destroy(&w->mu);
        pthread_cond_destroy(&w->cv);
        pdt_rp_bfree(b, w->block, SW_SPARE * b->fbuf_recs * sizeof *w->block);
        free(w);
        b->sw = NULL;
    }
    free(b->fcur);
    b->fcur = NULL;
}
