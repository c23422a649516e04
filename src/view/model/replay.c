/* pdt — the replay model: index the events once, then answer "state at k".
 * This file: the build's plan and passes, the builder's memory, and the
 * replay's accessors. */
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

/* The builder's accounting of its working memory (streamed builds): what
 * pdt_rp_bmalloc gives, until pdt_rp_bfree. */
void *pdt_rp_bmalloc(builder *b, size_t bytes)
{
    void *p = malloc(bytes ? bytes : 1);
    if (!p) return NULL;
    uint64_t now = atomic_fetch_add(&b->held, bytes) + bytes, pk = atomic_load(&b->peak);
    while (now > pk && !atomic_compare_exchange_weak(&b->peak, &pk, now)) {}
    return p;
}

void pdt_rp_bfree(builder *b, void *p, size_t bytes)
{
    if (!p) return;
    free(p);
    atomic_fetch_sub(&b->held, bytes);
}

/* A big table of `bytes` (malloc'd, asking for huge pages), or NULL. */
static void *big_table(size_t bytes)
{
    void *p = malloc(bytes ? bytes : 1);
    if (p) pdt_big_advise(p, bytes);
    return p;
}

/* Write n entries of `elem` bytes from p at entry `at` of the table at `base`
 * of the place (streamed) or of the array `arr`. */
int pdt_rp_tput(builder *b, void *arr, uint64_t base, size_t at, const void *p, size_t n, size_t elem)
{
    if (!n) return 1;
    if (!b->pl) {
        memcpy((char *)arr + at * elem, p, n * elem);
        return 1;
    }
    if (!b->pl->put(b->pl->ctx, base + (uint64_t)at * elem, p, n * elem)) b->failed = 1;
    return !b->failed;
}

/* Flush the buffer of fine bucket f (streamed) to the end of the spill, a
 * chunk of it (in pass 1, by the spill's writer). */
int pdt_rp_fine_flush(builder *b, size_t f)
{
    size_t k = b->fbn[f];
    b->fbn[f] = 0;
    if (b->sw_live) {
        if (k) pdt_rp_sw_queue(b, f, k);
        return !b->failed;
    }
    return pdt_rp_spill_put(b, PDT_SCR_SPILL, &b->tlog, b->fcur[f], k, sizeof(tri_xrec), f);
}

/* Streamed pass 1: have events i .. i + PREFETCH_AHEAD (or to the end) in
 * the window.  0 when the stream failed or ended early (err set). */
static int win_fill(builder *b, size_t i, pdt_err *err)
{
    size_t end = b->win_lo + b->win_n;
    if (i + PREFETCH_AHEAD < end || end == b->r->m) return 1;
    size_t keep = end - i;
    memmove(b->win, b->win + (i - b->win_lo), keep * sizeof *b->win);
    b->win_lo = i;
    size_t want = WIN - keep;
    if (want > b->r->m - end) want = b->r->m - end;
    int got = b->pl->next(b->pl->ctx, b->win + keep, want, err);
    if (got < 0 || (got == 0 && keep == 0)) {
        if (got == 0) pdt_err_set(err, PDT_ERR_FORMAT, "the run has fewer events than counted");
        b->stream_failed = 1;
        return 0;
    }
    b->win_n = keep + (size_t)got;
    return 1;
}

/* After pass 1 (streamed): the chunks ordered by fine bucket, each
 * bucket's in the order written (its events' order). */
int pdt_rp_chunks_by_bucket(builder *b)
{
    b->ck_start = calloc(b->nfine + 1, sizeof *b->ck_start);
    return b->ck_start && pdt_rp_spill_group(&b->tlog, b->nfine, b->ck_start);
}

/* What a streamed build of n points holds in memory besides its working
 * set: the run's points (the caller's), and some room for the small tables
 * (a run with Graham's sort holds 16 bytes more per point). */
static uint64_t held_bytes(size_t n)
{
    return (uint64_t)n * sizeof(pdt_point) + ((uint64_t)16 << 20);
}

