/* pdt — the kept index: building it at a run's first opening, and opening a
 * run (from its kept index, building one, or in memory).  The file's layout
 * is in index_int.h. */
#include "pdt/safefile.h"
#include "pdt/io.h"
#include "pdt/view/replay.h"
#include "replay_int.h"
#include "index_int.h"
#include "scratch_int.h"
#include "pdt/tmpfile.h"
#include "pdt/testhook.h"
#include "pdt/bigmem.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

uint32_t pdt_ix_ihdr_crc(const ihdr *h)
{
    ihdr c = *h;
    c.hdr_crc = 0;
    return pdt_crc32c(0, &c, sizeof c);
}

/* ---- building ------------------------------------------------------------------ */

/* The events of a build: the merged order as segments (S_SEGS), and the
 * tables that find a block of a rank file (held here until write_tables
 * writes them). */
typedef struct evcopy {
    pdt_evsrc src;           /* over the reader's mappings and S_SEGS, once written */
    pdt_block_ref *blk;      /* src.blk */
    uint64_t *rank_blk;      /* src.rank_blk */
    crcacc segs_crc;
} evcopy;

/* The table of every rank's intact blocks (where each payload is in its
 * file, its aligned time base), and the source decoding them from the
 * reader's mappings of the rank files. */
static pdt_status block_table(pdt_run *run, evcopy *ec, pdt_err *err)
{
    int nranks = pdt_run_nranks(run);
    size_t nblk = 0;
    for (int q = 0; q < nranks; q++) {
        const pdt_block_ref *b;
        const uint8_t *file;
        int64_t shift;
        nblk += pdt_run_rank_blocks(run, q, &b, &file, &shift);
    }
    ec->blk = malloc((nblk ? nblk : 1) * sizeof *ec->blk);
    ec->rank_blk = malloc(((size_t)nranks + 1) * sizeof *ec->rank_blk);
    ec->src.file = calloc((size_t)nranks + 1, sizeof *ec->src.file);
    ec->src.file_len = calloc((size_t)nranks + 1, sizeof *ec->src.file_len);
    if (!ec->blk || !ec->rank_blk || !ec->src.file || !ec->src.file_len)
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    size_t k = 0;
    for (int q = 0; q < nranks; q++) {
        const pdt_block_ref *b;
        const uint8_t *file;
        int64_t shift;
        size_t nb = pdt_run_rank_blocks(run, q, &b, &file, &shift);
        pdt_rank_info ri;
        pdt_run_rank_info(run, q, &ri);
        ec->rank_blk[q] = k;
        ec->src.file[q] = file;
        ec->src.file_len[q] = file ? ri.bytes : 0;
        for (size_t j = 0; j < nb; j++, k++)
            ec->blk[k] = (pdt_block_ref){b[j].off + PDT_BLOCK_HEADER_BYTES, b[j].first,
                                         b[j].base_t + (uint64_t)shift, b[j].len, b[j].count};
    }
    ec->rank_blk[nranks] = k;
    ec->src.nblk = nblk;
    ec->src.nranks = nranks;
    return PDT_OK;
}

/* The merged order of run, streamed to the build (pass 1) by the reader's
 * merge (one decoded block per rank in memory), and written as it goes
 * into fd after the blocks as segments (S_SEGS).  At its end the blocks and
 * segments are mapped, and ec->src decodes the events from there. */
typedef struct evstream {
    pdt_merge *mg;
    int fd;
    ihdr *h;
    evcopy *ec;
    uint64_t at, off;     /* S_SEGS: where it starts, where the next batch goes */
    pdt_evseg cur, *buf;  /* the segment being made; a batch of finished ones */
    size_t nb, count, nseg;
    void *map;            /* at the end: [0, the end of S_SEGS) of the file */
    size_t map_len;
    uint64_t *place_off;  /* the placer's start: after S_SEGS */
    int done;
} evstream;

enum { SEG_BATCH = 8192 };

static int seg_flush(evstream *es, pdt_err *err)
{
    if (!es->nb) return 1;
    if (!pdt_pwrite_all(es->fd, es->buf, es->nb * sizeof *es->buf, es->off)) {
        pdt_err_set(err, PDT_ERR_IO, "writing the index: %s", strerror(errno));
        return 0;
    }
    pdt_ix_crc_feed(&es->ec->segs_crc, es->buf, es->nb * sizeof *es->buf);
    es->off += es->nb * sizeof *es->buf;
    es->nseg += es->nb;
    es->nb = 0;
    return 1;
}

