/* pdt — the replay model's insides, shared by replay.c and the kept index
 * (index.c), which writes these tables to a file and maps them back. */
#ifndef PDT_REPLAY_INT_H
#define PDT_REPLAY_INT_H

#include "pdt/view/replay.h"
#include "pdt/bigmem.h"

/* Checkpoints a kept index holds, at most (index.c makes 17 at most). */
#define PDT_ICK_MAX 48

/* ---- the merged events of a kept index, decoded on demand (evsrc.c) ----------
 *
 * A kept index holds no events: it holds a table of the rank files'
 * encoded blocks (where each is in its file) and the merged order as
 * segments, each a stretch of consecutive merged events that are
 * consecutive events of one rank.  An event is decoded when asked for, with
 * its block, from the rank file (mapped), into a small cache. */

/* The merged events [start, next segment's start) are events seq0, seq0 + 1,
 * ... of rank `rank`. */
typedef struct pdt_evseg {
    uint32_t start, rank, seq0;
} pdt_evseg;

struct evcur;
#define PDT_EVSRC_KEEP 8  /* (pdt_evsrc_get) */

typedef struct pdt_evsrc {
    const uint8_t **file;        /* per rank: its file's bytes (mapped), or NULL */
    uint64_t *file_len;          /* per rank */
    const pdt_block_ref *blk;    /* every rank's blocks, rank by rank; off: of the
                                  * payload in its file, base_t: the aligned time
                                  * base (the shift added) */
    size_t nblk;
    const uint64_t *rank_blk;    /* nranks + 1: rank q's blocks are
                                  * blk[rank_blk[q] .. rank_blk[q + 1]) */
    const pdt_evseg *seg;
    size_t nseg, m;
    int nranks;
    /* the decoded blocks (a cache; owned) */
    struct evslot *slot;
    size_t nslot, hot, last_seg;
    uint64_t tick;
    int drop_behind;             /* give back the mapped pages behind a forward pass
                                  * (madvise; the build's one-way passes) */
    uint64_t *released;          /* (per rank, made when needed) */
    struct evcur *cur;           /* per rank: where its forward decoding is (made
                                  * when needed; owned) */
    pdt_rec ring[PDT_EVSRC_KEEP]; /* the events decoded one at a time, the last
                                   * PDT_EVSRC_KEEP of them */
    unsigned ring_at;
    int verify;                  /* check each block's checksum when it is decoded;
                                  * on a mismatch call damaged(damaged_ctx, rank) */
    void (*damaged)(void *ctx, uint32_t rank);
    void *damaged_ctx;
} pdt_evsrc;

/* Event i (< m) of the merged order, decoded: a pointer into the cache,
 * valid at least until PDT_EVSRC_KEEP - 1 more calls.  Each rank's events
 * asked for in their order (a forward pass: every rank's in turn, at any
 * interleaving) are decoded one at a time from where the rank's last one
 * was; the others with their block, into the cache. */
const pdt_rec *pdt_evsrc_get(pdt_evsrc *s, size_t i);
/* The rank of event i (no decoding). */
uint32_t pdt_evsrc_rank(pdt_evsrc *s, size_t i);
/* Free the cache (the tables and the files' mappings are not s's). */
void pdt_evsrc_clear(pdt_evsrc *s);
/* 1 if the checksum of block b (its header and payload) matches. */
int pdt_evsrc_block_ok(const pdt_evsrc *s, size_t b, uint32_t rank);

#define PDT_PTAB_MAX 24  /* paged tables of a build at once */

typedef struct slot_change {
    uint32_t ev;
    int32_t val, prev;
    uint32_t slot;  /* rank * PDT_SLOT_PER_RANK + slot */
} slot_change;

struct pdt_replay {
    const pdt_point *pts;
    size_t n;
    const pdt_rec *recs;  /* the merged events, or NULL: decoded on demand from src */
    pdt_evsrc *src;       /* (kept index) */
    size_t m, skipped;
    int nranks;
    int32_t *ev_obj;   /* per event: object (see build(); a slot change: its index
                        * in ch) or -1 */
    uint32_t *ev_ent;  /* per event, while building only (then NULL): its history
                        * entry (a triangle event) */
    uint8_t *ev_kind;  /* per event: its kind and a mark (replay.c: KIND_*;
                        * stepping reads no records) */