/* tri_groups' share of a streamed build's budget: what the replay does not hold. */
uint64_t pdt_rp_group_work(const pdt_replay *r, uint64_t budget)
{
    uint64_t held = held_bytes(r->n);
    return budget > held + budget / 4 ? budget - held : budget / 4;
}

/* What a plan holds: one bucket's grouping, the buckets' buffers (pass 1's
 * records, the cursors' three records) and what a bucket costs besides,
 * and the spill's chunk table (a chunk per fbuf records). */
static uint64_t plan_bytes(uint64_t m, unsigned bits, uint64_t fbuf, uint64_t cur)
{
    uint64_t nf = (uint64_t)1 << bits;
    return ((m >> bits) + 1) * GROUP_BYTES_PER_EVENT + /* (every event of the run, as if a triangle's) */
           nf * (fbuf * sizeof(tri_xrec) + cur * (sizeof(tri_first) + 4 + sizeof(pdt_rtri_hist)) + 160) +
           (m / fbuf + nf) * sizeof(spill_chunk);
}

/* The fine buckets of a streamed build (the kept index; replay_int.h):
 * the grouping holds at least one whole bucket, and more buckets make the
 * build slower, so the fewest (from 2^8, doubling; the largest buffers
 * first) whose plan_bytes fit half the budget (or PLAN_ROOM_MIN: 2^8 with
 * full buffers for every run up to 10^9 events at the default budget,
 * 1.1·10^8 under any); when none does, the plan that holds least (2^8 to
 * 2^16 buckets, buffers of 32 to 1024 records). */
unsigned pdt_replay_plan_buckets(uint64_t m, uint64_t budget, size_t *fbuf_recs, size_t *cur_recs,
                                 uint64_t *bytes)
{
    uint64_t room = budget / 2 > PLAN_ROOM_MIN ? budget / 2 : PLAN_ROOM_MIN;
    unsigned best_bits = FINE_BITS;
    uint64_t best_f = FBUF, best_c = CUR_RECS, best = UINT64_MAX;
    for (unsigned bits = FINE_BITS; bits <= FINE_BITS_MAX && best > room; bits++)
        for (uint64_t f = FBUF; f >= 32 && best > room; f /= 2) {
            uint64_t c = f < CUR_RECS ? f : CUR_RECS, got = plan_bytes(m, bits, f, c);
            if (got < best) best = got, best_bits = bits, best_f = f, best_c = c;
        }
    *fbuf_recs = (size_t)best_f;
    *cur_recs = (size_t)best_c;
    if (bytes) *bytes = best;
    return best_bits;
}

/* The builder's fine buckets (fine_bits, nfine) and buffers (fbuf_recs,
 * cur_recs): held in memory, 2^FINE_BITS; streamed, as planned, or as
 * $PDTVIEW_BUCKETS says (a power of two from 2^8 to 2^16: the tests' runs
 * are far below where the plan changes). */
static void bucket_plan(builder *b, uint64_t m, uint64_t budget)
{
    b->fine_bits = FINE_BITS;
    b->fbuf_recs = FBUF;
    b->cur_recs = CUR_RECS;
    if (b->pl) {
        b->fine_bits = pdt_replay_plan_buckets(m, budget, &b->fbuf_recs, &b->cur_recs, NULL);
        const char *env = getenv("PDTVIEW_BUCKETS");
        unsigned long want = env ? strtoul(env, NULL, 10) : 0;
        for (unsigned bits = FINE_BITS; bits <= FINE_BITS_MAX; bits++)
            if (want == 1ul << bits) { /* (with small buffers, as the plan would) */
                b->fine_bits = bits;
                b->fbuf_recs = b->cur_recs = 64;
            }
    }
    b->nfine = (size_t)1 << b->fine_bits;
}

/* The builder for replay r (streamed to pl, or held in memory): the
 * buckets planned, and the tables sized (in memory: once, from counts of
 * the events that create objects and of the triangle events per bucket;
 * streamed: the events come once, the buckets are spilled in chunks,
 * counted as they come, and the small tables grow).  0 when out of memory. */
