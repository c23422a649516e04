/* pdt — the sequential Delaunay kernel (lift-up + lower hull, computed by
 * Guibas–Stolfi divide and conquer) and the sequential pipeline around it.
 *
 * The answer is always T*(P), the canonical Delaunay triangulation of
 * docs/algorithm.md §2.3 (simulation of simplicity on the lifted heights). */
#ifndef PDT_DELAUNAY_H
#define PDT_DELAUNAY_H

#include "pdt/common.h"
#include "pdt/trace.h"

/* The most points one kernel run takes (2^29 - 1 = 536 870 911): its edge
 * records are indexed by 32-bit numbers, 8 per point.  pdt_delaunay and
 * pdt_triangulate return PDT_ERR_ARG above it, before touching the points;
 * a parallel run needs about n / PDT_KERNEL_MAX_POINTS ranks or more. */
#define PDT_KERNEL_MAX_POINTS ((size_t)(UINT32_MAX / 8))

/* T*(pts) for n DISTINCT points sorted lexicographically (x, then y).
 * On success *tris is a malloc'd array of *ntri counter-clockwise triangles
 * (indices into pts; order unspecified; the caller frees).  Fewer than 3
 * points or all collinear: *ntri = 0 (and *tris may be NULL).
 * O(n log n) on every input.  Traces TRI_NEW (sub = `run`) at level 1 and
 * EDGE_ADD / EDGE_DEL at level 2.  Returns PDT_ERR_ARG (and nothing else
 * happens) if the points are not distinct and sorted, PDT_ERR_NOMEM when an
 * allocation fails. */
pdt_status pdt_delaunay(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri, int run,
                        pdt_trace *tr);

/* Bytes of working memory pdt_delaunay_on needs for n points: its 6n + 12
 * edge records of 12 bytes (72 bytes per point). */
#define PDT_DELAUNAY_WORK(n) ((size_t)72 * (size_t)(n) + 144)

/* pdt_delaunay on the caller's memory, with no copy of the points: pts[0, n)
 * (distinct, sorted lexicographically) are working memory during the call
 * and hold their values again on return, success or not; id: n words of
 * scratch; work: work_bytes >= PDT_DELAUNAY_WORK(n) bytes, 8-byte aligned.
 * On success the *ntri triangles (counter-clockwise, indices into pts) are
 * ((pdt_tri *)work)[0, *ntri) and the rest of work holds no data.  Allocates
 * nothing (but a map of n words when tracing with tr->gid).  Traces and
 * errors as pdt_delaunay (PDT_ERR_ARG also for too small a work). */
pdt_status pdt_delaunay_on(pdt_point *pts, size_t n, uint32_t *id, void *work, size_t work_bytes,
                           size_t *ntri, int run, pdt_trace *tr);

/* pdt_delaunay_on, and the convex hull as a by-product of the triangulation
 * (its outer face, walked before the triangles are written): *hull
 * (malloc'd, the caller frees) gets the indices of the hull vertices,
 * collinear boundary points included, counter-clockwise from pts[0] (the
 * lexicographically smallest) -- the same list as pdt_hull_chain's for a
 * set that is not degenerate.  When the points are all collinear, n < 3, or
 * on an error: *hull = NULL, *nhull = 0 (pdt_hull_chain says what a
 * degenerate hull is).  hull may be NULL (pdt_delaunay_on). */
pdt_status pdt_delaunay_hull_on(pdt_point *pts, size_t n, uint32_t *id, void *work,
                                size_t work_bytes, size_t *ntri, uint32_t **hull, size_t *nhull,
                                int run, pdt_trace *tr);

/* Rotate every triangle so that it starts at its smallest index (keeping the
 * counter-clockwise order) and sort the array lexicographically: the
 * canonical output order, identical for every algorithm and every rank count. */
void pdt_tri_canonical(pdt_tri *tris, size_t ntri);

/* The same with the caller's scratch: room for ntri triangles overlapping
 * tris nowhere (nothing of size ntri is allocated). */
void pdt_tri_canonical_on(pdt_tri *tris, size_t ntri, pdt_tri *scratch);

/* The kernel for one strip of a parallel run (untraced), leaving the points
 * in its own order: pts[0, n) distinct and sorted, name[i] the name of
 * pts[i], work as for pdt_delaunay_on.  Afterwards pts and name are in the
 * kernel's order (the same permutation applied to both), the *ntri
 * triangles at work's front and the hull (*hull, malloc'd, the caller
 * frees: counter-clockwise from the lexicographically smallest point, the
 * collinear boundary points included) name positions in that order: vertex
 * v is pts[v], called name[v].  The same triangles, in the same order and
 * orientation, and the same hull as pdt_delaunay_hull_on's, named so.  When
 * there is no hull (the points on a line, or n < 3): no triangle, *hull =
 * NULL, and pts and name given back in their first order.  PDT_ERR_ARG for
 * unsorted points or too small a work. */
pdt_status pdt_delaunay_strip(pdt_point *pts, size_t n, uint32_t *name, void *work,
                              size_t work_bytes, size_t *ntri, uint32_t **hull, size_t *nhull);

/* The canonical order in buckets, for triangles spread over ranks (the order
 * phase of a parallel run): bucket b holds the triangles whose smallest index
 * v has v >> shift == b.  Every rank counts its triangles by bucket
 * (pdt_tri_bucket_count, which rotates each to start at its smallest index),
 * groups them by bucket (pdt_tri_bucket_scatter) and sends each rank a range
 * of buckets; the receiver orders what it got (pdt_tri_bucket_order).  The
 * result is the canonical order of the union, whatever the grouping. */

