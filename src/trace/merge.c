/* pdt — the merged order of a run's events: every rank's events in time
 * order, a receive never before its send (reader.c opens the run). */
#include "tf_internal.h"
#include "run_int.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- merged order ----------------------------------------------------------- */

typedef struct msg_key {
    uint32_t src, dst, tag;
    int64_t seq;
} msg_key;

typedef struct msg_slot {
    msg_key k;
    uint32_t count;  /* sends not yet received */
    int used;
} msg_slot;

typedef struct msg_set {
    msg_slot *s;
    size_t cap, n;
} msg_set;

static uint64_t key_hash(const msg_key *k)
{
    uint64_t h = k->src * 0x9e3779b97f4a7c15u ^ k->dst * 0xc2b2ae3d27d4eb4fu ^
                 k->tag * 0x165667b19e3779f9u ^ (uint64_t)k->seq * 0xff51afd7ed558ccdu;
    return h ^ (h >> 29);
}

static int key_eq(const msg_key *a, const msg_key *b)
{
    return a->src == b->src && a->dst == b->dst && a->tag == b->tag && a->seq == b->seq;
}

/* Slot of k (inserting if `add`); NULL if absent or out of memory. */
static msg_slot *msg_find(msg_set *m, const msg_key *k, int add)
{
    if (add && 2 * (m->n + 1) > m->cap) {
        size_t cap = m->cap ? 2 * m->cap : 64;
        msg_slot *s = calloc(cap, sizeof *s);
        if (!s) return NULL;
        for (size_t i = 0; i < m->cap; i++) {
            if (!m->s[i].used) continue;
            size_t j = key_hash(&m->s[i].k) & (cap - 1);
            while (s[j].used) j = (j + 1) & (cap - 1);
            s[j] = m->s[i];
        }
        free(m->s);
        m->s = s;
        m->cap = cap;
    }
    if (!m->cap) return NULL;
    size_t j = key_hash(k) & (m->cap - 1);
    while (m->s[j].used) {
        if (key_eq(&m->s[j].k, k)) return &m->s[j];
        j = (j + 1) & (m->cap - 1);
    }
    if (!add) return NULL;
    m->s[j].used = 1;
    m->s[j].k = *k;
    m->s[j].count = 0;
    m->n++;
    return &m->s[j];
}

static msg_key ev_key(const pdt_event *e, uint32_t rank)
{
    msg_key k;
    k.tag = e->sub;
    k.seq = e->v;
    if (e->kind == PDT_EV_SEND) {
        k.src = rank;
        k.dst = e->a;
    } else {
        k.src = e->a;
        k.dst = rank;
    }
    return k;
}

/* ---- the streaming merge ------------------------------------------------------
 *
 * One cursor per rank; a heap of the ranks whose next event (head) may go
 * next, ordered by (aligned time, rank); a rank whose head is a RECV whose
 * SEND is still to come waits ("blocked") until that SEND has gone out.
 * Memory: one decoded block per rank plus the message sets — independent of
 * the number of events. */

struct pdt_merge {
    pdt_run *run;
    uint32_t R;
    pdt_cursor **cur;    /* per rank */
    pdt_event *head;     /* per rank: its next event, valid while has[r] */
    uint64_t *pos;       /* per rank: index of head in the rank */
    uint8_t *has;
    uint32_t *heap;      /* ranks whose head may go next */
    size_t nheap;
    uint8_t *blocked;    /* ranks whose head is a RECV waiting for its SEND */
    size_t nblocked;
    msg_set sent;        /* sends placed and not yet received */
    msg_set unsent;      /* sends not yet placed (all SENDs of the run at the start) */
    uint32_t next;       /* a rank known to go next without asking the heap, or UINT32_MAX */
    uint64_t left;       /* events not yet delivered */
};

static int head_less(const pdt_merge *m, uint32_t a, uint32_t b)
{
    uint64_t ta = m->head[a].t, tb = m->head[b].t;
    return ta != tb ? ta < tb : a < b;
}

static void heap_push(pdt_merge *m, uint32_t r)
{
    size_t i = m->nheap++;
    m->heap[i] = r;
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (!head_less(m, m->heap[i], m->heap[p])) break;
        uint32_t t = m->heap[i];
        m->heap[i] = m->heap[p];
        m->heap[p] = t;
        i = p;
    }
}

static uint32_t heap_pop(pdt_merge *m)
{
    uint32_t top = m->heap[0];
    m->heap[0] = m->heap[--m->nheap];
    size_t i = 0;
    for (;;) {
        size_t l = 2 * i + 1, k = i;
        if (l < m->nheap && head_less(m, m->heap[l], m->heap[k])) k = l;
        if (l + 1 < m->nheap && head_less(m, m->heap[l + 1], m->heap[k])) k = l + 1;
        if (k == i) break;
        uint32_t t = m->heap[i];
        m->heap[i] = m->heap[k];
        m->heap[k] = t;
        i = k;
    }
    return top;
}