/* The last segment out, the section's place, the mapping for ec->src. */
static int stream_finish(evstream *es, pdt_err *err)
{
    if (es->cur.rank != UINT32_MAX) es->buf[es->nb++] = es->cur;
    if (!seg_flush(es, err)) return 0;
    es->h->sec[S_SEGS] = (isec){es->at, (uint64_t)es->nseg * sizeof(pdt_evseg), 0, 0};
    es->h->count[S_SEGS] = es->nseg;
    es->map_len = (size_t)es->off;
    es->map = mmap(NULL, es->map_len, PROT_READ, MAP_SHARED, es->fd, 0);
    if (es->map == MAP_FAILED) {
        es->map = NULL;
        pdt_err_set(err, PDT_ERR_IO, "mapping the index: %s", strerror(errno));
        return 0;
    }
    pdt_evsrc *src = &es->ec->src;
    src->blk = es->ec->blk;
    src->rank_blk = es->ec->rank_blk;
    src->seg = (const pdt_evseg *)(void *)((const char *)es->map + es->at);
    src->nseg = es->nseg;
    src->m = es->count;
    src->drop_behind = 1;
    *es->place_off = es->off;
    return 1;
}

static int stream_fill(evstream *es, pdt_rec *out, size_t max, pdt_err *err)
{
    size_t j = 0;
    while (!es->done && j < max) {
        int got = pdt_merge_fill(es->mg, out + j, max - j, err);
        if (got < 0) return -1;
        if (got == 0) {
            es->done = 1;
            if (!stream_finish(es, err)) return -1;
            break;
        }
        for (size_t end = j + (size_t)got; j < end; j++) {
            const pdt_rec *rec = &out[j];
            if (rec->rank != es->cur.rank || rec->seq - es->cur.seq0 != es->count - es->cur.start) {
                if (es->cur.rank != UINT32_MAX) {
                    es->buf[es->nb++] = es->cur;
                    if (es->nb == SEG_BATCH && !seg_flush(es, err)) return -1;
                }
                es->cur = (pdt_evseg){(uint32_t)es->count, rec->rank, rec->seq};
            }
            es->count++;
        }
    }
    return (int)j;
}

/* The merge (decoding the rank files, the busier half of the build's first
 * pass) runs in a thread of its own, a batch of events ahead of the build:
 * two batches, one filled while the other is read. */
enum { PIPE_BATCH = 8192 };

typedef struct evpipe {
    evstream *es;
    pthread_t th;
    int started;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    pdt_rec *buf[2];
    size_t n[2];
    int full[2];      /* filled, not yet read */
    int last[2];      /* the stream ends after this batch (n may be 0) */
    int failed[2];    /* the stream failed filling it (perr) */
    int stop;         /* the reader is gone: stop filling */
    pdt_err perr;
    size_t slot, at;  /* the reader's batch and place in it */
    int ended;
} evpipe;

static void *pipe_worker(void *arg)
{
    evpipe *p = arg;
    for (size_t k = 0;; k ^= 1) {
        pthread_mutex_lock(&p->mu);
        while (p->full[k] && !p->stop) pthread_cond_wait(&p->cv, &p->mu);
        int stop = p->stop;
        pthread_mutex_unlock(&p->mu);
        if (stop) return NULL;
        int got = stream_fill(p->es, p->buf[k], PIPE_BATCH, &p->perr);
        pthread_mutex_lock(&p->mu);
        p->n[k] = got > 0 ? (size_t)got : 0;
        p->failed[k] = got < 0;
        p->last[k] = got <= 0 || p->es->done;
        p->full[k] = 1;
        int end = p->last[k];
        pthread_cond_broadcast(&p->cv);
        pthread_mutex_unlock(&p->mu);
        if (end) return NULL;
    }
}

