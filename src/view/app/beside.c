/* pdt — two runs side by side in one window (pdtview RUN --beside RUN2):
 * the plain run and a parallel run of the same points, stepping together
 * phase by phase (beside.h).
 *
 * The window's keys move the first run (left); the second (right) follows
 * by phase: when the first is at a phase stop (pdt_replay_phase_stops: where
 * every rank has begun the phase), the second is at its stop of the phase
 * of the same name; between two stops it goes the same share of the way
 * between its own.  A phase one run has and the other has not ("read",
 * "classify", "merge" of the parallel run; "output" of the plain one) holds
 * the other where it is: PgDn moves both to the same phase. */
#include "beside.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_STOPS 256

struct pdt_beside {
    const pdt_replay *r;
    pdt_rstate *s;
    pdt_phase_stop a[MAX_STOPS], b[MAX_STOPS];
    size_t na, nb;
    const pdt_replay *ra; /* the replay a[] belongs to */
    int64_t sel_point, sel_tri; /* the right run's selection (a click on its half) */
    int sel_edge;
};

pdt_beside *pdt_beside_new(const pdt_replay *r2, pdt_rstate *s2)
{
    pdt_beside *B = calloc(1, sizeof *B);
    if (!B) return NULL;
    B->r = r2;
    B->s = s2;
    B->sel_point = B->sel_tri = -1;
    B->sel_edge = -1;
    B->nb = pdt_replay_phase_stops(r2, B->b, MAX_STOPS);
    if (B->nb > MAX_STOPS) B->nb = MAX_STOPS;
    return B;
}

void pdt_beside_free(pdt_beside *B) { free(B); }

/* The second run's stop of the phase of first-run stop i, or -1. */
static long match(const pdt_beside *B, size_t i)
{
    const char *na = pdt_phase_name((int)B->a[i].phase);
    for (size_t j = 0; na && j < B->nb; j++) {
        const char *nb = pdt_phase_name((int)B->b[j].phase);
        if (nb && !strcmp(na, nb) && B->a[i].sub == B->b[j].sub) return (long)j;
    }
    return -1;
}

/* Where the second run is when the first is at stop i: its matching stop,
 * else that of the latest earlier stop that matches, else 0. */
static size_t place(const pdt_beside *B, long i)
{
    for (; i >= 0; i--) {
        long j = match(B, (size_t)i);
        if (j >= 0) return B->b[j].k;
    }
    return 0;
}

/* The second run's cursor for the first run's cursor k. */
static size_t follow(const pdt_beside *B, size_t k, size_t ma)
{
    size_t mb = pdt_replay_count(B->r);
    if (k >= ma) return mb;
    long i = -1;
    while ((size_t)(i + 1) < B->na && B->a[i + 1].k <= k) i++;
    size_t from_a = i >= 0 ? B->a[i].k : 0, to_a = (size_t)(i + 1) < B->na ? B->a[i + 1].k : ma;
    size_t from_b = place(B, i), to_b = (size_t)(i + 1) < B->na ? place(B, i + 1) : mb;
    if (to_b < from_b || to_a <= from_a) return from_b;
    double f = (double)(k - from_a) / (double)(to_a - from_a);
    return from_b + (size_t)floor(f * (double)(to_b - from_b));
}

/* The stops of r (into st, at most MAX_STOPS). */
static size_t stops_of(const pdt_replay *r, pdt_phase_stop *st)
{
    size_t n = pdt_replay_phase_stops(r, st, MAX_STOPS);
    return n > MAX_STOPS ? MAX_STOPS : n;
}

int pdt_beside_click(pdt_beside *B, const pdt_replay *ra, const pdt_rstate *sa, pdt_view *v,
                     double w, double h, double x, double y, size_t *seek)
{
    double hw = floor(w / 2);
    int side = x >= hw;
    const pdt_replay *r = side ? B->r : ra;
    double lx = side ? x - hw : x;
    size_t k = pdt_render_timeline_at(r, v, hw, h, lx, y);
    if (k != (size_t)-1) {
        if (!side) {
            *seek = k;
            return 1;
        }
        /* the right run's phase at k: the first run goes to that phase */
        if (B->ra != ra) B->ra = ra, B->na = stops_of(ra, B->a);
        long j = -1;
        for (size_t i = 0; i < B->nb && B->b[i].k <= k; i++) j = (long)i;
        *seek = 0;
        for (size_t i = 0; j >= 0 && i < B->na; i++)
            if (match(B, i) == j) {
                *seek = B->a[i].k;
                break;
            }
        return 1;
    }
    pdt_layout L;
    pdt_render_layout_view(hw, h, pdt_replay_nranks(r), v, &L);
    if (L.covered || lx < L.geo.x || lx > L.geo.x + L.geo.w || y < L.geo.y || y > L.geo.y + L.geo.h)
        return 0;
    if (side)
        pdt_render_pick(B->r, B->s, v, hw, h, lx, y, 0.8 * L.font, &B->sel_point, &B->sel_tri,
                        &B->sel_edge);
    else
        pdt_render_pick(ra, sa, v, hw, h, lx, y, 0.8 * L.font, &v->sel_point, &v->sel_tri,
                        &v->sel_edge);
    return 0;
}

void pdt_beside_draw(pdt_beside *B, cairo_t *cr, double w, double h, const pdt_replay *ra,
                     const pdt_rstate *sa, const pdt_view *v)
{
    if (B->ra != ra) {
        B->ra = ra;
        B->na = pdt_replay_phase_stops(ra, B->a, MAX_STOPS);
        if (B->na > MAX_STOPS) B->na = MAX_STOPS;
    }
    size_t kb = follow(B, sa->k, pdt_replay_count(ra));
    if (kb != B->s->k) pdt_replay_seek(B->r, B->s, kb);
    double hw = floor(w / 2);
    pdt_err err = {0};
    for (int side = 0; side < 2; side++) {
        pdt_view vv = *v;
        if (side) { /* the hidden ranks belong to the first run; the right has its own
                     * selection */
            vv.hidden = NULL;
            vv.sel_point = B->sel_point;
            vv.sel_tri = B->sel_tri;
            vv.sel_edge = B->sel_edge;
        }
        cairo_save(cr);
        cairo_rectangle(cr, side * hw, 0, hw, h);
        cairo_clip(cr);
        cairo_translate(cr, side * hw, 0);
        pdt_render(cr, hw, h, side ? B->r : ra, side ? B->s : sa, &vv, &err);
        cairo_restore(cr);
    }
    cairo_set_source_rgb(cr, 0.3, 0.3, 0.35);
    cairo_set_line_width(cr, 2);
    cairo_move_to(cr, hw, 0);
    cairo_line_to(cr, hw, h);
    cairo_stroke(cr);
}
