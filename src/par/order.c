/* pdt — the order phase (driver.h): canonical order across the ranks. */
#include <stdlib.h>
#include <string.h>

#include "driver.h"

#include "pdt/testhook.h"

/* ---- canonical order across ranks ------------------------------------------------ */

/* The canonical order sorts by smallest index first, so the output splits
 * into ranges of smallest index: rank q writes the triangles whose smallest
 * index lies in its range.  The ranges are made of buckets of 2^shift
 * consecutive indices, the same on every rank (pdt_tri_bucket_*): each rank
 * counts its final triangles by bucket, the counts summed over the ranks
 * (one allreduce) give each rank a range of buckets holding about T / p
 * triangles, each rank groups its triangles by bucket (one pass: the runs
 * for the ranks are then consecutive), one exchange of 12-byte records, and
 * each rank puts what it got in order bucket by bucket -- the counting sort
 * of the plain run, split at the exchange, with no sorted runs to merge. */

/* The final triangles of a rank: the local phase's and the merges'. */
typedef struct finals {
    pdt_tri *t[2];
    size_t n[2];
} finals;

/* The buckets: 2^shift consecutive smallest indices each, as many over
 * [0, n_total) as fit in max(2048, 16 p), at most 2^16: 16 or more per rank
 * (a bucket is never split between ranks: a rank's share is within 1/16 of
 * n / p), and narrow enough that one bucket's counters (8 bytes an index)
 * stay a third of its triangles.  Their histogram is one allreduce of 8
 * bytes a bucket: 256 per rank made it 512 KB from 256 ranks on, the
 * largest message of a run with little work per rank. */
static int order_shift(const drv *d)
{
    uint64_t top = d->n_total ? d->n_total - 1 : 0;
    uint64_t want = (uint64_t)16 * (uint64_t)d->p;
    if (want < 2048) want = 2048;
    if (want > ((uint64_t)1 << 16)) want = (uint64_t)1 << 16;
    int sh = 0;
    while ((top >> sh) + 1 > want) sh++;
    return sh;
}

static size_t order_buckets(const drv *d, int shift)
{
    return (size_t)((d->n_total ? d->n_total - 1 : 0) >> shift) + 1;
}

pdt_status pdt_drv_order_hist(drv *d)
{
    int shift = order_shift(d);
    d->order_hist = calloc(order_buckets(d, shift), sizeof *d->order_hist);
    if (!d->order_hist) return pdt_drv_nomem(d, "local");
    for (int j = 0; j < d->k; j++) {
        d->s[j].order_hist = d->order_hist;
        d->s[j].order_shift = shift;
    }
    return PDT_OK;
}

/* The plan of the exchange, in `rounds` rounds (bucket b goes in round
 * b % rounds: a round's grouped array holds about 1/rounds of the finals):
 * hist[b], this rank's triangles in bucket b; the buckets' owners from the
 * sum over the ranks (the rank whose share holds a bucket's middle:
 * nondecreasing in b); sc[q * rounds + r], how many this rank sends rank q in
 * round r, rc the same received; at[b], where bucket b starts in its round's
 * grouped array; most, the largest round's count. */
typedef struct order_plan {
    int shift, rounds;
    size_t nb, most;
    uint64_t *hist, *at, *sc, *rc;
    uint64_t first, all; /* the triangles of the ranks before this one; of all ranks */
} order_plan;

static void order_plan_free(order_plan *o)
{
    free(o->hist);
    free(o->at);
    free(o->sc);
    free(o->rc);
}

static pdt_status order_plan_make(drv *d, finals *f, order_plan *o, pdt_err *err)
{
    int p = d->p;
    int R = o->rounds = d->k > 1 ? 2 : 1; /* (two when the strips are, for memory) */
    o->shift = order_shift(d);
    o->nb = order_buckets(d, o->shift);
    o->hist = d->order_hist; /* the local phase's finals, counted (and rotated) */
    d->order_hist = NULL;
    size_t from[2] = {f->n[0], d->more_counted};
    o->at = calloc(o->nb, sizeof *o->at);
    o->sc = calloc((size_t)p * (size_t)R, sizeof *o->sc);
    o->rc = calloc((size_t)p * (size_t)R, sizeof *o->rc);
    uint64_t *sum = calloc(o->nb, sizeof *sum);
    if (!o->hist || !o->at || !o->sc || !o->rc || !sum) {
        free(sum);
        return pdt_drv_nomem(d, "order");
    }
    for (int k = 0; k < 2; k++)
        pdt_tri_bucket_count(f->t[k] + from[k], f->n[k] - from[k], o->shift, o->hist);
    memcpy(sum, o->hist, o->nb * sizeof *sum);
    pdt_status st = pdt_comm_allreduce_u64(d->c, sum, o->nb, PDT_COMM_SUM, err);
    if (st == PDT_OK) {
        pdt_drv_note_reduce(d, TAG_ORDER, o->nb * sizeof *sum);
        uint64_t total = 0, before = 0, pos[2] = {0, 0};
        for (size_t b = 0; b < o->nb; b++) total += sum[b];
        for (size_t b = 0; b < o->nb; b++) {
            uint64_t q = total ? (before + sum[b] / 2) * (uint64_t)p / total : 0;
            q = q < (uint64_t)p ? q : (uint64_t)p - 1;
            int r = (int)(b % (size_t)R);
            if (q < (uint64_t)d->rank) o->first += sum[b];
            before += sum[b];
            o->sc[q * (uint64_t)R + (uint64_t)r] += o->hist[b];
            o->at[b] = pos[r];
            pos[r] += o->hist[b];
        }
        o->all = total;
        o->most = (size_t)(pos[0] > pos[1] ? pos[0] : pos[1]);
        st = pdt_comm_alltoall(d->c, o->sc, (size_t)R * sizeof *o->sc, o->rc, err);
        if (st == PDT_OK) pdt_drv_note_all(d, TAG_COUNTS, (size_t)R * sizeof *o->sc);
    }
    free(sum);
    return st;
}