static int builder_open(builder *b, pdt_replay *r, const pdt_replay_place *pl)
{
    memset(b, 0, sizeof *b);
    b->r = r;
    b->pl = pl;
    size_t nslot = (size_t)r->nranks * PDT_SLOT_PER_RANK;
    b->cur = malloc((nslot ? nslot : 1) * sizeof *b->cur);
    b->lastst = calloc((size_t)r->nranks + 1, sizeof *b->lastst);
    bucket_plan(b, r->m, pl ? pl->budget : 0);
    b->fine_fill = calloc(b->nfine, sizeof *b->fine_fill);
    b->fine_off = calloc(b->nfine + 1, sizeof *b->fine_off);
    b->lifted_any = calloc((size_t)r->nranks + 1, 1);
    if (!b->cur || !b->lastst || !b->lifted_any || !b->fine_fill || !b->fine_off) return 0;
    for (size_t s = 0; s < nslot; s++) b->cur[s] = -1;
    for (int q = 0; q < r->nranks; q++) b->lastst[q] = -1;
    size_t cnt[PDT_EV_KIND_COUNT] = {0};
    for (size_t i = 0; !pl && i < r->m; i++) {
        const pdt_rec *rec = rec_at(r, i);
        if (rec->ev.kind < PDT_EV_KIND_COUNT) cnt[rec->ev.kind]++;
        size_t f = pdt_replay_fine_of(rec, r->n, r->nranks);
        if (f < b->nfine) b->fine_off[f + 1]++;
    }
    for (size_t f = 0; f < b->nfine; f++) b->fine_off[f + 1] += b->fine_off[f];
    memcpy(b->fine_fill, b->fine_off, b->nfine * sizeof *b->fine_fill);
    r->nhist = b->fine_off[b->nfine];
    if (pl) {
        r->streamed = 1;
        r->evobj_at = pl->evobj_at;
        r->evkind_at = pl->evkind_at;
        b->fbuf = pdt_rp_bmalloc(b, b->nfine * b->fbuf_recs * sizeof *b->fbuf);
        b->fbn = calloc(b->nfine, sizeof *b->fbn);
        b->win = pdt_rp_bmalloc(b, WIN * sizeof *b->win);
        b->wobj = pdt_rp_bmalloc(b, EVW * sizeof *b->wobj);
        b->wkind = pdt_rp_bmalloc(b, EVW);
        b->tcount = calloc(b->nfine, sizeof *b->tcount);
        b->npw = (r->n + PT_WINDOW - 1) / PT_WINDOW;
        b->pbuf = pdt_rp_bmalloc(b, (b->npw ? b->npw : 1) * PBUF * sizeof *b->pbuf);
        b->pbn = calloc(b->npw + 1, sizeof *b->pbn);
        if (!b->fbuf || !b->fbn || !b->win || !b->wobj || !b->wkind || !b->tcount || !b->pbuf || !b->pbn)
            return 0;
        pdt_big_advise(b->fbuf, b->nfine * b->fbuf_recs * sizeof *b->fbuf);
        if (!pdt_rp_sw_start(b)) return 0;
    } else {
        b->wobj = r->ev_obj;
        b->wkind = r->ev_kind;
        r->hist = big_table(r->nhist * sizeof *r->hist);
        r->tris = big_table(r->nhist * sizeof *r->tris); /* at most one per event */
        r->cap_tri = r->nhist;
        b->spill = big_table(r->nhist * sizeof *b->spill);
        if (!r->hist || !r->tris || !b->spill) return 0;
    }
    return pdt_rp_km_alloc(&b->edge_map, cnt[PDT_EV_EDGE_ADD], r->tab_limit) &&
           pdt_rp_km_alloc(&b->msg_map, cnt[PDT_EV_SEND], r->tab_limit) &&
           pdt_rp_tab_grow(r, (void **)&r->edges, &r->cap_edge, cnt[PDT_EV_EDGE_ADD], sizeof *r->edges) &&
           pdt_rp_tab_grow(r, (void **)&r->nodes, &r->cap_node, cnt[PDT_EV_PUSH], sizeof *r->nodes);
}

