/* pdt — the replay model: index the events once, then answer "state at k". */
#include "pdt/view/replay.h"
#include "replay_int.h"
#include "pdt/bigmem.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <pthread.h>
#include <stdatomic.h>
#include <sys/mman.h>
#include <unistd.h>

/* ---- a small growable array ----------------------------------------------- */

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap) return 1;
    size_t c = *cap ? *cap : 64;
    while (c < need) c *= 2;
    void *q = realloc(*p, c * elem);
    if (!q) return 0;
    *p = q;
    *cap = c;
    return 1;
}

/* ---- a hash map from a 128-bit key to an int32 ------------------------------ */

/* A slot holds val ^ INT32_MIN, so that zeroed memory is empty slots
 * (INT32_MIN, never a value) and a big map can start as a zero-filled file's
 * mapping. */
typedef struct km_slot_t {
    uint64_t hi, lo;
    uint32_t enc;  /* 0 = empty slot */
    int32_t pad;
} km_slot_t;

typedef struct keymap {
    km_slot_t *e;
    size_t cap, used;
    int paged;  /* e is a temporary file's mapping (beyond `limit` bytes) */
} keymap;

static uint64_t mix(uint64_t hi, uint64_t lo)
{
    uint64_t h = hi * 0x9E3779B97F4A7C15ull ^ (lo + 0x632BE59BD9B4E019ull + (hi << 6));
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 29;
    return h;
}

/* Room for at least `n` keys at load <= 3/4: in a temporary file's mapping
 * beyond `limit` bytes (0: no limit), else in memory.  Big tables in memory
 * ask for huge pages: lookups are random, and TLB misses otherwise
 * dominate. */
static int km_alloc(keymap *km, size_t n, uint64_t limit)
{
    size_t cap = 1024;
    while (cap / 4 * 3 < n) cap *= 2;
    size_t bytes = cap * sizeof *km->e;
    km->paged = limit && bytes > limit;
    if (km->paged) {
        km->e = pdt_temp_zeros(bytes);
    } else if (bytes >= ((size_t)4 << 20)) {
        km->e = aligned_alloc((size_t)2 << 20, bytes);
        if (km->e) madvise(km->e, bytes, MADV_HUGEPAGE);
        if (km->e) memset(km->e, 0, bytes);
    } else {
        km->e = calloc(cap, sizeof *km->e);
    }
    if (!km->e) return 0;
    km->cap = cap;
    km->used = 0;
    return 1;
}

static void km_free(keymap *km)
{
    if (km->paged && km->e) munmap(km->e, km->cap * sizeof *km->e);
    else free(km->e);
    memset(km, 0, sizeof *km);
}

/* A paged map's resident pages given back (the file keeps them). */
static void km_give_back(const keymap *km)
{
    if (km->paged) pdt_release_pages(km->e, km->cap * sizeof *km->e);
}

/* Slot of key (found, or the empty slot where it would go). */
static size_t km_slot(const keymap *km, uint64_t hi, uint64_t lo)
{
    size_t mask = km->cap - 1, i = (size_t)mix(hi, lo) & mask;
    while (km->e[i].enc != 0 && (km->e[i].hi != hi || km->e[i].lo != lo)) i = (i + 1) & mask;
    return i;
}

static int km_get(const keymap *km, uint64_t hi, uint64_t lo, int32_t *v)
{
    if (!km->cap) return 0;
    size_t i = km_slot(km, hi, lo);
    if (km->e[i].enc == 0) return 0;
    *v = (int32_t)(km->e[i].enc ^ 0x80000000u);
    return 1;
}

/* (v != INT32_MIN) */
static int km_put(keymap *km, uint64_t hi, uint64_t lo, int32_t v, uint64_t limit)
{
    if (km->used + 1 > km->cap / 4 * 3) {
        keymap big;
        if (!km_alloc(&big, km->cap ? km->cap : 512, limit)) return 0;
        for (size_t i = 0; i < km->cap; i++) {
            if (km->e[i].enc == 0) continue;
            big.e[km_slot(&big, km->e[i].hi, km->e[i].lo)] = km->e[i];
            if (++big.used % 65536 == 0) { /* (paged: the pages go back as it goes) */
                km_give_back(&big);
                km_give_back(km);
            }
        }
        km_free(km);
        *km = big;
    }
    size_t i = km_slot(km, hi, lo);
    if (km->e[i].enc == 0) km->used++;
    km->e[i] = (km_slot_t){hi, lo, (uint32_t)v ^ 0x80000000u, 0};
    return 1;
}

/* ---- the build's tables: in memory, or paged beyond a limit ----------------

 * A streamed build (a kept index) holds its tables of objects within a
 * share of its budget (r->tab_limit): a table that outgrows it moves to a
 * temporary file's mapping (pdt_temp_map, lengthened in place as it grows),
 * where the pages the build touched are given back every TICK_EVENTS events
 * (tabs_give_back): a read of them again faults them in from the page
 * cache.  Such a table is in r->ptab until tab_free unmaps it. */

#define TICK_EVENTS 65536u

static int tab_paged(const pdt_replay *r, const void *p)
{
    for (int i = 0; p && i < r->nptab; i++)
        if (r->ptab[i].p == p) return i;
    return -1;
}

static void tab_free(pdt_replay *r, void *p)
{
    int i = tab_paged(r, p);
    if (i < 0) {
        free(p);
        return;
    }
    pdt_temp_map_free(&r->ptab[i]);
    r->ptab[i] = r->ptab[--r->nptab];
}

/* A new table of `bytes` (zero-filled when paged; else malloc's, asking
 * for huge pages), or NULL. */
static void *tab_new(pdt_replay *r, size_t bytes)
{
    if (!r->tab_limit || bytes <= r->tab_limit || r->nptab == PDT_PTAB_MAX) {
        void *p = malloc(bytes ? bytes : 1);
        if (p) pdt_big_advise(p, bytes);
        return p;
    }
    pdt_temp_map m = {0};
    if (pdt_temp_map_new(&m, bytes) != 0) return NULL;
    r->ptab[r->nptab++] = m;
    return m.p;
}

/* grow() for a table of r: room for `need` entries of `elem` bytes, its
 * entries [0, *cap) kept. */
static int tab_grow(pdt_replay *r, void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap) return 1;
    size_t c = *cap ? *cap : 64;
    while (c < need) c *= 2;
    int i = tab_paged(r, *p);
    if (!r->tab_limit || (c * elem <= r->tab_limit && i < 0)) return grow(p, cap, need, elem);
    if (i >= 0) { /* (paged: the file lengthened, its mapping moved if need be) */
        if (pdt_temp_map_grow(&r->ptab[i], c * elem) != 0) return 0;
        *p = r->ptab[i].p;
        *cap = c;
        return 1;
    }
    void *q = tab_new(r, c * elem); /* (a table in memory outgrowing the limit: paged) */
    if (!q) return 0;
    memcpy(q, *p, *cap * elem); /* (at most tab_limit bytes) */
    pdt_replay_tab_release(r, q, *cap * elem);
    tab_free(r, *p);
    *p = q;
    *cap = c;
    return 1;
}

static void tabs_give_back(const pdt_replay *r)
{
    for (int i = 0; i < r->nptab; i++) pdt_release_pages(r->ptab[i].p, r->ptab[i].bytes);
}

void pdt_replay_tab_release(const pdt_replay *r, const void *p, size_t len)
{
    for (int i = 0; i < r->nptab; i++) {
        const char *b = r->ptab[i].p;
        if ((const char *)p >= b && (const char *)p + len <= b + r->ptab[i].bytes) {
            pdt_release_pages(p, len);
            return;
        }
    }
}

/* ---- the replay ------------------------------------------------------------ */

#define NONE32 UINT32_MAX

/* ev_kind: the event's kind in the low bits (KIND_UNKNOWN for kinds beyond
 * them), and KIND_FIRST on a triangle's first event: stepping forwards over
 * it gives the triangle its first history entry (tris[t].h0; in a build,
 * ev_ent), stepping back over it leaves the triangle with none, and every
 * other event of a triangle moves it one entry on or back (a triangle's
 * entries are consecutive, in event order).  So the replay keeps no entry
 * per event (ev_ent is the build's). */
#define KIND_MASK 0x3f
#define KIND_UNKNOWN 0x3f
#define KIND_FIRST 0x80
_Static_assert(PDT_EV_KIND_COUNT <= KIND_UNKNOWN, "every kind has a code below KIND_UNKNOWN");

static int kind_at(const pdt_replay *r, size_t i) { return r->ev_kind[i] & KIND_MASK; }


/* Event i (< m): from the array, or decoded (a kept index: the pointer
 * holds for PDT_EVSRC_KEEP - 1 more calls). */
