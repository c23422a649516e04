/* pdt — the replay model of the viewer: events in, state out (no pixels).
 *
 * A replay is built once from the points of a run and its merged event list
 * (pdt_run_merged(), or an in-memory array in tests).  Building indexes every
 * object the events talk about — triangles, kernel edges, Graham stacks,
 * phases, merges, messages — together with its whole history, in one pass.
 *
 * A cursor position k (0 <= k <= count) means "events 0 .. k-1 have happened";
 * the current event is k-1.  A pdt_rstate holds the state at one cursor:
 *
 *  - pdt_replay_seek() rebuilds it directly from the histories (each object
 *    looks up its last change before k: no replay from the start, cost linear
 *    in the number of objects, independent of k);
 *  - pdt_replay_step() moves it by one event forwards or backwards in O(1)
 *    (every event knows the object it changes and that object's previous
 *    value), so stepping back costs the same as stepping forwards.
 *
 * The tests check that both routes give identical states.
 *
 * Owns: the replay keeps pointers to `pts` and `recs`; they must outlive it. */
#ifndef PDT_REPLAY_H
#define PDT_REPLAY_H

#include "pdt/common.h"
#include "pdt/trace.h"
#include "pdt/tracefile.h"

/* Delaunay status of a triangle (the last status event applied to it). */
typedef enum pdt_tri_status {
    PDT_TS_NONE = 0,   /* not yet created */
    PDT_TS_CANDIDATE,  /* TRI_NEW: from a local or border kernel run */
    PDT_TS_FINAL,      /* TRI_FINAL: certified, part of the output */
    PDT_TS_DEFERRED,   /* RA_DEFER: its restricted area touches a foreign box */
    PDT_TS_SHIPPED,    /* SHIP: sent to a merge rank */
    PDT_TS_DISCARDED,  /* DISCARD: non-Delaunay */
    PDT_TS_COUNT
} pdt_tri_status;

/* Point flags in pdt_rstate.pflags. */
enum {
    PDT_PF_LIFTED = 1,  /* lifted to the paraboloid by some rank */
    PDT_PF_SORTED = 2,  /* has a position in Graham's angular order */
    PDT_PF_DELETED = 4  /* deleted by Graham's sort (tie or copy) */
};

/* Per-rank slots: the objects of which each rank has exactly one current value. */
enum {
    PDT_SLOT_PHASE = 0,  /* innermost open phase interval */
    PDT_SLOT_MERGE,      /* open merge step (merge rank only) */
    PDT_SLOT_HULL,       /* last hull reported (HULL event) */
    PDT_SLOT_STACK0,     /* + pdt_stack_id: top node of that stack */
    PDT_SLOT_PER_RANK = PDT_SLOT_STACK0 + 5
};

/* One triangle seen in the events; v[] as first reported (counter-clockwise). */
typedef struct pdt_rtri {
    uint32_t v[3];
    uint32_t maker;     /* rank of the first TRI_NEW (or first event) */
    uint32_t h0;        /* its history entries: hist[h0 .. h0+hn) */
    uint16_t hn;        /* (at most PDT_TRI_HIST_MAX) */
    uint8_t last;       /* the status of its last entry (hist[h0 + hn - 1].status):
                         * a triangle at its last entry needs no look at the
                         * histories, which are where the build grouped them */
    uint8_t pad;
} pdt_rtri;

/* One change of a triangle's status (12 bytes: a kept index holds one per
 * triangle event).  The event itself (pdt_replay_rec(r, ev)) says the rest:
 * the rank that reported it, and v (RA_DEFER: touched rank; SHIP:
 * destination; DISCARD: witness). */
typedef struct pdt_rtri_hist {
    uint32_t ev;        /* event index */
    uint32_t until;     /* TRI_NEW of a border kernel: the MERGE_END of its merge step.
                         * A candidate still in this state after that event was
                         * neither kept nor shipped: the merge dropped it without
                         * an event (pdt_rstate_tri_visible).  Else UINT32_MAX. */
    uint8_t status;     /* pdt_tri_status after the event */
    uint8_t run;        /* TRI_NEW: 0 local kernel, 1 border kernel (the event's sub) */
    uint8_t pad[2];
} pdt_rtri_hist;

