/* pdt — exact geometric predicates on int32 points, and the lift-up.
 *
 * All predicates are exact over the whole int32 range and return a sign
 * (-1, 0, +1).  See docs/algorithm.md §2.2 for the bit budget:
 * orient needs 65 bits (int128), incircle 133 bits (wider than int128), so
 * incircle has a fast path (floating-point filter / int128 when coordinate
 * differences are small) and an exact multi-limb fallback. */
#ifndef PDT_PREDICATES_H
#define PDT_PREDICATES_H

#include "pdt/common.h"

/* Sign of (b-a) x (c-a): +1 if a, b, c turn left (counter-clockwise),
 * -1 if they turn right, 0 if collinear. */
int pdt_orient(pdt_point a, pdt_point b, pdt_point c);

/* Sign of the in-circle determinant without tie-breaking.  For a, b, c
 * counter-clockwise: +1 if d is strictly inside their circle, -1 strictly
 * outside, 0 on it.  It is the orientation of the LIFTED points
 * a*, b*, c*, d* (p* = (x, y, x^2 + y^2)): +1 means d* lies strictly below the
 * plane through a*, b*, c*. */
int pdt_incircle0(pdt_point a, pdt_point b, pdt_point c, pdt_point d);

/* In-circle with simulation of simplicity on the lifted heights
 * (docs/algorithm.md §2.3): if pdt_incircle0 is 0, the answer is the sign of the
 * cofactor of the lexicographically smallest of the four points.  Never 0
 * unless all four points are collinear.  The four points must be distinct.
 * This is the only in-circle test any triangulation code may use. */
int pdt_incircle_sos(pdt_point a, pdt_point b, pdt_point c, pdt_point d);

/* The lift-up of Theorem 1.1: p -> (x, y, x^2 + y^2).  z is exact (< 2^63). */
typedef struct pdt_lifted {
    int32_t x, y;
    uint64_t z;
} pdt_lifted;

pdt_lifted pdt_lift(pdt_point p);

#endif
