/* pdt — the replay's checkpoints: the memory budget, states as blobs, and
 * seeking from the nearest checkpoint. */
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

/* ---- checkpoints --------------------------------------------------------------- */

/* A seek that steps over this many events or more gives back the kept
 * index's pages it read (pdt_index_release). */
#define SEEK_RELEASE ((size_t)1 << 16)

/* A seek this many events away or closer steps there instead (a step costs
 * about what looking at one object costs in pdt_replay_seek_direct). */
#define STEP_FACTOR 1

/* Restoring a kept checkpoint costs about a step per this many of its bytes
 * when the state is in memory (copying memory is far cheaper per byte than
 * stepping per event).  Too small a figure makes a seek step millions of
 * events rather than restore; too large, restore when a few steps would
 * do. */
#define RESTORE_BYTES_PER_STEP 192

size_t pdt_replay_state_bytes(const pdt_replay *r)
{
    return sizeof(pdt_rstate) + r->n + r->ntri * sizeof(uint16_t) + r->nedge + r->nmsg +
           (size_t)r->nranks * PDT_SLOT_PER_RANK * sizeof(int32_t);
}

/* Objects pdt_replay_seek_direct looks at: its cost, in steps. */
static size_t direct_cost(const pdt_replay *r)
{
    return r->n + r->ntri + r->nedge + r->nmsg + (size_t)r->nranks * PDT_SLOT_PER_RANK;
}

void pdt_replay_set_mem(pdt_replay *r, uint64_t budget)
{
    for (size_t c = 0; c < r->nck; c++) pdt_rstate_free(r->ck[c]);
    free(r->ck);
    r->ck = NULL;
    r->nck = r->ck_every = 0;
    r->ck_bytes = pdt_replay_state_bytes(r);
    /* a kept index's replay whose state takes over a quarter of the budget:
     * its pages given back after seeks and frames, and states beyond half
     * of the budget paged (pdt_rstate_new) */
    r->state_paged = r->map && r->ck_bytes > budget / 4;
    r->mem_budget = budget;
    if (r->nick) return;  /* the index's checkpoints serve */
    /* half the budget for checkpoints; one every at least 64 events */
    uint64_t fit = budget / 2 / r->ck_bytes;
    if (fit < 2 || r->m < 128) return;
    size_t every = (r->m + (size_t)fit - 1) / (size_t)fit;
    if (every < 64) every = 64;
    size_t n = r->m / every + 1;
    r->ck = calloc(n, sizeof *r->ck);
    if (!r->ck) return;  /* no checkpoints: seeks go the direct way */
    r->nck = n;
    r->ck_every = every;
}

size_t pdt_replay_checkpoints(const pdt_replay *r, size_t *every, size_t *made)
{
    if (r->nick) {
        if (every) *every = r->ick_every;
        if (made) *made = r->nick;
        return r->nick;
    }
    size_t got = 0;
    for (size_t c = 0; c < r->nck; c++) got += r->ck[c] != NULL;
    if (every) *every = r->ck_every;
    if (made) *made = got;
    return r->nck;
}

static void state_copy(const pdt_replay *r, pdt_rstate *to, const pdt_rstate *from)
{
    size_t nslot = (size_t)r->nranks * PDT_SLOT_PER_RANK;
    to->k = from->k;
    memcpy(to->pflags, from->pflags, r->n);
    memcpy(to->tcur, from->tcur, r->ntri * sizeof *to->tcur);
    memcpy(to->ealive, from->ealive, r->nedge);
    memcpy(to->mflight, from->mflight, r->nmsg);
    memcpy(to->slot, from->slot, nslot * sizeof *to->slot);
}

static size_t dist(size_t a, size_t b) { return a > b ? a - b : b - a; }

static size_t up8(size_t x) { return (x + 7) & ~(size_t)7; }

size_t pdt_rstate_blob_bytes(const pdt_replay *r, size_t born)
{
    size_t nslot = (size_t)r->nranks * PDT_SLOT_PER_RANK;
    return up8(r->n) + up8(born * sizeof(uint16_t)) + up8(r->nedge) + up8(r->nmsg) + up8(nslot * 4);
}

size_t pdt_rstate_born(const pdt_replay *r, const pdt_rstate *s)
{
    size_t t = r->ntri;
    while (t > 0 && s->tcur[t - 1] == PDT_TCUR_NONE) t--;
    return t;
}

