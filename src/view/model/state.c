/* pdt — the replay's states: new, free, step, seek without checkpoints, and
 * a forward pass over a streamed replay. */
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

/* ---- states ------------------------------------------------------------------ */

/* An array of a state: paged (s->paged[i] set) when `page` says so and a
 * temporary file takes it, else in memory. */
static void *state_array(int page, pdt_rstate *s, int i, size_t bytes, int zero)
{
    if (!bytes) bytes = 1;
    if (page) {
        void *p = pdt_temp_zeros(bytes);
        if (p) {
            s->paged[i] = bytes;
            return p;
        }
    }
    void *p = zero ? calloc(bytes, 1) : malloc(bytes);
    /* a state of a huge run is 10^8 bytes, filled at once: huge pages spare
     * most of the page faults (costly on virtual machines) */
    if (p) pdt_big_advise(p, bytes);
    return p;
}

static void state_array_free(void *p, size_t paged)
{
    if (paged) munmap(p, paged);
    else free(p);
}

pdt_rstate *pdt_rstate_new(const pdt_replay *r)
{
    pdt_rstate *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    size_t nslot = (size_t)r->nranks * PDT_SLOT_PER_RANK;
    uint64_t bytes = pdt_replay_state_bytes(r);
    pdt_replay *w = (pdt_replay *)r;  /* (the count of states held is a cache's) */
    int page = r->state_paged && r->state_held + bytes > r->mem_budget / 2;
    s->pflags = state_array(page, s, 0, r->n, 1);
    s->tcur = state_array(page, s, 1, r->ntri * sizeof *s->tcur, 0);
    s->ealive = state_array(page, s, 2, r->nedge, 1);
    if (!page && r->map) {  /* (a kept index's replay outlives its states) */
        s->held = &w->state_held;
        s->held_bytes = bytes;
        w->state_held += bytes;
    }
    s->mflight = calloc(r->nmsg ? r->nmsg : 1, 1);
    s->slot = malloc((nslot ? nslot : 1) * sizeof *s->slot);
    if (!s->pflags || !s->tcur || !s->ealive || !s->mflight || !s->slot) {
        pdt_rstate_free(s);
        return NULL;
    }
    pdt_replay_seek_direct(r, s, 0);
    return s;
}

void pdt_rstate_free(pdt_rstate *s)
{
    if (!s) return;
    if (s->held) *s->held -= s->held_bytes;
    state_array_free(s->pflags, s->paged[0]);
    state_array_free(s->tcur, s->paged[1]);
    state_array_free(s->ealive, s->paged[2]);
    free(s->mflight);
    free(s->slot);
    free(s);
}

/* A paged state's resident pages given back. */
static void state_give_back(const pdt_rstate *s)
{
    const void *a[3] = {s->pflags, s->tcur, s->ealive};
    for (int i = 0; i < 3; i++)
        if (s->paged[i]) pdt_release_pages(a[i], s->paged[i]);
}

void pdt_replay_give_back(const pdt_replay *r, const pdt_rstate *s)
{
    if (!r->state_paged) return;  /* what is resident fits the budget */
    if (s) state_give_back(s);
    if (r->release_points) r->release_points(r->release_ctx);
    pdt_index_release(r, r->map, r->map_len);
}

static uint8_t point_flags(const pdt_replay *r, size_t p, size_t k)
{
    ix_check_point(r, p);
    return (uint8_t)((r->lift_ev[p] < k ? PDT_PF_LIFTED : 0) |
                     (r->sort_ev && r->sort_ev[p] < k ? PDT_PF_SORTED : 0) |
                     (r->del_ev && r->del_ev[p] < k ? PDT_PF_DELETED : 0));
}

static uint8_t alive(uint32_t from, uint32_t to, size_t k)
{
    return from < k && !(to < k);
}

/* Cursor 0: nothing has happened (no history entry is before it). */
static void seek_zero(const pdt_replay *r, pdt_rstate *s)
{
    size_t nslot = (size_t)r->nranks * PDT_SLOT_PER_RANK;
    s->k = 0;
    memset(s->pflags, 0, r->n);
    memset(s->tcur, 0xff, r->ntri * sizeof *s->tcur);
    memset(s->ealive, 0, r->nedge);
    memset(s->mflight, 0, r->nmsg);
    for (size_t sl = 0; sl < nslot; sl++) s->slot[sl] = -1;
}