static int stream_next(void *ctx, pdt_rec *out, size_t max, pdt_err *err)
{
    evpipe *p = *(evpipe **)ctx;
    size_t j = 0;
    while (j < max && !p->ended) {
        size_t k = p->slot;
        pthread_mutex_lock(&p->mu);
        while (!p->full[k]) pthread_cond_wait(&p->cv, &p->mu);
        pthread_mutex_unlock(&p->mu);
        if (p->failed[k]) {
            *err = p->perr;
            return -1;
        }
        size_t take = p->n[k] - p->at < max - j ? p->n[k] - p->at : max - j;
        memcpy(out + j, p->buf[k] + p->at, take * sizeof *out);
        j += take;
        p->at += take;
        if (p->at == p->n[k]) { /* give the batch back */
            if (p->last[k]) p->ended = 1;
            pthread_mutex_lock(&p->mu);
            p->full[k] = 0;
            pthread_cond_broadcast(&p->cv);
            pthread_mutex_unlock(&p->mu);
            p->slot ^= 1;
            p->at = 0;
        }
    }
    return (int)j;
}

/* Start the merge's thread: 1, or 0 and err set. */
static int pipe_start(evpipe *p, evstream *es, pdt_err *err)
{
    memset(p, 0, sizeof *p);
    p->es = es;
    p->buf[0] = malloc(PIPE_BATCH * sizeof *p->buf[0]);
    p->buf[1] = malloc(PIPE_BATCH * sizeof *p->buf[1]);
    if (!p->buf[0] || !p->buf[1]) {
        pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
        return 0;
    }
    pthread_mutex_init(&p->mu, NULL);
    pthread_cond_init(&p->cv, NULL);
    if (pthread_create(&p->th, NULL, pipe_worker, p) != 0) {
        pdt_err_set(err, PDT_ERR_NOMEM, "cannot start a thread: %s", strerror(errno));
        return 0;
    }
    p->started = 1;
    return 1;
}

/* Stop the merge's thread (wherever it is) and free the batches. */
static void pipe_stop(evpipe *p)
{
    if (p->started) {
        pthread_mutex_lock(&p->mu);
        p->stop = 1;
        pthread_cond_broadcast(&p->cv);
        pthread_mutex_unlock(&p->mu);
        pthread_join(p->th, NULL);
        pthread_mutex_destroy(&p->mu);
        pthread_cond_destroy(&p->cv);
    }
    free(p->buf[0]);
    free(p->buf[1]);
    p->started = 0;
}

/* The triangles and histories of a replay being built, streamed to the index
 * file itself (pdt_replay_place): written once, in place, by pwrite (not
 * through a shared mapping: on this file system page faults on a file being
 * written back wait for the disk), and never held in memory.  The triangle
 * events the build groups go to a spill of their own, and its other scratch
 * tables to theirs: in memory while their share of the budget has room,
 * beyond it in unnamed files beside the index, dropped once read
 * (scratch_int.h). */
typedef struct placer {
    struct evpipe *pipe; /* (first: the stream's context is the placer's) */
    int fd;
    uint64_t off;  /* where the next table goes */
    scr_set scr;   /* the scratch files */
    pdt_run *run;
} placer;

static uint64_t place_reserve(void *ctx, uint64_t bytes)
{
    placer *pc = ctx;
    uint64_t at = (pc->off + 63) & ~(uint64_t)63;
    pc->off = at + bytes;
    return at;
}

static int place_put(void *ctx, uint64_t at, const void *p, size_t bytes)
{
    return pdt_pwrite_all(((placer *)ctx)->fd, p, bytes, at);
}

static int place_get(void *ctx, uint64_t at, void *p, size_t bytes)
{
    return pdt_pread_all(((placer *)ctx)->fd, at, p, bytes);
}

static int scratch_put(void *ctx, int file, uint64_t at, const void *p, size_t bytes)
{
    return pdt_scr_put(&((placer *)ctx)->scr, file, at, p, bytes);
}

static int scratch_get(void *ctx, int file, uint64_t at, void *p, size_t bytes)
{
    return pdt_scr_get(&((placer *)ctx)->scr, file, at, p, bytes);
}

static void scratch_drop(void *ctx, int file) { pdt_scr_drop(&((placer *)ctx)->scr, file); }

static void points_read(void *ctx) { pdt_run_release_points(((placer *)ctx)->run); }

/* 1 if section i of a streamed replay was written by the build (at *at). */
static int streamed_sec(const pdt_replay *r, int i, uint64_t *at)
{
    if (!r->streamed) return 0;
    switch (i) {
    case S_TRIS: *at = r->tris_at; return 1;
    case S_HIST: *at = r->hist_at; return 1;
    case S_EVOBJ: *at = r->evobj_at; return 1;
    case S_EVKIND: *at = r->evkind_at; return 1;
    case S_LIFT: *at = r->lift_at; return 1;
    default: return 0;
    }
}

