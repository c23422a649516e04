/* pdt — the replay's build: points (first lifts and the ranks' boxes,
 * streamed) and Graham's tables. */
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

static int pt_flush(builder *b, size_t w)
{
    size_t k = b->pbn[w];
    b->pbn[w] = 0;
    return pdt_rp_spill_put(b, PDT_SCR_POINTS, &b->plog, b->pbuf + w * PBUF, k, sizeof(pt_rec), w);
}

int pdt_rp_pt_note(builder *b, uint32_t p, uint32_t ev, uint32_t rank, uint32_t what)
{
    size_t w = p / PT_WINDOW;
    b->pbuf[w * PBUF + b->pbn[w]++] = (pt_rec){p, ev, rank, what};
    return b->pbn[w] < PBUF || pt_flush(b, w);
}

void pdt_rp_box_add(pdt_replay *r, uint32_t rank, pdt_point p)
{
    if (!r->has_box[rank]) {
        r->box_lo[rank] = r->box_hi[rank] = p;
        r->has_box[rank] = 1;
        return;
    }
    if (p.x < r->box_lo[rank].x) r->box_lo[rank].x = p.x;
    if (p.y < r->box_lo[rank].y) r->box_lo[rank].y = p.y;
    if (p.x > r->box_hi[rank].x) r->box_hi[rank].x = p.x;
    if (p.y > r->box_hi[rank].y) r->box_hi[rank].y = p.y;
}

/* The per-point tables of Graham's sort (sort_ev, del_ev, sort_pos), made
 * at the first SORT or DELETE event: a run without any (every
 * triangulation) has none, in memory or in its kept index.  0 when out of
 * memory. */
int pdt_rp_graham_tables(pdt_replay *r)
{
    size_t n = r->n;
    r->sort_ev = pdt_rp_tab_new(r, n * sizeof *r->sort_ev);
    r->del_ev = pdt_rp_tab_new(r, n * sizeof *r->del_ev);
    r->sort_pos = pdt_rp_tab_new(r, n * sizeof *r->sort_pos);
    if (!r->sort_ev || !r->del_ev || !r->sort_pos) {
        pdt_rp_tab_free(r, r->sort_ev);
        pdt_rp_tab_free(r, r->del_ev);
        pdt_rp_tab_free(r, r->sort_pos);
        r->sort_ev = r->del_ev = NULL;
        r->sort_pos = NULL;
        return 0;
    }
    for (size_t p = 0; p < n; p++) {
        r->sort_ev[p] = r->del_ev[p] = NONE32;
        r->sort_pos[p] = -1;
    }
    return 1;
}

#define PT_AHEAD 16 /* records ahead whose point is fetched (points_pass) */

/* After pass 1 (streamed): each window of points' records (pt_rec) gives
 * its first lifts (to lift_at of the place) and its share of the ranks'
 * boxes (lifted_any: the ranks that lifted a point outside a merge). */
