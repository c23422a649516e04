/* pdt — the viewer's keys and mouse for runs of many ranks (private to
 * pdtview): groups hidden and stepped through, the timeline zoomed,
 * scrolled and opened, the merge-tree panel clicked, the view following
 * the story while playing.  The shell calls these first; each says whether
 * it took the input. */
#ifndef PDT_VIEW_APP_CLUSTER_H
#define PDT_VIEW_APP_CLUSTER_H

#include <SDL.h>

#include "pdt/view/render.h"

typedef struct pdt_cluster pdt_cluster;

/* The rank tree of r and the timeline's open groups, put in v (v->tree,
 * v->tl_open).  NULL when out of memory (the renderer then makes a tree per
 * frame). */
pdt_cluster *pdt_cluster_new(const pdt_replay *r, pdt_view *v);
void pdt_cluster_free(pdt_cluster *cl, pdt_view *v);
/* Keep *cl made for r: when it was made for another replay (a hook's
 * replay changed) or is NULL, a new one (the old one freed). */
void pdt_cluster_take(pdt_cluster **cl, const pdt_replay *r, pdt_view *v);

/* A key: [ ] zoom the timeline's events out / in, Shift+[ ] scroll its rows,
 * u opens (or closes) the current event's group in the timeline, w turns
 * following on or off; beyond eight ranks also the digits (hide or show a
 * legend's group) and Ctrl+arrows (the next event of the current group).
 * hidden: the shell's per-rank flags.  1 if taken; *seek_to: the cursor to
 * go to, or SIZE_MAX. */
int pdt_cluster_key(pdt_cluster *cl, const pdt_replay *r, const pdt_rstate *s, pdt_view *v,
                    SDL_Keycode k, int shift, int ctrl, double w, double h, uint8_t *hidden,
                    size_t *seek_to);

/* A mouse event at drawable scale (sx, sy): the wheel over the timeline
 * zooms it (with Shift: scrolls its rows), a drag in it pans, a click on a
 * row's label opens or closes it, a click in the timeline seeks, a click
 * on the tree's step seeks to it.  1 if taken; *seek_to as above. */
int pdt_cluster_mouse(pdt_cluster *cl, const pdt_replay *r, pdt_view *v, const SDL_Event *e,
                      double sx, double sy, double w, double h, size_t *seek_to);

#endif