/* The places of the tables in the file from pc->off on (the checkpoints
 * last: their sizes are known once they are made); returns where the
 * checkpoints go. */
static uint64_t place_tables(pdt_replay *r, ihdr *h, const placer *pc, size_t elem[NSEC],
                             const uint64_t count[NSEC])
{
    uint64_t off = pc->off;
    for (int i = 0; i < NSEC; i++) {
        h->count[i] = count[i];
        if (i == S_SEGS || i == S_CKPT) continue; /* (S_SEGS: written first, stream_next) */
        uint64_t at;
        if (streamed_sec(r, i, &at)) {
            h->sec[i] = (isec){at, count[i] * elem[i], 0, 0};
            continue;
        }
        off = (off + 63) & ~(uint64_t)63;
        h->sec[i] = (isec){off, count[i] * elem[i], 0, 0};
        off += h->sec[i].bytes;
    }
    return (off + 63) & ~(uint64_t)63;
}

/* The chunk checksums (*tab, *n of them): of the tables in memory from
 * memory, of the records and checkpoints as they were written (ck_crc;
 * NULL: the checkpoints are not written yet, their section is empty), of
 * the streamed triangles and histories read back (pread, by up to four
 * threads). */
static pdt_status chunk_table(pdt_replay *r, int fd, const ihdr *h, const placer *pc,
                              void **ptr[NSEC], const evcopy *ec, const crcacc *ck_crc,
                              uint32_t **tab_out, uint64_t *n_out, pdt_err *err)
{
    uint64_t first[NSEC + 1], n = 0;
    for (int i = 0; i < NSEC; i++) first[i] = n, n += chunks_of(h->sec[i].bytes);
    first[NSEC] = n;
    uint32_t *tab = malloc(n ? n * sizeof *tab : 1);
    uint8_t *todo = calloc(n ? n : 1, 1);
    int have = tab && todo;
    for (int i = 0; have && i < NSEC; i++) {
        uint64_t nc = chunks_of(h->sec[i].bytes), at;
        if (i == S_SEGS) {
            have = pdt_ix_crc_done(&ec->segs_crc, h->sec[i].bytes, tab + first[i]);
        } else if (i == S_CKPT) {
            have = !ck_crc || pdt_ix_crc_done(ck_crc, h->sec[i].bytes, tab + first[i]);
        } else if (streamed_sec(r, i, &at)) {
            memset(todo + first[i], 1, nc);
        } else {
            const char *p = *ptr[i];
            for (uint64_t c = 0; c < nc; c++) {
                uint64_t lo = c * CHUNK_BYTES, hi = lo + CHUNK_BYTES;
                if (hi > h->sec[i].bytes) hi = h->sec[i].bytes;
                tab[first[i] + c] = pdt_crc32c(0, p + lo, (size_t)(hi - lo));
                if (i == S_POINTS) pdt_run_release_points(pc->run);
                pdt_replay_tab_release(r, p + lo, (size_t)(hi - lo));
            }
        }
    }
    if (!have) {
        free(tab);
        free(todo);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory for the index's checksums");
    }
    verify_job j = {fd, h, tab, 1, todo, n, first, 0, 0};
    pdt_ix_run_job(&j);
    free(todo);
    if (atomic_load(&j.bad)) {
        free(tab);
        return pdt_err_set(err, PDT_ERR_IO, "reading the index back for its checksums failed");
    }
    *tab_out = tab;
    *n_out = n;
    return PDT_OK;
}

