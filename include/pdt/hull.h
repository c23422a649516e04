/* pdt — planar convex hulls: Graham's scan (thesis Chapter 2, Version B) and
 * the monotone chain the triangulation needs.  Both run on one traced stack
 * abstraction, so that every push and pop can be observed. */
#ifndef PDT_HULL_H
#define PDT_HULL_H

#include "pdt/common.h"
#include "pdt/trace.h"

/* A stack of point indices.  Every push and pop is reported to `tr`
 * (PDT_EV_PUSH / PDT_EV_POP with stack id `id`). */
typedef struct pdt_stack {
    uint32_t *item;
    size_t n, cap;
    int id;          /* pdt_stack_id */
    pdt_trace *tr;   /* may be NULL */
} pdt_stack;

pdt_status pdt_stack_init(pdt_stack *s, size_t cap, int id, pdt_trace *tr);
void pdt_stack_free(pdt_stack *s);
/* Push i (grows as needed). */
pdt_status pdt_stack_push(pdt_stack *s, uint32_t i);
/* Pop and return the top; `cause` is the point that made the pop happen
 * (reported in the trace), or UINT32_MAX.  Requires s->n > 0. */
uint32_t pdt_stack_pop(pdt_stack *s, uint32_t cause);

/* Graham's scan, Version B, exactly as the thesis describes: the rightmost
 * lowest point is the origin; the other points are sorted by angle around it
 * with the integer area test; on an angular tie only the farther point is
 * kept; of coincident points one copy is kept; a point is pushed only on a
 * strict left turn.  Writes the indices of the extreme points only,
 * counter-clockwise starting at the origin, to out[0..*nout) (out must hold n
 * entries).  n may be 0; duplicates and collinear input are allowed.
 * Traces SORT, DELETE, PUSH, POP and the two Graham phases. */
pdt_status pdt_hull_graham(const pdt_point *pts, size_t n, uint32_t *out, size_t *nout,
                           pdt_trace *tr);

/* Monotone chain (Andrew; Graham's scan with the origin at infinity) over
 * points that are distinct and sorted lexicographically.  Collinear boundary
 * points are KEPT (pop only on a strict right turn).  Writes the hull
 * counter-clockwise starting at pts[0] (the lexicographically smallest) to
 * out (must hold n + 1 entries).  If n <= 2 or all points are collinear,
 * *degenerate is set to 1 and out holds all points in order.  Stacks are
 * traced as `lower_id` / `upper_id` (e.g. PDT_STACK_LOWER/UPPER). */
pdt_status pdt_hull_chain(const pdt_point *pts, size_t n, uint32_t *out, size_t *nout,
                          int *degenerate, int lower_id, int upper_id, pdt_trace *tr);

#endif
