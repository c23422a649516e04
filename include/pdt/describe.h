/* pdt — what the viewer says, in words: the event line and the pseudo-code.
 *
 * The window, the headless renderer and `pdtview --describe` (the lesson
 * checks) all print these texts, so a lesson that quotes them quotes what the
 * screen shows.  No pixels here: the renderer draws the strings. */
#ifndef PDT_DESCRIBE_H
#define PDT_DESCRIBE_H

#include "pdt/replay.h"

/* The event before cursor k, in words ("rank 2: pop 17 — right turn at
 * (12,40)").  Writes at most `cap` bytes (always terminated). */
void pdt_replay_describe(const pdt_replay *r, size_t k, char *buf, size_t cap);

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