    pdt_rtri *tris;
    size_t ntri, cap_tri;
    pdt_rtri_hist *hist;
    size_t nhist;
    pdt_redge *edges;
    size_t nedge, cap_edge;
    pdt_rnode *nodes;
    size_t nnode, cap_node;
    pdt_rphase *phases;
    size_t nphase, cap_phase;
    pdt_rmerge *merges;
    size_t nmerge, cap_merge;
    pdt_rmsg *msgs;
    size_t nmsg, cap_msg;
    pdt_rhull *hulls;
    size_t nhull, cap_hull;

    slot_change *ch;    /* every slot change, in event order */
    size_t nch, cap_ch;
    uint32_t *slot_ch;  /* changes grouped by slot: slot_ch[slot_start[s] .. slot_start[s+1]) */
    uint32_t *slot_start;

    uint32_t *lift_ev, *sort_ev, *del_ev;  /* per point: first such event or UINT32_MAX */
    int64_t *sort_pos;  /* sort_ev, del_ev, sort_pos: NULL when the run has no SORT
                         * and no DELETE event (then all none) */
    pdt_point *box_lo, *box_hi;  /* per rank */
    uint8_t *has_box;
    size_t kind_count[PDT_EV_KIND_COUNT];

    /* Kept index: when map is set, every table above points into it (a
     * read-only mapping of the index file) and pdt_replay_free unmaps it
     * instead of freeing the tables. */
    void *map;
    size_t map_len;
    /* Streamed (pdt_replay_build with a place): no table per event and none
     * per triangle in memory (ev_obj, ev_ent, ev_kind, tris and hist are
     * NULL, and so is lift_ev): they are at evobj_at, evkind_at, tris_at,
     * hist_at and lift_at of the place; the replay steps forwards through them (pdt_fwd: the index's
     * checkpoints) but draws nothing. */
    int streamed;
    uint64_t tris_at, hist_at, evobj_at, evkind_at, lift_at;
    uint64_t build_peak;   /* the build's own working memory, at most (bytes) */
    uint64_t build_ck_bytes; /* ... and what the copies of its checkpoints held (index_ck.c) */
    uint32_t build_buckets; /* the fine buckets its triangle events were grouped in */
    struct lazy *lazy;     /* the map is verified chunk by chunk as it is read (index.c) */
    const char *warnings;  /* the reader's warnings about the run (kept index), or NULL */
    int state_paged;       /* a big run's state: pages given back after seeks and
                            * frames, states beyond half the budget paged
                            * (pdt_rstate_new) */
    uint64_t mem_budget;   /* pdt_replay_set_mem's budget */
    uint64_t state_held;   /* bytes of the states held in memory (a count) */
    /* A streamed build's tables (edges, stacks, phases, merges, messages,
     * hulls, slot changes, Graham's per-point tables) that outgrow tab_limit
     * bytes live in temporary files' mappings (replay.c: tab_grow), their
     * pages given back as the build goes on (freed by tab_free). */
    pdt_temp_map ptab[PDT_PTAB_MAX];
    int nptab;
    uint64_t tab_limit;    /* 0: every table in memory (pdt_replay_new) */
    int bbox_known;        /* pdt_replay_bbox's answer, found once */
    pdt_point bbox_lo, bbox_hi;
    /* the run's points are read in place: give their resident pages back
     * (pdt_replay_give_back); NULL: they are the replay's or the caller's */
    void (*release_points)(const void *ctx);
    const void *release_ctx;

    /* Checkpoints: a copy of the state at every `ck_every`-th cursor, made on
     * the first seek near it (NULL until then); none when ck_every == 0. */
    size_t ck_every, nck, ck_bytes;
    pdt_rstate **ck;

    /* Checkpoints kept in the index: the state at every ick_every-th cursor
     * (pdt_rstate_to_blob), nick of them (at most PDT_ICK_MAX), checkpoint c
     * at ick + ick_off[c] (ick_off[nick]: their bytes), holding the triangles
     * born before its cursor, ick_born[c] of them; none: nick == 0.  They
     * take the place of the checkpoints above. */
    const uint8_t *ick;
    size_t ick_every, nick;
    uint64_t ick_off[PDT_ICK_MAX + 1];
    uint64_t ick_born[PDT_ICK_MAX];
};

/* Scratch files of a streamed build (pdt_replay_place's sput, sget, sdrop):
 * each written and read back by the build only, in chunks. */
