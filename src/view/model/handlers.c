/* pdt — the replay's build, pass 1: one handler per kind of event. */
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

static int set_slot(builder *b, uint32_t ev, int rank, int slot, int32_t val)
{
    pdt_replay *r = b->r;
    size_t s = (size_t)rank * PDT_SLOT_PER_RANK + (size_t)slot;
    if (!pdt_rp_tab_grow(r, (void **)&r->ch, &r->cap_ch, r->nch + 1, sizeof *r->ch)) return 0;
    if (r->nch >= INT32_MAX) return 0;
    r->ch[r->nch] = (slot_change){ev, val, b->cur[s], (uint32_t)s};
    set_obj(b, ev, (int32_t)r->nch);  /* the change (its slot: ch[].slot) */
    r->nch++;
    b->cur[s] = val;
    return 1;
}

/* Ancestor of node t at depth d (or the deepest above it). */
static int32_t node_at_depth(const pdt_replay *r, int32_t t, uint32_t d)
{
    while (t >= 0 && r->nodes[t].depth > d) t = r->nodes[t].parent;
    return t;
}

/* ---- pass 1: one handler per kind of event ------------------------------------
 *
 * Each makes or completes the object its event names (and the build's
 * current slots of its rank); a malformed event (a point, rank or stack
 * beyond the run's) is counted as skipped.  0 only when out of memory or a
 * write failed. */

#define IX_ARGS builder *b, uint32_t i, const pdt_rec *rec
#define IX_CUR (b->cur + (size_t)rec->rank * PDT_SLOT_PER_RANK)

static int ix_phase_begin(IX_ARGS)
{
    pdt_replay *r = b->r;
    const pdt_event *e = &rec->ev;
    if (!pdt_rp_tab_grow(r, (void **)&r->phases, &r->cap_phase, r->nphase + 1, sizeof *r->phases)) return 0;
    r->phases[r->nphase] = (pdt_rphase){rec->rank, e->sub, e->a, i, NONE32, IX_CUR[PDT_SLOT_PHASE], 0,
                                              e->t, 0};
    r->nphase++;
    return set_slot(b, i, (int)rec->rank, PDT_SLOT_PHASE, (int32_t)(r->nphase - 1));
}

static int ix_phase_end(IX_ARGS)
{
    pdt_replay *r = b->r;
    int32_t p = IX_CUR[PDT_SLOT_PHASE];
    while (p >= 0 && r->phases[p].phase != rec->ev.sub) p = r->phases[p].parent;
    if (p < 0) {
        r->skipped++;
        return 1;
    }
    r->phases[p].end_ev = i;
    r->phases[p].end_t = rec->ev.t;
    return set_slot(b, i, (int)rec->rank, PDT_SLOT_PHASE, r->phases[p].parent);
}

static int ix_merge_begin(IX_ARGS)
{
    pdt_replay *r = b->r;
    const pdt_event *e = &rec->ev;
    if (!pdt_rp_tab_grow(r, (void **)&r->merges, &r->cap_merge, r->nmerge + 1, sizeof *r->merges)) return 0;
    r->merges[r->nmerge] = (pdt_rmerge){rec->rank, e->sub, e->a, e->b, e->c, i, NONE32, 0, 0, 0, 0,
                                              e->t, 0};
    r->nmerge++;
    return set_slot(b, i, (int)rec->rank, PDT_SLOT_MERGE, (int32_t)(r->nmerge - 1));
}

static int ix_merge_end(IX_ARGS)
{
    pdt_replay *r = b->r;
    const pdt_event *e = &rec->ev;
    int32_t g = IX_CUR[PDT_SLOT_MERGE];
    if (g < 0) {
        r->skipped++;
        return 1;
    }
    pdt_rmerge *mg = &r->merges[g];
    mg->end_ev = i;
    mg->end_t = e->t;
    mg->shipped = e->a;
    mg->border = e->b;
    mg->kept = e->c;
    mg->discarded = (uint32_t)e->v;
    return set_slot(b, i, (int)rec->rank, PDT_SLOT_MERGE, -1);
}

/* A push makes a stack node (its parent the node below it); a pop moves the
 * stack's slot down to the node at the depth it names. */