void pdt_rstate_to_blob(const pdt_replay *r, const pdt_rstate *s, size_t born, uint8_t *out)
{
    size_t nslot = (size_t)r->nranks * PDT_SLOT_PER_RANK;
    memset(out, 0, pdt_rstate_blob_bytes(r, born));
    memcpy(out, s->pflags, r->n);
    out += up8(r->n);
    memcpy(out, s->tcur, born * sizeof *s->tcur);
    out += up8(born * sizeof *s->tcur);
    memcpy(out, s->ealive, r->nedge);
    out += up8(r->nedge);
    memcpy(out, s->mflight, r->nmsg);
    out += up8(r->nmsg);
    memcpy(out, s->slot, nslot * 4);
}

void pdt_rstate_blob_parts(const pdt_replay *r, const pdt_rstate *s, size_t born,
                           const void *part[5], size_t len[5], size_t pad[5])
{
    size_t nslot = (size_t)r->nranks * PDT_SLOT_PER_RANK;
    const void *p[5] = {s->pflags, s->tcur, s->ealive, s->mflight, s->slot};
    size_t l[5] = {r->n, born * sizeof *s->tcur, r->nedge, r->nmsg, nslot * 4};
    for (int j = 0; j < 5; j++) part[j] = p[j], len[j] = l[j], pad[j] = up8(l[j]) - l[j];
}

#define BLOB_STEP ((size_t)8 << 20) /* bytes of a kept checkpoint copied between givings back */
#define PAGE_STEP ((size_t)4096)

/* memcpy into a paged state a page at a time, leaving a page that holds the
 * bytes already untouched: a checkpoint restored over a state near it
 * dirties only the pages that differ (a dirty page of the temporary file is
 * written to the disk sooner or later; a seek that dirtied the whole state
 * waited on that). */
static void paged_copy(char *to, const uint8_t *from, size_t len)
{
    for (size_t o = 0; o < len; o += PAGE_STEP) {
        size_t k = len - o < PAGE_STEP ? len - o : PAGE_STEP;
        if (memcmp(to + o, from + o, k)) memcpy(to + o, from + o, k);
    }
}

/* memcpy from a kept index's mapping, its pages given back behind the copy
 * (a checkpoint of a huge run is 10^8 bytes: its pages would double what a
 * seek holds), and a paged state's pages too (`paged`: the array is one). */
static void copy_out(const pdt_replay *r, void *to, const uint8_t *from, size_t len, size_t paged)
{
    for (size_t o = 0; o < len; o += BLOB_STEP) {
        size_t k = len - o < BLOB_STEP ? len - o : BLOB_STEP;
        if (paged) paged_copy((char *)to + o, from + o, k);
        else memcpy((char *)to + o, from + o, k);
        pdt_index_release(r, from + o, k);
        if (paged) pdt_release_pages((char *)to + o, k);
    }
}

/* memset, a paged state's pages given back behind it (and, as in
 * paged_copy, a page that holds the bytes already left clean). */
static void fill_out(void *to, int byte, size_t len, size_t paged)
{
    if (!paged) {
        memset(to, byte, len);
        return;
    }
    uint8_t want[PAGE_STEP];
    memset(want, byte, sizeof want);
    char *p = to;
    for (size_t o = 0; o < len; o += BLOB_STEP) {
        size_t k = len - o < BLOB_STEP ? len - o : BLOB_STEP;
        for (size_t i = 0; i < k; i += PAGE_STEP) {
            size_t j = k - i < PAGE_STEP ? k - i : PAGE_STEP;
            if (memcmp(p + o + i, want, j)) memset(p + o + i, byte, j);
        }
        pdt_release_pages(p + o, k);
    }
}

void pdt_rstate_from_blob(const pdt_replay *r, pdt_rstate *s, const uint8_t *in, size_t born,
                          size_t k)
{
    size_t nslot = (size_t)r->nranks * PDT_SLOT_PER_RANK;
    s->k = k;
    copy_out(r, s->pflags, in, r->n, s->paged[0]);
    in += up8(r->n);
    copy_out(r, s->tcur, in, born * sizeof *s->tcur, s->paged[1]);
    fill_out(s->tcur + born, 0xff, (r->ntri - born) * sizeof *s->tcur, s->paged[1]);
    in += up8(born * sizeof *s->tcur);
    copy_out(r, s->ealive, in, r->nedge, s->paged[2]);
    in += up8(r->nedge);
    copy_out(r, s->mflight, in, r->nmsg, 0);
    in += up8(r->nmsg);
    copy_out(r, s->slot, in, nslot * 4, 0);
}

#define STEP_AHEAD 24  /* events ahead whose object a long stepping fetches */

/* What applying event i will touch, fetched ahead (a hint): the state's
 * entry of its triangle or point, at random places in arrays of up to
 * 10^8 bytes (cache misses were most of a long seek). */
