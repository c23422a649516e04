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

/* ---- following the story ---- */

/* What the current event belongs to: the merge phase it is in (index into
 * pdt_replay_phases, or -1), and whether it is phase-wide (a phase, merge,
 * message or hull event) and then whether it begins or ends a top-level
 * phase (one right under the rank's "run"). */
typedef struct story {
    pdt_rec e;
    int32_t merge_ph;   /* the enclosing merge phase, or -1 */
    int wide, top;
} story;

static int is_top(const pdt_rphase *P, int32_t i)
{
    return i < 0 || P[i].phase == PDT_PH_RUN || P[i].parent < 0 || P[P[i].parent].phase == PDT_PH_RUN;
}

static void story_of(const pdt_replay *r, const pdt_rstate *s, story *st)
{
    size_t np;
    const pdt_rphase *P = pdt_replay_phases(r, &np);
    st->e = *pdt_replay_rec(r, s->k - 1);
    int kd = st->e.ev.kind;
    st->wide = kd == PDT_EV_MERGE_BEGIN || kd == PDT_EV_MERGE_END || kd == PDT_EV_SEND || kd == PDT_EV_RECV ||
               kd == PDT_EV_PHASE_BEGIN || kd == PDT_EV_PHASE_END || kd == PDT_EV_HULL;
    int32_t ph = pdt_rstate_slot(r, s, (int)st->e.rank, PDT_SLOT_PHASE);
    /* PHASE_BEGIN: the phase begun is the slot; PHASE_END: the slot is its
     * parent.  The end of one rank's merge phase is not top-level: other
     * ranks' merges of that level go on (the next phase's begin backs out). */
    st->top = (kd == PDT_EV_PHASE_BEGIN && is_top(P, ph)) ||
              (kd == PDT_EV_PHASE_END && st->e.ev.sub != PDT_PH_MERGE && (ph < 0 || P[ph].phase == PDT_PH_RUN));
    st->merge_ph = -1;
    for (int32_t i = ph; i >= 0 && (size_t)i < np; i = P[i].parent)
        if (P[i].phase == PDT_PH_MERGE) {
            st->merge_ph = i;
            break;
        }
}

/* The picture's pixels per world unit at view v. */
static double px_per_unit(const pdt_replay *r, const pdt_view *v, double w, double h)
{
    double ax, ay, bx, by;
    pdt_view_to_screen(r, v, w, h, 0, 0, &ax, &ay);
    pdt_view_to_screen(r, v, w, h, 1e6, 0, &bx, &by);
    return hypot(bx - ax, by - ay) / 1e6;
}

/* The box of the merge step that merge phase ph of its rank belongs to (the
 * strip boxes of the ranks it joins); 0 when unknown. */
static int merge_box(const pdt_replay *r, const pdt_rphase *ph, pdt_point *lo, pdt_point *hi)
{
    size_t nm;
    const pdt_rmerge *M = pdt_replay_merges(r, &nm);
    for (size_t i = 0; i < nm; i++) {
        if (M[i].level != ph->sub || ph->rank < M[i].gl || ph->rank >= M[i].gend) continue;
        int any = 0;
        for (uint32_t q = M[i].gl; q < M[i].gend; q++) {
            pdt_point a, b;
            if (!pdt_replay_box(r, (int)q, &a, &b)) continue;
            if (!any || a.x < lo->x) lo->x = a.x;
            if (!any || a.y < lo->y) lo->y = a.y;
            if (!any || b.x > hi->x) hi->x = b.x;
            if (!any || b.y > hi->y) hi->y = b.y;
            any = 1;
        }
        return any;
    }
    return 0;
}

/* The picture backs out: to the whole run after a top-level phase event,
 * to its merge step's box after a merge's own event, when zoomed in
 * further than that. */
static int picture_out(const pdt_replay *r, const story *st, pdt_view *v, double w, double h,
                       const pdt_layout *L)
{
    size_t np;
    const pdt_rphase *P = pdt_replay_phases(r, &np);
    pdt_point lo, hi;
    int kd = st->e.ev.kind;
    if (st->merge_ph >= 0 && (kd == PDT_EV_MERGE_BEGIN || kd == PDT_EV_MERGE_END || st->top) &&
        merge_box(r, &P[st->merge_ph], &lo, &hi)) {
        double u = px_per_unit(r, v, w, h) / v->zoom; /* at zoom 1 */
        double bw = fmax(1, (double)hi.x - lo.x), bh = fmax(1, (double)hi.y - lo.y);
        double z = fmax(1, 0.8 * fmin(L->geo.w / (bw * u), L->geo.h / (bh * u)));
        if (v->zoom <= 1.3 * z) return 0;
        v->zoom = z;
        v->cx = ((double)lo.x + hi.x) / 2;
        v->cy = ((double)lo.y + hi.y) / 2;
        v->centred = 1;
        return 1;
    }
    if (!st->top || st->merge_ph >= 0 || (v->zoom <= 1.0001 && !v->centred)) return 0;
    v->zoom = 1;
    v->centred = 0;
    return 1;
}