enum {
    PDT_SCR_SPILL,   /* the triangle events by fine bucket, 20 bytes each */
    PDT_SCR_TRIEV,   /* per triangle event, by fine bucket: the event and its
                      * triangle (8 bytes) */
    PDT_SCR_TRIS,    /* per triangle, by fine bucket: its first event, its
                      * entries and its corners (tri_first, 20 bytes) */
    PDT_SCR_IDS,     /* per triangle, by fine bucket: its number (4 bytes) */
    PDT_SCR_POINTS,  /* lifts and pushes by window of points (replay.c: pt_rec) */
    PDT_SCR_COUNT
};

/* Where pdt_replay_build streams the replay's big tables (the per-event
 * tables, the triangles and their histories) instead of holding them:
 * reserve(ctx, bytes) gives a place for a table (e.g. a file offset;
 * UINT64_MAX: none), put and get write and read bytes there (1 on success).
 * budget: the build's working memory (0: no limit); what it holds besides
 * is the points (the caller's) and the tables of objects (phases, merges,
 * stacks, edges, messages, slot changes, hulls; for a run with Graham's sort
 * 16 bytes per point), each in memory up to budget / 16 bytes and beyond it
 * in a temporary file's mapping whose pages are given back as the build
 * goes on (tab_grow in replay.c). */
typedef struct pdt_replay_place {
    uint64_t (*reserve)(void *ctx, uint64_t bytes);
    int (*put)(void *ctx, uint64_t at, const void *p, size_t bytes);
    int (*get)(void *ctx, uint64_t at, void *p, size_t bytes);
    /* scratch file `file` (PDT_SCR_*, from 0 each): written and read by the
     * build only; sdrop: the build is done with it (its pages may go) */
    int (*sput)(void *ctx, int file, uint64_t at, const void *p, size_t bytes);
    int (*sget)(void *ctx, int file, uint64_t at, void *p, size_t bytes);
    void (*sdrop)(void *ctx, int file);
    /* the build is done reading the points (their resident pages may be
     * given back: pdt_run_release_points); NULL: nothing to do */
    void (*points_read)(void *ctx);
    void *ctx;
    uint64_t budget;
    /* The events (the build is given no array of them: recs NULL), in
     * order, once: up to max of them into out; returns how many, 0 at the
     * end, -1 on an error (err set).  When it has given them all, src must be
     * ready: the numbering of the triangles decodes their first events
     * there. */
    int (*next)(void *ctx, pdt_rec *out, size_t max, pdt_err *err);
    pdt_evsrc *src;
    /* Where the per-event tables go (the caller's places for m objects of
     * 4 bytes and m kind bytes): pass 1 writes them there as the events
     * come, and the triangle events' objects and marks are filled in last. */
    uint64_t evobj_at, evkind_at;
} pdt_replay_place;

/* The triangle events of a build are grouped in this many buckets by a hash
 * of their triangle: pdt_replay_fine_of gives the bucket of record rec of a
 * run of n points and nranks ranks, or PDT_REPLAY_NFINE when the build does
 * not group it (not a triangle event, or naming a point or rank beyond the
 * run's). */
/* pdt_replay_coverage shares its pass between two threads from this many
 * triangles on (default 2^20; the tests set 1 and SIZE_MAX to compare). */
void pdt_replay_set_cov_split(size_t tris);

#define PDT_REPLAY_NFINE 256
size_t pdt_replay_fine_of(const pdt_rec *rec, size_t n, int nranks);
/* A streamed build (the kept index) of m events under budget bytes groups
 * its triangle events in 2^(the result) buckets instead, from 8 to 16 bits,
 * buffering *fbuf_recs records a bucket in its first pass and *cur_recs a
 * cursor after it; *bytes (when not NULL): what that holds at most, by
 * PDT_REPLAY_GROUP_BYTES_PER_EVENT bytes per event of a bucket (what the
 * grouping holds per triangle event at most; the plan counts every
 * event).  At most half the budget (or 64 MiB) when a plan does it, else the least a plan holds (321
 * MiB for a run of 2^32 events). */
#define PDT_REPLAY_GROUP_BYTES_PER_EVENT 128u
unsigned pdt_replay_plan_buckets(uint64_t m, uint64_t budget, size_t *fbuf_recs, size_t *cur_recs,
                                 uint64_t *bytes);

/* pdt_replay_new, with the triangles and histories streamed to pl (NULL:
 * held in memory, no budget: pdt_replay_new); recs NULL: the events are
 * pl->src's (nranks must then be given). */
pdt_status pdt_replay_build(const pdt_point *pts, size_t n, const pdt_rec *recs, size_t m,
                            int nranks, const pdt_replay_place *pl, pdt_replay **out, pdt_err *err);