/* Where the order phase groups, receives and orders: in the rank's block
 * (room for cap triangles, the local finals at its front) when each fits,
 * else in arrays of their own, and each as low in the block as it fits, so
 * that the phase touches about the pages the kernel did (finals, grp and got
 * take some 6 triangles per point, the kernel's edges 72 bytes), not the
 * block's far end (room for 1/16 more points than the strip holds):
 *   grp  the grouped triangles, behind the finals;
 *   got  the received ones, right past grp (sent before anything arrives)
 *        or past out, whichever ends later;
 *   out  the ordered output at the front (the finals and grp have been read
 *        by then). */
typedef struct order_room {
    pdt_tri *blk;
    size_t cap;
    pdt_tri *grp, *got, *out;
    int grp_own, got_own, out_own;
} order_room;

static void order_room_free(order_room *o)
{
    if (o->grp_own) free(o->grp);
    if (o->got_own) free(o->got);
    if (o->out_own) free(o->out);
}

/* PDT_TEST_ORDER_ROOM=N: the order phase sees at most N triangles of room
 * in the block (tests: every choice of room below runs on small inputs). */
static size_t test_order_room(size_t cap)
{
    const char *e = pdt_test_hook("PDT_TEST_ORDER_ROOM");
    char *end;
    unsigned long long v = e && *e ? strtoull(e, &end, 10) : 0;
    return e && *e && !*end && v < cap ? (size_t)v : cap;
}

static pdt_status order_room_grp(drv *d, order_room *o, const finals *f, size_t mine)
{
    o->blk = d->s[0].fin;
    o->cap = o->blk ? test_order_room(d->blk_bytes / sizeof(pdt_tri)) : 0; /* (the strip's
                                                                              points are done) */
    if (o->blk && f->n[0] + mine + 1 <= o->cap) { /* (+ 1: a round's spare place) */
        o->grp = o->blk + f->n[0];
        return PDT_OK;
    }
    o->grp = srm_big((mine + 1) * sizeof *o->grp);
    o->grp_own = 1;
    return o->grp ? PDT_OK : pdt_drv_nomem(d, "order");
}

static pdt_status order_room_out(drv *d, order_room *o, const finals *f, size_t grp,
                                 size_t total)
{
    size_t busy = o->grp_own ? 0 : f->n[0] + grp + 1; /* grp, until it has been sent */
    size_t got_at = busy > total ? busy : total;
    if (o->blk && got_at <= o->cap && o->cap - got_at >= total) {
        o->got = o->blk + got_at;
    } else {
        o->got = srm_big((total + 1) * sizeof *o->got);
        o->got_own = 1;
    }
    if (o->blk && total <= o->cap) { /* below got, if got is in the block */
        o->out = o->blk;
    } else {
        o->out = srm_big((total + 1) * sizeof *o->out);
        o->out_own = 1;
    }
    return o->got && o->out ? PDT_OK : pdt_drv_nomem(d, "order");
}

/* The exchange's per-peer counts and the received runs (for the ordering). */
typedef struct order_io {
    size_t *cnt, *rcnt, *len;
    const pdt_tri **src;
    uint8_t *in;    /* several rounds: bucket b in this round */
    uint64_t *at;   /* several rounds: where bucket b goes in grp (the spare place if not) */
} order_io;

static void order_io_free(order_io *x)
{
    free(x->cnt);
    free(x->rcnt);
    free(x->len);
    free((void *)x->src);
    free(x->in);
    free(x->at);
}