/* A kernel edge (level 2) between its EDGE_ADD and EDGE_DEL. */
typedef struct pdt_redge {
    uint32_t a, b, rank;
    uint32_t add_ev, del_ev;  /* del_ev = UINT32_MAX: never deleted */
} pdt_redge;

/* A stack node: the stacks are persistent (a push makes a node whose parent
 * is the element below it), so any past stack can be listed from its top. */
typedef struct pdt_rnode {
    uint32_t pt;
    int32_t parent;     /* -1 at the bottom */
    uint32_t depth;     /* 1 at the bottom */
    uint32_t hull_ev;   /* first HULL event that reported this stack, or UINT32_MAX */
} pdt_rnode;

/* A phase of one rank: from its PHASE_BEGIN event to its PHASE_END event. */
typedef struct pdt_rphase {
    uint32_t rank;
    uint32_t phase;     /* pdt_phase */
    uint32_t sub;       /* merge level or 0 */
    uint32_t begin_ev, end_ev;  /* end_ev = UINT32_MAX: never ended */
    int32_t parent;     /* enclosing phase of the same rank, or -1 */
    uint8_t first;      /* 1 if no other rank was already in the same phase
                         * (same id and level) when it began: PgUp/PgDn stops */
    uint64_t begin_t, end_t;  /* their events' times (end_t 0 while it never ended):
                               * the clock reads them without decoding the events */
} pdt_rphase;

/* A merge step, from MERGE_BEGIN to MERGE_END on the merge rank. */
typedef struct pdt_rmerge {
    uint32_t rank, level, gl, gr, gend;
    uint32_t begin_ev, end_ev;
    uint32_t shipped, border, kept, discarded;  /* from MERGE_END (0 before) */
    uint64_t begin_t, end_t;  /* their events' times (end_t 0 while it never ended) */
} pdt_rmerge;

/* A message: SEND on src and the matching RECV on dst. */
typedef struct pdt_rmsg {
    uint32_t src, dst, tag;
    uint32_t pad;               /* 0 (the table is kept in the index as it is) */
    uint64_t bytes;
    uint32_t send_ev, recv_ev;  /* UINT32_MAX when that side is missing */
    uint64_t send_t, recv_t;    /* their events' times (0 when that side is missing) */
} pdt_rmsg;

/* A hull reported by a HULL event: the stack that was just built. */
typedef struct pdt_rhull {
    uint32_t rank, ev;
    int32_t top;        /* top node of the stack (Graham, merge or lower chain) */
    int32_t top2;       /* upper chain's top for a monotone chain, else -1 */
    uint32_t count;     /* hull vertices as reported */
    uint8_t degenerate;
    uint8_t pad[3];     /* 0 (the table is kept in the index as it is) */
} pdt_rhull;

typedef struct pdt_replay pdt_replay;

/* A triangle's state names its history entry in 16 bits: a triangle has at
 * most PDT_TRI_HIST_MAX entries (a vertex set with more events in a run,
 * which only a damaged or made-up trace has, is several triangles, each of
 * that many events but the last). */
#define PDT_TCUR_NONE UINT16_MAX
#define PDT_TRI_HIST_MAX 65535u

/* The state at one cursor position.  Arrays are sized by the replay and
 * owned by the state (pdt_rstate_new / pdt_rstate_free). */
typedef struct pdt_rstate {
    size_t k;            /* events applied: 0 .. k-1 */
    uint8_t *pflags;     /* per point: PDT_PF_* */
    uint16_t *tcur;      /* per triangle t: its history entry in effect, as an offset
                          * from its first (tris' h0: entry h0 + tcur[t]);
                          * PDT_TCUR_NONE = none (2 bytes a triangle) */
    uint8_t *ealive;     /* per kernel edge: 1 while it exists */
    uint8_t *mflight;    /* per message: 1 sent and not yet received */
    int32_t *slot;       /* per rank * PDT_SLOT_PER_RANK: current value or -1 */
    size_t paged[3];     /* bytes of pflags, tcur, ealive when they live in a
                          * temporary file's mapping (0: in memory) */
    uint64_t *held;      /* the replay's count of state bytes in memory, which
                          * this state adds to (NULL: none) */
    uint64_t held_bytes;
} pdt_rstate;

