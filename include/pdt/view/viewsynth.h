/* pdt — synthetic runs for the viewer's tests, benchmark and demo.
 *
 * Makes points and a merged event list that tell the same story as a real
 * run, without the algorithm code: so the viewer can be tested on its own.
 *
 *  - "srm": a rectangular grid of cols x rows points (spacing 10 in x, 30 in
 *    y, so that circles of boundary cells reach the next strip), cut into
 *    vertical strips, one per rank.  Each rank lifts its points, triangulates
 *    its cells (level 2: with kernel edges), builds its strip hull with a
 *    real monotone chain (push/pop), classifies every triangle against the
 *    other ranks' boxes (final or deferred); then the merge tree: pending
 *    triangles are shipped (SEND/RECV), the merge rank lifts the border set,
 *    triangulates the seam, discards the shipped triangles of every other
 *    row next to the seam (flipping their diagonal — cocircular, so both are
 *    Delaunay: the story is synthetic), reclassifies, merges the hulls.
 *  - "graham": rank 0 runs Graham's scan Version B (real integer predicates)
 *    on n pseudo-random points, with angular-order SORT and DELETE events.
 *
 * The triangles are a valid triangulation of the grid; the stacks and hulls
 * are the real ones. */
#ifndef PDT_VIEWSYNTH_H
#define PDT_VIEWSYNTH_H

#include "pdt/common.h"
#include "pdt/tracefile.h"

typedef struct pdt_synth {
    pdt_point *pts;   /* malloc'd */
    size_t n;
    pdt_rec *recs;    /* malloc'd, merged order */
    size_t m;
    int nranks;
} pdt_synth;

/* A grid run: cols >= 2, rows >= 2, 1 <= nranks <= cols / 2, level 1 or 2. */
pdt_status pdt_synth_srm(int cols, int rows, int nranks, int level, pdt_synth *out, pdt_err *err);
/* A Graham Version B run on n >= 3 points (deterministic for a seed; some
 * points repeat and some share an angle, to show the deletions). */
pdt_status pdt_synth_graham(size_t n, uint64_t seed, pdt_synth *out, pdt_err *err);
void pdt_synth_free(pdt_synth *s);

#endif