void pdt_replay_seek_direct(const pdt_replay *r, pdt_rstate *s, size_t k)
{
    if (k > r->m) k = r->m;
    if (k == 0 && (r->map || r->streamed)) { /* do not touch every table of a mapped index */
        seek_zero(r, s);
        return;
    }
    if (r->lazy && !pdt_ix_need_all(r)) return;  /* (every table is read) */
    s->k = k;
    for (size_t p = 0; p < r->n; p++) s->pflags[p] = point_flags(r, p, k);
    for (size_t t = 0; t < r->ntri; t++) {
        const pdt_rtri *tr = &r->tris[t];
        uint16_t c = PDT_TCUR_NONE;
        for (uint32_t h = tr->h0; h < tr->h0 + tr->hn && r->hist[h].ev < k; h++) c = (uint16_t)(h - tr->h0);
        s->tcur[t] = c;
    }
    for (size_t e = 0; e < r->nedge; e++) s->ealive[e] = alive(r->edges[e].add_ev, r->edges[e].del_ev, k);
    for (size_t g = 0; g < r->nmsg; g++) s->mflight[g] = alive(r->msgs[g].send_ev, r->msgs[g].recv_ev, k);
    size_t nslot = (size_t)r->nranks * PDT_SLOT_PER_RANK;
    for (size_t sl = 0; sl < nslot; sl++) {
        /* last change of this slot with ev < k: binary search */
        uint32_t lo = r->slot_start[sl], hi = r->slot_start[sl + 1];
        while (lo < hi) {
            uint32_t mid = lo + (hi - lo) / 2;
            if (r->ch[r->slot_ch[mid]].ev < k) lo = mid + 1;
            else hi = mid;
        }
        s->slot[sl] = lo > r->slot_start[sl] ? r->ch[r->slot_ch[lo - 1]].val : -1;
    }
}

/* Apply (fwd) or undo (!fwd) an event of object obj (>= 0) and kind (with
 * its mark); s->k is already the new cursor.  A triangle's event moves its
 * entry one on or back; its first event, from none to its first or back. */
static void apply_obj(const pdt_replay *r, pdt_rstate *s, int32_t obj, int kind, int fwd)
{
    switch (kind & KIND_MASK) {
    case PDT_EV_LIFT:
    case PDT_EV_SORT:
    case PDT_EV_DELETE:
        s->pflags[obj] = point_flags(r, (size_t)obj, s->k);
        return;
    case PDT_EV_EDGE_ADD:
    case PDT_EV_EDGE_DEL:
        s->ealive[obj] = alive(r->edges[obj].add_ev, r->edges[obj].del_ev, s->k);
        return;
    case PDT_EV_SEND:
    case PDT_EV_RECV:
        s->mflight[obj] = alive(r->msgs[obj].send_ev, r->msgs[obj].recv_ev, s->k);
        return;
    default:
        if (is_tri_kind(kind & KIND_MASK)) {
            uint16_t *t = &s->tcur[obj];
            if (!(kind & KIND_FIRST)) *t = (uint16_t)(fwd ? *t + 1 : *t - 1);
            else *t = fwd ? 0 : PDT_TCUR_NONE;
            return;
        }
        /* a slot change */
        const slot_change *c = &r->ch[obj];
        s->slot[c->slot] = fwd ? c->val : c->prev;
        return;
    }
}

/* Apply (fwd) or undo (!fwd) event i; s->k is already the new cursor. */
static void apply(const pdt_replay *r, pdt_rstate *s, size_t i, int fwd)
{
    int32_t obj = r->ev_obj[i];
    if (obj < 0) return;
    apply_obj(r, s, obj, r->ev_kind[i], fwd);
}

int pdt_replay_step(const pdt_replay *r, pdt_rstate *s, int dir)
{
    if (r->lazy) { /* the event's entries and the triangles born by then, checked first */
        size_t i = dir > 0 ? s->k : s->k - (s->k > 0);
        if (!pdt_ix_need_events(r, i, i + 1) || !pdt_ix_need_born(r, s->k + (dir > 0))) return 0;
    }
    return pdt_rp_step(r, s, dir);
}

int pdt_rp_step(const pdt_replay *r, pdt_rstate *s, int dir)
{
    if (dir > 0) {
        if (s->k >= r->m) return 0;
        s->k++;
        apply(r, s, s->k - 1, 1);
        return 1;
    }
    if (dir < 0) {
        if (s->k == 0) return 0;
        s->k--;
        apply(r, s, s->k, 0);
        return 1;
    }
    return 0;
}

/* ---- a forward pass over a streamed replay ------------------------------------------ */

#define FWD_EVENTS 65536u  /* events per window of the per-event tables */
#define FWD_AHEAD 24        /* events ahead whose object the pass fetches */

struct pdt_fwd {
    const pdt_replay *r;
    int (*get)(void *ctx, uint64_t at, void *p, size_t bytes);
    void *ctx;
    int32_t *obj;
    uint8_t *kind;
    size_t lo, n;      /* the window of events: lo .. lo + n - 1 */
};

pdt_fwd *pdt_fwd_new(const pdt_replay *r, int (*get)(void *ctx, uint64_t at, void *p, size_t bytes),
                     void *ctx)
{
    pdt_fwd *f = calloc(1, sizeof *f);
    if (!f) return NULL;
    f->r = r;
    f->get = get;
    f->ctx = ctx;
    f->obj = malloc(FWD_EVENTS * sizeof *f->obj);
    f->kind = malloc(FWD_EVENTS);
    if (!f->obj || !f->kind) {
        pdt_fwd_free(f);
        return NULL;
    }
    return f;
}

