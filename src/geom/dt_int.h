/* pdt — internals of the sequential Delaunay kernel (internal to src/geom).
 *
 * The kernel is made of five files, one concern each, in the order a run
 * goes through them:
 *   dt_sort.c    the points sorted lexicographically and their copies dropped
 *                (one LSD radix sort for both record layouts);
 *   dt_cut.c     Dwyer's alternating cuts, all made before any edge exists:
 *                the points moved to the order of the recursion's leaves;
 *   dt_kernel.c  the edge structure, the Guibas–Stolfi recursion and merge,
 *                the triangles and the hull read off the edges;
 *   dt_order.c   the canonical order of the triangles (alone, or in buckets
 *                spread over ranks);
 *   delaunay.c   the public entry points and the pipeline chaining the above
 *                (pdt_triangulate_inplace).
 * The design is in docs/algorithm.md §2.3 and docs/geometry.md. */
#ifndef PDT_GEOM_DT_INT_H
#define PDT_GEOM_DT_INT_H

#include <stddef.h>
#include <stdint.h>

#include "pdt/delaunay.h"

#define DT_NIL UINT32_MAX

/* One directed edge: 12 bytes, e and its twin e ^ 1 side by side, so the
 * three fields an operation reads share a cache line (dt_kernel.c says what
 * they mean).  The triangles (12 bytes each) are written over them. */
typedef struct dt_edge {
    uint32_t org, onext, oprev;
} dt_edge;

/* Edge records for the kernel on n points (the planar bound and a margin);
 * PDT_DELAUNAY_WORK(n) is their size in bytes. */
static inline size_t dt_edge_cap(size_t n)
{
    return 6 * n + 12;
}

/* The key of p in frame `axis`: frame 0 is the lexicographic (x, y) order,
 * frame 1 the same order after the rotation (x, y) -> (y, -x), i.e. by y,
 * then by decreasing x (dt_cut.c says why). */
static inline uint64_t dt_frame_key(pdt_point p, int axis)
{
    if (!axis) return pdt_key(p);
    return ((uint64_t)((uint32_t)p.y ^ 0x80000000u) << 32) |
           (uint64_t)(~((uint32_t)p.x ^ 0x80000000u));
}

/* ---- dt_cut.c ---- */

/* Scratch bytes pdt_dt_cut_order needs per point (two key arrays, an id and
 * a point). */
enum { PDT_DT_CUT_SCRATCH = 28 };

/* A node [lo, hi) of the cut tree (hi - lo >= 2) is named by
 * lo + (hi - lo) / 2: an internal node's median, a leaf's second point; no
 * two nodes share it. */
static inline uint32_t dt_node_at(uint32_t lo, uint32_t hi)
{
    return lo + (hi - lo) / 2;
}

/* Make every cut of the recursion on q[0, n) (distinct, sorted), the root
 * cutting in frame `axis`: afterwards q lists the points in the order of the
 * leaves (every node's points one contiguous range, each leaf of at most 3
 * points sorted in its frame), id moved along.  scratch: n *
 * PDT_DT_CUT_SCRATCH bytes, 8-byte aligned.  With ax (n bytes) a node of
 * DT_SPREAD_MIN points or more cuts across the wider spread of its points
 * (dt_cut.c), and its frame is kept in ax[dt_node_at(lo, hi)]; without,
 * the frames alternate from the root's. */
enum { DT_SPREAD_MIN = 64 };
void pdt_dt_cut_order(pdt_point *q, uint32_t *id, size_t n, void *scratch, int axis,
                      uint8_t *ax);

/* ---- dt_kernel.c ---- */

/* pdt_dt_kernel's flags: the triangles named by vertex (not id[v]); the
 * cuts across the points' spread (pdt_dt_cut_order with ax: for thin
 * bands, the border sets of the merges; an untraced kernel only). */
enum { DT_BY_VERTEX = 1, DT_SPREAD = 2 };

/* The kernel on q[0, n) (n >= 2, distinct, sorted), moved to its leaf order
 * along with id, on cap edge records at e (cap >= dt_edge_cap(n)).  The
 * triangles are left over the edge records, ((pdt_tri *)e)[0, *ntri),
 * counter-clockwise, named id[v] (the vertex v itself with DT_BY_VERTEX);
 * the trace names vertex v tr->gid[id[v]] and marks new triangles with
 * `run`.  hull (may be NULL): the convex hull, malloc'd, named as the
 * triangles (nothing when all points are on a line).  Returns PDT_OK or
 * PDT_ERR_NOMEM. */
pdt_status pdt_dt_kernel(uint32_t *id, pdt_point *q, size_t n, dt_edge *e, size_t cap,
                         size_t *ntri, int run, pdt_trace *tr, uint32_t **hull, size_t *nhull,
                         int flags);

/* ---- dt_sort.c ---- */

/* What pdt_dt_sort writes: order[0, nu) the input indices of the distinct
 * points in order, each the smallest of its copies; q (NULL, or room for n
 * points): the distinct points in order, decoded from the keys (q[i] ==
 * pts[order[i]]); dup (NULL, or room for 2n words): a pair (index of a
 * copy, index kept for it) for each of the ndup copies dropped. */
typedef struct pdt_dt_sorted {
    uint32_t *order;
    pdt_point *q;
    uint32_t *dup;
    size_t nu, ndup;
} pdt_dt_sorted;

/* Counters pdt_dt_sort needs in each of cnt and hc. */
enum { PDT_DT_SORT_COUNTERS = 2049 };

/* Sort and dedupe pts[0, n) (n >= 1, n <= UINT32_MAX) into o, on the
 * caller's scratch: 32 bytes per point at work (two arrays of 16-byte
 * records, 8-byte aligned), PDT_DT_SORT_COUNTERS counters in each of cnt
 * and hc. */
void pdt_dt_sort(const pdt_point *pts, size_t n, void *work, size_t *cnt, size_t *hc,
                 pdt_dt_sorted *o);

/* ---- dt_order.c ---- */

/* The canonical order of in[0, ntri), written to out[0, ntri) (out may be
 * in, or overlap it: in is read whole before out is written); scratch: room
 * for ntri triangles overlapping neither (NULL: allocated here, with a
 * qsort in place when that fails). */
void pdt_dt_canonical(pdt_tri *in, pdt_tri *out, size_t ntri, pdt_tri *scratch);

#endif
