/* pdt — a lecturer's tools over the replay window (lecture.c):
 *
 *  - bookmarks: a lesson's key moments (pdtview --bookmarks FILE, lines
 *    "K<TAB>TITLE<TAB>TEXT"; scripts/lesson.sh writes them from the
 *    lesson's checks), b / Shift+b go to the next / previous one;
 *  - the notes pane (--panels notes, key n): the bookmarks, and the text of
 *    the lesson's step for the moment shown;
 *  - a pointer (p: a ring follows the mouse) and a pen (d: drag draws over
 *    the picture; e erases);
 *  - every key's effect said on screen, in a line at the top of the picture.
 *
 * A shell hook (shell.h): it takes its own keys and lets the others through. */
#ifndef PDT_VIEW_LECTURE_H
#define PDT_VIEW_LECTURE_H

#include "pdt/view/render.h"
#include "pdt/view/replay.h"
#include "shell.h"

typedef struct pdt_lecture pdt_lecture;

/* The tools over replay r shown at state s (both the caller's, outliving
 * the tools); bookmarks: a file, or NULL for none.  Fails when the file
 * cannot be read or a line is not "K<TAB>TITLE<TAB>TEXT" with K <= the
 * run's events (err names file:line). */
pdt_status pdt_lecture_new(const pdt_replay *r, pdt_rstate *s, const char *bookmarks,
                           pdt_lecture **out, pdt_err *err);
void pdt_lecture_free(pdt_lecture *L);
/* Draw a second run beside the first, following it phase by phase
 * (beside.h); r2 and s2 are the caller's. */
pdt_status pdt_lecture_beside(pdt_lecture *L, const pdt_replay *r2, pdt_rstate *s2, pdt_err *err);
/* The shell hook; valid while L is. */
const pdt_shell_hook *pdt_lecture_hook(pdt_lecture *L);
/* The hook's overlay (the notes pane, the pen, the pointer, the key line). */
void pdt_lecture_overlay(void *user, cairo_t *cr, double w, double h, const pdt_view *v);

#endif
