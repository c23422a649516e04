/* pdt — questions the viewer asks about a replay state (no pixels): what a
 * stack holds, whether a hull or stack is still the current one, which line
 * of the pseudo-code the current event belongs to, how many points lie inside
 * a circle.  The renderer draws their answers; tests and tools (lesson
 * checks) can ask them without cairo.  See pdt/view/replay.h for states. */
#ifndef PDT_QUERY_H
#define PDT_QUERY_H

#include "pdt/view/replay.h"

/* The points of the stack whose top node is `top` (-1: empty), bottom to
 * top, into out[0 .. cap); returns how many were written (at most cap; the
 * bottom ones are kept when the stack is deeper than cap). */
size_t pdt_replay_stack_list(const pdt_replay *r, int32_t top, uint32_t *out, size_t cap);

/* 1 if hull h (an index into pdt_replay_hulls) reported by rank q is still
 * the hull of q's group in state s: no merge covering q that began after it
 * has reported its own hull yet. */
int pdt_replay_hull_live(const pdt_replay *r, const pdt_rstate *s, int q, int32_t h);

/* 1 if rank q's last Graham scan begun before the cursor of s has ended.
 * Graham's Version B reports no HULL event: once the scan is over, its stack
 * is the hull. */
int pdt_replay_graham_scan_ended(const pdt_replay *r, const pdt_rstate *s, int q);

/* 1 if the stack whose top node is `top` (>= 0) is still being built in s:
 * not yet reported as a hull. */
int pdt_replay_stack_open(const pdt_replay *r, const pdt_rstate *s, int32_t top);

/* Input points strictly inside the circumcircle of triangle v (either
 * orientation), by the exact pdt_incircle0 (no tie rule: points on the
 * circle are not counted), lifted or not.  0 if v is degenerate or names a
 * point out of range.  Costs one in-circle test per input point. */
size_t pdt_replay_inside_count(const pdt_replay *r, const uint32_t v[3]);

/* The pseudo-code line (0-based, pdt_code_text of pdt/view/describe.h) of the
 * current event of s (event k-1), and in *id the listing it belongs to
 * (PDT_CODE_GRAHAM or PDT_CODE_SRM); -1 when no line applies (cursor 0, or
 * an event outside both listings). */
int pdt_replay_code_line(const pdt_replay *r, const pdt_rstate *s, int *id);

/* Cursor just after the next (dir > 0: events k, k+1, ...) or previous
 * (dir < 0: events before the current one, k-2, k-3, ...) event of `rank`;
 * k when there is none. */
size_t pdt_replay_find_rank(const pdt_replay *r, size_t k, int dir, int rank);

/* Cursor just after the event of `rank` nearest to event k-1 (ties: the
 * later one); (size_t)-1 when the rank has no event. */
size_t pdt_replay_nearest_of_rank(const pdt_replay *r, size_t k, int rank);

/* One edge of the Voronoi diagram: dual of the Delaunay edge a-b.  A
 * segment between the circumcentres of the two final triangles on a-b, or,
 * for a hull edge (one final triangle), a ray from (x0,y0) in the unit
 * direction (x1,y1) pointing away from the triangle. */
typedef struct pdt_vseg {
    double x0, y0, x1, y1;
    int ray;
    uint32_t a, b;
} pdt_vseg;

/* The Voronoi diagram of the final triangles of state s (ranks with
 * hidden[rank] set left out; hidden may be NULL): one element per distinct
 * edge of those triangles, so for a triangulation of n points with T
 * triangles there are n + T - 1 (Euler).  Circumcentres in double precision
 * (drawing only).  *out is malloc'd (free it); PDT_ERR_NOMEM otherwise. */
pdt_status pdt_replay_voronoi(const pdt_replay *r, const pdt_rstate *s, const uint8_t *hidden,
                              pdt_vseg **out, size_t *nout, pdt_err *err);

#endif
