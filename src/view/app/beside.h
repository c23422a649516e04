/* pdt — two runs side by side in one window (beside.c): pdtview RUN
 * --beside RUN2 shows RUN on the left and RUN2 on the right, RUN2 following
 * RUN phase by phase (the plain run and a parallel run of the same points). */
#ifndef PDT_VIEW_BESIDE_H
#define PDT_VIEW_BESIDE_H

#include <cairo.h>

#include "pdt/view/render.h"
#include "pdt/view/replay.h"

typedef struct pdt_beside pdt_beside;

/* The second run's replay and state (the caller's; they outlive it).  NULL
 * when out of memory. */
pdt_beside *pdt_beside_new(const pdt_replay *r2, pdt_rstate *s2);
void pdt_beside_free(pdt_beside *B);
/* Move the second run to follow the first (ra at sa) and draw both, each in
 * half of the w x h picture, with the view v. */
void pdt_beside_draw(pdt_beside *B, cairo_t *cr, double w, double h, const pdt_replay *ra,
                     const pdt_rstate *sa, const pdt_view *v);

/* A left-button click at (x, y) of the w x h window, routed to the half it
 * falls in, laid out as that half is drawn: a click on a timeline seeks
 * (the right run's timeline: the first run goes to the phase stop of the
 * same name at or before the event clicked), a click on a picture selects a
 * point, edge or triangle of that half's run (the right run's selection is
 * its own).  Returns 1 and sets *seek (the first run's new cursor) when the
 * cursor moves, 0 when it does not. */
int pdt_beside_click(pdt_beside *B, const pdt_replay *ra, const pdt_rstate *sa, pdt_view *v,
                     double w, double h, double x, double y, size_t *seek);

#endif
