/* pdt — pdt trace check's insides, shared by check.c (the events, rank by
 * rank, and the cross-rank checks) and check_finals.c (the final triangles
 * and what grows with the points, within the memory budget).  Private to
 * src/trace. */
#ifndef PDT_CHECK_INT_H
#define PDT_CHECK_INT_H

#include <stdint.h>
#include <stdio.h>

#include "pdt/tracefile.h"
#include "tf_internal.h"
#include "pdt/bigmem.h"

typedef struct fin {   /* a TRI_FINAL, rotated to start at its smallest index */
    pdt_tri t;
    uint32_t rank;
    uint64_t seq;
} fin;

typedef struct msg {   /* a SEND or RECV */
    uint32_t src, dst, tag, rank;
    uint64_t bytes;
    int64_t seq_no;
    uint64_t seq;      /* event index */
    pdt_event ev;
} msg;

typedef struct merge {
    uint32_t level, gl, gr, end, rank;
    uint64_t seq, lifts, discards;
    int closed;
} merge;

/* A stack of point indices as the events build it (a rank's stack of one
 * id, or the final Graham stack): malloc'd while all of them together fit
 * an eighth of the budget, beyond it in a growable temporary file's
 * mapping (v == map.p), whose resident pages are given back as the check
 * goes (chk_stacks_tick in check.c). */
typedef struct chk_stack {
    uint32_t *v;
    size_t n, cap;
    pdt_temp_map map;       /* map.p NULL: v is malloc'd */
} chk_stack;

typedef struct chk {
    pdt_run *run;
    pdt_err *err;
    const pdt_point *pts;
    size_t npts;
    int is_tri, is_hull;
    int bisect;             /* the run was cut by bisection (its regions are checked, not strips) */
    uint8_t *mark;          /* per point: see M_* */
    size_t mark_map;        /* bytes of the marks' file mapping (0: in memory) */
    int certify;            /* T* certified on disk, not recomputed (over budget) */
    int dedup_on_disk;      /* the distinct points found by a sort on disk */
    uint64_t dedup_runs;    /* sorted runs that sort wrote */
    int give_back;          /* give back the pages of the points and marks (tick) */
    uint64_t ticks;
    uint64_t cert_runs;     /* sorted runs the certificate wrote */
    fin *fin;               /* final triangles not yet spilled (see spill_finals) */
    size_t nfin, capfin;
    size_t maxfin;          /* finals held in memory before a spill (from the budget) */
    uint64_t budget;        /* the memory budget (bytes) */
    pdt_tstar_fn tstar;     /* recomputes T* (NULL: pdt_triangulate) */
    int tstar_strips;       /* the strips it worked on (0: the whole kernel) */
    FILE **runs;            /* sorted runs of finals spilled to temporary files */
    size_t nruns, capruns;
    uint64_t totfin;        /* final triangles recorded in all */
    uint64_t spills;        /* sorted runs written (before any compaction) */
    msg *msg;
    size_t nmsg, capmsg;
    merge *mg;
    size_t nmg, capmg;
    chk_stack graham_final; /* last finished Graham stack of rank 0 (moved, not copied) */
    uint64_t stack_bytes;   /* malloc'd by the stacks (at most budget / 8) */
    int hull_certify;       /* a hull run's hull certified, not recomputed (over budget) */
    uint64_t events, pushes, pops, instances, lifts_local, lifts_merge, sorts, hulls;
    uint64_t edge_scopes;   /* kernel runs whose level-2 edges were replayed */
    uint64_t edge_spills;   /* of them, replayed on disk (over a quarter of the budget) */
    /* the region of each rank: lexicographic keys of its local lift-ups,
     * (x, y) and (y, x) */
    uint64_t *kmin, *kmax, *nlocal, *ymin, *ymax;
} chk;

enum { M_SORTED = 1, M_DELETED = 2, M_PUSHED = 4, M_LIFTED = 8, M_REP = 16 };

/* What recomputing T* takes per point (the kernel's arrays and the reference
 * triangles; measured: some 90 bytes per point at 2*10^6 points).  When the
 * finals still in memory and this do not fit the budget together, the
 * finals go to disk before T* is recomputed. */
#define TSTAR_BYTES_PER_POINT 96u
#define DEDUP_BYTES_PER_POINT 36u  /* pdt_sort_unique: order 4, work 32 */
/* What recomputing a hull run's hull takes per point: pdt_hull_graham's
 * order and its sort's scratch (or its stack), and the hull written.  Over
 * the budget the final Graham stack is certified instead (hullcert.h). */
#define HULL_BYTES_PER_POINT 12u
/* Calls between two givings-back of resident pages (chk_tick, the stacks). */
#define GIVE_BACK_EVERY ((uint64_t)1 << 16)

/* check.c */
pdt_status chk_nomem(chk *c);
/* PDT_ERR_CHECK: "rank R event #K (the event): what" (e NULL: "what"). */
pdt_status chk_viol(chk *c, uint32_t rank, uint64_t seq, const pdt_event *e, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
/* Room for one more of n elements of `size` bytes in *p (doubling).  0 or -1. */
int chk_grow(void **p, size_t *cap, size_t n, size_t size);
/* Give back the resident pages of n stacks' arrays beyond their use. */
void chk_stacks_give_back(chk_stack *st, size_t n);
void chk_stack_free(chk *c, chk_stack *s);

/* check_run.c: the checks of the whole run, after every rank's pass */
/* Every distinct point lifted (nu of them). */
pdt_status chk_lifts(chk *c, size_t nu);
/* The ranks' local points are consecutive lexicographic blocks (strips). */
pdt_status chk_strips(chk *c);
/* Every send received, of the same size. */
pdt_status chk_messages(chk *c);
/* The merge steps of a level do not overlap; the last joins every rank. */
pdt_status chk_merges(chk *c);
/* A bisection: one cut separates the two groups of every merge step. */
pdt_status chk_regions(chk *c);
/* A hull run: every point sorted, each deleted or pushed, the final stack the hull. */
pdt_status chk_graham_hull(chk *c);
/* The one-line summary of a run that passed. */
void chk_summary(const chk *c, char *summary, size_t cap);

/* check_finals.c */
/* A temporary file's failure: "temporary file for <of> in DIR: <what>: why". */
pdt_status chk_tmp_fail(chk *c, const char *of, const char *what);
/* Sort the buffered finals and write them out as one run; empties the buffer. */
pdt_status chk_spill_finals(chk *c);
/* Every final once, and their set T* of the run's points (nu distinct). */
pdt_status chk_finals(chk *c, size_t nu);
/* The marks: in memory, or beyond a quarter of the budget in a temporary
 * file's mapping.  0 or -1 (errno). */
int chk_marks_new(chk *c);
void chk_marks_free(chk *c);
/* Every so many calls over the budget: the points' and marks' pages given back. */
void chk_tick(chk *c);
/* M_REP on the smallest index of each distinct point, and their number. */
pdt_status chk_find_distinct(chk *c, size_t *nu);

#endif