/* Whether an event of this kind has a place to fetch ahead
 * (pdt_rp_probe_addr): a point's first lift, sort or deletion where those
 * tables are held, an edge.  (Checked here, without a call for every
 * event: most are triangles'.) */
static inline int probe_wanted(const pdt_replay *r, int kind)
{
    return (kind == PDT_EV_LIFT && r->lift_ev) ||
           ((kind == PDT_EV_SORT || kind == PDT_EV_DELETE) && r->sort_ev) ||
           kind == PDT_EV_EDGE_ADD || kind == PDT_EV_EDGE_DEL;
}

/* Pass 1: every event once, in order (streamed: from pl's stream, a window
 * at a time, the per-event tables written out a window at a time). */
static int first_pass(builder *b, pdt_err *err)
{
    pdt_replay *r = b->r;
    const pdt_replay_place *pl = b->pl;
    for (size_t i = 0; i < r->m; i++) {
        pdt_rp_drop_recs(b, i);
        if (pl && (!win_fill(b, i, err) || (i - b->wlo == EVW && !pdt_rp_ev_window(b, i)))) return 0;
        set_obj(b, i, -1);
        if (r->ev_ent) r->ev_ent[i] = 0;
        const pdt_rec *rec = pl ? &b->win[i - b->win_lo] : rec_at(r, i);
        b->wkind[i - b->wlo] = rec->ev.kind < KIND_UNKNOWN ? rec->ev.kind : KIND_UNKNOWN;
        if (rec->rank >= (uint32_t)r->nranks) {
            r->skipped++;
            continue;
        }
        if (pl ? i + PREFETCH_AHEAD < b->win_lo + b->win_n : i + PREFETCH_AHEAD < r->m) {
            const pdt_rec *ahead = pl ? &b->win[i + PREFETCH_AHEAD - b->win_lo] : rec_at(r, i + PREFETCH_AHEAD);
            const void *also = NULL, *p = NULL;
            if (probe_wanted(r, ahead->ev.kind)) p = pdt_rp_probe_addr(b, ahead, &also);
            if (p) __builtin_prefetch(p);
            if (also) __builtin_prefetch(also);
        }
        if (rec->ev.kind < PDT_EV_KIND_COUNT) r->kind_count[rec->ev.kind]++;
        if (!pdt_rp_index_event(b, (uint32_t)i, rec)) return 0;
        if (i % TICK_EVENTS == TICK_EVENTS - 1) { /* (paged tables: their pages go back) */
            pdt_rp_tabs_give_back(r);
            pdt_rp_km_give_back(&b->edge_map);
            pdt_rp_km_give_back(&b->msg_map);
        }
    }
    return 1;
}

/* After pass 1 (streamed): the stream's end (it finishes its part: pl->src
 * is ready), the last window of the per-event tables, and the place of the
 * points' first lifts (made with the ranks' boxes after the numbering,
 * pdt_rp_points_start). */
static int stream_end(builder *b, pdt_err *err)
{
    pdt_replay *r = b->r;
    const pdt_replay_place *pl = b->pl;
    pdt_rp_sw_stop(b); /* (the spill complete) */
    pdt_rec extra;
    int more = pl->next(pl->ctx, &extra, 1, err);
    if (more != 0) {
        if (more > 0) pdt_err_set(err, PDT_ERR_FORMAT, "the run has more events than counted");
        b->stream_failed = 1;
        return 0;
    }
    pdt_rp_bfree(b, b->win, WIN * sizeof *b->win);
    b->win = NULL;
    if (!pdt_rp_ev_window(b, r->m)) return 0;
    pdt_rp_bfree(b, b->wobj, EVW * sizeof *b->wobj);
    pdt_rp_bfree(b, b->wkind, EVW);
    b->wobj = NULL;
    b->wkind = NULL;
    return (r->lift_at = pl->reserve(pl->ctx, (uint64_t)r->n * sizeof(uint32_t))) != UINT64_MAX;
}