static inline const pdt_rec *rec_at(const pdt_replay *r, size_t i)
{
    return r->recs ? &r->recs[i] : pdt_evsrc_get(r->src, i);
}

static int is_tri_kind(int k)
{
    return k == PDT_EV_TRI_NEW || k == PDT_EV_TRI_FINAL || k == PDT_EV_RA_DEFER ||
           k == PDT_EV_SHIP || k == PDT_EV_DISCARD;
}

static uint8_t tri_status_of(int k)
{
    switch (k) {
    case PDT_EV_TRI_NEW: return PDT_TS_CANDIDATE;
    case PDT_EV_TRI_FINAL: return PDT_TS_FINAL;
    case PDT_EV_RA_DEFER: return PDT_TS_DEFERRED;
    case PDT_EV_SHIP: return PDT_TS_SHIPPED;
    default: return PDT_TS_DISCARDED;
    }
}

static void sort3(uint32_t v[3], const uint32_t in[3])
{
    uint32_t a = in[0], b = in[1], c = in[2], t;
    if (a > b) { t = a; a = b; b = t; }
    if (b > c) { t = b; b = c; c = t; }
    if (a > b) { t = a; a = b; b = t; }
    v[0] = a;
    v[1] = b;
    v[2] = c;
}

/* ---- triangles: their events grouped by triangle, in buckets of bounded size ----
 *
 * The first pass writes every triangle event as its triangle's key (the
 * corners sorted) and its event index into a spill (memory, or the place's
 * spill file), sorted by a hash of the key into fine buckets (NFINE held
 * in memory; a streamed build plans their number from the run and its
 * budget, pdt_replay_plan_buckets), each in event order; what its history
 * entry needs besides (its sub field, and for
 * a border kernel's candidate the merge step open on its rank) waits in
 * ev_ent and ev_obj, which the grouping overwrites.  Then runs of
 * consecutive fine buckets that fit the working budget are grouped one
 * after the other with a hash table of their own size (tri_groups): the
 * events of one triangle are all in one fine bucket, so each run's
 * triangles are whole, and their history entries take the run's place in
 * the history table; a vertex set of more than PDT_TRI_HIST_MAX events is
 * grouped as several triangles (a state names a triangle's entry in 16
 * bits).  A last pass in event order numbers the triangles by their first
 * event (tri_ids; streamed: tri_number).  Memory: the tables themselves (which may be
 * the caller's, e.g. a mapping of the index file) and a working set bounded
 * by the budget. */

typedef struct tri_rec {
    uint32_t s[3];  /* corners, sorted: the triangle's key */
    uint32_t ev;
} tri_rec;

/* A streamed build's spill record: what the history entry needs besides
 * the key and the event travels with it (the build keeps nothing per
 * event): x = XREC_BORDER | (merge step + 1) for a border kernel's
 * candidate (TRI_NEW, sub 1), else kind | sub << 8. */
typedef struct tri_xrec {
    uint32_t s[3], ev, x;
} tri_xrec;
#define XREC_BORDER 0x80000000u

#define FINE_BITS 8
#define NFINE ((size_t)1 << FINE_BITS)
_Static_assert(NFINE == PDT_REPLAY_NFINE, "replay_int.h says how many fine buckets");
#define GROUP_BYTES_PER_EVENT PDT_REPLAY_GROUP_BYTES_PER_EVENT /* tri_groups' working memory
                                                              * per event, at most */
/* Events per run, at most (unless one fine bucket holds more): a working set
 * of some 60 MiB, reused from run to run (fresh pages are dear on virtual
 * machines, and a smaller hash table misses the caches less). */
#define GROUP_RUN_MAX ((size_t)1 << 19)

static uint64_t key_hash(const uint32_t s[3])
{
    return mix(((uint64_t)s[0] << 32) | s[1], s[2]);
}

static size_t fine_of(const uint32_t s[3], unsigned bits) { return (size_t)(key_hash(s) >> (64 - bits)); }

size_t pdt_replay_fine_of(const pdt_rec *rec, size_t n, int nranks)
{
    const pdt_event *e = &rec->ev;
    if (!is_tri_kind(e->kind) || rec->rank >= (uint32_t)nranks || e->a >= n || e->b >= n ||
        e->c >= n)
        return NFINE;
    uint32_t in[3] = {e->a, e->b, e->c}, s[3];
    sort3(s, in);
    return fine_of(s, FINE_BITS);
}

/* A chunk of a spill: where, whose (fine bucket, or window of points), how
 * many records. */
typedef struct spill_chunk {
    uint64_t off;      /* in the spill */
    uint32_t f, n;     /* fine bucket, records */
} spill_chunk;

/* A spill's chunks as written, and where the spill ends (bytes). */
typedef struct spill_log {
    spill_chunk *chunk;
    size_t n, cap;
    uint64_t end;
} spill_log;

/* Build state while indexing: the current slot values of every rank. */
typedef struct builder {
    pdt_replay *r;
    int32_t *cur;   /* per rank * PDT_SLOT_PER_RANK */
    int32_t *lastst;     /* per rank: the stack touched last (HULL reports it) */
    keymap edge_map, msg_map;
    /* the fine buckets: 2^fine_bits of them (FINE_BITS held in memory;
     * streamed, bucket_plan), the records buffered per bucket in pass 1
     * (fbuf_recs) and per cursor after it (cur_recs) */
    unsigned fine_bits;
    size_t nfine, fbuf_recs, cur_recs;
    size_t *fine_fill;    /* per fine bucket: the next free history entry (pass 1) */
    size_t *fine_off;     /* per fine bucket: its first history entry; nfine + 1 */
    const pdt_replay_place *pl;  /* streamed: the place, and per fine bucket a buffer */
    tri_xrec *fbuf;       /* nfine * fbuf_recs records */
    tri_rec *spill;       /* not streamed: the triangle events by fine bucket */
    /* streamed: the spill is written a buffer (a chunk) at a time, where it
     * ends; chunk k of fine bucket f is chunk[ck_start[f] + k] after pass 1 */
    spill_log tlog;
    size_t *ck_start;
    int stream_failed;    /* the place's stream of events failed (err set by it) */
    pdt_rec *win;         /* streamed: events win_lo .. win_lo + win_n - 1 of the stream */
    size_t win_lo, win_n;
    uint32_t *fbn;        /* records in each buffer */
    int failed;           /* a put or get failed */
    /* the per-event tables as pass 1 writes them: the replay's (in memory)
     * or a window of EVW events from wlo (streamed: then to the place) */
    int32_t *wobj;
    uint8_t *wkind;
    size_t wlo;
    size_t *tcount;       /* streamed: triangles per fine bucket (nfine) */
    /* streamed: what lifts and pushes do to points (pt_rec), spilled by
     * point window (PT_WINDOW points each) to PDT_SCR_POINTS in chunks */
    struct pt_rec *pbuf;  /* npw * PBUF records */
    uint32_t *pbn;
    size_t npw;
    spill_log plog;
    uint8_t *lifted_any;  /* per rank: it lifted a point outside a merge */
    _Atomic uint64_t held, peak;  /* streamed: working memory (bytes) */
} builder;

#define EVW 65536u  /* events per window of the per-event tables (streamed) */

/* The builder's accounting of its working memory (streamed builds): what
 * bmalloc gives, until bfree. */
static void *bmalloc(builder *b, size_t bytes)
{
    void *p = malloc(bytes ? bytes : 1);
    if (!p) return NULL;
    uint64_t now = atomic_fetch_add(&b->held, bytes) + bytes, pk = atomic_load(&b->peak);
    while (now > pk && !atomic_compare_exchange_weak(&b->peak, &pk, now)) {}
    return p;
}

static void bfree(builder *b, void *p, size_t bytes)
{
    if (!p) return;
    free(p);
    atomic_fetch_sub(&b->held, bytes);
}

static void set_obj(builder *b, size_t i, int32_t v) { b->wobj[i - b->wlo] = v; }

/* ---- points: first lifts and the ranks' boxes, streamed ---------------------------
 *
 * A streamed build holds no table per point of its own: a lift and a push
 * that counts for its rank's box are written down (pt_rec) by window of
 * points, and after pass 1 each window's records give its points' first
 * lifts (the place's lift table, at lift_at) and their share of the boxes
 * (the points read a window at a time).  A rank's box is the box of the
 * points it lifted outside a merge, or, when it lifted none, of the points
 * it pushed: what box_add makes in event order. */
typedef struct pt_rec {
    uint32_t p, ev, rank, what;  /* what: PT_PUSH, PT_LIFT (in a merge), PT_LIFT_BOX */
} pt_rec;
enum { PT_PUSH, PT_LIFT, PT_LIFT_BOX };
#define PT_WINDOW ((size_t)1 << 20)  /* points per window */
#define PBUF 256u                    /* records buffered per window */

