/* pdt — what the viewer says, in words: the event line and the pseudo-code.
 *
 * The window, the headless renderer and `pdtview --describe` (the lesson
 * checks) all print these texts, so a lesson that quotes them quotes what the
 * screen shows.  No pixels here: the renderer draws the strings. */
#ifndef PDT_DESCRIBE_H
#define PDT_DESCRIBE_H

#include "pdt/view/replay.h"

/* The event before cursor s->k, in words, as the window's event line shows
 * it ("rank 0: pop p4 (point 2) — Area2(p3, p4, p5) = -24: right turn").
 * Points are named by their input index ("point 7 (0,4)"), in Graham's scan
 * also by their place in the angular order ("p4 (point 2)"); triangles in
 * one corner order (pdt_replay_tri_order).  Writes at most `cap` bytes (always
 * terminated).  s may be NULL: then the cursor is k, and the parts that need
 * the state (the point below a popped one, the phase) are left out. */
void pdt_replay_describe_state(const pdt_replay *r, const pdt_rstate *s, size_t k, char *buf,
                               size_t cap);
/* The same for cursor k, with a state of its own (allocated and sought:
 * costs a seek; use pdt_replay_describe_state when a state is at hand). */
void pdt_replay_describe(const pdt_replay *r, size_t k, char *buf, size_t cap);

/* The one corner order every text prints a triangle in: counter-clockwise,
 * starting at the smallest index ("9 30 28").  in and out may not overlap. */
void pdt_replay_tri_order(const pdt_replay *r, const uint32_t in[3], uint32_t out[3]);

/* The label of point p in the picture in state s: its input index ("2"), in
 * Graham's scan once sorted also its place in the angular order ("2=p4"). */
void pdt_point_label(const pdt_replay *r, const pdt_rstate *s, size_t p, char *buf, size_t cap);

/* 1 if the closed circumdisk of triangle v touches the strip box of `rank`
 * (pdt_replay_box), in double precision with a relative slack of 1e-9: the
 * boxes the picture outlines as touched, and the ranks a deferral's event
 * line names.  0 for a degenerate triangle or a rank without a box. */
int pdt_replay_disk_touches(const pdt_replay *r, const uint32_t v[3], int rank);

/* The pseudo-code listings of the code panel. */
typedef enum pdt_code_id {
    PDT_CODE_GRAHAM = 0, /* Graham's scan, Version B (pdt hull) */
    PDT_CODE_SRM,        /* the SRM algorithm, per rank (pdt triangulate) */
    PDT_CODE_COUNT
} pdt_code_id;

/* Title of listing `id` ("Graham's scan, Version B"); NULL for a bad id. */
const char *pdt_code_title(int id);
/* Number of lines of listing `id` (0 for a bad id). */
size_t pdt_code_count(int id);
/* Line `i` (0-based) of listing `id`, as the panel prints it, its number
 * first ("4  S := (p0, p1)"); NULL when out of range. */
const char *pdt_code_text(int id, size_t i);

#endif