/* The header of the index of r (file_bytes long) into its first page. */
static pdt_status write_header(pdt_replay *r, int fd, ihdr *h, uint64_t ident, uint64_t file_bytes,
                               pdt_err *err)
{
    memcpy(h->magic, magic, sizeof magic);
    h->version = INDEX_VERSION;
    h->ident = ident;
    h->file_bytes = file_bytes;
    pdt_ix_layout_of(h->layout);
    h->n = r->n;
    h->m = r->m;
    h->skipped = r->skipped;
    h->nranks = (uint64_t)r->nranks;
    h->ick_every = r->ick_every;
    h->nick = r->nick;
    memcpy(h->ick_off, r->ick_off, sizeof h->ick_off);
    memcpy(h->ick_born, r->ick_born, sizeof h->ick_born);
    for (int k = 0; k < PDT_EV_KIND_COUNT; k++) h->kind_count[k] = r->kind_count[k];
    h->hdr_crc = pdt_ix_ihdr_crc(h);
    unsigned char page[HDR_BYTES];
    memset(page, 0, sizeof page);
    memcpy(page, h, sizeof *h);
    if (ftruncate(fd, (off_t)file_bytes) != 0 || !pdt_pwrite_all(fd, page, sizeof page, 0))
        return pdt_err_set(err, PDT_ERR_IO, "writing the index: %s", strerror(errno));
    return PDT_OK;
}

/* Write the tables held in memory (ptr) and make the chunk checksums of
 * every section but the checkpoints' (*tab, *n), while a second thread
 * writes the checkpoints at off (their checksums into *ck_crc: stepping
 * through the run takes a core).  The points are read in place from the
 * run: a chunk at a time, their pages given back behind, while the
 * checkpoints' state is held. */
static pdt_status write_sections(pdt_replay *r, int fd, const ihdr *h, const placer *pc,
                                 void **ptr[NSEC], uint64_t off, const evcopy *ec,
                                 crcacc *ck_crc, uint32_t **tab, uint64_t *n, pdt_err *err)
{
    ck_job *ck = pdt_ix_ck_start(r, fd, off);  /* (the checkpoints, stepped beside) */
    int wrote = 1;
    for (int i = 0; wrote && i < NSEC; i++) {
        uint64_t at;
        if (i == S_SEGS || i == S_CKPT || streamed_sec(r, i, &at)) continue;
        for (uint64_t o = 0; wrote && o < h->sec[i].bytes; o += CHUNK_BYTES) {
            uint64_t k = h->sec[i].bytes - o < CHUNK_BYTES ? h->sec[i].bytes - o : CHUNK_BYTES;
            wrote = pdt_pwrite_all(fd, (const char *)*ptr[i] + o, (size_t)k, h->sec[i].off + o);
            if (i == S_POINTS) pdt_run_release_points(pc->run);
            pdt_replay_tab_release(r, (const char *)*ptr[i] + o, (size_t)k);  /* (paged) */
        }
    }
    int werr = wrote ? 0 : errno;
    pdt_status st = wrote ? chunk_table(r, fd, h, pc, ptr, ec, NULL, tab, n, err) : PDT_OK;
    int ck_ok = pdt_ix_ck_finish(ck, ck_crc, &r->build_ck_bytes);
    if (!wrote || !ck_ok) {
        free(*tab);
        *tab = NULL;
        return pdt_err_set(err, PDT_ERR_IO, "writing the index: %s", strerror(werr ? werr : errno));
    }
    return st;
}

/* Write the tables of r after the records and the streamed ones (at pc->off),
 * then the chunk table and the header. */
static pdt_status write_tables(pdt_replay *r, int fd, ihdr *h, uint64_t ident, const placer *pc,
                               evcopy *ec, pdt_err *err)
{
    void **ptr[NSEC];
    size_t elem[NSEC];
    uint64_t count[NSEC];
    pdt_ix_sections(r, ptr, elem, count);
    uint64_t off = place_tables(r, h, pc, elem, count);
    crcacc ck_crc = {0};
    uint32_t *tab = NULL;
    uint64_t n = 0;
    pdt_status st = write_sections(r, fd, h, pc, ptr, off, ec, &ck_crc, &tab, &n, err);
    h->count[S_CKPT] = r->nick ? r->ick_off[r->nick] : 0;
    h->sec[S_CKPT] = (isec){off, h->count[S_CKPT], 0, 0};
    off += h->count[S_CKPT];
    if (st == PDT_OK) { /* (the checkpoints' chunks last: theirs is the last section) */
        uint64_t n0 = n;
        n += chunks_of(h->sec[S_CKPT].bytes);
        uint32_t *grown = realloc(tab, n ? n * sizeof *tab : 1);
        if (grown) tab = grown;
        if (!grown || !pdt_ix_crc_done(&ck_crc, h->sec[S_CKPT].bytes, tab + n0))
            st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory for the index's checksums");
    }
    free(ck_crc.crc);
    if (st != PDT_OK) {
        free(tab);
        return st;
    }
    off = (off + 63) & ~(uint64_t)63;
    h->ctab = (isec){off, n * sizeof *tab, pdt_crc32c(0, tab, (size_t)(n * sizeof *tab)), 0};
    int wrote = pdt_pwrite_all(fd, tab, (size_t)(n * sizeof *tab), off);
    free(tab);
    if (!wrote) return pdt_err_set(err, PDT_ERR_IO, "writing the index: %s", strerror(errno));
    return write_header(r, fd, h, ident, off + h->ctab.bytes, err);
}