/* Write k records of `rec` bytes from buf where scratch stream scr ends, a
 * chunk of bucket f in lg.  0 when out of memory or the write failed. */
static int spill_put(builder *b, int scr, spill_log *lg, const void *buf, size_t k, size_t rec,
                     size_t f)
{
    if (!k) return 1;
    if (!grow((void **)&lg->chunk, &lg->cap, lg->n + 1, sizeof *lg->chunk)) return 0;
    if (!b->pl->sput(b->pl->ctx, scr, lg->end, buf, k * rec)) {
        b->failed = 1;
        return 0;
    }
    lg->chunk[lg->n++] = (spill_chunk){lg->end, (uint32_t)f, (uint32_t)k};
    lg->end += k * rec;
    return 1;
}

/* lg's chunks ordered by bucket, each bucket's in the order written (its
 * records' order): start[f] .. start[f + 1] - 1 are bucket f's (start: nb +
 * 1 entries, zeroed by the caller).  0 when out of memory. */
static int spill_group(spill_log *lg, size_t nb, size_t *start)
{
    spill_chunk *sorted = malloc((lg->n ? lg->n : 1) * sizeof *sorted);
    size_t *fill = malloc((nb + 1) * sizeof *fill);
    if (!sorted || !fill) {
        free(sorted);
        free(fill);
        return 0;
    }
    for (size_t c = 0; c < lg->n; c++) start[lg->chunk[c].f + 1]++;
    for (size_t f = 0; f < nb; f++) start[f + 1] += start[f];
    memcpy(fill, start, (nb + 1) * sizeof *fill);
    for (size_t c = 0; c < lg->n; c++) sorted[fill[lg->chunk[c].f]++] = lg->chunk[c];
    free(fill);
    free(lg->chunk);
    lg->chunk = sorted;
    lg->cap = lg->n;
    return 1;
}

static int pt_flush(builder *b, size_t w)
{
    size_t k = b->pbn[w];
    b->pbn[w] = 0;
    return spill_put(b, PDT_SCR_POINTS, &b->plog, b->pbuf + w * PBUF, k, sizeof(pt_rec), w);
}

static int pt_note(builder *b, uint32_t p, uint32_t ev, uint32_t rank, uint32_t what)
{
    size_t w = p / PT_WINDOW;
    b->pbuf[w * PBUF + b->pbn[w]++] = (pt_rec){p, ev, rank, what};
    return b->pbn[w] < PBUF || pt_flush(b, w);
}

#define FBUF 1024u  /* records buffered per fine bucket (streamed): a chunk of the spill */

#define WIN 8192u  /* events of the stream at hand (streamed) */

/* The index pass is bound by cache misses in the edge map (random slots in
 * a table of 10^8 bytes at level 2).  The events are all known in advance,
 * so the slot an event a few places ahead will probe is fetched while the
 * current one is handled.  A hint only: nothing depends on it. */
#define PREFETCH_AHEAD 12


/* A big table of `bytes` (malloc'd, asking for huge pages), or NULL. */
static void *big_table(size_t bytes)
{
    void *p = malloc(bytes ? bytes : 1);
    if (p) pdt_big_advise(p, bytes);
    return p;
}

/* Write n entries of `elem` bytes from p at entry `at` of the table at `base`
 * of the place (streamed) or of the array `arr`. */
static int tput(builder *b, void *arr, uint64_t base, size_t at, const void *p, size_t n, size_t elem)
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
 * chunk of it. */