void pdt_fwd_free(pdt_fwd *f)
{
    if (!f) return;
    free(f->obj);
    free(f->kind);
    free(f);
}

int pdt_fwd_to(pdt_fwd *f, pdt_rstate *s, size_t k)
{
    const pdt_replay *r = f->r;
    if (k > r->m) k = r->m;
    while (s->k < k) {
        size_t i = s->k;
        if (i < f->lo || i >= f->lo + f->n) {
            size_t n = r->m - i < FWD_EVENTS ? r->m - i : FWD_EVENTS;
            if (!f->get(f->ctx, r->evobj_at + (uint64_t)i * sizeof *f->obj, f->obj, n * sizeof *f->obj) ||
                !f->get(f->ctx, r->evkind_at + i, f->kind, n))
                return 0;
            f->lo = i;
            f->n = n;
        }
        if (i + FWD_AHEAD < f->lo + f->n) { /* (what the step ahead writes, fetched now:
                                              * random places in tables of megabytes) */
            int32_t ao = f->obj[i + FWD_AHEAD - f->lo];
            int ak = f->kind[i + FWD_AHEAD - f->lo] & KIND_MASK;
            if (ao >= 0 && is_tri_kind(ak)) __builtin_prefetch(&s->tcur[ao], 1);
            else if (ao >= 0 && (ak == PDT_EV_LIFT || ak == PDT_EV_SORT || ak == PDT_EV_DELETE))
                __builtin_prefetch(&s->pflags[ao], 1);
        }
        s->k++;
        /* (a paged build's tables go back as it goes; the state's pages, which
         * the steps write at random, when a checkpoint of it has been written:
         * a page of a file mapping written again costs a fault into the file
         * system, and giving them back here made the build twice as slow) */
        if (i % TICK_EVENTS == TICK_EVENTS - 1) pdt_rp_tabs_give_back(r);
        int32_t obj = f->obj[i - f->lo];
        int kind = f->kind[i - f->lo];
        if (obj < 0) continue;
        switch (kind & KIND_MASK) { /* (streamed: no table per point; forwards the
                                     * flags only gather: what point_flags gives) */
        case PDT_EV_LIFT: s->pflags[obj] |= PDT_PF_LIFTED; continue;
        case PDT_EV_SORT: s->pflags[obj] |= PDT_PF_SORTED; continue;
        case PDT_EV_DELETE: s->pflags[obj] |= PDT_PF_DELETED; continue;
        default: apply_obj(r, s, obj, kind, 1);
        }
    }
    return 1;
}

int pdt_rstate_equal(const pdt_replay *r, const pdt_rstate *a, const pdt_rstate *b)
{
    size_t nslot = (size_t)r->nranks * PDT_SLOT_PER_RANK;
    return a->k == b->k && !memcmp(a->pflags, b->pflags, r->n) &&
           !memcmp(a->tcur, b->tcur, r->ntri * sizeof *a->tcur) &&
           !memcmp(a->ealive, b->ealive, r->nedge) && !memcmp(a->mflight, b->mflight, r->nmsg) &&
           !memcmp(a->slot, b->slot, nslot * sizeof *a->slot);
}

int32_t pdt_rstate_slot(const pdt_replay *r, const pdt_rstate *s, int rank, int slot)
{
    if (rank < 0 || rank >= r->nranks || slot < 0 || slot >= PDT_SLOT_PER_RANK) return -1;
    return s->slot[(size_t)rank * PDT_SLOT_PER_RANK + (size_t)slot];
}

pdt_tri_status pdt_rstate_tri_status(const pdt_replay *r, const pdt_rstate *s, size_t t)
{
    if (t >= r->ntri || s->tcur[t] == PDT_TCUR_NONE) return PDT_TS_NONE;
    const pdt_rtri *tr = &r->tris[t];
    if (s->tcur[t] + 1u == tr->hn) return (pdt_tri_status)tr->last;
    return (pdt_tri_status)r->hist[tr->h0 + s->tcur[t]].status;
}

uint32_t pdt_rstate_tri_entry(const pdt_replay *r, const pdt_rstate *s, size_t t)
{
    if (t >= r->ntri || s->tcur[t] == PDT_TCUR_NONE) return NONE32;
    const pdt_rtri *tr = &r->tris[t];
    uint32_t h = tr->h0 + s->tcur[t];
    if (s->tcur[t] + 1u == tr->hn && tr->last != PDT_TS_CANDIDATE) return h;  /* (no look) */
    while (r->hist[h].status == PDT_TS_CANDIDATE && r->hist[h].until < s->k) {
        if (h == r->tris[t].h0) return NONE32;
        h--;
    }
    return h;
}

int pdt_rstate_tri_visible(const pdt_replay *r, const pdt_rstate *s, size_t t)
{
    return pdt_rstate_tri_entry(r, s, t) != NONE32;
}

size_t pdt_replay_born_at_most(const pdt_replay *r, size_t k)
{
    for (size_t c = 0; c < r->nick; c++)
        if (c * r->ick_every >= k) return (size_t)r->ick_born[c];
    return r->ntri;
}