static int ix_stack(IX_ARGS)
{
    pdt_replay *r = b->r;
    const pdt_event *e = &rec->ev;
    int rank = (int)rec->rank;
    if (e->sub >= 5 || e->a >= r->n) {
        r->skipped++;
        return 1;
    }
    int slot = PDT_SLOT_STACK0 + e->sub;
    int32_t t = IX_CUR[slot];
    b->lastst[rank] = e->sub;
    if (e->kind == PDT_EV_POP) return set_slot(b, i, rank, slot, node_at_depth(r, t, e->b));
    uint32_t d = e->b ? e->b : (t >= 0 ? r->nodes[t].depth + 1 : 1);
    int32_t parent = node_at_depth(r, t, d - 1);
    if (!pdt_rp_tab_grow(r, (void **)&r->nodes, &r->cap_node, r->nnode + 1, sizeof *r->nodes)) return 0;
    r->nodes[r->nnode] = (pdt_rnode){e->a, parent, d, NONE32};
    r->nnode++;
    if (!b->lifted_any[rank]) {
        if (b->pl && !pdt_rp_pt_note(b, e->a, i, rec->rank, PT_PUSH)) return 0;
        if (!b->pl) pdt_rp_box_add(r, rec->rank, r->pts[e->a]);
    }
    return set_slot(b, i, rank, slot, (int32_t)(r->nnode - 1));
}

/* A hull: the tops of the stacks its rank touched last. */
static int ix_hull(IX_ARGS)
{
    pdt_replay *r = b->r;
    const pdt_event *e = &rec->ev;
    const int32_t *cur = IX_CUR;
    if (!pdt_rp_tab_grow(r, (void **)&r->hulls, &r->cap_hull, r->nhull + 1, sizeof *r->hulls)) return 0;
    int st = b->lastst[rec->rank];
    pdt_rhull h = {rec->rank, i, -1, -1, e->a, (uint8_t)(e->b != 0), {0, 0, 0}};
    if (st == PDT_STACK_LOWER || st == PDT_STACK_UPPER) {
        h.top = cur[PDT_SLOT_STACK0 + PDT_STACK_LOWER];
        h.top2 = cur[PDT_SLOT_STACK0 + PDT_STACK_UPPER];
    } else if (st == PDT_STACK_MERGE_LOWER || st == PDT_STACK_MERGE_UPPER) {
        h.top = cur[PDT_SLOT_STACK0 + PDT_STACK_MERGE_LOWER];
        h.top2 = cur[PDT_SLOT_STACK0 + PDT_STACK_MERGE_UPPER];
    } else if (st == PDT_STACK_GRAHAM) {
        h.top = cur[PDT_SLOT_STACK0 + PDT_STACK_GRAHAM];
    }
    if (h.top >= 0 && r->nodes[h.top].hull_ev == NONE32) r->nodes[h.top].hull_ev = i;
    if (h.top2 >= 0 && r->nodes[h.top2].hull_ev == NONE32) r->nodes[h.top2].hull_ev = i;
    r->hulls[r->nhull] = h;
    r->nhull++;
    return set_slot(b, i, (int)rec->rank, PDT_SLOT_HULL, (int32_t)(r->nhull - 1));
}

/* A lift, sort or deletion of a point: its first such event; a lift outside
 * a merge also counts for its rank's box. */
static int ix_point(IX_ARGS)
{
    pdt_replay *r = b->r;
    const pdt_event *e = &rec->ev;
    const int32_t *cur = IX_CUR;
    int rank = (int)rec->rank;
    if (e->a >= r->n) {
        r->skipped++;
        return 1;
    }
    if (e->kind != PDT_EV_LIFT && !r->sort_ev && !pdt_rp_graham_tables(r)) return 0;
    uint32_t *first = e->kind == PDT_EV_LIFT ? r->lift_ev : e->kind == PDT_EV_SORT ? r->sort_ev : r->del_ev;
    set_obj(b, i, (int32_t)e->a);
    if (!first) { /* a streamed build's lift (see pt_rec) */
    } else if (first[e->a] == NONE32) {
        first[e->a] = i;
        if (e->kind == PDT_EV_SORT) r->sort_pos[e->a] = e->b;
    }
    if (e->kind != PDT_EV_LIFT) return 1;
    int32_t ph = cur[PDT_SLOT_PHASE];
    int in_merge = cur[PDT_SLOT_MERGE] >= 0;
    for (; ph >= 0 && !in_merge; ph = r->phases[ph].parent)
        if (r->phases[ph].phase == PDT_PH_MERGE) in_merge = 1;
    if (b->pl) {
        if (!in_merge) b->lifted_any[rank] = 1;
        return pdt_rp_pt_note(b, e->a, i, rec->rank, in_merge ? PT_LIFT : PT_LIFT_BOX);
    }
    if (!in_merge) {
        if (!b->lifted_any[rank]) r->has_box[rank] = 0; /* forget pushed points */
        b->lifted_any[rank] = 1;
        pdt_rp_box_add(r, rec->rank, r->pts[e->a]);
    }
    return 1;
}

