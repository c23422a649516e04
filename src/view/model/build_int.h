/* pdt — the replay's build, private to src/view/model: the event kinds as
 * the replay keeps them, the builder's state, and the functions its files
 * share (containers.c, group.c, points.c, handlers.c, number.c, replay.c). */
#ifndef PDT_VIEW_BUILD_INT_H
#define PDT_VIEW_BUILD_INT_H

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "pdt/view/replay.h"
#include "replay_int.h"

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

/* ---- the build's tables: in memory, or paged beyond a limit ----------------

 * A streamed build (a kept index) holds its tables of objects within a
 * share of its budget (r->tab_limit): a table that outgrows it moves to a
 * temporary file's mapping (pdt_temp_map, lengthened in place as it grows),
 * where the pages the build touched are given back every TICK_EVENTS events
 * (pdt_rp_tabs_give_back): a read of them again faults them in from the page
 * cache.  Such a table is in r->ptab until pdt_rp_tab_free unmaps it. */

#define TICK_EVENTS 65536u

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

static inline int kind_at(const pdt_replay *r, size_t i)
{
    ix_check_events(r, i, i + 1);  /* (a kept index's chunk checked before its first read) */
    return r->ev_kind[i] & KIND_MASK;
}

/* Event i (< m): from the array, or decoded (a kept index: the pointer
 * holds for PDT_EVSRC_KEEP - 1 more calls). */
static inline const pdt_rec *rec_at(const pdt_replay *r, size_t i)
{
    return r->recs ? &r->recs[i] : pdt_evsrc_get(r->src, i);
}

static inline int is_tri_kind(int k)
{
    return k == PDT_EV_TRI_NEW || k == PDT_EV_TRI_FINAL || k == PDT_EV_RA_DEFER ||
           k == PDT_EV_SHIP || k == PDT_EV_DISCARD;
}

static inline uint8_t tri_status_of(int k)
{
    switch (k) {
    case PDT_EV_TRI_NEW: return PDT_TS_CANDIDATE;
    case PDT_EV_TRI_FINAL: return PDT_TS_FINAL;
    case PDT_EV_RA_DEFER: return PDT_TS_DEFERRED;
    case PDT_EV_SHIP: return PDT_TS_SHIPPED;
    default: return PDT_TS_DISCARDED;
    }
}

