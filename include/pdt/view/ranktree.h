/* pdt — the ranks of a run as a tree: the merge tree.  A merge step joins
 * the ranks [gl, gr) and [gr, gend) (MERGE_BEGIN), so the steps nest into a
 * binary tree whose leaves are the ranks; a group of ranks is a subtree.
 * The viewer colours, lists, hides and steps ranks by group, and opens a
 * group of the timeline into its subgroups, down to single ranks.
 *
 * Ranges no merge step joined (a run without merges, a hull run) are split
 * in halves, so the tree is the same shape for every run.  Knows nothing of
 * pixels (the renderer asks it which groups a screen shows). */
#ifndef PDT_VIEW_RANKTREE_H
#define PDT_VIEW_RANKTREE_H

#include "pdt/view/replay.h"

/* A node: the ranks [lo, hi).  A leaf has hi == lo + 1. */
typedef struct pdt_rtnode {
    uint32_t lo, hi;
    int32_t parent, kid[2];  /* node indices, -1 when none */
    int32_t merge;           /* index into pdt_replay_merges, or -1 */
    uint32_t depth;          /* root 0 */
    uint64_t t_ns;           /* merge: MERGE_END's time - MERGE_BEGIN's (0 unknown) */
    uint64_t bytes;          /* merge: bytes the merge rank received during it */
    uint64_t ready_ns;       /* when its result was ready: MERGE_END's time, or a
                              * leaf's last local phase end (0 unknown) */
    uint8_t critical;        /* on the critical path: from the root, the child
                              * ready last, down to a rank */
} pdt_rtnode;

typedef struct pdt_ranktree pdt_ranktree;

/* The tree of r's ranks.  NULL when out of memory.  The caller owns it
 * (pdt_ranktree_free); r must outlive it. */
pdt_ranktree *pdt_ranktree_new(const pdt_replay *r);
void pdt_ranktree_free(pdt_ranktree *t);

/* Its nodes (node 0 is the root) and their number. */
const pdt_rtnode *pdt_ranktree_nodes(const pdt_ranktree *t, size_t *n);
int pdt_ranktree_nranks(const pdt_ranktree *t);
/* The leaf node of rank q, or -1. */
int32_t pdt_ranktree_leaf(const pdt_ranktree *t, int q);
/* The node of merge step i (pdt_replay_merges), or -1. */
int32_t pdt_ranktree_of_merge(const pdt_ranktree *t, size_t i);

/* The groups a screen shows: at most maxg nodes covering every rank with
 * on[rank] != 0 (on NULL: every rank), as deep as that many allow (the
 * smallest subtree holding them, split at its most populous groups first),
 * in rank order, into out[0..maxg).  Returns their number (>= 1). */
size_t pdt_ranktree_cut(const pdt_ranktree *t, const uint8_t *on, size_t maxg, int32_t *out);

/* The rows of a timeline: each group of the cut, or, when open[node] is
 * set (open NULL: none), its children's rows in its place, recursively.
 * Writes at most cap nodes into rows (rows may be NULL with cap 0) and
 * returns how many there are. */
size_t pdt_ranktree_rows(const pdt_ranktree *t, const int32_t *cut, size_t ncut,
                         const uint8_t *open, int32_t *rows, size_t cap);

/* The run's clock, for the timeline: every time as a fraction u of the
 * span of the run's times (0 at the first, 1 at the last), or, for a run of
 * fewer than PDT_RANKTREE_TIMED_RANKS ranks (the lessons' small runs, told
 * a step per event) or a trace without times (all equal), of the merged
 * order (event e at e / count).
 * pdt_ranktree_timed: 1 when times are known (and *span_ns, if not NULL, the
 * span in the trace's nanoseconds; simulated or synthetic runs have their
 * own clocks), else 0.  pdt_ranktree_at: event e's u (1 past the end).
 * pdt_ranktree_phase_at / _msg_at: per phase (pdt_replay_phases) its begin's
 * and end's u, per message (pdt_replay_msgs) its send's and receive's, two
 * doubles each, owned by t.  pdt_ranktree_event_at: the first event whose u is
 * at least u (count when none). */
#define PDT_RANKTREE_TIMED_RANKS 9
int pdt_ranktree_timed(const pdt_ranktree *t, double *span_ns);
double pdt_ranktree_at(const pdt_ranktree *t, size_t e);
const double *pdt_ranktree_phase_at(const pdt_ranktree *t);
const double *pdt_ranktree_msg_at(const pdt_ranktree *t);
size_t pdt_ranktree_event_at(const pdt_ranktree *t, double u);

/* "r12" for a leaf, "r0–127" for a group, into buf. */
void pdt_ranktree_name(const pdt_ranktree *t, int32_t node, char *buf, size_t cap);

#endif
