/* pdt — moving the timeline's window (zoom and scroll in time and in rows)
 * and the view that follows the story: the current event's points kept in
 * the picture, its event and its rank's row in the timeline. */
#include "render_int.h"

void pdt_view_timeline_zoom(const pdt_replay *r, pdt_view *v, double w, double h, double x, double f)
{
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(r), v, &L);
    tl_geom g;
    pdt_timeline_geom(L.timeline, L.font, pdt_replay_nranks(r), 1, 1, v, &g);
    double u = (x - g.x0) / (g.x1 - g.x0); /* where x is in the window */
    u = u < 0 ? 0 : u > 1 ? 1 : u;
    double t0 = v->tl_t0, t1 = v->tl_t1;
    if (!(t0 >= 0 && t1 <= 1 && t1 > t0)) t0 = 0, t1 = 1;
    double at = t0 + u * (t1 - t0), span = (t1 - t0) / f;
    size_t m = pdt_replay_count(r);
    double least = m ? 8.0 / (double)m : 1; /* at most 8 events across */
    if (span < least) span = least;
    if (span > 1) span = 1;
    t0 = at - u * span;
    if (t0 < 0) t0 = 0;
    if (t0 + span > 1) t0 = 1 - span;
    v->tl_t0 = t0;
    v->tl_t1 = t0 + span;
}

void pdt_view_timeline_pan(const pdt_replay *r, pdt_view *v, double w, double h, double dx, int drow)
{
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(r), v, &L);
    tl_geom g;
    pdt_timeline_geom(L.timeline, L.font, pdt_replay_nranks(r), 1, 1, v, &g);
    double t0 = v->tl_t0, t1 = v->tl_t1;
    if (!(t0 >= 0 && t1 <= 1 && t1 > t0)) t0 = 0, t1 = 1;
    double d = -dx / (g.x1 - g.x0) * (t1 - t0);
    if (t0 + d < 0) d = -t0;
    if (t1 + d > 1) d = 1 - t1;
    v->tl_t0 = t0 + d;
    v->tl_t1 = t1 + d;
    int nshow, n = pdt_render_timeline_rows(r, v, w, h, &nshow);
    int r0 = v->tl_row0 + drow;
    if (r0 > n - nshow) r0 = n - nshow;
    v->tl_row0 = r0 < 0 ? 0 : r0;
}

/* The timeline: the cursor inside the window's middle 90 %, the current
 * rank's row among the rows shown. */
static int follow_timeline(const pdt_replay *r, const pdt_rstate *s, pdt_view *v, double w, double h)
{
    size_t m = pdt_replay_count(r);
    int changed = 0;
    double t0 = v->tl_t0, t1 = v->tl_t1, u = m ? (double)s->k / (double)m : 0;
    if (t0 >= 0 && t1 <= 1 && t1 > t0 && (u < t0 + 0.05 * (t1 - t0) || u > t1 - 0.05 * (t1 - t0))) {
        double span = t1 - t0;
        t0 = u - 0.5 * span;
        t0 = t0 < 0 ? 0 : t0 + span > 1 ? 1 - span : t0;
        v->tl_t0 = t0;
        v->tl_t1 = t0 + span;
        changed = 1;
    }
    if (!s->k) return changed;
    int nshow, n = pdt_render_timeline_rows(r, v, w, h, &nshow);
    if (n <= nshow) return changed;
    pdt_ranktree *own = NULL;
    const pdt_ranktree *t = v && v->tree ? v->tree : (own = pdt_ranktree_new(r));
    int32_t *rows = NULL;
    size_t nr = t ? pdt_timeline_rows(t, v, &rows) : 0, nn;
    uint32_t q = pdt_replay_rank_of(r, s->k - 1);
    for (size_t i = 0; i < nr; i++) {
        const pdt_rtnode *d = &pdt_ranktree_nodes(t, &nn)[rows[i]];
        if (q < d->lo || q >= d->hi) continue;
        if ((int)i < v->tl_row0 || (int)i >= v->tl_row0 + nshow) {
            v->tl_row0 = (int)i - nshow / 2 < 0 ? 0 : (int)i - nshow / 2;
            changed = 1;
        }
        break;
    }
    free(rows);
    pdt_ranktree_free(own);
    return changed;
}

/* The picture: when the current event's point leaves the picture (its
 * middle 80 %), centre it. */
static int follow_picture(const pdt_replay *r, const pdt_rstate *s, pdt_view *v, double w, double h)
{
    if (!s->k) return 0;
    pdt_rec e = *pdt_replay_rec(r, s->k - 1);
    size_t np;
    const pdt_point *P = pdt_replay_points(r, &np);
    uint32_t p = e.ev.a;
    if (e.ev.kind == PDT_EV_MERGE_BEGIN || e.ev.kind == PDT_EV_MERGE_END || e.ev.kind == PDT_EV_SEND ||
        e.ev.kind == PDT_EV_RECV || e.ev.kind == PDT_EV_PHASE_BEGIN || e.ev.kind == PDT_EV_PHASE_END ||
        e.ev.kind == PDT_EV_HULL)
        return 0;
    if (p >= np) return 0;
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(r), v, &L);
    double sx, sy;
    pdt_view_to_screen(r, v, w, h, P[p].x, P[p].y, &sx, &sy);
    if (sx >= L.geo.x + 0.1 * L.geo.w && sx <= L.geo.x + 0.9 * L.geo.w && sy >= L.geo.y + 0.1 * L.geo.h &&
        sy <= L.geo.y + 0.9 * L.geo.h)
        return 0;
    v->cx = P[p].x;
    v->cy = P[p].y;
    v->centred = 1;
    return 1;
}

int pdt_view_follow(const pdt_replay *r, const pdt_rstate *s, pdt_view *v, double w, double h)
{
    if (!v->follow) return 0;
    int a = follow_picture(r, s, v, w, h);
    int b = follow_timeline(r, s, v, w, h);
    return a || b;
}