/* The events of the run's ranks. */
static size_t run_events(pdt_run *run, int nranks)
{
    uint64_t events = 0;
    for (int q = 0; q < nranks; q++) {
        pdt_rank_info ri;
        pdt_run_rank_info(run, q, &ri);
        events += ri.events;
    }
    return (size_t)events;
}

/* Where the index's checkpoints go: every m/ICK_PARTS events or more often
 * for a long run (ICK_MAX_EVERY), within ICK_MAX_PARTS; their state paged
 * beyond a quarter of the budget, as a replay's is (pdt_replay_set_mem). */
static void plan_checkpoints(pdt_replay *r, uint64_t budget)
{
    size_t parts = (r->m + ICK_MAX_EVERY - 1) / ICK_MAX_EVERY;
    parts = parts < ICK_PARTS ? ICK_PARTS : parts > ICK_MAX_PARTS ? ICK_MAX_PARTS : parts;
    size_t every = r->m / parts;
    r->ick_every = every < ICK_MIN_EVERY ? ICK_MIN_EVERY : every;
    r->nick = r->m / r->ick_every + 1;
    r->mem_budget = budget;
    r->state_paged = budget && pdt_replay_state_bytes(r) > budget / 4;
}

static void evcopy_free(evcopy *ec)
{
    free(ec->blk);
    free(ec->rank_blk);
    free(ec->src.file);
    free(ec->src.file_len);
    free(ec->segs_crc.crc);
}

static void evstream_free(evstream *es)
{
    pdt_merge_close(es->mg);
    free(es->buf);
    if (es->map) munmap(es->map, es->map_len);
}

/* The replay r built: its checkpoints planned and every table written to
 * the index (fd, header h); the build's working memory (*work) and
 * buckets said. */
static pdt_status finish_build(pdt_replay *r, pdt_run *run, int fd, ihdr *h, uint64_t ident,
                               placer *pc, evcopy *ec, uint64_t budget, uint64_t *work,
                               uint32_t *buckets, pdt_err *err)
{
    r->warnings = pdt_run_warnings(run);
    plan_checkpoints(r, budget);
    pdt_status st = write_tables(r, fd, h, ident, pc, ec, err);
    pdt_run_release_points(run);  /* (written from them) */
    *work = r->build_peak + (r->state_paged ? 0 : pdt_replay_state_bytes(r)) + /* (the
             * checkpoints' state, when held, and its copies) */ r->build_ck_bytes;
    *buckets = r->build_buckets;
    r->nick = 0;  /* r's own tables are freed by the caller; it has no mapped checkpoints */
    return st;
}

/* The scratch files' share of a build's budget (scratch_int.h): half of a
 * budget of SCRATCH_POOL_FROM or more, the build planning its own work
 * within the other half (a build under a smaller one needs all of it);
 * none without a limit.  A test build may set it ($PDT_TEST_SCRATCH_MEM,
 * bytes). */
#define SCRATCH_POOL_FROM ((uint64_t)512 << 20)

static uint64_t scratch_pool(uint64_t budget)
{
    const char *t = pdt_test_hook("PDT_TEST_SCRATCH_MEM");
    if (t) {
        uint64_t want = strtoull(t, NULL, 10);
        return want < budget / 2 ? want : budget / 2;
    }
    return budget >= SCRATCH_POOL_FROM ? budget / 2 : 0;
}