static void step_prefetch(const pdt_replay *r, const pdt_rstate *s, size_t i)
{
    int32_t obj = r->ev_obj[i];
    if (obj < 0) return;
    int kind = r->ev_kind[i];
    if (is_tri_kind(kind & KIND_MASK)) {
        __builtin_prefetch(&s->tcur[obj], 1);
    } else if ((kind & KIND_MASK) == PDT_EV_LIFT && r->lift_ev) {
        __builtin_prefetch(&s->pflags[obj], 1);
        __builtin_prefetch(&r->lift_ev[obj]);
    }
}

static void step_to(const pdt_replay *r, pdt_rstate *s, size_t k)
{
    size_t lo = s->k < k ? s->k : k, hi = s->k < k ? k : s->k;
    if (!ix_check_events(r, lo, hi) || !ix_check_born(r, hi)) return;
    /* (a paged state's pages are given back when the seek is done, not on
     * the way: a page of a file mapping written again costs a fault into
     * the file system, which made seeks several times slower) */
    while (s->k < k) {
        if (s->k + STEP_AHEAD < k) step_prefetch(r, s, s->k + STEP_AHEAD);
        pdt_rp_step(r, s, 1);
    }
    while (s->k > k) {
        if (s->k > k + STEP_AHEAD) step_prefetch(r, s, s->k - 1 - STEP_AHEAD);
        pdt_rp_step(r, s, -1);
    }
}

/* The cheapest of: stepping from where s is; restoring the checkpoint
 * nearest k and stepping from it; the direct seek (which, when the
 * checkpoint near k is not made yet, goes to the checkpoint's cursor, keeps a
 * copy, and steps from it).  Every route gives the same state. */
void pdt_replay_seek(const pdt_replay *r, pdt_rstate *s, size_t k)
{
    if (k > r->m) k = r->m;
    size_t direct = direct_cost(r), from_here = dist(s->k, k) * STEP_FACTOR;
    if (r->nick) { /* the index's checkpoints */
        size_t c = (k + r->ick_every / 2) / r->ick_every;
        if (c >= r->nick) c = r->nick - 1;
        size_t ck = c * r->ick_every;
        size_t bytes = (size_t)(r->ick_off[c + 1] - r->ick_off[c]);
        if (from_here > dist(ck, k) * STEP_FACTOR + bytes / (s->paged[1] ? 64 : RESTORE_BYTES_PER_STEP) &&
            (!r->lazy || pdt_ix_need_ckpt(r, c))) {
            pdt_rstate_from_blob(r, s, r->ick + r->ick_off[c], r->ick_born[c], ck);
            pdt_index_release(r, r->ick + r->ick_off[c], bytes); /* (copied: not kept) */
        }
        size_t from = s->k;
        step_to(r, s, k);
        if (dist(from, k) >= SEEK_RELEASE) { /* the per-event tables stepped over, and the
                                              * triangles born there (read in order) */
            size_t lo = from < k ? from : k, hi = from < k ? k : from;
            pdt_index_release(r, &r->ev_obj[lo], (hi - lo) * sizeof *r->ev_obj);
            pdt_index_release(r, &r->ev_kind[lo], hi - lo);
            size_t c0 = lo / r->ick_every, c1 = hi / r->ick_every + 1;
            size_t t0 = c0 < r->nick ? r->ick_born[c0] : r->ntri;
            size_t t1 = c1 < r->nick ? r->ick_born[c1] : r->ntri;
            if (t1 > t0) pdt_index_release(r, &r->tris[t0], (t1 - t0) * sizeof *r->tris);
        }
        if (r->state_paged) pdt_replay_give_back(r, s);
        return;
    }
    if (from_here <= direct && (!r->nck || from_here <= r->ck_every / 2)) {
        step_to(r, s, k);
        return;
    }
    if (!r->nck) {
        pdt_replay_seek_direct(r, s, k);
        return;
    }
    size_t c = (k + r->ck_every / 2) / r->ck_every;
    if (c >= r->nck) c = r->nck - 1;
    size_t ck = c * r->ck_every;
    if (from_here <= dist(ck, k) * STEP_FACTOR) {
        step_to(r, s, k);
        return;
    }
    pdt_replay *w = (pdt_replay *)r;  /* the checkpoints are a cache */
    if (!w->ck[c]) {
        pdt_rstate *cs = pdt_rstate_new(r);
        if (!cs) {  /* no room for it: the direct way */
            pdt_replay_seek_direct(r, s, k);
            return;
        }
        pdt_replay_seek_direct(r, cs, ck);
        w->ck[c] = cs;
    }
    state_copy(r, s, w->ck[c]);
    step_to(r, s, k);
}