/* The phases that open a cluster of overlapping same phases (any rank). */
static int phase_clusters(pdt_replay *r)
{
    keymap last_end;
    memset(&last_end, 0, sizeof last_end);
    int ok = 1;
    for (size_t p = 0; ok && p < r->nphase; p++) {
        pdt_rphase *ph = &r->phases[p];
        int32_t end;
        int have = pdt_rp_km_get(&last_end, ph->phase, ph->sub, &end);
        uint32_t e = ph->end_ev == NONE32 ? (uint32_t)INT32_MAX : ph->end_ev;
        ph->first = !have || (uint32_t)end < ph->begin_ev;
        if (!have || (uint32_t)end < e)
            ok = pdt_rp_km_put(&last_end, ph->phase, ph->sub, (int32_t)(e > INT32_MAX ? INT32_MAX : e), 0);
    }
    pdt_rp_km_free(&last_end);
    return ok;
}

/* The slot changes grouped by slot (a counting sort: event order kept). */
static int slot_index(pdt_replay *r)
{
    size_t nslot = (size_t)r->nranks * PDT_SLOT_PER_RANK;
    r->slot_start = calloc(nslot + 1, sizeof *r->slot_start);
    r->slot_ch = pdt_rp_tab_new(r, (r->nch ? r->nch : 1) * sizeof *r->slot_ch);
    uint32_t *fill = malloc((nslot ? nslot : 1) * sizeof *fill);
    if (!r->slot_start || !r->slot_ch || !fill) {
        free(fill);
        return 0;
    }
    for (size_t c = 0; c < r->nch; c++) r->slot_start[r->ch[c].slot + 1]++;
    for (size_t s = 0; s < nslot; s++) r->slot_start[s + 1] += r->slot_start[s];
    memcpy(fill, r->slot_start, nslot * sizeof *fill);
    for (size_t c = 0; c < r->nch; c++) {
        r->slot_ch[fill[r->ch[c].slot]++] = (uint32_t)c;
        if (c % TICK_EVENTS == TICK_EVENTS - 1) pdt_rp_tabs_give_back(r);
    }
    free(fill);
    pdt_rp_tabs_give_back(r);
    return 1;
}

/* Free the builder; the build's status from ok and what failed. */
static pdt_status builder_close(builder *b, int ok, pdt_err *err)
{
    pdt_replay *r = b->r;
    pdt_rp_points_finish(b); /* (a failed build's: it may still run) */
    pdt_rp_sw_free(b);
    free(b->cur);
    free(b->lastst);
    free(b->lifted_any);
    free(b->fine_fill);
    free(b->fine_off);
    if (b->pl) {
        pdt_rp_bfree(b, b->fbuf, b->nfine * b->fbuf_recs * sizeof *b->fbuf);
        pdt_rp_bfree(b, b->win, WIN * sizeof *b->win);
        pdt_rp_bfree(b, b->wobj, EVW * sizeof *b->wobj);
        pdt_rp_bfree(b, b->wkind, EVW);
        pdt_rp_bfree(b, b->pbuf, (b->npw ? b->npw : 1) * PBUF * sizeof *b->pbuf);
        r->build_peak = atomic_load(&b->peak);
        r->build_buckets = (uint32_t)b->nfine;
    } else {
        free(b->fbuf);
        free(b->win);
    }
    free(b->pbn);
    free(b->plog.chunk);
    free(b->tcount);
    free(b->fbn);
    free(b->spill);
    free(b->tlog.chunk);
    free(b->ck_start);
    pdt_rp_km_free(&b->edge_map);
    pdt_rp_km_free(&b->msg_map);
    if (ok) return PDT_OK;
    if (b->stream_failed) return err->code ? err->code : PDT_ERR_IO;
    if (b->failed) return pdt_err_set(err, PDT_ERR_IO, "the index file: %s", strerror(errno));
    return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory indexing %zu events", r->m);
}

/* Build replay r: its tables, in memory or streamed to pl (the kept index). */
static pdt_status build(pdt_replay *r, const pdt_replay_place *pl, pdt_err *err)
{
    builder b;
    int ok = builder_open(&b, r, pl) &&     /* the buckets planned, the tables sized */
             first_pass(&b, err) &&          /* every event once */
             (!pl || stream_end(&b, err)) && /* the stream's end, the spill complete */
             phase_clusters(r) &&
             pdt_rp_tri_histories(&b) &&     /* grouped by triangle, numbered; the points' pass */
             slot_index(r);
    return builder_close(&b, ok, err);
}

