/* pdt — the replay's build: the triangles' numbers by first event, and the
 * per-event tables (in memory, or streamed in windows of events). */
#include "pdt/view/replay.h"
#include "replay_int.h"
#include "build_int.h"
#include "pdt/bigmem.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <pthread.h>
#include <stdatomic.h>
#include <sys/mman.h>
#include <unistd.h>

/* A streamed build reads the records (a mapping of the index file) from
 * start to end a few times: the pages behind the pass are let go every
 * DROP_EVERY records (they stay in the page cache), so the process does not
 * hold all of them at once. */
#define DROP_EVERY ((size_t)1 << 20)

void pdt_rp_drop_recs(const builder *b, size_t upto)
{
    if (!b->pl || !b->r->recs || !upto || upto % DROP_EVERY) return;
    pdt_release_pages(b->r->recs + upto - DROP_EVERY, DROP_EVERY * sizeof *b->r->recs);
}

/* Number the triangles by their first event (after tri_groups): the
 * triangle table (in r->tris, or streamed to tris_at), and ev_obj[ev] = the
 * triangle of every triangle event; the entry of a triangle's first event
 * is marked (FIRST_ENTRY). */
int pdt_rp_tri_ids(builder *b)
{
    pdt_replay *r = b->r;
    enum { TBUF = 4096 };
    pdt_rtri tb[TBUF], *to = b->pl ? tb : r->tris;
    size_t nb = 0;
    r->ntri = 0;
    for (size_t i = 0; i < r->m; i++) {
        pdt_rp_drop_recs(b, i);
        if (i + PREFETCH_AHEAD < r->m) {
            int32_t a = r->ev_obj[i + PREFETCH_AHEAD];
            if (a >= 0 && is_tri_kind(r->ev_kind[i + PREFETCH_AHEAD])) __builtin_prefetch(&r->ev_obj[a]);
        }
        if (!is_tri_kind(kind_at(r, i))) continue;
        int32_t o = r->ev_obj[i];
        if (o == -1) continue;  /* skipped */
        if (o >= 0) {
            r->ev_obj[i] = r->ev_obj[o];
            continue;
        }
        const pdt_rec *rec = rec_at(r, i);
        uint32_t h0 = r->ev_ent[i], hn = (uint32_t)(-1 - o);
        to[b->pl ? nb++ : r->ntri] = (pdt_rtri){{rec->ev.a, rec->ev.b, rec->ev.c}, rec->rank, h0,
                                               (uint16_t)hn, r->hist[h0 + hn - 1].status, 0};
        r->ev_kind[i] |= KIND_FIRST;
        r->ev_obj[i] = (int32_t)r->ntri++;
        if (nb == TBUF) {
            if (!pdt_rp_tput(b, NULL, r->tris_at, r->ntri - nb, tb, nb, sizeof *tb)) return 0;
            nb = 0;
        }
    }
    return pdt_rp_tput(b, NULL, r->tris_at, r->ntri - nb, tb, nb, sizeof *tb);
}

/* Records of `rec` bytes, read in order from `left` of them at `at` of
 * scratch file `file`, cap at a time (a bucket's: the builder's cur_recs). */
typedef struct bcur {
    int file;
    uint64_t at;
    size_t left, rec, n, i, cap;  /* cap: records the buffer holds */
    unsigned char *buf;
} bcur;

/* The next record, or NULL at the end (or when a read failed: b->failed). */
static const void *bcur_peek(builder *b, bcur *c)
{
    if (c->i < c->n) return c->buf + c->i * c->rec;
    if (!c->left) return NULL;
    size_t k = c->left < c->cap ? c->left : c->cap;
    if (!b->pl->sget(b->pl->ctx, c->file, c->at, c->buf, k * c->rec)) {
        b->failed = 1;
        c->left = 0;
        return NULL;
    }
    c->at += k * c->rec;
    c->left -= k;
    c->n = k;
    c->i = 0;
    return c->buf;
}

/* Records appended at `at` of scratch file `file` (file < 0: of the place),
 * cap at a time.  0 when a write failed. */