/* Build a replay from `n` points and `m` merged event records of `nranks`
 * ranks (nranks = 0: take 1 + the largest rank seen).  Events that name
 * points >= n or ranks >= nranks are counted in pdt_replay_skipped() and
 * otherwise ignored.  Returns PDT_OK and *out, or an error (out of memory). */
pdt_status pdt_replay_new(const pdt_point *pts, size_t n, const pdt_rec *recs, size_t m,
                          int nranks, pdt_replay **out, pdt_err *err);
void pdt_replay_free(pdt_replay *r);

/* Sizes and tables (owned by the replay, valid until pdt_replay_free). */
size_t pdt_replay_count(const pdt_replay *r);       /* events */
size_t pdt_replay_skipped(const pdt_replay *r);     /* events ignored as malformed */
size_t pdt_replay_kind_count(const pdt_replay *r, int kind); /* events of a pdt_event_kind */
int pdt_replay_nranks(const pdt_replay *r);
const pdt_point *pdt_replay_points(const pdt_replay *r, size_t *n);
/* Event i of the merged order, NULL if i >= count.  A replay opened from a
 * kept index decodes it on demand into a small cache: the pointer holds for
 * the next 7 calls at least (copy the record to keep it longer). */
const pdt_rec *pdt_replay_rec(const pdt_replay *r, size_t i);
/* The rank of event i, without decoding it; UINT32_MAX if i >= count. */
uint32_t pdt_replay_rank_of(const pdt_replay *r, size_t i);
/* The triangles and (pdt_replay_tri_hist) their entries.  Of a lazily
 * verified kept index (pdt_replay_lazy_verify) only the triangles born by
 * a cursor a state of r has been moved to (pdt_replay_born_at_most) are
 * checked, with their entries: read a triangle only once a state says it
 * has an entry (pdt_rstate_tri_entry), as the renderer does. */
const pdt_rtri *pdt_replay_tris(const pdt_replay *r, size_t *n);
/* A bound on the triangles born before cursor k, known without reading a
 * table: triangles t >= it have no entry at k (the triangles are numbered by
 * their first event).  A kept index's checkpoints give it (the triangles
 * born before the first checkpoint at or after k); else all of them. */
size_t pdt_replay_born_at_most(const pdt_replay *r, size_t k);
const pdt_rtri_hist *pdt_replay_tri_hist(const pdt_replay *r);
const pdt_redge *pdt_replay_edges(const pdt_replay *r, size_t *n);
const pdt_rnode *pdt_replay_nodes(const pdt_replay *r, size_t *n);
const pdt_rphase *pdt_replay_phases(const pdt_replay *r, size_t *n);
const pdt_rmerge *pdt_replay_merges(const pdt_replay *r, size_t *n);
const pdt_rmsg *pdt_replay_msgs(const pdt_replay *r, size_t *n);
const pdt_rhull *pdt_replay_hulls(const pdt_replay *r, size_t *n);
/* Graham's angular position of point p (first SORT event), or -1. */
int64_t pdt_replay_sort_pos(const pdt_replay *r, size_t p);
/* Strip box of a rank: the bounding box of the points it lifted outside merge
 * steps (or pushed, when it lifted none).  Returns 0 if the rank has no box. */
int pdt_replay_box(const pdt_replay *r, int rank, pdt_point *lo, pdt_point *hi);
/* Bounding box of all points; 0 when there are none. */
int pdt_replay_bbox(const pdt_replay *r, pdt_point *lo, pdt_point *hi);
/* Index of the point's first lift event, or UINT32_MAX. */
uint32_t pdt_replay_lift_ev(const pdt_replay *r, size_t p);

/* Allocate a state for `r`, at cursor 0.  NULL when out of memory.  For a
 * kept index's run whose state takes more than a quarter of the budget
 * (pdt_replay_set_mem), a state that would bring the states held in memory
 * over half the budget has its per-point, per-triangle and per-edge arrays
 * in the mapping of an anonymous temporary file ($TMPDIR, else /tmp)
 * instead: paged by the kernel, their resident pages given back by
 * pdt_replay_give_back.  (The viewer's own state stays in memory while it
 * fits half the budget: seeks rewrite a paged state through the page cache,
 * several times slower.) */
