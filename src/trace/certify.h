/* pdt — certify that a set of triangles is T* of a run's points, edge by
 * edge, in bounded memory (private to src/trace; used by pdt trace check
 * when recomputing T* would not fit its memory budget).
 *
 * Instead of recomputing T* and comparing, the triangles are checked
 * against conditions that hold only for T*:
 *   1. every triangle is counter-clockwise (the caller checks it), none twice
 *      (the caller checks it: it sees them sorted);
 *   2. a side is shared by at most two triangles, in opposite directions;
 *   3. every shared side is locally Delaunay under the tie rule: the far
 *      corner of either triangle is outside the other's circle
 *      (pdt_incircle_sos < 0);
 *   4. the unshared sides (the boundary) meet one in, one out at each of
 *      their points, turn left or go straight at every one, and together
 *      turn round exactly once;
 *   5. Euler's formula for a triangulated disc, corners = (triangles +
 *      boundary sides + 2) / 2, gives the number of distinct points, and
 *      every corner is a distinct point (the caller checks it).
 * By 2 and 4 the triangles cover a convex polygon exactly once (the sum of
 * their boundaries winds once round every point inside it, so no point is
 * covered twice); by 5 every distinct point is a corner, so the polygon is
 * the convex hull; by 3 their lifted surface is locally convex over it,
 * hence convex, hence the lower hull of the perturbed lift: T* (docs/
 * trace-format.md, "T* in bounded memory").
 *
 * The sides and the boundary are sorted on disk (xsort.h), so memory is the
 * budget whatever the number of triangles; the corners' coordinates are
 * read from the run's points, whose resident pages are given back as the
 * check goes. */
#ifndef PDT_CERTIFY_H
#define PDT_CERTIFY_H

#include <stdint.h>

#include "pdt/tracefile.h"

typedef struct pdt_cert pdt_cert;

/* A new certificate over the run's points, within about `budget` bytes, or
 * NULL (no memory). */
pdt_cert *pdt_cert_new(const pdt_run *run, uint64_t budget);

/* One triangle (counter-clockwise corners, any rotation): PDT_OK, or
 * PDT_ERR_NOMEM / PDT_ERR_IO (the temporary file named) in err. */
pdt_status pdt_cert_add(pdt_cert *c, const uint32_t v[3], pdt_err *err);

/* After the last triangle: PDT_OK when the triangles are T* of points with
 * `nu` distinct points; PDT_ERR_CHECK naming the first condition violated;
 * PDT_ERR_IO or PDT_ERR_NOMEM.  With no triangles at all it only says so
 * (PDT_OK): whether T* is empty is the caller's to decide. */
pdt_status pdt_cert_finish(pdt_cert *c, uint64_t nu, pdt_err *err);

/* Sorted runs written to disk so far. */
uint64_t pdt_cert_runs(const pdt_cert *c);

void pdt_cert_free(pdt_cert *c);

#endif