static inline void sort3(uint32_t v[3], const uint32_t in[3])
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
 * event (pdt_rp_tri_ids; streamed: pdt_rp_tri_number).  Memory: the tables themselves (which may be
 * the caller's, e.g. a mapping of the index file) and a working set bounded
 * by the budget. */

/* A hash of a key of two words (the keymaps', the triangles' buckets):
 * inline, for the tens of millions of events a big run's build hashes. */
static inline uint64_t pdt_rp_mix(uint64_t hi, uint64_t lo)
{
    uint64_t h = hi * 0x9E3779B97F4A7C15ull ^ (lo + 0x632BE59BD9B4E019ull + (hi << 6));
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ull;
    h ^= h >> 29;
    return h;
}

/* The hash of a triangle's key s (its corners sorted): its fine bucket is
 * the top bits, its slot in the grouping's table the low ones. */
static inline uint64_t pdt_rp_key_hash(const uint32_t s[3])
{
    return pdt_rp_mix(((uint64_t)s[0] << 32) | s[1], s[2]);
}

/* The fine bucket (of 2^bits) of a triangle's key s. */
static inline size_t pdt_rp_fine_of(const uint32_t s[3], unsigned bits)
{
    return (size_t)(pdt_rp_key_hash(s) >> (64 - bits));
}

typedef struct tri_rec {
    uint32_t s[3];  /* corners, sorted: the triangle's key */
    uint32_t ev;
} tri_rec;

/* A streamed build's spill record: what the history entry needs besides
 * the key and the event travels with it (the build keeps nothing per
 * event): in x, XREC_BORDER | (merge step + 1) for a border kernel's
 * candidate (TRI_NEW, sub 1; a step past XREC_STEP_MAX is not kept), else
 * kind | sub << 8; and where each corner of the event is in the key
 * (xrec_corners), so that numbering the triangles need not decode their
 * first events. */
typedef struct tri_xrec {
    uint32_t s[3], ev, x;
} tri_xrec;
#define XREC_BORDER 0x80000000u
#define XREC_ORDER_SHIFT 24
#define XREC_ORDER_MASK (0x3fu << XREC_ORDER_SHIFT)
#define XREC_STEP_MAX ((1u << XREC_ORDER_SHIFT) - 2)

/* The corners' places in key s (2 bits each), for x. */
static inline uint32_t xrec_order(const uint32_t s[3], const uint32_t in[3])
{
    uint32_t o = 0;
    for (int k = 0; k < 3; k++) o |= (in[k] == s[0] ? 0u : in[k] == s[1] ? 1u : 2u) << (2 * k);
    return o << XREC_ORDER_SHIFT;
}

/* The event's corners as it reported them, from its record. */
static inline void xrec_corners(const tri_xrec *t, uint32_t v[3])
{
    uint32_t o = (t->x & XREC_ORDER_MASK) >> XREC_ORDER_SHIFT;
    for (int k = 0; k < 3; k++) v[k] = t->s[(o >> (2 * k)) & 3u];
}

#define FINE_BITS 8
#define NFINE ((size_t)1 << FINE_BITS)
_Static_assert(NFINE == PDT_REPLAY_NFINE, "replay_int.h says how many fine buckets");
#define GROUP_BYTES_PER_EVENT PDT_REPLAY_GROUP_BYTES_PER_EVENT /* tri_groups' working memory
                                                              * per event, at most */
/* Events per run, at most (unless one fine bucket holds more): a working set
 * of some 30 MiB, reused from run to run (fresh pages are dear on virtual
 * machines, and a smaller hash table misses the caches less: at 2^19 the
 * one-rank 10^7-point run's grouping took 1.7-1.9 s, at 2^18 1.4-1.6 s,
 * one bucket a run instead of three). */
#define GROUP_RUN_MAX ((size_t)1 << 18)

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
    tri_xrec **fcur;      /* streamed: per fine bucket, its buffer now (fbuf's, or a spare) */
    struct spill_writer *sw;  /* streamed: pass 1's spill writer (spillw.c), or NULL */
    int sw_live;          /* ... and its thread runs */
    tri_rec *spill;       /* not streamed: the triangle events by fine bucket */
    /* streamed: the spill is written a buffer (a chunk) at a time, where it
     * ends; chunk k of fine bucket f is chunk[ck_start[f] + k] after pass 1 */
    spill_log tlog;
    size_t *ck_start;
    int stream_failed;    /* the place's stream of events failed (err set by it) */
    pdt_rec *win;         /* streamed: events win_lo .. win_lo + win_n - 1 of the stream */
    size_t win_lo, win_n;
    uint32_t *fbn;        /* records in each buffer */
    _Atomic int failed;   /* a put or get failed (on any of the build's threads) */
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
    pthread_t pt_th;      /* the points' pass, beside the join (pdt_rp_points_start) */
    int pt_started, pt_ok;
    _Atomic uint64_t held, peak;  /* streamed: working memory (bytes) */
} builder;

#define EVW 65536u  /* events per window of the per-event tables (streamed) */

static inline void set_obj(builder *b, size_t i, int32_t v) { b->wobj[i - b->wlo] = v; }

/* ---- points: first lifts and the ranks' boxes, streamed ---------------------------
 *
 * A streamed build holds no table per point of its own: a lift and a push
 * that counts for its rank's box are written down (pt_rec) by window of
 * points, and after pass 1 each window's records give its points' first
 * lifts (the place's lift table, at lift_at) and their share of the boxes
 * (the points read a window at a time).  A rank's box is the box of the
 * points it lifted outside a merge, or, when it lifted none, of the points
 * it pushed: what pdt_rp_box_add makes in event order. */
typedef struct pt_rec {
    uint32_t p, ev, rank, what;  /* what: PT_PUSH, PT_LIFT (in a merge), PT_LIFT_BOX */
} pt_rec;
enum { PT_PUSH, PT_LIFT, PT_LIFT_BOX };
#define PT_WINDOW ((size_t)1 << 20)  /* points per window */
#define PBUF 256u                    /* records buffered per window */

#define FBUF 1024u  /* records buffered per fine bucket (streamed): a chunk of the spill */

#define WIN 8192u  /* events of the stream at hand (streamed) */

/* The index pass is bound by cache misses in the edge map (random slots in
 * a table of 10^8 bytes at level 2).  The events are all known in advance,
 * so the slot an event a few places ahead will probe is fetched while the
 * current one is handled.  A hint only: nothing depends on it. */
#define PREFETCH_AHEAD 12

/* A triangle event's record in PDT_SCR_TRIEV: its event, and its triangle
 * (its number in its fine bucket, then after pdt_rp_tri_join its number in the
 * replay), TEV_FIRST on the triangle's first event. */
typedef struct tri_ev {
    uint32_t ev, t;
} tri_ev;
#define TEV_FIRST 0x80000000u

/* A triangle's record in PDT_SCR_TRIS: its first event, its entries and
 * the status of its last (n: TF_N_MASK and TF_LAST_SHIFT), its corners as
 * that event reported them. */