static int bput_flush(builder *b, bcur *c)
{
    if (!c->n) return 1;
    size_t bytes = c->n * c->rec;
    int ok = c->file < 0 ? b->pl->put(b->pl->ctx, c->at, c->buf, bytes)
                         : b->pl->sput(b->pl->ctx, c->file, c->at, c->buf, bytes);
    c->at += bytes;
    c->n = 0;
    if (!ok) b->failed = 1;
    return ok;
}

/* nfine cursors over records of rec bytes with one buffer; NULL when out of memory. */
static bcur *bcurs_new(builder *b, size_t rec)
{
    bcur *c = pdt_rp_bmalloc(b, b->nfine * sizeof *c);
    unsigned char *buf = pdt_rp_bmalloc(b, (size_t)b->nfine * b->cur_recs * rec);
    if (!c || !buf) {
        pdt_rp_bfree(b, c, b->nfine * sizeof *c);
        pdt_rp_bfree(b, buf, (size_t)b->nfine * b->cur_recs * rec);
        return NULL;
    }
    memset(c, 0, b->nfine * sizeof *c);
    for (size_t f = 0; f < b->nfine; f++)
        c[f].buf = buf + f * b->cur_recs * rec, c[f].rec = rec, c[f].cap = b->cur_recs;
    return c;
}

static void bcurs_free(builder *b, bcur *c, size_t rec)
{
    if (!c) return;
    pdt_rp_bfree(b, c[0].buf, (size_t)b->nfine * b->cur_recs * rec);
    pdt_rp_bfree(b, c, b->nfine * sizeof *c);
}

/* Number the triangles by their first events: the triangle table (streamed
 * to tris_at), a bucket's numbers in PDT_SCR_IDS (from fine_off[f]); a
 * triangle's corners as the grouping found them in its first event, its
 * maker that event's rank, its entries where the grouping wrote them (the
 * history table in the buckets' order: a bucket's triangles' entries one
 * triangle after the other, from its fine_off). */
/* The windows of the numbering: the triangles whose first event is in
 * [lo, hi), by event (wn: entries, 0 for none; wf: their bucket; wv:
 * their corners).  One thread finds them (num_window) a window ahead of
 * the one that numbers them (num_emit), so they are NUM_SLOTS. */
#define NUM_SLOTS 2
#define NUM_AHEAD 64 /* events ahead whose found counts num_emit fetches */
typedef struct num_slot {
    uint32_t *wn, (*wv)[3];
    uint16_t *wf;
    size_t lo, hi;
} num_slot;

/* The numbering pass's cursors: per fine bucket, its triangles' first
 * events (tc, read by the finding thread), their ids (ic, written) and
 * where its next triangle's entries are (hpos); the triangle table written
 * in order (tw); the windows, and between the two threads the windows
 * found and numbered, and whether the numbering stopped. */
typedef struct numbering {
    builder *b;
    bcur *tc, *ic, tw;
    size_t *hpos;
    num_slot w[NUM_SLOTS];
    size_t h0;  /* entries numbered */
    size_t found, done;
    int stop;
    pthread_mutex_t mu;
    pthread_cond_t cv;
} numbering;

static int num_open(builder *b, numbering *N)
{
    pdt_replay *r = b->r;
    memset(N, 0, sizeof *N);
    N->b = b;
    N->tc = bcurs_new(b, sizeof(tri_first));
    N->ic = bcurs_new(b, sizeof(uint32_t));
    N->hpos = pdt_rp_bmalloc(b, b->nfine * sizeof *N->hpos);
    N->tw.buf = pdt_rp_bmalloc(b, CUR_RECS * sizeof(pdt_rtri));
    int ok = N->tc && N->ic && N->hpos && N->tw.buf;
    for (int k = 0; k < NUM_SLOTS; k++) {
        num_slot *w = &N->w[k];
        w->wn = pdt_rp_bmalloc(b, NUM_WINDOW * sizeof *w->wn);
        w->wf = pdt_rp_bmalloc(b, NUM_WINDOW * sizeof *w->wf);
        w->wv = pdt_rp_bmalloc(b, NUM_WINDOW * sizeof *w->wv);
        ok = ok && w->wn && w->wf && w->wv;
    }
    if (!ok) return 0;
    for (size_t f = 0; f < b->nfine; f++) {
        N->tc[f].file = PDT_SCR_TRIS;
        N->tc[f].at = (uint64_t)b->fine_off[f] * sizeof(tri_first);
        N->tc[f].left = b->tcount[f];
        N->ic[f].file = PDT_SCR_IDS;
        N->ic[f].at = (uint64_t)b->fine_off[f] * sizeof(uint32_t);
        N->hpos[f] = b->fine_off[f];
    }
    N->tw.file = -1;
    N->tw.at = r->tris_at;
    N->tw.rec = sizeof(pdt_rtri);
    N->tw.cap = CUR_RECS;
    return 1;
}