/* Load rank r's next event into head[r]. */
static void advance(pdt_merge *m, uint32_t r)
{
    m->has[r] = (uint8_t)pdt_cursor_next(m->cur[r], &m->head[r], &m->pos[r]);
}

/* Put rank r's head event into the heap, or mark it blocked.  A RECV waits
 * only for a SEND that is still to come: one whose SEND is in no file (a
 * lost or damaged rank file) is placed by its time at once, so it cannot
 * hold up, or be forced ahead of, messages that are all there. */
static void schedule(pdt_merge *m, uint32_t r)
{
    if (!m->has[r]) return;
    const pdt_event *e = &m->head[r];
    if (e->kind == PDT_EV_RECV) {
        msg_key key = ev_key(e, r);
        msg_slot *s = msg_find(&m->sent, &key, 0);
        msg_slot *u = msg_find(&m->unsent, &key, 0);
        if ((!s || s->count == 0) && u && u->count > 0) {
            m->blocked[r] = 1;
            m->nblocked++;
            return;
        }
    }
    heap_push(m, r);
}

/* Every SEND of the run into m->unsent (one pass over the events). */
static pdt_status count_sends(pdt_merge *m, pdt_err *err)
{
    for (uint32_t r = 0; r < m->R; r++) {
        pdt_cursor *c;
        pdt_status st = pdt_cursor_open(m->run, (int)r, &c, err);
        if (st != PDT_OK) return st;
        pdt_event e;
        while (pdt_cursor_next(c, &e, NULL)) {
            if (e.kind != PDT_EV_SEND) continue;
            msg_key key = ev_key(&e, r);
            msg_slot *u = msg_find(&m->unsent, &key, 1);
            if (!u) {
                pdt_cursor_close(c);
                return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory (message index)");
            }
            u->count++;
        }
        pdt_cursor_close(c);
    }
    return PDT_OK;
}

pdt_status pdt_merge_open(pdt_run *run, pdt_merge **out, pdt_err *err)
{
    *out = NULL;
    pdt_merge *m = calloc(1, sizeof *m);
    if (!m) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    size_t R = (size_t)run->nranks;
    m->run = run;
    m->R = (uint32_t)R;
    m->next = UINT32_MAX;
    m->cur = calloc(R ? R : 1, sizeof *m->cur);
    m->head = calloc(R ? R : 1, sizeof *m->head);
    m->pos = calloc(R ? R : 1, sizeof *m->pos);
    m->has = calloc(R ? R : 1, 1);
    m->heap = calloc(R ? R : 1, sizeof *m->heap);
    m->blocked = calloc(R ? R : 1, 1);
    pdt_status st = PDT_OK;
    if (!m->cur || !m->head || !m->pos || !m->has || !m->heap || !m->blocked)
        st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    /* one rank: the order is its file order whatever the messages say */
    if (st == PDT_OK && R > 1) st = count_sends(m, err);
    for (uint32_t r = 0; st == PDT_OK && r < R; r++) {
        st = pdt_cursor_open(run, (int)r, &m->cur[r], err);
        m->left += run->rk[r].nev;
    }
    if (st != PDT_OK) {
        pdt_merge_close(m);
        return st;
    }
    for (uint32_t r = 0; r < R; r++) {
        advance(m, r);
        schedule(m, r);
    }
    *out = m;
    return PDT_OK;
}

/* Bookkeeping of the messages when event e of rank r is placed. */
static int place_message(pdt_merge *m, const pdt_event *e, uint32_t r, uint64_t seq)
{
    msg_key key = ev_key(e, r);
    if (e->kind == PDT_EV_SEND) {
        msg_slot *s = msg_find(&m->sent, &key, 1);
        if (!s) return -1;
        s->count++;
        msg_slot *u = msg_find(&m->unsent, &key, 0);
        if (u && u->count) u->count--;
        uint32_t d = key.dst;  /* wake the receiver waiting for this message */
        if (m->nblocked && d < m->R && m->blocked[d]) {
            msg_key wk = ev_key(&m->head[d], d);
            if (key_eq(&wk, &key)) {
                m->blocked[d] = 0;
                m->nblocked--;
                heap_push(m, d);
            }
        }
    } else {
        msg_slot *s = msg_find(&m->sent, &key, 0);
        if (s && s->count) s->count--;
        else  /* its SEND is in no file, or a cycle forced it */
            pdt_tf_warnf(m->run, "rank %u event #%" PRIu64 ": recv from rank %u (tag %u, seq %" PRId64
                          ") has no matching send", r, seq, e->a, e->sub, e->v);
    }
    return 0;
}

/* Event e of rank r (its index seq) as the next record; -1 when its message
 * could not be indexed (err set). */