static int fine_flush(builder *b, size_t f)
{
    size_t k = b->fbn[f];
    b->fbn[f] = 0;
    return spill_put(b, PDT_SCR_SPILL, &b->tlog, b->fbuf + f * b->fbuf_recs, k, sizeof(tri_xrec), f);
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
static int chunks_by_bucket(builder *b)
{
    b->ck_start = calloc(b->nfine + 1, sizeof *b->ck_start);
    return b->ck_start && spill_group(&b->tlog, b->nfine, b->ck_start);
}

static int set_slot(builder *b, uint32_t ev, int rank, int slot, int32_t val)
{
    pdt_replay *r = b->r;
    size_t s = (size_t)rank * PDT_SLOT_PER_RANK + (size_t)slot;
    if (!tab_grow(r, (void **)&r->ch, &r->cap_ch, r->nch + 1, sizeof *r->ch)) return 0;
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

static void box_add(pdt_replay *r, uint32_t rank, pdt_point p)
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
static int graham_tables(pdt_replay *r)
{
    size_t n = r->n;
    r->sort_ev = tab_new(r, n * sizeof *r->sort_ev);
    r->del_ev = tab_new(r, n * sizeof *r->del_ev);
    r->sort_pos = tab_new(r, n * sizeof *r->sort_pos);
    if (!r->sort_ev || !r->del_ev || !r->sort_pos) {
        tab_free(r, r->sort_ev);
        tab_free(r, r->del_ev);
        tab_free(r, r->sort_pos);
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
    if (!tab_grow(r, (void **)&r->phases, &r->cap_phase, r->nphase + 1, sizeof *r->phases)) return 0;
    r->phases[r->nphase] = (pdt_rphase){rec->rank, e->sub, e->a, i, NONE32, IX_CUR[PDT_SLOT_PHASE], 0};
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
    return set_slot(b, i, (int)rec->rank, PDT_SLOT_PHASE, r->phases[p].parent);
}

static int ix_merge_begin(IX_ARGS)
{
    pdt_replay *r = b->r;
    const pdt_event *e = &rec->ev;
    if (!tab_grow(r, (void **)&r->merges, &r->cap_merge, r->nmerge + 1, sizeof *r->merges)) return 0;
    r->merges[r->nmerge] = (pdt_rmerge){rec->rank, e->sub, e->a, e->b, e->c, i, NONE32, 0, 0, 0, 0};
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
    if (!tab_grow(r, (void **)&r->nodes, &r->cap_node, r->nnode + 1, sizeof *r->nodes)) return 0;
    r->nodes[r->nnode] = (pdt_rnode){e->a, parent, d, NONE32};
    r->nnode++;
    if (!b->lifted_any[rank]) {
        if (b->pl && !pt_note(b, e->a, i, rec->rank, PT_PUSH)) return 0;
        if (!b->pl) box_add(r, rec->rank, r->pts[e->a]);
    }
    return set_slot(b, i, rank, slot, (int32_t)(r->nnode - 1));
}

/* A hull: the tops of the stacks its rank touched last. */
static int ix_hull(IX_ARGS)
{
    pdt_replay *r = b->r;
    const pdt_event *e = &rec->ev;
    const int32_t *cur = IX_CUR;
    if (!tab_grow(r, (void **)&r->hulls, &r->cap_hull, r->nhull + 1, sizeof *r->hulls)) return 0;
    int st = b->lastst[rec->rank];
    pdt_rhull h = {rec->rank, i, -1, -1, e->a, (uint8_t)(e->b != 0)};
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
    if (e->kind != PDT_EV_LIFT && !r->sort_ev && !graham_tables(r)) return 0;
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
        return pt_note(b, e->a, i, rec->rank, in_merge ? PT_LIFT : PT_LIFT_BOX);
    }
    if (!in_merge) {
        if (!b->lifted_any[rank]) r->has_box[rank] = 0; /* forget pushed points */
        b->lifted_any[rank] = 1;
        box_add(r, rec->rank, r->pts[e->a]);
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
    int have = km_get(&b->edge_map, rec->rank, k, &id) && id >= 0;
    if (e->kind == PDT_EV_EDGE_ADD) {
        if (!tab_grow(r, (void **)&r->edges, &r->cap_edge, r->nedge + 1, sizeof *r->edges)) return 0;
        r->edges[r->nedge] = (pdt_redge){e->a, e->b, rec->rank, i, NONE32};
        if (!km_put(&b->edge_map, rec->rank, k, (int32_t)r->nedge, r->tab_limit)) return 0;
        set_obj(b, i, (int32_t)r->nedge);
        r->nedge++;
    } else if (have) {
        r->edges[id].del_ev = i;
        set_obj(b, i, id);
        if (!km_put(&b->edge_map, rec->rank, k, -1, r->tab_limit)) return 0;
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
    if (!km_get(&b->msg_map, hi, lo, &id) || (send ? r->msgs[id].send_ev : r->msgs[id].recv_ev) != NONE32) {
        if (!tab_grow(r, (void **)&r->msgs, &r->cap_msg, r->nmsg + 1, sizeof *r->msgs)) return 0;
        r->msgs[r->nmsg] = (pdt_rmsg){src, dst, e->sub, pdt_event_bytes(e), NONE32, NONE32};
        id = (int32_t)r->nmsg++;
        if (!km_put(&b->msg_map, hi, lo, id, r->tab_limit)) return 0;
    }
    if (send) r->msgs[id].send_ev = i;
    else r->msgs[id].recv_ev = i;
    set_obj(b, i, id);
    return 1;
}

/* A triangle event: into its triangle's fine bucket (grouped after pass 1,
 * tri_histories), with what its history entry needs. */
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
    size_t f = fine_of(t.s, b->fine_bits);
    if (!b->pl) { /* for hist_of, until the grouping writes these two */
        r->ev_ent[i] = e->sub;
        r->ev_obj[i] = border ? cur[PDT_SLOT_MERGE] : -1;
        b->spill[b->fine_fill[f]++] = t;
        return 1;
    }
    /* (streamed: fine_fill counts the bucket's events) */
    b->fbuf[f * b->fbuf_recs + b->fbn[f]++] =
        (tri_xrec){{t.s[0], t.s[1], t.s[2]}, i,
                   border ? XREC_BORDER | (uint32_t)(cur[PDT_SLOT_MERGE] + 1)
                          : (uint32_t)e->kind | (uint32_t)e->sub << 8};
    b->fine_fill[f]++;
    return b->fbn[f] < b->fbuf_recs || fine_flush(b, f);
}

/* Pass 1's handling of event i (every object but triangle histories, which
 * need counts first). */
static int index_event(builder *b, uint32_t i, const pdt_rec *rec)
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

/* (PREFETCH_AHEAD: see probe_addr) */

/* The slot that looking up event i will probe first, or NULL; for a lift,
 * sort or deletion, the point's entry of its first such event, and (*also)
 * for a lift its coordinates (random places in tables of 4 and 8 bytes per
 * point).  (The caller prefetches them: GCC drops a __builtin_prefetch
 * inside a helper function, which it deems free of side effects.) */
static const void *probe_addr(const builder *b, const pdt_rec *rec, const void **also)
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
    return km->cap ? &km->e[(size_t)mix(rec->rank, ((uint64_t)x << 32) | y) & (km->cap - 1)] : NULL;
}

/* One slot of tri_groups' hash table: a key and its group, UINT32_MAX = empty. */
typedef struct gslot {
    uint32_t s[3], g;
} gslot;

/* The history entry of triangle event ev (the status it sets), from what
 * the first pass left in ev_ent (its sub field) and ev_obj (a border
 * kernel's candidate: the merge step open on its rank, else -1).  That step
 * is the one whose MERGE_END the candidate waits for: a merge step that ends
 * was its rank's open one from its MERGE_BEGIN to its MERGE_END. */
static pdt_rtri_hist hist_of(const pdt_replay *r, uint32_t ev)
{
    int kind = kind_at(r, ev);
    uint8_t sub = (uint8_t)r->ev_ent[ev];
    int32_t g = r->ev_obj[ev];
    pdt_rtri_hist h = {ev, NONE32, tri_status_of(kind), sub, {0, 0}};
    if (kind == PDT_EV_TRI_NEW && sub == 1 && g >= 0 && (size_t)g < r->nmerge)
        h.until = r->merges[g].end_ev;  /* (NONE32: it never ended) */
    return h;
}

/* One thread's share of tri_groups: runs of fine buckets (run[] holds
 * their bounds) taken in turn from *next; each thread its own buffers of
 * `most` events (the largest run). */
typedef struct group_job {
    builder *b;
    const size_t *run;      /* bucket bounds: run k is [run[k], run[k + 1]) */
    size_t nrun, most;
    _Atomic size_t next;    /* next run to take */
    _Atomic int failed;     /* out of memory, or (io) a read or write of the place failed */
    _Atomic int io;
    _Atomic size_t ntri;    /* triangles found */
} group_job;

/* Group the nb records at buf (stride bytes apart, each beginning with a
 * tri_rec) by their key, with the hash table slot (room for nb at load 3/4):
 * gid[j] is record j's group, numbered by first appearance; gfirst[g] the
 * event of group g's first record, gn[g] its records.  Returns the groups. */
static uint32_t group_keys(const void *buf, size_t stride, size_t nb, gslot *slot, uint32_t *gid,
                           uint32_t *gfirst, uint32_t *gn)
{
#define KREC(j) ((const tri_rec *)(const void *)((const char *)buf + (j) * stride))
    size_t hc = 1024;
    while (hc / 4 * 3 < nb) hc *= 2;
    size_t mask = hc - 1;
    for (size_t q = 0; q < hc; q++) slot[q].g = NONE32;
    uint32_t ng = 0;
    for (size_t j = 0; j < nb; j++) {
        if (j + PREFETCH_AHEAD < nb)
            __builtin_prefetch(&slot[(size_t)key_hash(KREC(j + PREFETCH_AHEAD)->s) & mask]);
        const uint32_t *s = KREC(j)->s;
        size_t q = (size_t)key_hash(s) & mask;
        while (slot[q].g != NONE32 &&
               (slot[q].s[0] != s[0] || slot[q].s[1] != s[1] || slot[q].s[2] != s[2]))
            q = (q + 1) & mask;
        if (slot[q].g == NONE32 || gn[slot[q].g] == PDT_TRI_HIST_MAX) { /* (a new triangle,
                                                  * or the next of a vertex set's) */
            slot[q] = (gslot){{s[0], s[1], s[2]}, ng};
            gfirst[ng] = KREC(j)->ev;
            gn[ng++] = 0;
        }
        gid[j] = slot[q].g;
        gn[gid[j]]++;
    }
    return ng;
#undef KREC
}

/* A grouping thread's scratch (both builds): `most` records of `rec` bytes,
 * the hash table for them, the per-record group and the per-group tables
 * (group_keys), and the next place of each group (gfill). */
typedef struct group_scratch {
    void *buf;
    gslot *slot;
    uint32_t *gid, *gfirst, *gn, *gfill;
    size_t most, hcap, rec;
} group_scratch;

static int scratch_get(builder *b, group_scratch *s, size_t most, size_t rec)
{
    size_t hcap = 1024;
    while (hcap / 4 * 3 < most) hcap *= 2;
    *s = (group_scratch){.most = most, .hcap = hcap, .rec = rec};
    s->buf = bmalloc(b, most * rec);
    s->slot = bmalloc(b, hcap * sizeof *s->slot);
    s->gid = bmalloc(b, most * sizeof *s->gid);
    s->gfirst = bmalloc(b, most * sizeof *s->gfirst);
    s->gn = bmalloc(b, most * sizeof *s->gn);
    s->gfill = bmalloc(b, most * sizeof *s->gfill);
    if (!(s->buf && s->slot && s->gid && s->gfirst && s->gn && s->gfill)) return 0;
    pdt_big_advise(s->buf, most * rec);
    pdt_big_advise(s->slot, hcap * sizeof *s->slot);
    return 1;
}

static void scratch_put(builder *b, group_scratch *s)
{
    bfree(b, s->buf, s->most * s->rec);
    bfree(b, s->slot, s->hcap * sizeof *s->slot);
    bfree(b, s->gid, s->most * sizeof *s->gid);
    bfree(b, s->gfirst, s->most * sizeof *s->gfirst);
    bfree(b, s->gn, s->most * sizeof *s->gn);
    bfree(b, s->gfill, s->most * sizeof *s->gfill);
}

/* Group the nb records in s->buf; gfill[g] = base + the entries of groups
 * before g (where group g's entries begin).  Returns the groups. */
static uint32_t scratch_group(group_scratch *s, size_t nb, size_t base)
{
    uint32_t ng = group_keys(s->buf, s->rec, nb, s->slot, s->gid, s->gfirst, s->gn);
    size_t h = base;
    for (uint32_t q = 0; q < ng; q++) s->gfill[q] = (uint32_t)h, h += s->gn[q];
    return ng;
}

/* The in-memory build's grouping: the entries into r->hist, and per event
 * its entry (ev_ent) and its triangle's first event (ev_obj; see
 * tri_groups). */
static void *group_worker(void *arg)
{
    group_job *J = arg;
    builder *b = J->b;
    pdt_replay *r = b->r;
    group_scratch S;
    int ok = scratch_get(b, &S, J->most, sizeof(tri_rec));
    const tri_rec *buf = S.buf;
    size_t found = 0;
    while (ok && !J->failed) {
        size_t k = J->next++;
        if (k >= J->nrun) break;
        size_t base = b->fine_off[J->run[k]], nb = b->fine_off[J->run[k + 1]] - base;
        if (!nb) continue;
        memcpy(S.buf, &b->spill[base], nb * sizeof *buf);
        uint32_t ng = scratch_group(&S, nb, base);
        pdt_rtri_hist *to = r->hist + base;
        for (size_t j = 0; j < nb; j++) {
            if (j + PREFETCH_AHEAD < nb) { /* random places in three tables of 4, 4, 1 bytes per event */
                __builtin_prefetch(&r->ev_ent[buf[j + PREFETCH_AHEAD].ev], 1);
                __builtin_prefetch(&r->ev_obj[buf[j + PREFETCH_AHEAD].ev], 1);
                __builtin_prefetch(&r->ev_kind[buf[j + PREFETCH_AHEAD].ev]);
            }
            uint32_t q = S.gid[j], ev = buf[j].ev, at = S.gfill[q]++;
            to[at - base] = hist_of(r, ev);
            r->ev_ent[ev] = at;  /* (threads write distinct events) */
            r->ev_obj[ev] = ev == S.gfirst[q] ? -1 - (int32_t)S.gn[q] : (int32_t)S.gfirst[q];
        }
        found += ng;
    }
    if (!ok) J->failed = 1;
    J->ntri += found;
    scratch_put(b, &S);
    return NULL;
}

/* The history entry of a streamed build's spill record (hist_of, from what
 * the record carries). */
static pdt_rtri_hist hist_of_x(const pdt_replay *r, const tri_xrec *t)
{
    int kind = PDT_EV_TRI_NEW;
    uint8_t sub = 1;
    int32_t g = -1;
    if (t->x & XREC_BORDER) g = (int32_t)(t->x & ~XREC_BORDER) - 1;
    else kind = (int)(t->x & 0xff), sub = (uint8_t)(t->x >> 8);
    pdt_rtri_hist h = {t->ev, NONE32, tri_status_of(kind), sub, {0, 0}};
    if (kind == PDT_EV_TRI_NEW && sub == 1 && g >= 0 && (size_t)g < r->nmerge)
        h.until = r->merges[g].end_ev;
    return h;
}

/* A triangle event's record in PDT_SCR_TRIEV: its event, and its triangle
 * (its number in its fine bucket, then after tri_join its number in the
 * replay), TEV_FIRST on the triangle's first event. */
typedef struct tri_ev {
    uint32_t ev, t;
} tri_ev;
#define TEV_FIRST 0x80000000u

/* A triangle's record in PDT_SCR_TRIS: its first event, its entries. */
typedef struct tri_first {
    uint32_t ev, n;
} tri_first;

/* The streamed build's grouping: a run's entries to the place's history
 * table; per triangle event a tri_ev (PDT_SCR_TRIEV, at its place in the
 * bucket order), per triangle a tri_first (PDT_SCR_TRIS, from its bucket's
 * first place: fine_off[f]), both in event order within each bucket, and
 * the triangles per bucket (tcount).  Nothing is written per event in
 * memory: numbering the triangles comes after (tri_number). */
static void *group_worker_streamed(void *arg)
{
    group_job *J = arg;
    builder *b = J->b;
    pdt_replay *r = b->r;
    const pdt_replay_place *pl = b->pl;
    size_t most = J->most;
    group_scratch S;
    int ok = scratch_get(b, &S, most, sizeof(tri_xrec));
    tri_xrec *buf = S.buf;
    pdt_rtri_hist *out = bmalloc(b, most * sizeof *out);  /* the run's entries */
    tri_ev *eout = bmalloc(b, most * sizeof *eout);
    tri_first *tout = bmalloc(b, most * sizeof *tout);
    ok = ok && out && eout && tout;
    size_t found = 0;
    while (ok && !J->failed) {
        size_t k = J->next++;
        if (k >= J->nrun) break;
        size_t base = b->fine_off[J->run[k]], nb = b->fine_off[J->run[k + 1]] - base;
        if (!nb) continue;
        for (size_t c = b->ck_start[J->run[k]], got = 0; c < b->ck_start[J->run[k + 1]]; c++) {
            const spill_chunk *ck = &b->tlog.chunk[c]; /* the run's chunks, bucket by bucket */
            if (got + ck->n > nb ||
                !pl->sget(pl->ctx, PDT_SCR_SPILL, ck->off, buf + got, ck->n * sizeof *buf)) {
                J->io = 1;
                ok = 0;
                break;
            }
            got += ck->n;
        }
        if (!ok) break;
        uint32_t ng = scratch_group(&S, nb, base);
        /* bucket by bucket: its triangles are the groups first seen in it */
        uint32_t g0 = 0;
        for (size_t f = J->run[k]; f < J->run[k + 1]; f++) {
            size_t j0 = b->fine_off[f] - base, j1 = b->fine_off[f + 1] - base;
            uint32_t g1 = g0;
            for (size_t j = j0; j < j1; j++) {
                uint32_t q = S.gid[j], ev = buf[j].ev, at = S.gfill[q]++;
                if (q >= g1) g1 = q + 1;
                out[at - base] = hist_of_x(r, &buf[j]);
                eout[j] = (tri_ev){ev, (q - g0) | (ev == S.gfirst[q] ? TEV_FIRST : 0)};
            }
            for (uint32_t q = g0; q < g1; q++) tout[q - g0] = (tri_first){S.gfirst[q], S.gn[q]};
            b->tcount[f] = g1 - g0;
            if (g1 > g0 && !pl->sput(pl->ctx, PDT_SCR_TRIS, (uint64_t)b->fine_off[f] * sizeof *tout,
                                     tout, (g1 - g0) * sizeof *tout)) {
                ok = 0;
                break;
            }
            g0 = g1;
        }
        if (!ok || !pl->sput(pl->ctx, PDT_SCR_HIST, base * sizeof *out, out, nb * sizeof *out) ||
            !pl->sput(pl->ctx, PDT_SCR_TRIEV, (uint64_t)base * sizeof *eout, eout, nb * sizeof *eout)) {
            J->io = 1;
            ok = 0;
        }
        found += ng;
    }
    if (!ok) J->failed = 1;
    J->ntri += found;
    bfree(b, out, most * sizeof *out);
    bfree(b, eout, most * sizeof *eout);
    bfree(b, tout, most * sizeof *tout);
    scratch_put(b, &S);
    return NULL;
}

/* Threads that group triangle events at once (each with its own share of
 * the working budget): the runs are independent, and the grouping is bound
 * by cache misses and copying, which a second core halves. */
#define GROUP_THREADS 2

/* Group the triangle events (hist[], in fine buckets) by triangle, a run
 * of fine buckets at a time: each triangle's entries become consecutive, in
 * event order; ev_ent[ev] is the event's entry; ev_obj[ev] is -1 - (entries
 * of its triangle) for a triangle's first event, else that first event.
 * Working memory: about budget bytes (0: no limit), over GROUP_THREADS
 * threads when the runs are several. */
static int tri_groups(builder *b, uint64_t budget, size_t *ntri)
{
    *ntri = 0;
    size_t cap = budget ? (size_t)(budget / GROUP_BYTES_PER_EVENT / GROUP_THREADS) : SIZE_MAX;
    if (cap < 1024) cap = 1024;
    if (b->pl && cap > GROUP_RUN_MAX) cap = GROUP_RUN_MAX;
    size_t *run = malloc((b->nfine + 1) * sizeof *run), nrun = 0, most = 0; /* the runs' bounds; the largest run */
    if (!run) return 0;
    run[0] = 0;
    for (size_t f = 0; f < b->nfine;) {
        size_t g = f + 1;
        while (g < b->nfine && b->fine_off[g + 1] - b->fine_off[f] <= cap) g++;
        if (b->fine_off[g] - b->fine_off[f] > most) most = b->fine_off[g] - b->fine_off[f];
        run[++nrun] = g;
        f = g;
    }
    if (!most) {
        free(run);
        return 1;
    }
    group_job J = {.b = b, .run = run, .nrun = nrun, .most = most};
    pthread_t th[GROUP_THREADS];
    int started = 0;
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    /* one thread when a single fine bucket is all the budget takes (a huge
     * run under a small budget: a bucket is the least a run is) */
    int threads = budget && (uint64_t)most * GROUP_BYTES_PER_EVENT * GROUP_THREADS > budget ? 1
                                                                                       : GROUP_THREADS;
    for (int t = 1; t < threads && t < cpus && (size_t)t < nrun; t++)
        if (pthread_create(&th[t], NULL, b->pl ? group_worker_streamed : group_worker, &J) == 0)
            started |= 1 << t;
    (b->pl ? group_worker_streamed : group_worker)(&J);
    for (int t = 1; t < GROUP_THREADS; t++)
        if (started & (1 << t)) pthread_join(th[t], NULL);
    free(run);
    if (J.failed) {
        if (J.io) b->failed = 1;
        return 0;
    }
    *ntri = J.ntri;
    return 1;
}

/* A streamed build reads the records (a mapping of the index file) from
 * start to end a few times: the pages behind the pass are let go every
 * DROP_EVERY records (they stay in the page cache), so the process does not
 * hold all of them at once. */
#define DROP_EVERY ((size_t)1 << 20)

static void drop_recs(const builder *b, size_t upto)
{
    if (!b->pl || !b->r->recs || !upto || upto % DROP_EVERY) return;
    pdt_release_pages(b->r->recs + upto - DROP_EVERY, DROP_EVERY * sizeof *b->r->recs);
}

/* Number the triangles by their first event (after tri_groups): the
 * triangle table (in r->tris, or streamed to tris_at), and ev_obj[ev] = the
 * triangle of every triangle event; the entry of a triangle's first event
 * is marked (FIRST_ENTRY). */
static int tri_ids(builder *b)
{
    pdt_replay *r = b->r;
    enum { TBUF = 4096 };
    pdt_rtri tb[TBUF], *to = b->pl ? tb : r->tris;
    size_t nb = 0;
    r->ntri = 0;
    for (size_t i = 0; i < r->m; i++) {
        drop_recs(b, i);
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
        to[b->pl ? nb++ : r->ntri] = (pdt_rtri){{rec->ev.a, rec->ev.b, rec->ev.c}, rec->rank,
                                               r->ev_ent[i], (uint32_t)(-1 - o)};
        r->ev_kind[i] |= KIND_FIRST;
        r->ev_obj[i] = (int32_t)r->ntri++;
        if (nb == TBUF) {
            if (!tput(b, NULL, r->tris_at, r->ntri - nb, tb, nb, sizeof *tb)) return 0;
            nb = 0;
        }
    }
    return tput(b, NULL, r->tris_at, r->ntri - nb, tb, nb, sizeof *tb);
}


/* ---- the streamed build's numbering, in windows of events -------------------------
 *
 * After the grouping (group_worker_streamed) each fine bucket has, in event
 * order, its triangles (tri_first) and its triangle events (tri_ev).
 * tri_number takes the buckets' triangles in order of their first events,
 * a window of events at a time, which numbers them (the triangle table,
 * and per bucket the numbers: PDT_SCR_IDS); tri_join gives each bucket's
 * triangle events their numbers; ev_tables merges them into the per-event
 * tables that pass 1 wrote (at the place) a window at a time.  Memory:
 * a buffer per bucket and a window, independent of the run's size (but for
 * the numbers of the largest bucket's triangles in tri_join). */

#define NUM_WINDOW ((size_t)1 << 18)  /* events per window (tri_number, ev_tables) */
#define CUR_RECS 512u                 /* records buffered per cursor, at most */

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

static int bput(builder *b, bcur *c, const void *p)
{
    memcpy(c->buf + c->n * c->rec, p, c->rec);
    return ++c->n < c->cap || bput_flush(b, c);
}

/* nfine cursors over records of rec bytes with one buffer; NULL when out of memory. */
static bcur *bcurs_new(builder *b, size_t rec)
{
    bcur *c = bmalloc(b, b->nfine * sizeof *c);
    unsigned char *buf = bmalloc(b, (size_t)b->nfine * b->cur_recs * rec);
    if (!c || !buf) {
        bfree(b, c, b->nfine * sizeof *c);
        bfree(b, buf, (size_t)b->nfine * b->cur_recs * rec);
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
    bfree(b, c[0].buf, (size_t)b->nfine * b->cur_recs * rec);
    bfree(b, c, b->nfine * sizeof *c);
}

/* Number the triangles by their first events: the triangle table and the
 * history table in the triangles' order (streamed to tris_at and hist_at:
 * a pass over the triangles reads their entries in order), a bucket's
 * numbers in PDT_SCR_IDS (from fine_off[f]); the corners and maker of a
 * triangle from its first event (decoded, in event order).  Each bucket's
 * entries (PDT_SCR_HIST, from its fine_off) are its triangles' in order. */
static int tri_number(builder *b)
{
    pdt_replay *r = b->r;
    bcur *tc = bcurs_new(b, sizeof(tri_first)), *ic = bcurs_new(b, sizeof(uint32_t));
    bcur *hc = bcurs_new(b, sizeof(pdt_rtri_hist)), tw, hw;
    uint32_t *wn = bmalloc(b, NUM_WINDOW * sizeof *wn);
    uint16_t *wf = bmalloc(b, NUM_WINDOW * sizeof *wf);
    memset(&tw, 0, sizeof tw);
    memset(&hw, 0, sizeof hw);
    tw.buf = bmalloc(b, CUR_RECS * sizeof(pdt_rtri));
    hw.buf = bmalloc(b, CUR_RECS * sizeof(pdt_rtri_hist));
    int ok = tc && ic && hc && wn && wf && tw.buf && hw.buf;
    if (ok) {
        for (size_t f = 0; f < b->nfine; f++) {
            tc[f].file = PDT_SCR_TRIS;
            tc[f].at = (uint64_t)b->fine_off[f] * sizeof(tri_first);
            tc[f].left = b->tcount[f];
            ic[f].file = PDT_SCR_IDS;
            ic[f].at = (uint64_t)b->fine_off[f] * sizeof(uint32_t);
            hc[f].file = PDT_SCR_HIST;
            hc[f].at = (uint64_t)b->fine_off[f] * sizeof(pdt_rtri_hist);
            hc[f].left = b->fine_off[f + 1] - b->fine_off[f];
        }
        tw.file = hw.file = -1;
        tw.at = r->tris_at;
        tw.rec = sizeof(pdt_rtri);
    tw.cap = hw.cap = CUR_RECS;
        hw.at = r->hist_at;
        hw.rec = sizeof(pdt_rtri_hist);
    }
    r->ntri = 0;
    size_t h0 = 0;
    for (size_t lo = 0; ok && lo < r->m; lo += NUM_WINDOW) {
        size_t hi = r->m - lo < NUM_WINDOW ? r->m : lo + NUM_WINDOW;
        memset(wn, 0, (hi - lo) * sizeof *wn);
        for (size_t f = 0; f < b->nfine; f++) {
            const tri_first *t;
            while ((t = bcur_peek(b, &tc[f])) && t->ev < hi) {
                if (t->ev < lo || !t->n) { /* (not in event order: never written so) */
                    b->failed = 1;
                    break;
                }
                wn[t->ev - lo] = t->n;
                wf[t->ev - lo] = (uint16_t)f;
                tc[f].i++;
            }
        }
        for (size_t k = 0; ok && k < hi - lo; k++) {
            if (!wn[k]) continue;
            const pdt_rec *rec = rec_at(r, lo + k);
            pdt_rtri t = {{rec->ev.a, rec->ev.b, rec->ev.c}, rec->rank, (uint32_t)h0, wn[k]};
            uint32_t id = (uint32_t)r->ntri++;
            ok = bput(b, &tw, &t) && bput(b, &ic[wf[k]], &id);
            for (uint32_t j = 0; ok && j < wn[k]; j++) { /* its entries, from its bucket's */
                const pdt_rtri_hist *e = bcur_peek(b, &hc[wf[k]]);
                ok = e && bput(b, &hw, e);
                hc[wf[k]].i++;
            }
            h0 += wn[k];
        }
        ok = ok && !b->failed;
    }
    for (size_t f = 0; ok && f < b->nfine; f++) ok = bput_flush(b, &ic[f]);
    ok = ok && bput_flush(b, &tw) && bput_flush(b, &hw) && h0 == r->nhist;
    bfree(b, tw.buf, CUR_RECS * sizeof(pdt_rtri));
    bfree(b, hw.buf, CUR_RECS * sizeof(pdt_rtri_hist));
    bfree(b, wn, NUM_WINDOW * sizeof *wn);
    bfree(b, wf, NUM_WINDOW * sizeof *wf);
    bcurs_free(b, tc, sizeof(tri_first));
    bcurs_free(b, ic, sizeof(uint32_t));
    bcurs_free(b, hc, sizeof(pdt_rtri_hist));
    if (!ok) b->failed = 1;
    return ok;
}

/* Give every triangle event of every bucket its triangle's number (in
 * place in PDT_SCR_TRIEV), with the bucket's numbers in memory. */
static int tri_join(builder *b)
{
    size_t most = 0;
    for (size_t f = 0; f < b->nfine; f++)
        if (b->tcount[f] > most) most = b->tcount[f];
    enum { JOIN_RECS = 1 << 16 };
    uint32_t *ids = bmalloc(b, most * sizeof *ids);
    tri_ev *ev = bmalloc(b, JOIN_RECS * sizeof *ev);
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
    bfree(b, ids, most * sizeof *ids);
    bfree(b, ev, JOIN_RECS * sizeof *ev);
    return ok;
}

/* The per-event tables (at evobj_at and evkind_at of the place): pass 1's,
 * completed in place with every triangle event's triangle and the mark on
 * a triangle's first event (PDT_SCR_TRIEV, bucket by bucket in event order). */
static int ev_tables(builder *b)
{
    pdt_replay *r = b->r;
    const pdt_replay_place *pl = b->pl;
    bcur *ec = bcurs_new(b, sizeof(tri_ev));
    int32_t *obj = bmalloc(b, NUM_WINDOW * sizeof *obj);
    uint8_t *kind = bmalloc(b, NUM_WINDOW);
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
    bfree(b, obj, NUM_WINDOW * sizeof *obj);
    bfree(b, kind, NUM_WINDOW);
    bcurs_free(b, ec, sizeof(tri_ev));
    return ok;
}

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
    uint32_t *lift = bmalloc(b, PT_WINDOW * sizeof *lift);
    pt_rec *rec = bmalloc(b, PBUF * sizeof *rec);
    pdt_point *lo = malloc(2 * q1 * sizeof *lo), *hi = malloc(2 * q1 * sizeof *hi);
    uint8_t *has = calloc(2 * q1, 1);  /* [0, q1): pushed points' boxes, [q1, 2 q1): lifted */
    int ok = start && lift && rec && lo && hi && has && spill_group(&b->plog, b->npw, start);
    const spill_chunk *sorted = b->plog.chunk;
    for (size_t w = 0, c = 0; ok && w < b->npw; w++) {
        size_t p0 = w * PT_WINDOW, np = r->n - p0 < PT_WINDOW ? r->n - p0 : PT_WINDOW;
        memset(lift, 0xff, np * sizeof *lift);
        for (; ok && c < start[w + 1]; c++) {
            ok = pl->sget(pl->ctx, PDT_SCR_POINTS, sorted[c].off, rec, sorted[c].n * sizeof *rec);
            for (size_t j = 0; ok && j < sorted[c].n; j++) {
                const pt_rec *t = &rec[j];
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
    bfree(b, lift, PT_WINDOW * sizeof *lift);
    bfree(b, rec, PBUF * sizeof *rec);
    free(lo);
    free(hi);
    free(has);
    return ok;
}

/* Pass 1 of a streamed build: the window of per-event tables out to the
 * place when event i is past it (or at the end: i == m). */
static int ev_window(builder *b, size_t i)
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

/* What a streamed build of n points holds in memory besides its working
 * set: the run's points (the caller's), and some room for the small tables
 * (a run with Graham's sort holds 16 bytes more per point). */
static uint64_t held_bytes(size_t n)
{
    return (uint64_t)n * sizeof(pdt_point) + ((uint64_t)16 << 20);
}

/* tri_groups' share of a streamed build's budget: what the replay does not hold. */
static uint64_t group_work(const pdt_replay *r, uint64_t budget)
{
    uint64_t held = held_bytes(r->n);
    return budget > held + budget / 4 ? budget - held : budget / 4;
}

/* Fine bits a streamed build may use at most (tri_number keeps a bucket's
 * number in 16 bits). */
#define FINE_BITS_MAX 16u
/* The least room planned for the grouping, whatever the budget (below it,
 * more and smaller buckets only make the build slower: 2^11 buckets made
 * the 10^7-point run's build 15-20 % slower than 2^8). */
#define PLAN_ROOM_MIN ((uint64_t)64 << 20)

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
        b->fbuf = bmalloc(b, b->nfine * b->fbuf_recs * sizeof *b->fbuf);
        b->fbn = calloc(b->nfine, sizeof *b->fbn);
        b->win = bmalloc(b, WIN * sizeof *b->win);
        b->wobj = bmalloc(b, EVW * sizeof *b->wobj);
        b->wkind = bmalloc(b, EVW);
        b->tcount = calloc(b->nfine, sizeof *b->tcount);
        b->npw = (r->n + PT_WINDOW - 1) / PT_WINDOW;
        b->pbuf = bmalloc(b, (b->npw ? b->npw : 1) * PBUF * sizeof *b->pbuf);
        b->pbn = calloc(b->npw + 1, sizeof *b->pbn);
        if (!b->fbuf || !b->fbn || !b->win || !b->wobj || !b->wkind || !b->tcount || !b->pbuf || !b->pbn)
            return 0;
        pdt_big_advise(b->fbuf, b->nfine * b->fbuf_recs * sizeof *b->fbuf);
    } else {
        b->wobj = r->ev_obj;
        b->wkind = r->ev_kind;
        r->hist = big_table(r->nhist * sizeof *r->hist);
        r->tris = big_table(r->nhist * sizeof *r->tris); /* at most one per event */
        r->cap_tri = r->nhist;
        b->spill = big_table(r->nhist * sizeof *b->spill);
        if (!r->hist || !r->tris || !b->spill) return 0;
    }
    return km_alloc(&b->edge_map, cnt[PDT_EV_EDGE_ADD], r->tab_limit) &&
           km_alloc(&b->msg_map, cnt[PDT_EV_SEND], r->tab_limit) &&
           tab_grow(r, (void **)&r->edges, &r->cap_edge, cnt[PDT_EV_EDGE_ADD], sizeof *r->edges) &&
           tab_grow(r, (void **)&r->nodes, &r->cap_node, cnt[PDT_EV_PUSH], sizeof *r->nodes);
}

/* Pass 1: every event once, in order (streamed: from pl's stream, a window
 * at a time, the per-event tables written out a window at a time). */
static int first_pass(builder *b, pdt_err *err)
{
    pdt_replay *r = b->r;
    const pdt_replay_place *pl = b->pl;
    for (size_t i = 0; i < r->m; i++) {
        drop_recs(b, i);
        if (pl && (!win_fill(b, i, err) || (i - b->wlo == EVW && !ev_window(b, i)))) return 0;
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
            const void *also, *p = probe_addr(b, ahead, &also);
            if (p) __builtin_prefetch(p);
            if (also) __builtin_prefetch(also);
        }
        if (rec->ev.kind < PDT_EV_KIND_COUNT) r->kind_count[rec->ev.kind]++;
        if (!index_event(b, (uint32_t)i, rec)) return 0;
        if (i % TICK_EVENTS == TICK_EVENTS - 1) { /* (paged tables: their pages go back) */
            tabs_give_back(r);
            km_give_back(&b->edge_map);
            km_give_back(&b->msg_map);
        }
    }
    return 1;
}

/* After pass 1 (streamed): the stream's end (it finishes its part: pl->src
 * is ready), the last window of the per-event tables, and the points' first
 * lifts and the ranks' boxes (points_pass). */
static int stream_end(builder *b, pdt_err *err)
{
    pdt_replay *r = b->r;
    const pdt_replay_place *pl = b->pl;
    pdt_rec extra;
    int more = pl->next(pl->ctx, &extra, 1, err);
    if (more != 0) {
        if (more > 0) pdt_err_set(err, PDT_ERR_FORMAT, "the run has more events than counted");
        b->stream_failed = 1;
        return 0;
    }
    bfree(b, b->win, WIN * sizeof *b->win);
    b->win = NULL;
    if (!ev_window(b, r->m)) return 0;
    bfree(b, b->wobj, EVW * sizeof *b->wobj);
    bfree(b, b->wkind, EVW);
    b->wobj = NULL;
    b->wkind = NULL;
    if ((r->lift_at = pl->reserve(pl->ctx, (uint64_t)r->n * sizeof(uint32_t))) == UINT64_MAX ||
        !points_pass(b, b->lifted_any))
        return 0;
    pl->sdrop(pl->ctx, PDT_SCR_POINTS);
    if (pl->points_read) pl->points_read(pl->ctx);
    bfree(b, b->pbuf, (b->npw ? b->npw : 1) * PBUF * sizeof *b->pbuf);
    b->pbuf = NULL;
    return 1;
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
        int have = km_get(&last_end, ph->phase, ph->sub, &end);
        uint32_t e = ph->end_ev == NONE32 ? (uint32_t)INT32_MAX : ph->end_ev;
        ph->first = !have || (uint32_t)end < ph->begin_ev;
        if (!have || (uint32_t)end < e)
            ok = km_put(&last_end, ph->phase, ph->sub, (int32_t)(e > INT32_MAX ? INT32_MAX : e), 0);
    }
    km_free(&last_end);
    return ok;
}

/* The triangles' histories: grouped by triangle (tri_groups), then the
 * triangles numbered by their first event (streamed: tri_number, tri_join,
 * ev_tables, through scratch files; in memory: tri_ids). */
static int tri_histories(builder *b)
{
    pdt_replay *r = b->r;
    const pdt_replay_place *pl = b->pl;
    if (pl) { /* the last chunks; the buckets' places in the history table */
        for (size_t f = 0; f < b->nfine; f++)
            if (!fine_flush(b, f)) return 0;
        if (!chunks_by_bucket(b)) return 0;
        for (size_t f = 0; f < b->nfine; f++) b->fine_off[f + 1] = b->fine_off[f] + b->fine_fill[f];
        r->nhist = b->fine_off[b->nfine];
        if ((r->hist_at = pl->reserve(pl->ctx, (uint64_t)r->nhist * sizeof *r->hist)) == UINT64_MAX)
            return 0;
        bfree(b, b->fbuf, b->nfine * b->fbuf_recs * sizeof *b->fbuf);
        b->fbuf = NULL;
    }
    size_t ntri;
    if (!tri_groups(b, pl ? group_work(r, pl->budget) : 0, &ntri)) return 0;
    free(b->spill);
    b->spill = NULL;
    if (!pl) return tri_ids(b);
    pl->sdrop(pl->ctx, PDT_SCR_SPILL);
    if ((r->tris_at = pl->reserve(pl->ctx, (uint64_t)ntri * sizeof *r->tris)) == UINT64_MAX ||
        !tri_number(b) || !tri_join(b))
        return 0;
    pl->sdrop(pl->ctx, PDT_SCR_TRIS);
    pl->sdrop(pl->ctx, PDT_SCR_IDS);
    pl->sdrop(pl->ctx, PDT_SCR_HIST);
    if (!ev_tables(b)) return 0;
    pl->sdrop(pl->ctx, PDT_SCR_TRIEV);
    return 1;
}

/* The slot changes grouped by slot (a counting sort: event order kept). */
static int slot_index(pdt_replay *r)
{
    size_t nslot = (size_t)r->nranks * PDT_SLOT_PER_RANK;
    r->slot_start = calloc(nslot + 1, sizeof *r->slot_start);
    r->slot_ch = tab_new(r, (r->nch ? r->nch : 1) * sizeof *r->slot_ch);
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
        if (c % TICK_EVENTS == TICK_EVENTS - 1) tabs_give_back(r);
    }
    free(fill);
    tabs_give_back(r);
    return 1;
}

