/* pdt — certify that a stack of point indices is exactly what Graham's scan
 * (pdt_hull_graham, include/pdt/hull.h) writes for a set of points, in one
 * pass over the points and no memory beyond the stack (private to
 * src/trace; used by pdt trace check when recomputing the hull would not
 * fit its memory budget).
 *
 * pdt_hull_graham writes the extreme points counter-clockwise from the
 * origin o, the rightmost lowest point; of coincident points it writes the
 * first copy of o and the last copy of every other corner.  Instead of
 * recomputing that and comparing, the stack S[0..h) is checked against
 * conditions only that output meets:
 *   1. S[0] is o: no point is lower, or as low and further right, and no
 *      earlier point coincides with it;
 *   2. no S[k] (k > 0) coincides with S[0], and for h >= 3 the angles of
 *      S[1], ..., S[h-1] around S[0] strictly increase (each consecutive
 *      pair turns left at S[0]) and every cyclically consecutive triple of
 *      S turns strictly left;
 *   3. every point lies in the closed polygon S: its point for h = 1, the
 *      segment S[0] S[1] for h = 2, and for h >= 3 the fan triangle
 *      S[0] S[k] S[k+1] of its angular wedge, found by binary search;
 *   4. a point that coincides with a corner S[k] (k > 0) is that corner or
 *      an earlier copy of it.
 * By 1 all points lie in the closed upper half-plane of S[0] with the ray
 * to its left, so increasing angles never wrap round: by 2, S is a simple
 * polygon turning strictly left at every corner, strictly convex.  By 3 it
 * holds every point, and its corners are points, so it is their convex
 * hull and its corners are the extreme points; in counter-clockwise order
 * from o.  1 and 4 pick the copies Graham's scan writes.  For h <= 2 the
 * points are all at o (h = 1) or all on a segment from o (h = 2), which
 * is when Graham's scan writes 1 or 2 points (docs/trace-format.md, "The
 * hull in bounded memory"). */
#ifndef PDT_HULLCERT_H
#define PDT_HULLCERT_H

#include <stddef.h>
#include <stdint.h>

#include "pdt/common.h"

/* PDT_OK when s[0..h) is what pdt_hull_graham(pts, n) writes; else
 * PDT_ERR_CHECK with what fails in err, a phrase about the stack ("pt 17
 * (3, 5) lies outside it", "no strict left turn at position 4 (pts 9 12
 * 15)") for the caller to put after its own words.  Requires s[k] < n for
 * every k.  Memory: none beyond the arguments.  `release` (may be NULL)
 * is called with `ctx` every 2^16 points read in the pass over them: the
 * caller may give back the resident pages of pts and s there. */
pdt_status pdt_hull_certify(const pdt_point *pts, size_t n, const uint32_t *s, size_t h,
                            void (*release)(void *ctx), void *ctx, pdt_err *err);

#endif