static void num_close(builder *b, numbering *N)
{
    pdt_rp_bfree(b, N->tw.buf, CUR_RECS * sizeof(pdt_rtri));
    pdt_rp_bfree(b, N->hpos, b->nfine * sizeof *N->hpos);
    for (int k = 0; k < NUM_SLOTS; k++) {
        pdt_rp_bfree(b, N->w[k].wn, NUM_WINDOW * sizeof *N->w[k].wn);
        pdt_rp_bfree(b, N->w[k].wf, NUM_WINDOW * sizeof *N->w[k].wf);
        pdt_rp_bfree(b, N->w[k].wv, NUM_WINDOW * sizeof *N->w[k].wv);
    }
    bcurs_free(b, N->tc, sizeof(tri_first));
    bcurs_free(b, N->ic, sizeof(uint32_t));
}

/* The triangles whose first event is in [lo, hi), from every bucket, by
 * event (into w). */
static void num_window(builder *b, numbering *N, num_slot *w, size_t lo, size_t hi)
{
    w->lo = lo;
    w->hi = hi;
    memset(w->wn, 0, (hi - lo) * sizeof *w->wn);
    for (size_t f = 0; f < b->nfine; f++) {
        const tri_first *t;
        while ((t = bcur_peek(b, &N->tc[f])) && t->ev < hi) {
            if (t->ev < lo || !(t->n & TF_N_MASK)) { /* (not in event order: never written so) */
                b->failed = 1;
                break;
            }
            w->wn[t->ev - lo] = t->n;
            w->wf[t->ev - lo] = (uint16_t)f;
            memcpy(w->wv[t->ev - lo], t->v, sizeof t->v);
            N->tc[f].i++;
        }
    }
}

/* Triangle t and its id to the table and to its bucket's ids (typed: a
 * copy of a known size, not a call). */
static int put_tri(builder *b, numbering *N, bcur *ic, const pdt_rtri *t, uint32_t id)
{
    ((pdt_rtri *)(void *)N->tw.buf)[N->tw.n] = *t;
    uint32_t *ids = (uint32_t *)(void *)ic->buf;
    ids[ic->n] = id;
    /* the bucket's next line, for writing: the buckets are written at random,
     * and each id stored to a line not in the cache stalled the numbering */
    __builtin_prefetch(ids + ic->n + 16, 1);
    return (++N->tw.n < N->tw.cap || bput_flush(b, &N->tw)) && (++ic->n < ic->cap || bput_flush(b, ic));
}

/* Window w's triangles numbered in the order of their first events: each
 * written to the table, its id to its bucket's. */
static int num_emit(builder *b, numbering *N, const num_slot *w)
{
    pdt_replay *r = b->r;
    int ok = 1;
    size_t nw = w->hi - w->lo;
    for (size_t k = 0; ok && k < nw; k++) {
        if (k + NUM_AHEAD < nw) __builtin_prefetch(&w->wn[k + NUM_AHEAD]); /* (the finder's,
                                                    * from the other core's cache) */
        uint32_t nk = w->wn[k] & TF_N_MASK;
        if (!nk) continue;
        const uint32_t *v = w->wv[k];
        size_t f = w->wf[k];
        pdt_rtri t = {{v[0], v[1], v[2]}, pdt_replay_rank_of(r, w->lo + k), (uint32_t)N->hpos[f],
                      (uint16_t)nk, (uint8_t)(w->wn[k] >> TF_LAST_SHIFT), 0};
        ok = put_tri(b, N, &N->ic[f], &t, (uint32_t)r->ntri++);
        N->hpos[f] += nk;
        N->h0 += nk;
    }
    return ok;
}

/* The finding thread: window k into slot k % NUM_SLOTS once the numbering
 * is done with the window that slot held, until the last or a stop. */