pdt_status pdt_replay_new(const pdt_point *pts, size_t n, const pdt_rec *recs, size_t m,
                          int nranks, pdt_replay **out, pdt_err *err)
{
    return pdt_replay_build(pts, n, recs, m, nranks, NULL, out, err);
}

pdt_status pdt_replay_build(const pdt_point *pts, size_t n, const pdt_rec *recs, size_t m,
                            int nranks, const pdt_replay_place *pl, pdt_replay **out, pdt_err *err)
{
    *out = NULL;
    if (m >= NONE32 || n >= NONE32)
        return pdt_err_set(err, PDT_ERR_ARG, "too many events or points (%zu, %zu)", m, n);
    if (!recs && m && (!pl || !pl->src || nranks <= 0))
        return pdt_err_set(err, PDT_ERR_ARG, "no events to build a replay of");
    if (nranks <= 0) {
        uint32_t mx = 0;
        for (size_t i = 0; i < m; i++)
            if (recs[i].rank > mx) mx = recs[i].rank;
        nranks = m ? (int)mx + 1 : 1;
    }
    pdt_replay *r = calloc(1, sizeof *r);
    if (!r) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    r->pts = pts;
    r->n = n;
    r->recs = recs;
    r->src = recs || !pl ? NULL : pl->src;
    r->m = m;
    r->nranks = nranks;
    if (pl && pl->budget) /* (a sixteenth: some ten tables, and the build's own) */
        r->tab_limit = pl->budget / 16 > 4096 ? pl->budget / 16 : 4096;
    size_t q1 = (size_t)nranks;
    if (!pl) { /* (streamed: none per event or point in memory) */
        r->ev_obj = big_table(m * sizeof *r->ev_obj);
        r->ev_ent = big_table(m * sizeof *r->ev_ent);
        r->ev_kind = big_table(m * sizeof *r->ev_kind);
        r->lift_ev = big_table(n * sizeof *r->lift_ev);
    }
    r->box_lo = malloc(q1 * sizeof *r->box_lo);
    r->box_hi = malloc(q1 * sizeof *r->box_hi);
    r->has_box = calloc(q1, 1);
    if ((!pl && (!r->ev_obj || !r->ev_ent || !r->ev_kind || !r->lift_ev)) ||
        !r->box_lo || !r->box_hi || !r->has_box) {
        pdt_replay_free(r);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory for %zu events", m);
    }
    for (size_t p = 0; r->lift_ev && p < n; p++) r->lift_ev[p] = NONE32;
    pdt_status st = build(r, pl, err);
    if (st != PDT_OK) {
        pdt_replay_free(r);
        return st;
    }
    if (!pl) { /* stepping finds a triangle's first entry in tris (streamed: the caller
                * steps before it writes tris, and frees ev_ent with the replay) */
        free(r->ev_ent);
        r->ev_ent = NULL;
    }
    *out = r;
    return PDT_OK;
}

void pdt_replay_free(pdt_replay *r)
{
    if (!r) return;
    for (size_t c = 0; c < r->nck; c++) pdt_rstate_free(r->ck[c]);
    free(r->ck);
    if (r->map) { /* the tables live in the kept index's mapping */
        pdt_index_unmap(r);
        free(r);
        return;
    }
    free(r->ev_obj);
    free(r->ev_ent);
    free(r->ev_kind);
    free(r->tris);
    free(r->hist);
    free(r->lift_ev);
    pdt_rp_tab_free(r, r->sort_ev);
    pdt_rp_tab_free(r, r->del_ev);
    pdt_rp_tab_free(r, r->sort_pos);
    pdt_rp_tab_free(r, r->edges);
    pdt_rp_tab_free(r, r->nodes);
    pdt_rp_tab_free(r, r->phases);
    pdt_rp_tab_free(r, r->merges);
    pdt_rp_tab_free(r, r->msgs);
    pdt_rp_tab_free(r, r->hulls);
    pdt_rp_tab_free(r, r->ch);
    pdt_rp_tab_free(r, r->slot_ch);
    free(r->slot_start);
    free(r->box_lo);
    free(r->box_hi);
    free(r->has_box);
    free(r);
}