/* t rotated to start at its smallest index (the same triangle, the same
 * orientation), branch-free: which corner is the smallest is random, and a
 * branch on it mispredicts every other triangle. */
static inline pdt_tri pdt_tri_smallest_first(pdt_tri t)
{
    uint32_t a = t.v[0], b = t.v[1], c = t.v[2];
    uint32_t w[5] = {a, b, c, a, b};
    unsigned r = (unsigned)((b < a) & (b < c)) + 2u * (unsigned)((c < a) & (c < b));
    return (pdt_tri){{w[r], w[r + 1], w[r + 2]}};
}

/* Rotate each of t[0, n) to start at its smallest index v and add 1 to
 * hist[v >> shift] (hist: room for every bucket that occurs). */
void pdt_tri_bucket_count(pdt_tri *t, size_t n, int shift, uint64_t *hist);

/* Copy each of t[0, n) (rotated) to dst[at[b]++], b its bucket. */
void pdt_tri_bucket_scatter(const pdt_tri *t, size_t n, int shift, uint64_t *at, pdt_tri *dst);
/* The same for the triangles of the buckets b with in[b] = 1 only (an
 * exchange in rounds, each with a grouped array of its own share); the
 * others are moved down to the front of t, in their order, and their number
 * is returned, so that the next round reads only them.  Each of the others
 * is also written to dst[at[b]] without moving on (no branch on the round):
 * at[b] must name one spare place past the round's for them. */
size_t pdt_tri_bucket_scatter_split(pdt_tri *t, size_t n, int shift, const uint8_t *in,
                                     uint64_t *at, pdt_tri *dst);

/* The ns runs src[k][0, len[k]) (rotated, each grouped by bucket in
 * increasing order, no triangle twice) into out in canonical order; out has
 * room for them all and overlaps none.  2^shift counters are allocated
 * (8 bytes each: keep shift small, 21 is 16 MiB): PDT_ERR_NOMEM when that
 * fails. */
pdt_status pdt_tri_bucket_order(const pdt_tri *const *src, const size_t *len, size_t ns, int shift,
                                pdt_tri *out);

/* Figures reported by the pipeline. */
typedef struct pdt_tri_stats {
    size_t n_in;        /* points read */
    size_t n_unique;    /* distinct points */
    size_t n_dup;       /* duplicates dropped (the smallest input index is kept) */
    size_t n_tri;       /* triangles */
    size_t n_hull;      /* hull vertices (collinear boundary points included) */
    int collinear;      /* 1 if all distinct points are collinear (or n_unique < 3) */
    int prefaulted;     /* 1 if a second thread faulted the memory in (PDT_TRI_PREFAULT) */
    double t_sort, t_kernel, t_canon; /* seconds */
} pdt_tri_stats;

/* The whole sequential pipeline: sort by key, remove duplicates (the
 * smallest input index is kept), lift-up (traced), kernel, map back to input
 * indices, canonical order.  *tris (malloc'd, caller frees) holds triangles as
 * 0-based input indices.  `stats` may be NULL. */
pdt_status pdt_triangulate(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri,
                           pdt_tri_stats *stats, pdt_trace *tr);

/* What pdt_triangulate_inplace leaves in the caller's points, and how it
 * uses the machine. */
enum {
    PDT_PTS_RESTORE = 1, /* their values again (one more pass, a scatter) */
    PDT_PTS_SPEND = 0,   /* unspecified values: the caller only frees them */
    /* (or'd with one of the above) a second thread faults the pipeline's
     * working memory in ahead of use (docs/geometry.md, "Prefault"): only
     * for a caller that leaves a core idle (a plain run, never an MPI rank
     * sharing the machine's cores); costs that core the CPU time of the
     * page faults, and saves the caller about as much on the critical
     * path.  Same results with or without. */
    PDT_TRI_PREFAULT = 2
};

/* The same pipeline on the caller's points used as working memory (8 bytes
 * per point less at the peak than pdt_triangulate, which copies them): during
 * the call pts[] hold other values; on return, success or not, they hold
 * their values again if keep has PDT_PTS_RESTORE. */
pdt_status pdt_triangulate_inplace(pdt_point *pts, size_t n, int keep, pdt_tri **tris,
                                   size_t *ntri, pdt_tri_stats *stats, pdt_trace *tr);

/* Sort-and-dedupe helper used by the pipeline and the parallel driver:
 * writes to order[0..*nu) the input indices of the distinct points in
 * lexicographic order, each the smallest index among its copies. */
pdt_status pdt_sort_unique(const pdt_point *pts, size_t n, uint32_t *order, size_t *nu);

/* The same on the caller's scratch, work: PDT_SORT_WORK(n) bytes, 8-byte
 * aligned (overlapping none of pts, order, q); q, if not NULL, gets the
 * distinct points themselves (q[i] == pts[order[i]]).  PDT_ERR_ARG if n is
 * above 2^32 - 1. */
#define PDT_SORT_WORK(n) ((size_t)32 * (size_t)(n) + 2 * 2049 * sizeof(size_t))
pdt_status pdt_sort_unique_on(const pdt_point *pts, size_t n, void *work, uint32_t *order,
                              pdt_point *q, size_t *nu);

#endif