static void *num_finder(void *arg)
{
    numbering *N = arg;
    builder *b = N->b;
    size_t m = b->r->m;
    for (size_t k = 0, lo = 0; lo < m; k++, lo += NUM_WINDOW) {
        pthread_mutex_lock(&N->mu);
        while (N->done + NUM_SLOTS <= k && !N->stop) pthread_cond_wait(&N->cv, &N->mu);
        int stop = N->stop;
        pthread_mutex_unlock(&N->mu);
        if (stop) break;
        num_window(b, N, &N->w[k % NUM_SLOTS], lo, m - lo < NUM_WINDOW ? m : lo + NUM_WINDOW);
        pthread_mutex_lock(&N->mu);
        N->found = k + 1;
        pthread_cond_broadcast(&N->cv);
        pthread_mutex_unlock(&N->mu);
    }
    return NULL;
}

/* Window k, found (by the finder, or here without one): its slot. */
static const num_slot *num_found(numbering *N, size_t k, int finder)
{
    num_slot *w = &N->w[k % NUM_SLOTS];
    if (!finder) {
        size_t lo = k * NUM_WINDOW, m = N->b->r->m;
        num_window(N->b, N, w, lo, m - lo < NUM_WINDOW ? m : lo + NUM_WINDOW);
        return w;
    }
    pthread_mutex_lock(&N->mu);
    while (N->found <= k) pthread_cond_wait(&N->cv, &N->mu);
    pthread_mutex_unlock(&N->mu);
    return w;
}

/* Window k numbered: its slot back to the finder. */
static void num_done(numbering *N, size_t k, int stop)
{
    pthread_mutex_lock(&N->mu);
    N->done = k + 1;
    if (stop) N->stop = 1;
    pthread_cond_broadcast(&N->cv);
    pthread_mutex_unlock(&N->mu);
}

int pdt_rp_tri_number(builder *b)
{
    pdt_replay *r = b->r;
    numbering N;
    int ok = num_open(b, &N);
    pthread_mutex_init(&N.mu, NULL);
    pthread_cond_init(&N.cv, NULL);
    pthread_t th;
    int finder = ok && sysconf(_SC_NPROCESSORS_ONLN) > 1 && pthread_create(&th, NULL, num_finder, &N) == 0;
    r->ntri = 0;
    for (size_t k = 0, lo = 0; ok && lo < r->m; k++, lo += NUM_WINDOW) {
        const num_slot *w = num_found(&N, k, finder);
        ok = !b->failed && num_emit(b, &N, w) && !b->failed;
        if (finder) num_done(&N, k, !ok);
    }
    if (finder) {
        num_done(&N, N.done, 1);  /* (stopped early: the finder stops too) */
        pthread_join(th, NULL);
    }
    for (size_t f = 0; ok && f < b->nfine; f++)
        ok = bput_flush(b, &N.ic[f]) && N.hpos[f] == b->fine_off[f + 1];
    ok = ok && bput_flush(b, &N.tw) && N.h0 == r->nhist && !b->failed;
    pthread_mutex_destroy(&N.mu);
    pthread_cond_destroy(&N.cv);
    num_close(b, &N);
    if (!ok) b->failed = 1;
    return ok;
}

/* Give every triangle event of every bucket its triangle's number (in
 * place in PDT_SCR_TRIEV), with the bucket's numbers in memory. */