size_t pdt_replay_count(const pdt_replay *r) { return r->m; }
size_t pdt_replay_skipped(const pdt_replay *r) { return r->skipped; }

size_t pdt_replay_kind_count(const pdt_replay *r, int kind)
{
    return kind >= 0 && kind < PDT_EV_KIND_COUNT ? r->kind_count[kind] : 0;
}
int pdt_replay_nranks(const pdt_replay *r) { return r->nranks; }
const char *pdt_replay_run_warnings(const pdt_replay *r) { return r->warnings ? r->warnings : ""; }

const pdt_point *pdt_replay_points(const pdt_replay *r, size_t *n)
{
    *n = r->n;
    ix_check_points(r);
    return r->pts;
}

const pdt_rec *pdt_replay_rec(const pdt_replay *r, size_t i) { return i < r->m ? rec_at(r, i) : NULL; }

uint32_t pdt_replay_rank_of(const pdt_replay *r, size_t i)
{
    if (i >= r->m) return UINT32_MAX;
    return r->recs ? r->recs[i].rank : pdt_evsrc_rank(r->src, i);
}

#define TABLE(fn, type, arr, cnt)                                \
    const type *fn(const pdt_replay *r, size_t *n)               \
    {                                                            \
        *n = r->cnt;                                             \
        return r->arr;                                           \
    }
TABLE(pdt_replay_tris, pdt_rtri, tris, ntri)
TABLE(pdt_replay_edges, pdt_redge, edges, nedge)
TABLE(pdt_replay_nodes, pdt_rnode, nodes, nnode)
TABLE(pdt_replay_phases, pdt_rphase, phases, nphase)
TABLE(pdt_replay_merges, pdt_rmerge, merges, nmerge)
TABLE(pdt_replay_msgs, pdt_rmsg, msgs, nmsg)
TABLE(pdt_replay_hulls, pdt_rhull, hulls, nhull)
#undef TABLE

const pdt_rtri_hist *pdt_replay_tri_hist(const pdt_replay *r) { return r->hist; }

int64_t pdt_replay_sort_pos(const pdt_replay *r, size_t p)
{
    return p < r->n && r->sort_pos && ix_check_point(r, p) ? r->sort_pos[p] : -1;
}

uint32_t pdt_replay_lift_ev(const pdt_replay *r, size_t p)
{
    return p < r->n && ix_check_point(r, p) ? r->lift_ev[p] : NONE32;
}

int pdt_replay_box(const pdt_replay *r, int rank, pdt_point *lo, pdt_point *hi)
{
    if (rank < 0 || rank >= r->nranks || !r->has_box[rank]) return 0;
    *lo = r->box_lo[rank];
    *hi = r->box_hi[rank];
    return 1;
}

int pdt_replay_bbox(const pdt_replay *r, pdt_point *lo, pdt_point *hi)
{
    if (!r->n) return 0;
    /* a kept index's run (its points never change) is scanned once, at the
     * first frame: 8 bytes a point read at every frame otherwise */
    pdt_replay *w = (pdt_replay *)r;
    if (!w->bbox_known) {
        if (!ix_check_points(r)) return 0;
        pdt_point a = r->pts[0], b = r->pts[0];
        for (size_t p = 1; p < r->n; p++) {
            if (p % ((size_t)1 << 21) == 0 && r->release_points) r->release_points(r->release_ctx);
            pdt_point q = r->pts[p];
            if (q.x < a.x) a.x = q.x;
            if (q.y < a.y) a.y = q.y;
            if (q.x > b.x) b.x = q.x;
            if (q.y > b.y) b.y = q.y;
        }
        w->bbox_lo = a;
        w->bbox_hi = b;
        w->bbox_known = r->map != NULL;
    }
    *lo = w->bbox_lo;
    *hi = w->bbox_hi;
    return 1;
}
