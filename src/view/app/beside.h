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

#endif
