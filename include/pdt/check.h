/* pdt — the independent checker and the brute-force oracle.
 *
 * Shares no code path with the kernel or with predicates.c: it carries its
 * own exact arithmetic, so a bug in one cannot hide a bug in the other. */
#ifndef PDT_CHECK_H
#define PDT_CHECK_H

#include "pdt/common.h"

/* Verify that tris (0-based input indices, any order, any rotation) is
 * exactly T*(pts): duplicates are expected to be represented by their
 * smallest input index and never used otherwise; every triangle CCW; the
 * triangles tile the convex hull exactly (each interior edge shared by two
 * triangles of opposite sides, boundary edges = the hull with its collinear
 * points); every interior edge locally Delaunay under the tie rule; Euler
 * count 2n - h - 2 (thesis D5).  Returns PDT_OK, or PDT_ERR_CHECK with the
 * first violation described in err. */
pdt_status pdt_check_delaunay(const pdt_point *pts, size_t n, const pdt_tri *tris, size_t ntri,
                              pdt_err *err);

/* Brute-force lift-up oracle in the spirit of O'Rourke's dt4: every triple
 * whose lifted plane has all other lifted points above it (with the tie
 * rule).  O(n^4); for n <= ~80.  Same output conventions as pdt_triangulate
 * (canonical order, input indices, duplicates -> smallest index). */
pdt_status pdt_brute_delaunay(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri);

#endif