/* A state as bytes (the index's checkpoints): pdt_rstate_blob_bytes(r, born)
 * bytes, holding the current entries of triangles 0 .. born-1 only (every
 * later one must have none: born >= pdt_rstate_born(r, s)).  The triangles
 * are numbered by their first event, so a checkpoint at cursor k needs only
 * those born before k: the checkpoints of a run take about half the bytes
 * of whole states. */
size_t pdt_rstate_blob_bytes(const pdt_replay *r, size_t born);
/* 1 + the last triangle that has a current entry in s (0: none has). */
size_t pdt_rstate_born(const pdt_replay *r, const pdt_rstate *s);
void pdt_rstate_to_blob(const pdt_replay *r, const pdt_rstate *s, size_t born, uint8_t *out);
/* s = the state of the blob at `in` (made with `born`) at cursor k. */
void pdt_rstate_from_blob(const pdt_replay *r, pdt_rstate *s, const uint8_t *in, size_t born,
                          size_t k);

/* A forward pass over a streamed replay's events (the index's checkpoints):
 * the per-event tables and the triangles read from the place through get
 * (a window of each), the state stepped as pdt_replay_step would.  NULL
 * when out of memory. */
typedef struct pdt_fwd pdt_fwd;
pdt_fwd *pdt_fwd_new(const pdt_replay *r, int (*get)(void *ctx, uint64_t at, void *p, size_t bytes),
                     void *ctx);
/* Step s (at or before k) forwards to cursor k.  0 when a read failed. */
int pdt_fwd_to(pdt_fwd *f, pdt_rstate *s, size_t k);
void pdt_fwd_free(pdt_fwd *f);

/* The pieces of pdt_rstate_to_blob's bytes, in order, without copying
 * them: piece j is len[j] bytes at part[j], followed by pad[j] zero bytes. */
void pdt_rstate_blob_parts(const pdt_replay *r, const pdt_rstate *s, size_t born,
                           const void *part[5], size_t len[5], size_t pad[5]);

/* Give back the resident pages of [p, p + len) of a replay's kept index
 * mapping (whole pages inside it; nothing when p is not in it): a read
 * of them again faults them in from the page cache.  Touched pages of a
 * shared mapping count as the process's memory until given back. */
void pdt_index_release(const pdt_replay *r, const void *p, size_t len);

/* Give back the resident pages of [p, p + len) when they belong to one of
 * r's paged build tables (nothing otherwise: a table in memory keeps its
 * pages). */
void pdt_replay_tab_release(const pdt_replay *r, const void *p, size_t len);

/* Unmap a replay's kept index (index.c). */
void pdt_index_unmap(pdt_replay *r);

/* ---- a lazily verified kept index: the checks before a read (index_verify.c) ----
 *
 * A replay whose kept index is verified lazily (r->lazy) checks each chunk
 * of its big tables the first time one of these asks for it.  Each returns
 * 1, or 0 when the chunk did not match (the index is then removed and the
 * program told: it should stop).  Without r->lazy they cost one branch. */
/* pdt_replay_step without the checks: the caller asked for the events and triangles
 * (state.c). */
int pdt_rp_step(const pdt_replay *r, pdt_rstate *s, int dir);
int pdt_ix_need(const pdt_replay *r, int sec, uint64_t lo, uint64_t hi); /* bytes of section sec */
int pdt_ix_need_events(const pdt_replay *r, size_t lo, size_t hi);  /* ev_obj, ev_kind */
int pdt_ix_need_born(const pdt_replay *r, size_t k); /* the triangles born by cursor k, entries */
int pdt_ix_need_ckpt(const pdt_replay *r, size_t c);                 /* checkpoint c */
int pdt_ix_need_point(const pdt_replay *r, size_t p);  /* point p's per-point tables */
int pdt_ix_need_points(const pdt_replay *r);                         /* the points */
int pdt_ix_need_all(const pdt_replay *r);                            /* every table */

static inline int ix_check_events(const pdt_replay *r, size_t lo, size_t hi)
{
    return !r->lazy || pdt_ix_need_events(r, lo, hi);
}
static inline int ix_check_born(const pdt_replay *r, size_t k) { return !r->lazy || pdt_ix_need_born(r, k); }
static inline int ix_check_point(const pdt_replay *r, size_t p) { return !r->lazy || pdt_ix_need_point(r, p); }
static inline int ix_check_points(const pdt_replay *r) { return !r->lazy || pdt_ix_need_points(r); }

#endif