static pdt_status build(pdt_run *run, const pdt_point *pts, size_t n, int nranks, uint64_t ident,
                        const char *path, uint64_t budget, uint64_t *work, uint32_t *buckets,
                        pdt_err *err)
{
    /* the index's name is ours: a link planted there is replaced, not
     * followed; leftovers of killed builds are removed (pdt/safefile.h) */
    pdt_safe_file sf;
    pdt_status st0 = pdt_safe_open(&sf, path, PDT_SAFE_NOFOLLOW, err);
    if (st0 != PDT_OK) return st0;
    char tmp[PATH_MAX + 256];
    snprintf(tmp, sizeof tmp, "%s", sf.tmp);
    int fd = sf.fd;
    ihdr *h = calloc(1, sizeof *h);
    evcopy ec;
    memset(&ec, 0, sizeof ec);
    pdt_replay *r = NULL;
    size_t m = run_events(run, nranks);
    evstream es;
    memset(&es, 0, sizeof es);
    es.cur.rank = UINT32_MAX;
    es.buf = malloc(SEG_BATCH * sizeof *es.buf);
    evpipe pipe;
    memset(&pipe, 0, sizeof pipe);
    placer pc = {.pipe = &pipe, .fd = fd, .run = run};
    uint64_t pool = scratch_pool(budget);
    pdt_scr_init(&pc.scr, tmp, pool);
    pdt_replay_place pl = {place_reserve, place_put,   place_get, scratch_put,   scratch_get,
                           scratch_drop,  points_read, &pc,       budget - pool, stream_next,
                           &ec.src,       0,           0};
    pdt_status st = h && es.buf ? block_table(run, &ec, err)
                                : pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    if (st == PDT_OK) st = pdt_merge_open(run, &es.mg, err);
    if (st == PDT_OK) {
        es.fd = fd;
        es.h = h;
        es.ec = &ec;
        /* the per-event tables first (their sizes are known: pass 1 writes
         * them as it goes), then the segments */
        pc.off = HDR_BYTES;
        pl.evobj_at = place_reserve(&pc, (uint64_t)m * sizeof(int32_t));
        pl.evkind_at = place_reserve(&pc, m);
        es.at = es.off = (pc.off + 63) & ~(uint64_t)63;
        es.place_off = &pc.off;
        if (!pdt_scr_make_file(&pc.scr, PDT_SCR_SPILL))
            st = pdt_err_set(err, PDT_ERR_IO, "%s: a scratch file beside it: %s", tmp, strerror(errno));
    }
    if (st == PDT_OK && !pipe_start(&pipe, &es, err)) st = err->code;
    if (st == PDT_OK) st = pdt_replay_build(pts, n, NULL, m, nranks, &pl, &r, err);
    pipe_stop(&pipe);
    uint64_t scratch_peak = pc.scr.peak;
    pdt_scr_free(&pc.scr);  /* the scratch: gone */
    if (st == PDT_OK) st = finish_build(r, run, fd, h, ident, &pc, &ec, budget, work, buckets, err);
    if (st == PDT_OK) *work += scratch_peak;
    pdt_replay_free(r);
    pdt_evsrc_clear(&ec.src);
    evstream_free(&es);
    /* into place over a stale index by an exchange of names, without ext4
     * writing the new one back inside the call (gigabytes for a big run) */
    if (st == PDT_OK) st = pdt_safe_commit(&sf, err);
    else pdt_safe_abort(&sf);
    free(h);
    evcopy_free(&ec);
    return st;
}

/* ---- opening a run ---------------------------------------------------------------- */

pdt_status pdt_replay_open_kept(const char *dir, uint64_t budget, pdt_replay **out,
                                pdt_replay_open_info *info, pdt_err *err)
{
    pdt_replay_open_info dummy;
    if (!info) info = &dummy;
    memset(info, 0, sizeof *info);
    *out = NULL;
    uint64_t ident = 0;
    pdt_status st = pdt_ix_run_ident(dir, &ident, err);
    if (st != PDT_OK) return st;
    char path[PATH_MAX];
    for (int where = 0; where < 2; where++) {
        char why[160];
        if (!pdt_ix_index_path(dir, where, path, sizeof path)) continue;
        pdt_replay *r = pdt_ix_load(path, dir, ident, NULL, 0, 1, why, sizeof why);
        if (!r) {
            if (where == 0 || strcmp(why, "no index yet"))
                snprintf(info->why, sizeof info->why, "%s", why);
            continue;
        }
        info->indexed = 1;
        info->events = r->m;
        snprintf(info->path, sizeof info->path, "%s", path);
        pdt_replay_set_mem(r, budget);
        *out = r;
        return PDT_OK;
    }
    return PDT_OK;
}