/* A kernel edge (trace level 2): made by its ADD, ended by its DEL. */
static int ix_edge(IX_ARGS)
{
    pdt_replay *r = b->r;
    const pdt_event *e = &rec->ev;
    if (e->a >= r->n || e->b >= r->n) {
        r->skipped++;
        return 1;
    }
    uint32_t lo = e->a < e->b ? e->a : e->b, hi = e->a < e->b ? e->b : e->a;
    uint64_t k = ((uint64_t)lo << 32) | hi;
    int32_t id;
    int have = pdt_rp_km_get(&b->edge_map, rec->rank, k, &id) && id >= 0;
    if (e->kind == PDT_EV_EDGE_ADD) {
        if (!pdt_rp_tab_grow(r, (void **)&r->edges, &r->cap_edge, r->nedge + 1, sizeof *r->edges)) return 0;
        r->edges[r->nedge] = (pdt_redge){e->a, e->b, rec->rank, i, NONE32};
        if (!pdt_rp_km_put(&b->edge_map, rec->rank, k, (int32_t)r->nedge, r->tab_limit)) return 0;
        set_obj(b, i, (int32_t)r->nedge);
        r->nedge++;
    } else if (have) {
        r->edges[id].del_ev = i;
        set_obj(b, i, id);
        if (!pdt_rp_km_put(&b->edge_map, rec->rank, k, -1, r->tab_limit)) return 0;
    } else {
        r->skipped++;
    }
    return 1;
}

/* A message: its SEND and RECV paired by ranks, tag and sequence number. */
static int ix_msg(IX_ARGS)
{
    pdt_replay *r = b->r;
    const pdt_event *e = &rec->ev;
    if (e->a >= (uint32_t)r->nranks) {
        r->skipped++;
        return 1;
    }
    int send = e->kind == PDT_EV_SEND;
    uint32_t src = send ? rec->rank : e->a, dst = send ? e->a : rec->rank;
    uint64_t hi = ((uint64_t)src << 32) | dst;
    uint64_t lo = ((uint64_t)e->sub << 56) ^ (uint64_t)e->v;
    int32_t id;
    if (!pdt_rp_km_get(&b->msg_map, hi, lo, &id) || (send ? r->msgs[id].send_ev : r->msgs[id].recv_ev) != NONE32) {
        if (!pdt_rp_tab_grow(r, (void **)&r->msgs, &r->cap_msg, r->nmsg + 1, sizeof *r->msgs)) return 0;
        r->msgs[r->nmsg] = (pdt_rmsg){src, dst, e->sub, 0, pdt_event_bytes(e), NONE32, NONE32, 0, 0};
        id = (int32_t)r->nmsg++;
        if (!pdt_rp_km_put(&b->msg_map, hi, lo, id, r->tab_limit)) return 0;
    }
    if (send) {
        r->msgs[id].send_ev = i;
        r->msgs[id].send_t = e->t;
    } else {
        r->msgs[id].recv_ev = i;
        r->msgs[id].recv_t = e->t;
    }
    set_obj(b, i, id);
    return 1;
}

/* A triangle event: into its triangle's fine bucket (grouped after pass 1,
 * pdt_rp_tri_histories), with what its history entry needs. */