/* Free the builder; the build's status from ok and what failed. */
static pdt_status builder_close(builder *b, int ok, pdt_err *err)
{
    pdt_replay *r = b->r;
    free(b->cur);
    free(b->lastst);
    free(b->lifted_any);
    free(b->fine_fill);
    free(b->fine_off);
    if (b->pl) {
        bfree(b, b->fbuf, b->nfine * b->fbuf_recs * sizeof *b->fbuf);
        bfree(b, b->win, WIN * sizeof *b->win);
        bfree(b, b->wobj, EVW * sizeof *b->wobj);
        bfree(b, b->wkind, EVW);
        bfree(b, b->pbuf, (b->npw ? b->npw : 1) * PBUF * sizeof *b->pbuf);
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
    km_free(&b->edge_map);
    km_free(&b->msg_map);
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
             (!pl || stream_end(&b, err)) && /* the points' first lifts, the ranks' boxes */
             phase_clusters(r) &&
             tri_histories(&b) &&            /* grouped by triangle, numbered */
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
    tab_free(r, r->sort_ev);
    tab_free(r, r->del_ev);
    tab_free(r, r->sort_pos);
    tab_free(r, r->edges);
    tab_free(r, r->nodes);
    tab_free(r, r->phases);
    tab_free(r, r->merges);
    tab_free(r, r->msgs);
    tab_free(r, r->hulls);
    tab_free(r, r->ch);
    tab_free(r, r->slot_ch);
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
    return p < r->n && r->sort_pos ? r->sort_pos[p] : -1;
}

uint32_t pdt_replay_lift_ev(const pdt_replay *r, size_t p) { return p < r->n ? r->lift_ev[p] : NONE32; }

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
        s->k++;
        /* (a paged build's tables go back as it goes; the state's pages, which
         * the steps write at random, when a checkpoint of it has been written:
         * a page of a file mapping written again costs a fault into the file
         * system, and giving them back here made the build twice as slow) */
        if (i % TICK_EVENTS == TICK_EVENTS - 1) tabs_give_back(r);
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

/* ---- checkpoints --------------------------------------------------------------- */

/* A seek that steps over this many events or more gives back the kept
 * index's pages it read (pdt_index_release). */
#define SEEK_RELEASE ((size_t)1 << 16)

/* A seek this many events away or closer steps there instead (a step costs
 * about what looking at one object costs in pdt_replay_seek_direct). */
#define STEP_FACTOR 1

/* Restoring a kept checkpoint costs about a step per this many of its bytes
 * when the state is in memory (191 MiB in 9-15 ms on the 4*10^7-point run,
 * a step 12.6 ns; a paged state's pages cost more: one step per 64 bytes).
 * At 64 for both, a seek there stepped up to 3*10^6 events from where it
 * was rather than restore: the worst of 101 random seeks took 108-143 ms,
 * 93-104 ms with this. */
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
    /* (a paged state's pages are given back when the seek is done, not on
     * the way: a page of a file mapping written again costs a fault into
     * the file system, which made seeks several times slower) */
    while (s->k < k) {
        if (s->k + STEP_AHEAD < k) step_prefetch(r, s, s->k + STEP_AHEAD);
        pdt_replay_step(r, s, 1);
    }
    while (s->k > k) {
        if (s->k > k + STEP_AHEAD) step_prefetch(r, s, s->k - 1 - STEP_AHEAD);
        pdt_replay_step(r, s, -1);
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
        if (from_here > dist(ck, k) * STEP_FACTOR + bytes / (s->paged[1] ? 64 : RESTORE_BYTES_PER_STEP)) {
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
    return (pdt_tri_status)r->hist[r->tris[t].h0 + s->tcur[t]].status;
}

uint32_t pdt_rstate_tri_entry(const pdt_replay *r, const pdt_rstate *s, size_t t)
{
    if (t >= r->ntri || s->tcur[t] == PDT_TCUR_NONE) return NONE32;
    uint32_t h = r->tris[t].h0 + s->tcur[t];
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

/* ---- searching --------------------------------------------------------------- */

static const char *const class_names[PDT_EVC_COUNT] = {"any event", "push/pop", "lift-up",
                                                       "rejection", "merge", "triangle"};

const char *pdt_ev_class_name(int c) { return c >= 0 && c < PDT_EVC_COUNT ? class_names[c] : NULL; }

int pdt_ev_in_class(int kind, int c)
{
    switch (c) {
    case PDT_EVC_ANY: return 1;
    case PDT_EVC_STACK: return kind == PDT_EV_PUSH || kind == PDT_EV_POP;
    case PDT_EVC_LIFT: return kind == PDT_EV_LIFT;
    case PDT_EVC_REJECT: return kind == PDT_EV_RA_DEFER || kind == PDT_EV_DISCARD;
    case PDT_EVC_MERGE: return kind == PDT_EV_MERGE_BEGIN || kind == PDT_EV_MERGE_END;
    case PDT_EVC_TRI: return is_tri_kind(kind);
    default: return 0;
    }
}

size_t pdt_replay_find(const pdt_replay *r, size_t k, int dir, int c, const uint8_t *rank_visible)
{
    if (k > r->m) k = r->m;
    if (dir > 0) {
        for (size_t i = k; i < r->m; i++)
            if (pdt_ev_in_class(kind_at(r, i), c) &&
                (!rank_visible || rank_visible[pdt_replay_rank_of(r, i)]))
                return i + 1;
    } else {
        for (size_t i = k >= 2 ? k - 1 : 0; i-- > 0;)
            if (pdt_ev_in_class(kind_at(r, i), c) &&
                (!rank_visible || rank_visible[pdt_replay_rank_of(r, i)]))
                return i + 1;
        if (k >= 1) return 0;
    }
    return k;
}

size_t pdt_replay_find_phase(const pdt_replay *r, size_t k, int dir)
{
    if (dir > 0) {
        for (size_t p = 0; p < r->nphase; p++)
            if (r->phases[p].first && r->phases[p].phase != PDT_PH_RUN && r->phases[p].begin_ev >= k)
                return (size_t)r->phases[p].begin_ev + 1;
        return r->m;
    }
    for (size_t p = r->nphase; p-- > 0;)
        if (r->phases[p].first && r->phases[p].phase != PDT_PH_RUN && (size_t)r->phases[p].begin_ev + 1 < k)
            return (size_t)r->phases[p].begin_ev + 1;
    return 0;
}

size_t pdt_replay_find_phase_name(const pdt_replay *r, const char *name)
{
    char base[64];
    long level = -1;
    const char *colon = strchr(name, ':');
    size_t len = colon ? (size_t)(colon - name) : strlen(name);
    if (len >= sizeof base) return (size_t)-1;
    memcpy(base, name, len);
    base[len] = 0;
    if (colon) level = strtol(colon + 1, NULL, 10);
    for (size_t i = 0; i < r->m; i++) {
        if (kind_at(r, i) != PDT_EV_PHASE_BEGIN) continue;
        const pdt_event *e = &rec_at(r, i)->ev;
        const char *nm = pdt_phase_name(e->sub);
        if (nm && !strcmp(nm, base) && (level < 0 || (long)e->a == level)) return i + 1;
    }
    return (size_t)-1;
}