static int take(pdt_merge *m, const pdt_event *e, uint32_t r, uint64_t seq, pdt_rec *rec,
                pdt_err *err)
{
    rec->ev = *e;
    rec->rank = r;
    rec->seq = (uint32_t)seq;
    m->left--;
    if ((e->kind == PDT_EV_SEND || e->kind == PDT_EV_RECV) && place_message(m, e, r, seq) != 0) {
        pdt_err_set(err, PDT_ERR_NOMEM, "out of memory (message index)");
        return -1;
    }
    return 0;
}

int pdt_merge_next(pdt_merge *m, pdt_rec *rec, pdt_err *err)
{
    if (m->left == 0) return 0;
    uint32_t r = UINT32_MAX;
    if (m->next != UINT32_MAX) {
        r = m->next;
        m->next = UINT32_MAX;
    } else if (m->nheap > 0) {
        r = heap_pop(m);
    } else {  /* every remaining head is a RECV whose SEND is missing: force one */
        for (uint32_t q = 0; q < m->R; q++)
            if (m->blocked[q] && (r == UINT32_MAX || head_less(m, q, r))) r = q;
        if (r == UINT32_MAX) {  /* a cursor stopped early: it could not get memory */
            pdt_err_set(err, PDT_ERR_NOMEM, "out of memory decoding a trace block");
            return -1;
        }
        m->blocked[r] = 0;
        m->nblocked--;
    }
    if (take(m, &m->head[r], r, m->pos[r], rec, err) != 0) return -1;
    advance(m, r);
    /* Fast path: if r's next event is no RECV and comes before every head in
     * the heap, pushing r and popping the heap would give r again (the order
     * (t, rank) is total), so skip both. */
    if (m->has[r] && m->head[r].kind != PDT_EV_RECV &&
        (m->nheap == 0 || head_less(m, r, m->heap[0])))
        m->next = r;
    else
        schedule(m, r);
    return 1;
}

/* One rank: its file order (pdt_merge_open).  Its head, then the rest of
 * that head's block straight from the cursor's decoded events, then the
 * next head; rank 0 stays where pdt_merge_next finds it (the heap, or
 * m->next), head[0] always the next event. */
static int fill_one(pdt_merge *m, pdt_rec *out, size_t max, pdt_err *err)
{
    size_t k = 0;
    while (k < max && m->left) {
        if (!m->has[0]) {  /* a cursor stopped early: it could not get memory */
            pdt_err_set(err, PDT_ERR_NOMEM, "out of memory decoding a trace block");
            return -1;
        }
        if (take(m, &m->head[0], 0, m->pos[0], &out[k++], err) != 0) return -1;
        const pdt_event *evs;
        uint64_t seq, want = max - k < m->left ? max - k : m->left;
        size_t n = pdt_cursor_span(m->cur[0], &evs, (size_t)want, &seq);
        for (size_t i = 0; i < n; i++)
            if (take(m, &evs[i], 0, seq + i, &out[k++], err) != 0) return -1;
        advance(m, 0);
    }
    return (int)k;
}

int pdt_merge_fill(pdt_merge *m, pdt_rec *out, size_t max, pdt_err *err)
{
    if (max > INT32_MAX) max = INT32_MAX;
    if (m->R == 1) return fill_one(m, out, max, err);
    size_t k = 0;
    int got = 1;
    while (k < max && (got = pdt_merge_next(m, &out[k], err)) == 1) k++;
    return got < 0 ? -1 : (int)k;
}

void pdt_merge_close(pdt_merge *m)
{
    if (!m) return;
    for (uint32_t r = 0; m->cur && r < m->R; r++) pdt_cursor_close(m->cur[r]);
    free(m->cur);
    free(m->head);
    free(m->pos);
    free(m->has);
    free(m->heap);
    free(m->blocked);
    free(m->sent.s);
    free(m->unsent.s);
    free(m);
}

pdt_status pdt_run_merged(pdt_run *run, const pdt_rec **recs, size_t *n, pdt_err *err)
{
    *recs = NULL;
    *n = 0;
    if (run->merged_done) {
        *recs = run->merged;
        *n = run->nmerged;
        return PDT_OK;
    }
    uint64_t total = 0;
    for (int r = 0; r < run->nranks; r++) total += run->rk[r].nev;
    if (total > SIZE_MAX / sizeof(pdt_rec))
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory (%" PRIu64 " events)", total);
    pdt_merge *m;
    pdt_status st = pdt_merge_open(run, &m, err);
    if (st != PDT_OK) return st;
    pdt_rec *out = pdt_tf_big_alloc((size_t)total * sizeof *out);
    if (!out) {
        pdt_merge_close(m);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory (%" PRIu64 " events)", total);
    }
    size_t k = 0;
    int got;
    while (k < total && (got = pdt_merge_fill(m, &out[k], (size_t)(total - k), err)) > 0)
        k += (size_t)got;
    pdt_merge_close(m);
    if (k < total) {
        free(out);
        return err->code ? err->code : pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    run->merged = out;
    run->nmerged = (size_t)total;
    run->merged_done = 1;
    *recs = run->merged;
    *n = run->nmerged;
    return PDT_OK;
}