static int points_pass(builder *b, const uint8_t *lifted_any)
{
    pdt_replay *r = b->r;
    const pdt_replay_place *pl = b->pl;
    size_t q1 = (size_t)r->nranks;
    for (size_t w = 0; w < b->npw; w++)
        if (!pt_flush(b, w)) return 0;
    /* the chunks by window (each window's in the order written) */
    size_t *start = calloc(b->npw + 1, sizeof *start);
    uint32_t *lift = pdt_rp_bmalloc(b, PT_WINDOW * sizeof *lift);
    pt_rec *rec = pdt_rp_bmalloc(b, PBUF * sizeof *rec);
    pdt_point *lo = malloc(2 * q1 * sizeof *lo), *hi = malloc(2 * q1 * sizeof *hi);
    uint8_t *has = calloc(2 * q1, 1);  /* [0, q1): pushed points' boxes, [q1, 2 q1): lifted */
    int ok = start && lift && rec && lo && hi && has && pdt_rp_spill_group(&b->plog, b->npw, start);
    const spill_chunk *sorted = b->plog.chunk;
    for (size_t w = 0, c = 0; ok && w < b->npw; w++) {
        size_t p0 = w * PT_WINDOW, np = r->n - p0 < PT_WINDOW ? r->n - p0 : PT_WINDOW;
        memset(lift, 0xff, np * sizeof *lift);
        for (; ok && c < start[w + 1]; c++) {
            ok = pl->sget(pl->ctx, PDT_SCR_POINTS, sorted[c].off, rec, sorted[c].n * sizeof *rec);
            for (size_t j = 0; ok && j < sorted[c].n; j++) {
                const pt_rec *t = &rec[j];
                if (j + PT_AHEAD < sorted[c].n && rec[j + PT_AHEAD].what != PT_LIFT) /* (random
                                                  * places in a table of 10^8 bytes) */
                    __builtin_prefetch(&r->pts[rec[j + PT_AHEAD].p]);
                if (t->what != PT_PUSH && t->ev < lift[t->p - p0]) lift[t->p - p0] = t->ev;
                if (t->what == PT_LIFT) continue;
                size_t k = t->what == PT_PUSH ? t->rank : q1 + t->rank;
                pdt_point pt = r->pts[t->p];
                if (!has[k]) {
                    lo[k] = hi[k] = pt;
                    has[k] = 1;
                    continue;
                }
                if (pt.x < lo[k].x) lo[k].x = pt.x;
                if (pt.y < lo[k].y) lo[k].y = pt.y;
                if (pt.x > hi[k].x) hi[k].x = pt.x;
                if (pt.y > hi[k].y) hi[k].y = pt.y;
            }
        }
        ok = ok && pl->put(pl->ctx, r->lift_at + (uint64_t)p0 * sizeof *lift, lift, np * sizeof *lift);
        if (pl->points_read) pl->points_read(pl->ctx);  /* (the window's pages go back) */
    }
    for (size_t q = 0; ok && q < q1; q++) {
        size_t k = lifted_any[q] ? q1 + q : q;
        r->has_box[q] = has[k];
        if (has[k]) r->box_lo[q] = lo[k], r->box_hi[q] = hi[k];
    }
    if (!ok) b->failed = 1;
    free(start);
    pdt_rp_bfree(b, lift, PT_WINDOW * sizeof *lift);
    pdt_rp_bfree(b, rec, PBUF * sizeof *rec);
    free(lo);
    free(hi);
    free(has);
    return ok;
}

static void *points_thread(void *arg)
{
    builder *b = arg;
    b->pt_ok = points_pass(b, b->lifted_any);
    return NULL;
}

/* After the numbering (streamed): the points' pass started on a thread of
 * its own, beside the join and the per-event tables, which take one core (or
 * run here, when no thread can be made).  Its results (the lift table at
 * lift_at, the ranks' boxes) are read by no one before pdt_rp_points_finish.
 * 1, or 0 when it ran here and failed. */
int pdt_rp_points_start(builder *b)
{
    b->pt_ok = 0;
    if (pthread_create(&b->pt_th, NULL, points_thread, b) == 0) { /* (pt_ok is the thread's now) */
        b->pt_started = 1;
        return 1;
    }
    b->pt_started = 0;
    points_thread(b);
    return b->pt_ok;
}

/* Wait for the points' pass (if it runs; also on a failed build's way out),
 * then drop its scratch and buffers.  1 when it succeeded. */
int pdt_rp_points_finish(builder *b)
{
    if (b->pt_started) pthread_join(b->pt_th, NULL);
    b->pt_started = 0;
    if (!b->pt_ok) return 0;
    const pdt_replay_place *pl = b->pl;
    pl->sdrop(pl->ctx, PDT_SCR_POINTS);
    if (pl->points_read) pl->points_read(pl->ctx);
    pdt_rp_bfree(b, b->pbuf, (b->npw ? b->npw : 1) * PBUF * sizeof *b->pbuf);
    b->pbuf = NULL;
    b->pt_ok = 0;
    return 1;
}