pdt_rstate *pdt_rstate_new(const pdt_replay *r);
void pdt_rstate_free(pdt_rstate *s);

/* After a seek or a frame: give back the resident pages of what grows with
 * the run and is read through mappings (a paged state's arrays, the run's
 * points read in place, the kept index's tables), so that what the viewer
 * holds stays within its budget.  The next reads take them again from the
 * page cache.  Nothing for a replay held in memory. */
void pdt_replay_give_back(const pdt_replay *r, const pdt_rstate *s);

/* Set `s` to the state at cursor k (clamped to count), the cheapest way:
 * stepping from where s is, from the nearest checkpoint (pdt_replay_set_mem),
 * or pdt_replay_seek_direct.  Every way gives the same state.  Not
 * thread-safe: it may keep a checkpoint in r (a cache; r stays const to its
 * users). */
void pdt_replay_seek(const pdt_replay *r, pdt_rstate *s, size_t k);
/* The same from the histories alone (no stepping, no checkpoints): cost
 * linear in the number of objects, independent of k.  For tests. */
void pdt_replay_seek_direct(const pdt_replay *r, pdt_rstate *s, size_t k);

/* Bytes of one pdt_rstate of r (what a checkpoint costs). */
size_t pdt_replay_state_bytes(const pdt_replay *r);
/* Give checkpoints half of `budget` bytes: a copy of the state every K
 * events (K >= 64, as small as the budget allows), each made on the first
 * seek near it, so that a seek costs at most K/2 steps once its checkpoint
 * exists.  A budget too small for two checkpoints leaves none (seeks step or
 * go the direct way).  Replaces earlier checkpoints. */
void pdt_replay_set_mem(pdt_replay *r, uint64_t budget);
/* Checkpoint slots (0: none); *every = K, *made = those made so far
 * (either may be NULL). */
size_t pdt_replay_checkpoints(const pdt_replay *r, size_t *every, size_t *made);
/* Move `s` by one event: dir > 0 forwards, dir < 0 backwards.  Returns 1 if
 * it moved, 0 at either end. */
int pdt_replay_step(const pdt_replay *r, pdt_rstate *s, int dir);
/* 1 if the two states (of the same replay) are identical. */
int pdt_rstate_equal(const pdt_replay *r, const pdt_rstate *a, const pdt_rstate *b);

/* Value of a rank's slot in state s (-1 when empty or rank out of range). */
int32_t pdt_rstate_slot(const pdt_replay *r, const pdt_rstate *s, int rank, int slot);
/* Status of triangle t in s. */
pdt_tri_status pdt_rstate_tri_status(const pdt_replay *r, const pdt_rstate *s, size_t t);
/* The history entry that decides how triangle t looks in s: its current
 * entry, except that a border-kernel candidate dropped silently by its merge
 * (pdt_rtri_hist.until passed) gives way to the entry before it (a final
 * triangle recomputed by a border kernel stays final).  UINT32_MAX when the
 * triangle does not exist (yet, or any more). */
uint32_t pdt_rstate_tri_entry(const pdt_replay *r, const pdt_rstate *s, size_t t);
/* pdt_rstate_tri_entry() != UINT32_MAX; discarded triangles count as visible. */
int pdt_rstate_tri_visible(const pdt_replay *r, const pdt_rstate *s, size_t t);

/* ---- level of detail ------------------------------------------------------------ */

/* One cell of a coverage grid: the visible triangles (pdt_rstate_tri_entry
 * != UINT32_MAX, discarded ones included) that touch the cell (a triangle
 * larger than a cell counts in every cell it touches, so big triangles
 * leave no holes). */