typedef struct tri_first {
    uint32_t ev, n, v[3];
} tri_first;
#define TF_N_MASK 0xffffu  /* (PDT_TRI_HIST_MAX) */
#define TF_LAST_SHIFT 16
_Static_assert(PDT_TRI_HIST_MAX <= TF_N_MASK, "a triangle's entries fit tri_first's n");

/* ---- the streamed build's numbering, in windows of events -------------------------
 *
 * After the grouping (group_worker_streamed) each fine bucket has, in event
 * order, its triangles (tri_first) and its triangle events (tri_ev).
 * pdt_rp_tri_number takes the buckets' triangles in order of their first events,
 * a window of events at a time, which numbers them (the triangle table,
 * and per bucket the numbers: PDT_SCR_IDS); pdt_rp_tri_join gives each bucket's
 * triangle events their numbers; pdt_rp_ev_tables merges them into the per-event
 * tables that pass 1 wrote (at the place) a window at a time.  Memory:
 * a buffer per bucket and a window, independent of the run's size (but for
 * the numbers of the largest bucket's triangles in pdt_rp_tri_join). */

#define NUM_WINDOW ((size_t)1 << 18)  /* events per window (pdt_rp_tri_number, pdt_rp_ev_tables) */
#define CUR_RECS 512u                 /* records buffered per cursor, at most */

/* Fine bits a streamed build may use at most (pdt_rp_tri_number keeps a bucket's
 * number in 16 bits). */
#define FINE_BITS_MAX 16u
/* The least room planned for the grouping, whatever the budget: below it,
 * more and smaller buckets only make the build slower (each bucket costs
 * its own buffers and passes). */
#define PLAN_ROOM_MIN ((uint64_t)64 << 20)

/* ---- shared between the replay's files (each defined in the file named) ---- */

/* containers.c */
int pdt_rp_grow(void **p, size_t *cap, size_t need, size_t elem);
int pdt_rp_km_alloc(keymap *km, size_t n, uint64_t limit);
void pdt_rp_km_free(keymap *km);
void pdt_rp_km_give_back(const keymap *km);
int pdt_rp_km_get(const keymap *km, uint64_t hi, uint64_t lo, int32_t *v);
int pdt_rp_km_put(keymap *km, uint64_t hi, uint64_t lo, int32_t v, uint64_t limit);
void pdt_rp_tab_free(pdt_replay *r, void *p);
void *pdt_rp_tab_new(pdt_replay *r, size_t bytes);
int pdt_rp_tab_grow(pdt_replay *r, void **p, size_t *cap, size_t need, size_t elem);
void pdt_rp_tabs_give_back(const pdt_replay *r);

/* group.c */
int pdt_rp_spill_put(builder *b, int scr, spill_log *lg, const void *buf, size_t k, size_t rec,
                     size_t f);
int pdt_rp_spill_group(spill_log *lg, size_t nb, size_t *start);
int pdt_rp_tri_histories(builder *b);

/* replay.c */
void *pdt_rp_bmalloc(builder *b, size_t bytes);
void pdt_rp_bfree(builder *b, void *p, size_t bytes);
int pdt_rp_tput(builder *b, void *arr, uint64_t base, size_t at, const void *p, size_t n, size_t elem);
int pdt_rp_fine_flush(builder *b, size_t f);
int pdt_rp_chunks_by_bucket(builder *b);
uint64_t pdt_rp_group_work(const pdt_replay *r, uint64_t budget);

/* spillw.c */
typedef struct spill_writer spill_writer;
int pdt_rp_sw_start(builder *b);
void pdt_rp_sw_queue(builder *b, size_t f, size_t n);
void pdt_rp_sw_stop(builder *b);
void pdt_rp_sw_free(builder *b);

/* points.c */
int pdt_rp_pt_note(builder *b, uint32_t p, uint32_t ev, uint32_t rank, uint32_t what);
void pdt_rp_box_add(pdt_replay *r, uint32_t rank, pdt_point p);
int pdt_rp_graham_tables(pdt_replay *r);
int pdt_rp_points_start(builder *b);
int pdt_rp_points_finish(builder *b);

/* handlers.c */
int pdt_rp_index_event(builder *b, uint32_t i, const pdt_rec *rec);
const void *pdt_rp_probe_addr(const builder *b, const pdt_rec *rec, const void **also);

/* number.c */
void pdt_rp_drop_recs(const builder *b, size_t upto);
int pdt_rp_tri_ids(builder *b);
int pdt_rp_tri_number(builder *b);
int pdt_rp_tri_join(builder *b);
int pdt_rp_ev_tables(builder *b);
int pdt_rp_ev_window(builder *b, size_t i);

#endif