/* The replay of run in memory, as before the kept index. */
static pdt_status in_memory(pdt_run *run, const pdt_point *pts, size_t n, int nranks,
                            pdt_replay **out, pdt_err *err)
{
    const pdt_rec *recs;
    size_t m;
    pdt_status st = pdt_run_merged(run, &recs, &m, err);
    if (st != PDT_OK) return st;
    return pdt_replay_new(pts, n, recs, m, nranks, out, err);
}

static void release_run_points(const void *run)
{
    pdt_run_release_points(run);
}

/* A valid kept index of the run (identity ident) beside it, else in the
 * cache: the replay (its place in path), or NULL (info->why says why). */
static pdt_replay *find_kept(const char *dir, uint64_t ident, const pdt_point *pts, size_t n,
                             char *path, size_t pcap, pdt_replay_open_info *info)
{
    pdt_replay *r = NULL;
    for (int where = 0; where < 2 && !r; where++) {
        char why[160];
        if (!pdt_ix_index_path(dir, where, path, pcap)) continue;
        r = pdt_ix_load(path, dir, ident, pts, n, 1, why, sizeof why);
        if (!r && where == 0) snprintf(info->why, sizeof info->why, "%s", why);
        if (!r && where == 1 && strcmp(why, "no index yet"))
            snprintf(info->why, sizeof info->why, "%s", why);
    }
    return r;
}

/* Build the run's index beside it if the folder takes it, else in the
 * cache, and open it: the replay (its place in path), or NULL
 * (info->write_error says why). */
static pdt_replay *build_kept(pdt_run *run, const char *dir, uint64_t ident, uint64_t budget,
                              char *path, size_t pcap, pdt_replay_open_info *info)
{
    size_t n;
    const pdt_point *pts = pdt_run_points(run, &n);
    pdt_replay *r = NULL;
    double t0 = pdt_seconds();
    for (int where = 0; where < 2 && !r; where++) {
        if (!pdt_ix_index_path(dir, where, path, pcap)) continue;
        if (where == 1) {
            char cdir[PATH_MAX];
            if (!pdt_ix_cache_dir(cdir, sizeof cdir) || !pdt_ix_make_dirs(cdir)) continue;
        }
        pdt_err e2 = {0};
        if (build(run, pts, n, pdt_run_nranks(run), ident, path, budget, &info->build_bytes,
                  &info->build_buckets, &e2) != PDT_OK) {
            snprintf(info->write_error, sizeof info->write_error, "%s", e2.msg);
            pdt_err_clear(&e2);
            continue;
        }
        char why[160];
        r = pdt_ix_load(path, dir, ident, pts, n, 0, why, sizeof why);
    }
    if (r) info->write_error[0] = 0; /* (the run's folder refused it, the cache took it) */
    info->built = r != NULL;
    info->build_s = pdt_seconds() - t0;
    return r;
}

pdt_status pdt_replay_open_run(pdt_run *run, const char *dir, uint64_t budget, int use_index,
                               pdt_replay **out, pdt_replay_open_info *info, pdt_err *err)
{
    pdt_replay_open_info dummy;
    if (!info) info = &dummy;
    memset(info, 0, sizeof *info);
    *out = NULL;
    size_t n;
    const pdt_point *pts = pdt_run_points(run, &n);
    int nranks = pdt_run_nranks(run);
    info->events = run_events(run, nranks);
    if (use_index < 0) use_index = info->events * EST_BYTES_PER_EVENT > budget / 4;
    uint64_t ident = 0;
    pdt_status st = use_index ? pdt_ix_run_ident(dir, &ident, err) : PDT_OK;
    if (st != PDT_OK) return st;
    char path[PATH_MAX];
    pdt_replay *r = use_index ? find_kept(dir, ident, pts, n, path, sizeof path, info) : NULL;
    if (use_index && !r) r = build_kept(run, dir, ident, budget, path, sizeof path, info);
    if (!r) { /* not asked for, or no place to keep an index: the whole run in memory */
        st = in_memory(run, pts, n, nranks, out, err);
        if (st == PDT_OK) pdt_replay_set_mem(*out, budget);
        return st;
    }
    info->indexed = 1;
    snprintf(info->path, sizeof info->path, "%s", path);
    r->release_points = release_run_points;  /* read in place: given back after frames */
    r->release_ctx = run;
    pdt_replay_set_mem(r, budget);
    *out = r;
    return PDT_OK;
}