static pdt_status order_io_make(drv *d, const order_plan *o, order_io *x)
{
    size_t p = (size_t)d->p;
    x->cnt = calloc(p, sizeof *x->cnt);
    x->rcnt = calloc(p, sizeof *x->rcnt);
    x->len = calloc(2 * p, sizeof *x->len);
    x->src = calloc(2 * p, sizeof *x->src);
    if (o->rounds > 1) {
        x->in = malloc(o->nb);
        x->at = malloc(o->nb * sizeof *x->at);
    }
    if (!x->cnt || !x->rcnt || !x->len || !x->src || (o->rounds > 1 && (!x->in || !x->at)))
        return pdt_drv_nomem(d, "order");
    return PDT_OK;
}

/* Round r: the triangles of its buckets grouped, sent, received behind the
 * rounds before (*off of them); each source's run of a round is in bucket
 * order.  A round before the last moves the triangles it leaves to the
 * front of their arrays (f shrinks to them): the rounds read the finals
 * once and then only what is left. */
static pdt_status order_round(drv *d, finals *f, const order_plan *o, order_room *room,
                              order_io *x, int r, size_t *off, pdt_err *err)
{
    int p = d->p;
    if (r == o->rounds - 1) { /* (every triangle left is this round's) */
        for (int k = 0; k < 2; k++) pdt_tri_bucket_scatter(f->t[k], f->n[k], o->shift, o->at, room->grp);
    } else {
        for (size_t b = 0; b < o->nb; b++) { /* (the others: to the spare place) */
            x->in[b] = b % (size_t)o->rounds == (size_t)r;
            x->at[b] = x->in[b] ? o->at[b] : o->most;
        }
        for (int k = 0; k < 2; k++)
            f->n[k] = pdt_tri_bucket_scatter_split(f->t[k], f->n[k], o->shift, x->in, x->at, room->grp);
    }
    pdt_tri *into = room->got + *off;
    for (int q = 0; q < p; q++) {
        size_t i = (size_t)q * (size_t)o->rounds + (size_t)r, j = (size_t)r * (size_t)p + (size_t)q;
        x->cnt[q] = (size_t)o->sc[i] * sizeof(pdt_tri);
        x->rcnt[q] = (size_t)o->rc[i] * sizeof(pdt_tri);
        x->src[j] = room->got + *off;
        x->len[j] = (size_t)o->rc[i];
        *off += x->len[j];
    }
    pdt_status st = pdt_comm_alltoallv(d->c, room->grp, x->cnt, into, x->rcnt, err);
    if (st == PDT_OK) pdt_drv_note_v(d, TAG_ORDER, x->cnt, x->rcnt);
    return st;
}

/* The ordered triangles handed to out (the block shrunk to them when they
 * are in it), with their place in the whole output: the plan's, from the
 * histogram summed over the ranks (no prefix sum: every rank knows which
 * buckets the ranks before it hold). */
static void order_done(drv *d, const order_plan *o, order_room *room, size_t total,
                       pdt_par_output *out)
{
    free(d->more); /* every triangle went somewhere (itself included) */
    d->more = NULL;
    d->nmore = 0;
    d->s[0].fin = NULL; /* the block is room->blk */
    d->s[0].nfin = d->s[0].capfin = 0;
    if (room->out == room->blk) {
        pdt_tri *shrunk = realloc(room->out, (total + 1) * sizeof *room->out);
        room->out = shrunk ? shrunk : room->out;
    } else {
        free(room->blk);
    }
    room->blk = NULL;
    room->out_own = 0;
    out->tris = room->out;
    out->ntri = total;
    out->first = o->first;
    out->n_total = o->all;
    room->out = NULL;
}

/* Phase 4: the final triangles go to the rank of their smallest index's
 * range, which puts them in canonical order: rank q ends with the q-th block
 * of the canonical output in out (and its place in the whole output). */
pdt_status pdt_drv_order(drv *d, pdt_par_output *out, pdt_err *err)
{
    finals f = {{d->s[0].fin, d->more}, {d->s[0].nfin, d->nmore}};
    order_plan o = {0};
    order_room room = {0};
    order_io x = {0};
    pdt_status st = order_plan_make(d, &f, &o, err);
    if (st == PDT_OK) st = order_io_make(d, &o, &x);
    if (st == PDT_OK) st = order_room_grp(d, &room, &f, o.most);
    size_t total = 0, off = 0;
    for (size_t i = 0; st == PDT_OK && i < (size_t)d->p * (size_t)o.rounds; i++)
        total += (size_t)o.rc[i];
    if (st == PDT_OK) st = order_room_out(d, &room, &f, o.most, total);
    for (int r = 0; r < o.rounds && st == PDT_OK; r++)
        st = order_round(d, &f, &o, &room, &x, r, &off, err);
    if (st == PDT_OK &&
        pdt_tri_bucket_order(x.src, x.len, (size_t)d->p * (size_t)o.rounds, o.shift, room.out) != PDT_OK)
        st = pdt_drv_nomem(d, "order");
    if (st == PDT_OK) order_done(d, &o, &room, total, out);
    order_room_free(&room);
    order_plan_free(&o);
    order_io_free(&x);
    return st;
}