typedef struct pdt_cov_cell {
    uint32_t n;                          /* triangles */
    uint32_t by_status[PDT_TS_COUNT];    /* of them, by the status that decides their look */
    uint32_t rank;                       /* the maker rank of all of them, or
                                          * PDT_COV_MIXED when makers differ (seams,
                                          * merge regions); meaningless when n == 0 */
    uint32_t rank_lo, rank_hi;           /* the least and greatest maker rank (a
                                          * mixed cell within one group of ranks
                                          * can wear the group's colour) */
} pdt_cov_cell;
#define PDT_COV_MIXED UINT32_MAX

/* Aggregate the triangles of state s over a cols x rows grid covering the
 * world box [x0, x1) x [y0, y1) (cell (0, 0) holds x0, y0; row-major, cell
 * (i, j) at cells[j * cols + i]).  Triangles of ranks with rank_visible[q] ==
 * 0 are left out (rank_visible NULL: all shown), and so are triangles
 * discarded fade events or more before the cursor (the picture has faded
 * them out; fade 0: every discarded one counts).  cells must hold cols * rows
 * entries; they are overwritten.  Returns the number of triangles that touch
 * the box.  Cost O(triangles + cells touched): for drawing runs of millions of triangles as a
 * picture of their density, ranks and statuses when they are too many to
 * draw one by one (pdt_draw_lod). */
size_t pdt_replay_coverage(const pdt_replay *r, const pdt_rstate *s, double x0, double y0,
                           double x1, double y1, int cols, int rows,
                           const uint8_t *rank_visible, uint64_t fade, pdt_cov_cell *cells);

/* ---- run folders and the kept index (index.c) -------------------------------- */

/* Default memory budget of the viewer (pdtview --mem). */
#define PDT_VIEW_MEM_DEFAULT ((uint64_t)1 << 30)

/* What pdt_replay_open_run did. */
typedef struct pdt_replay_open_info {
    uint64_t events;         /* events in the rank files */
    int indexed;             /* 1: the tables are mapped from a kept index (path) */
    int built;               /* 1: the index was built at this opening */
    double build_s;          /* seconds the build took */
    uint64_t build_bytes;    /* the build's working memory at most (its buffers,
                              * and the state it steps for the checkpoints),
                              * besides the run's points and the small tables */
    uint32_t build_buckets;  /* the buckets its triangle events were grouped in */
    char path[4096];         /* the index file */
    char why[160];           /* why an index found was not used ("stale: ...", "damaged: ...") */
    char write_error[1024];   /* why no index could be written (then: in memory) */
} pdt_replay_open_info;

/* The replay of run folder `dir` (opened as `run`, which must outlive the
 * replay: the points stay in it).  use_index 1: through a kept index,
 * 0: in memory (the merged events decoded, as pdt_run_merged), -1: the
 * index when holding the run in memory would take more than a quarter of
 * `budget` bytes (about 100 bytes per event).
 *
 * The kept index (every table of the replay, the merged order of the
 * events and the table of the rank files' blocks: the events themselves
 * stay in the rank files, decoded on demand) is DIR/.pdtview-index, or, when the folder cannot take a file,
 * $XDG_CACHE_HOME/pdt (else ~/.cache/pdt)/run-HASH.pdtview-index, keyed by
 * the folder's real path.  It is checked at every opening (identity of the
 * run's files: names, sizes, modification times, the manifest's bytes;
 * checksums of every section; its size; each rank file block's checksum,
 * at the opening or when the block is decoded) and rebuilt when stale or
 * damaged, written to a temporary file and renamed.  Then it and the rank
 * files are memory-mapped: the replay's own memory is its checkpoints
 * (pdt_replay_set_mem(budget)) and a few decoded blocks.  Building takes
 * the merged events once as a stream (pdt_merge_*), spills the triangle
 * events (16 bytes each) to a scratch file beside the index, and holds 9
 * bytes per event and 28 per point in memory.  When no index can
 * be written anywhere, the run is held in memory (info->write_error says why).
 * Returns PDT_OK and *out (pdt_replay_free), or an error; info may be NULL. */
pdt_status pdt_replay_open_run(pdt_run *run, const char *dir, uint64_t budget, int use_index,
                               pdt_replay **out, pdt_replay_open_info *info, pdt_err *err);

