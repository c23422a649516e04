/* pdt — live runs for the viewer's editor: the real algorithm, run in the
 * viewer's process on points in memory, recording the same events a
 * `pdt triangulate --trace` / `pdt hull --trace` run records (timings
 * aside), as a merged event list the replay model takes as it is.
 *
 *  - triangulate, 1 rank: the sequential pipeline (pdt_triangulate) between
 *    a "run" phase, then the output phase with one TRI_FINAL per triangle of
 *    T*, exactly as the command's tracing does;
 *  - triangulate, P > 1 ranks: the parallel pipeline of libpdtpar
 *    (pdt_par_triangulate) on P threads over the local communicator
 *    (pdt_comm_local_run), each rank with its block of the input as
 *    pdt_par_read deals the file pdt_write_points writes for the points and the events `mpirun -np P pdt triangulate
 *    --trace` records at that rank (run, read, the triangulation, write);
 *    times are the shared monotonic clock, and the ranks are merged as the
 *    reader merges a run folder (a RECV never before its SEND, else by time);
 *  - hull: Graham's scan, Version B (pdt_hull_graham) inside a "run" phase
 *    (one rank whatever o->ranks says: `pdt hull` has no parallel mode).
 *
 * The run also says where the tie rule decided: an interior edge of T* whose
 * two triangles have their four points on one circle (exact pdt_incircle0 of
 * the opposite point = 0): there the other diagonal would have been
 * Delaunay too, and the lexicographic rule picked this one. */
#ifndef PDT_LIVE_H
#define PDT_LIVE_H

#include "pdt/common.h"
#include "pdt/tracefile.h"

/* The most simulated ranks a live run takes. */
#define PDT_LIVE_MAX_RANKS 64

typedef struct pdt_live_opts {
    int hull;     /* 1: Graham's scan only (pdt hull) */
    int ranks;    /* simulated ranks (1 = the sequential pipeline) */
    int level;    /* trace level, 1 or 2 */
    int node;     /* the points' file is Triangle's .node: its line lengths decide
                   * the ranks' blocks, as pdt_par_read deals them (0: "x y" text) */
} pdt_live_opts;

typedef struct pdt_live_result {
    pdt_rec *recs;      /* merged events (malloc'd) */
    size_t m;
    int nranks;
    pdt_tri *tris;      /* triangulate: T* as input indices (malloc'd), else NULL */
    size_t ntri;
    size_t nhull;       /* hull: extreme points */
    uint32_t *ties;     /* 2 * nties point indices: the edges the tie rule chose */
    size_t nties;
} pdt_live_result;

/* Run o's algorithm on pts[0..n) and record it into *res (which the caller
 * frees with pdt_live_free, also after an error).  Requires 1 <= o->ranks <=
 * PDT_LIVE_MAX_RANKS (else PDT_ERR_ARG).  Returns PDT_OK, or an error (out of
 * memory, too many points, a failed rank) described in err. */
pdt_status pdt_live_run(const pdt_point *pts, size_t n, const pdt_live_opts *o,
                        pdt_live_result *res, pdt_err *err);
void pdt_live_free(pdt_live_result *res);

/* The interior edges of triangulation tris[0..ntri) (input indices into
 * pts) whose quadrilateral is cocircular: *edges gets 2 point indices per
 * such edge (malloc'd, caller frees; NULL when there are none). */
pdt_status pdt_live_ties(const pdt_point *pts, size_t n, const pdt_tri *tris, size_t ntri,
                         uint32_t **edges, size_t *nedges, pdt_err *err);

#endif