/* The picture: a phase-wide event backs out (picture_out); an event at a
 * point zooms in when the points are packed tighter than 6 px apart on
 * screen (to 14 px apart), else centres it when it left the picture's
 * middle 80 %. */
static int follow_picture(const pdt_replay *r, const story *st, pdt_view *v, double w, double h)
{
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(r), v, &L);
    if (st->wide) return picture_out(r, st, v, w, h, &L);
    size_t np;
    const pdt_point *P = pdt_replay_points(r, &np);
    uint32_t p = st->e.ev.a;
    pdt_point lo, hi;
    if (p >= np || !pdt_replay_bbox(r, &lo, &hi)) return 0;
    double bw = (double)hi.x - lo.x, bh = (double)hi.y - lo.y;
    double gap = bw > 0 && bh > 0 ? sqrt(bw * bh / (double)np) : fmax(bw, bh) / (double)np;
    double ppu = px_per_unit(r, v, w, h);
    if (gap > 0 && gap * ppu < 6 && v->zoom < 512) {
        v->zoom = fmin(512, v->zoom * 14 / (gap * ppu));
        v->cx = P[p].x;
        v->cy = P[p].y;
        v->centred = 1;
        return 1;
    }
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

/* The extent on the clock of the merge step that merge phase ph belongs
 * to: from the first to the last end of the merge phases of its level on
 * the ranks it joins (so that the events of concurrent ranks agree). */
static void merge_extent(const pdt_replay *r, const pdt_ranktree *t, int32_t ph, double *a, double *b)
{
    size_t np, nm;
    const pdt_rphase *P = pdt_replay_phases(r, &np);
    const pdt_rmerge *M = pdt_replay_merges(r, &nm);
    const double *pa = pdt_ranktree_phase_at(t);
    uint32_t lo = P[ph].rank, hi = P[ph].rank + 1;
    for (size_t i = 0; i < nm; i++)
        if (M[i].level == P[ph].sub && P[ph].rank >= M[i].gl && P[ph].rank < M[i].gend) {
            lo = M[i].gl;
            hi = M[i].gend;
            break;
        }
    *a = pa[2 * ph];
    *b = pa[2 * ph + 1];
    for (size_t i = 0; i < np; i++)
        if (P[i].phase == PDT_PH_MERGE && P[i].sub == P[ph].sub && P[i].rank >= lo && P[i].rank < hi) {
            *a = fmin(*a, pa[2 * i]);
            *b = fmax(*b, pa[2 * i + 1]);
        }
}

/* The timeline's window in time: inside a merge step, twice the step's
 * extent, centred on it (unless it is within a factor 2 of that already);
 * the whole run again after a top-level phase event outside merges. */
static int follow_timeline_zoom(const pdt_replay *r, const story *st, pdt_view *v)
{
    const pdt_ranktree *t = v->tree;
    if (!t) return 0;
    double t0 = v->tl_t0, t1 = v->tl_t1;
    if (!(t0 >= 0 && t1 <= 1 && t1 > t0)) t0 = 0, t1 = 1;
    if (st->merge_ph < 0) {
        if (!st->top || (t0 <= 0 && t1 >= 1)) return 0;
        v->tl_t0 = 0;
        v->tl_t1 = 1;
        return 1;
    }
    double a, b;
    merge_extent(r, t, st->merge_ph, &a, &b);
    size_t m = pdt_replay_count(r);
    double span = fmin(1, fmax(2 * (b - a), m ? 8.0 / (double)m : 1));
    double s0 = (a + b) / 2 - span / 2;
    s0 = s0 < 0 ? 0 : s0 + span > 1 ? 1 - span : s0;
    if (t1 - t0 >= span / 2 && t1 - t0 <= 2 * span && t0 <= a && t1 >= b) return 0;
    v->tl_t0 = s0;
    v->tl_t1 = s0 + span;
    return 1;
}

/* The timeline: the cursor inside the window's middle 90 %, the current
 * rank's row among the rows shown. */
static int follow_timeline(const pdt_replay *r, const pdt_rstate *s, pdt_view *v, double w, double h)
{
    int changed = 0;
    size_t m = pdt_replay_count(r);
    double t0 = v->tl_t0, t1 = v->tl_t1, u = !s->k ? 0 : v->tree ? pdt_ranktree_at(v->tree, s->k - 1)
                                                              : (double)s->k / (double)m;
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

int pdt_view_follow(const pdt_replay *r, const pdt_rstate *s, pdt_view *v, double w, double h)
{
    if (!v->follow || !s->k || s->k > pdt_replay_count(r)) return 0;
    story st;
    story_of(r, s, &st);
    int a = follow_picture(r, &st, v, w, h);
    int b = follow_timeline_zoom(r, &st, v);
    int c = follow_timeline(r, s, v, w, h);
    return a || b || c;
}