/* The replay of run folder `dir` from its kept index, without opening the
 * run (the index holds the points; the rank files are mapped, and read only
 * for the events decoded): *out = NULL (and PDT_OK, with
 * info->why) when there is no valid index beside the run or in the cache.
 * Errors: the folder cannot be listed, out of memory. */
pdt_status pdt_replay_open_kept(const char *dir, uint64_t budget, pdt_replay **out,
                                pdt_replay_open_info *info, pdt_err *err);
/* Verify kept indexes of at least min_bytes bytes lazily: at the opening
 * their header, chunk table and small tables; each 16 MiB chunk of the big
 * tables when the replay first reads it (the replay checks it before the
 * read: no page is closed, no fault trapped).  A chunk that does not match,
 * or a rank file block that does not when it is decoded, removes the index
 * file and calls on_damage with a message naming it (the program should
 * stop; if it returns, the replay's answers are no longer meaningful).
 * Without this call (or with on_damage NULL), every index is verified
 * whole when opened, and the rank files' blocks with it. */
void pdt_replay_lazy_verify(void (*on_damage)(const char *msg), uint64_t min_bytes);

/* What the reader said about damage in the run when the kept index was
 * built ("" if nothing, or for a replay not opened from an index). */
const char *pdt_replay_run_warnings(const pdt_replay *r);

/* Searching the event list (for the controls).  Kinds of "selected event": */
typedef enum pdt_ev_class {
    PDT_EVC_ANY = 0,
    PDT_EVC_STACK,     /* push / pop */
    PDT_EVC_LIFT,      /* lift-up */
    PDT_EVC_REJECT,    /* ra-defer / discard */
    PDT_EVC_MERGE,     /* merge-begin / merge-end */
    PDT_EVC_TRI,       /* any triangle event */
    PDT_EVC_COUNT
} pdt_ev_class;
const char *pdt_ev_class_name(int c);
/* 1 if event kind `kind` belongs to class c. */
int pdt_ev_in_class(int kind, int c);
/* Cursor just after the next (dir > 0) / previous (dir < 0) event of class c
 * from cursor k, on a rank that `visible(rank)` accepts (NULL: all), or k
 * when there is none. */
size_t pdt_replay_find(const pdt_replay *r, size_t k, int dir, int c,
                       const uint8_t *rank_visible);
/* Cursor just after the next / previous PHASE_BEGIN that starts a phase no
 * rank was in yet (pdt_rphase.first; "run" excluded), or the end / 0. */
size_t pdt_replay_find_phase(const pdt_replay *r, size_t k, int dir);
/* Cursor just after the first PHASE_BEGIN of the phase named `name`
 * ("kernel", "merge", "graham-scan", ...; "merge:2" = merge level 2), or
 * (size_t)-1 when none. */
size_t pdt_replay_find_phase_name(const pdt_replay *r, const char *name);

/* Phase stops (phasestops.c): one per phase (name and merge level), at the
 * cursor just after the last rank that goes through it has begun it — every
 * such rank is then in it or past it, whatever the timing of the run.  In
 * the order the phases first begin ("run" left out), sorted by cursor.
 * Fills up to `cap` stops, returns how many there are. */
typedef struct pdt_phase_stop {
    size_t k;
    uint32_t phase, sub;  /* pdt_phase; merge level */
} pdt_phase_stop;
size_t pdt_replay_phase_stops(const pdt_replay *r, pdt_phase_stop *out, size_t cap);
/* The next stop after k (dir > 0; else the end) or the previous one before k
 * (dir < 0; else 0): PgDn / PgUp. */
size_t pdt_replay_find_phase_stop(const pdt_replay *r, size_t k, int dir);
/* The stop of the phase named `name` ("classify", "merge:1"), or (size_t)-1. */
size_t pdt_replay_phase_stop_named(const pdt_replay *r, const char *name);
/* The rank of the last hull reported before cursor k (the hull drawn
 * thickest, whose colour the legend's hull swatch takes), else 0
 * (hullrank.c). */
int pdt_replay_hull_rank(const pdt_replay *r, size_t k);
/* The cursor from which rank `rank`'s strip box is drawn: just after it
 * begins its partition phase (0 for a run without one). */
size_t pdt_replay_box_from(const pdt_replay *r, int rank);

#endif