int pdt_rp_tri_join(builder *b)
{
    size_t most = 0;
    for (size_t f = 0; f < b->nfine; f++)
        if (b->tcount[f] > most) most = b->tcount[f];
    enum { JOIN_RECS = 1 << 16 };
    uint32_t *ids = pdt_rp_bmalloc(b, most * sizeof *ids);
    tri_ev *ev = pdt_rp_bmalloc(b, JOIN_RECS * sizeof *ev);
    int ok = ids && ev;
    for (size_t f = 0; ok && f < b->nfine; f++) {
        ok = !b->tcount[f] || b->pl->sget(b->pl->ctx, PDT_SCR_IDS, (uint64_t)b->fine_off[f] * sizeof *ids,
                                         ids, b->tcount[f] * sizeof *ids);
        for (size_t j = b->fine_off[f]; ok && j < b->fine_off[f + 1]; j += JOIN_RECS) {
            size_t k = b->fine_off[f + 1] - j < JOIN_RECS ? b->fine_off[f + 1] - j : JOIN_RECS;
            uint64_t at = (uint64_t)j * sizeof *ev;
            ok = b->pl->sget(b->pl->ctx, PDT_SCR_TRIEV, at, ev, k * sizeof *ev);
            for (size_t i = 0; ok && i < k; i++) {
                uint32_t q = ev[i].t & ~TEV_FIRST;
                if (q >= b->tcount[f]) {
                    ok = 0;
                    break;
                }
                ev[i].t = ids[q] | (ev[i].t & TEV_FIRST);
            }
            ok = ok && b->pl->sput(b->pl->ctx, PDT_SCR_TRIEV, at, ev, k * sizeof *ev);
        }
    }
    if (!ok) b->failed = 1;
    pdt_rp_bfree(b, ids, most * sizeof *ids);
    pdt_rp_bfree(b, ev, JOIN_RECS * sizeof *ev);
    return ok;
}

/* The per-event tables (at evobj_at and evkind_at of the place): pass 1's,
 * completed in place with every triangle event's triangle and the mark on
 * a triangle's first event (PDT_SCR_TRIEV, bucket by bucket in event order). */
int pdt_rp_ev_tables(builder *b)
{
    pdt_replay *r = b->r;
    const pdt_replay_place *pl = b->pl;
    bcur *ec = bcurs_new(b, sizeof(tri_ev));
    int32_t *obj = pdt_rp_bmalloc(b, NUM_WINDOW * sizeof *obj);
    uint8_t *kind = pdt_rp_bmalloc(b, NUM_WINDOW);
    int ok = ec && obj && kind;
    for (size_t f = 0; ok && f < b->nfine; f++) {
        ec[f].file = PDT_SCR_TRIEV;
        ec[f].at = (uint64_t)b->fine_off[f] * sizeof(tri_ev);
        ec[f].left = b->fine_off[f + 1] - b->fine_off[f];
    }
    for (size_t lo = 0; ok && lo < r->m; lo += NUM_WINDOW) {
        size_t hi = r->m - lo < NUM_WINDOW ? r->m : lo + NUM_WINDOW, k = hi - lo;
        ok = pl->get(pl->ctx, r->evobj_at + (uint64_t)lo * sizeof *obj, obj, k * sizeof *obj) &&
             pl->get(pl->ctx, r->evkind_at + lo, kind, k);
        for (size_t f = 0; ok && f < b->nfine; f++) {
            const tri_ev *t;
            while ((t = bcur_peek(b, &ec[f])) && t->ev < hi) {
                if (t->ev < lo) {
                    b->failed = 1;
                    break;
                }
                obj[t->ev - lo] = (int32_t)(t->t & ~TEV_FIRST);
                if (t->t & TEV_FIRST) kind[t->ev - lo] |= KIND_FIRST;
                ec[f].i++;
            }
        }
        ok = ok && !b->failed && pl->put(pl->ctx, r->evobj_at + (uint64_t)lo * sizeof *obj, obj, k * sizeof *obj) &&
             pl->put(pl->ctx, r->evkind_at + lo, kind, k);
    }
    if (!ok) b->failed = 1;
    pdt_rp_bfree(b, obj, NUM_WINDOW * sizeof *obj);
    pdt_rp_bfree(b, kind, NUM_WINDOW);
    bcurs_free(b, ec, sizeof(tri_ev));
    return ok;
}

/* Pass 1 of a streamed build: the window of per-event tables out to the
 * place when event i is past it (or at the end: i == m). */
int pdt_rp_ev_window(builder *b, size_t i)
{
    if (i - b->wlo < EVW && i < b->r->m) return 1;
    size_t k = i - b->wlo;
    const pdt_replay_place *pl = b->pl;
    if (k && (!pl->put(pl->ctx, b->r->evobj_at + (uint64_t)b->wlo * 4, b->wobj, k * 4) ||
              !pl->put(pl->ctx, b->r->evkind_at + b->wlo, b->wkind, k))) {
        b->failed = 1;
        return 0;
    }
    b->wlo = i;
    return 1;
}