static int ix_tri(IX_ARGS)
{
    pdt_replay *r = b->r;
    const pdt_event *e = &rec->ev;
    const int32_t *cur = IX_CUR;
    if (e->a >= r->n || e->b >= r->n || e->c >= r->n) {
        r->skipped++;
        return 1;
    }
    tri_rec t;
    uint32_t in[3] = {e->a, e->b, e->c};
    sort3(t.s, in);
    t.ev = i;
    int border = e->kind == PDT_EV_TRI_NEW && e->sub == 1;
    size_t f = pdt_rp_fine_of(t.s, b->fine_bits);
    if (!b->pl) { /* for hist_of, until the grouping writes these two */
        r->ev_ent[i] = e->sub;
        r->ev_obj[i] = border ? cur[PDT_SLOT_MERGE] : -1;
        b->spill[b->fine_fill[f]++] = t;
        return 1;
    }
    /* (streamed: fine_fill counts the bucket's events) */
    uint32_t step = (uint32_t)(cur[PDT_SLOT_MERGE] + 1); /* (0: none) */
    uint32_t x = border ? XREC_BORDER | (step <= XREC_STEP_MAX + 1 ? step : 0)
                        : (uint32_t)e->kind | (uint32_t)e->sub << 8;
    tri_xrec *to = &b->fcur[f][b->fbn[f]++];
    /* the bucket's next lines, for writing: the buckets are written at
     * random, each a few records a thousand events, and a line written
     * first missed every cache (its buffer last held records the spill
     * writer took long ago): the pass's handler stalled on those stores */
    __builtin_prefetch(to + 6, 1);
    *to = (tri_xrec){{t.s[0], t.s[1], t.s[2]}, i, x | xrec_order(t.s, in)};
    b->fine_fill[f]++;
    return b->fbn[f] < b->fbuf_recs || pdt_rp_fine_flush(b, f);
}

/* Pass 1's handling of event i (every object but triangle histories, which
 * need counts first). */
int pdt_rp_index_event(builder *b, uint32_t i, const pdt_rec *rec)
{
    switch (rec->ev.kind) {
    case PDT_EV_PHASE_BEGIN: return ix_phase_begin(b, i, rec);
    case PDT_EV_PHASE_END: return ix_phase_end(b, i, rec);
    case PDT_EV_MERGE_BEGIN: return ix_merge_begin(b, i, rec);
    case PDT_EV_MERGE_END: return ix_merge_end(b, i, rec);
    case PDT_EV_PUSH:
    case PDT_EV_POP: return ix_stack(b, i, rec);
    case PDT_EV_HULL: return ix_hull(b, i, rec);
    case PDT_EV_LIFT:
    case PDT_EV_SORT:
    case PDT_EV_DELETE: return ix_point(b, i, rec);
    case PDT_EV_EDGE_ADD:
    case PDT_EV_EDGE_DEL: return ix_edge(b, i, rec);
    case PDT_EV_SEND:
    case PDT_EV_RECV: return ix_msg(b, i, rec);
    default: return is_tri_kind(rec->ev.kind) ? ix_tri(b, i, rec) : 1;
    }
}
#undef IX_ARGS
#undef IX_CUR

/* (PREFETCH_AHEAD: see pdt_rp_probe_addr) */

/* The slot that looking up event i will probe first, or NULL; for a lift,
 * sort or deletion, the point's entry of its first such event, and (*also)
 * for a lift its coordinates (random places in tables of 4 and 8 bytes per
 * point).  (The caller prefetches them: GCC drops a __builtin_prefetch
 * inside a helper function, which it deems free of side effects.) */
const void *pdt_rp_probe_addr(const builder *b, const pdt_rec *rec, const void **also)
{
    const pdt_event *e = &rec->ev;
    const pdt_replay *r = b->r;
    *also = NULL;
    if (((e->kind == PDT_EV_LIFT && r->lift_ev) ||
         (r->sort_ev && (e->kind == PDT_EV_SORT || e->kind == PDT_EV_DELETE))) &&
        e->a < r->n) {
        if (e->kind == PDT_EV_LIFT) *also = &r->pts[e->a];
        return e->kind == PDT_EV_LIFT ? &r->lift_ev[e->a]
               : e->kind == PDT_EV_SORT ? &r->sort_ev[e->a] : &r->del_ev[e->a];
    }
    if (e->kind != PDT_EV_EDGE_ADD && e->kind != PDT_EV_EDGE_DEL) return NULL;
    uint32_t x = e->a < e->b ? e->a : e->b, y = e->a < e->b ? e->b : e->a;
    const keymap *km = &b->edge_map;
    return km->cap ? &km->e[(size_t)pdt_rp_mix(rec->rank, ((uint64_t)x << 32) | y) & (km->cap - 1)] : NULL;
}
