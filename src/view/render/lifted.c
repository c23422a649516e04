/* pdt — the viewer's lifted view: the paraboloid z = x^2 + y^2, the lifted
 * points, and for a triangle event its plane and the points below it. */
#include "render_int.h"
#include "pdt/predicates.h"

typedef struct proj {
    double cx, cy, sc;      /* world -> unit square */
    double cy_, sy_, cp, sp;/* yaw and pitch */
    double ox, oy, s;       /* unit -> screen */
} proj;

static void lift_xy(const proj *J, double u, double w, double z, double *sx, double *sy)
{
    double X = u * J->cy_ - w * J->sy_, Y = u * J->sy_ + w * J->cy_;
    *sx = J->ox + J->s * X;
    *sy = J->oy - J->s * (z * J->cp + Y * J->sp);
}

/* A point lifted onto the paraboloid, on the screen. */
static void lift_pt(const proj *J, const pdt_point *p, double *sx, double *sy)
{
    double u = (p->x - J->cx) / J->sc, w = (p->y - J->cy) / J->sc;
    lift_xy(J, u, w, u * u + w * w, sx, sy);
}

/* The lifted point of input point p (on the floor when not lifted). */
static void lift_at(const ctx *c, const proj *J, uint32_t p, int lifted, double *sx, double *sy)
{
    double u = (c->P[p].x - J->cx) / J->sc, w = (c->P[p].y - J->cy) / J->sc;
    lift_xy(J, u, w, lifted ? u * u + w * w : 0, sx, sy);
}

static int is_lifted(const ctx *c, size_t p)
{
    return c->all_lifted || (c->s->pflags[p] & PDT_PF_LIFTED) != 0;
}

/* The projection of the run's box into panel R, turned by the view's yaw
 * and pitch. */
static proj projection(const ctx *c, pdt_rect R, double f)
{
    pdt_point lo = {0, 0}, hi = {1, 1};
    pdt_replay_bbox(c->r, &lo, &hi);
    proj J;
    J.cx = ((double)lo.x + hi.x) / 2;
    J.cy = ((double)lo.y + hi.y) / 2;
    J.sc = fmax(1, fmax((double)hi.x - lo.x, (double)hi.y - lo.y) / 2);
    J.cy_ = cos(c->v->yaw);
    J.sy_ = sin(c->v->yaw);
    J.cp = cos(c->v->pitch);
    J.sp = sin(c->v->pitch);
    /* under the title; above the two lines of text at the bottom */
    double top = R.y + 1.6 * f, H = R.h - 2.0 * f - 2.3 * c->L.label;
    /* vertical extent: z in [0,2], Y in [-1.42,1.42] */
    double ext_y = 2 * J.cp + 2.9 * J.sp, ext_x = 2.9;
    J.s = fmin((R.w - f) / ext_x, H / ext_y);
    J.ox = R.x + R.w / 2;
    J.oy = top + H / 2 + J.s * (J.cp * 1.0);
    return J;
}

/* The paraboloid: rings and meridians. */
static void draw_paraboloid(const ctx *c, const proj *J)
{
    cairo_t *cr = c->cr;
    cairo_set_line_width(cr, 1);
    rgb(cr, c->T->hollow, 0.5);
    for (int ring_i = 1; ring_i <= 5; ring_i++) {
        double rho = 0.28 * ring_i;
        for (int i = 0; i <= 48; i++) {
            double a = 2 * M_PI * i / 48, sx, sy;
            lift_xy(J, rho * cos(a), rho * sin(a), rho * rho, &sx, &sy);
            if (i) cairo_line_to(cr, sx, sy);
            else cairo_move_to(cr, sx, sy);
        }
    }
    for (int mi = 0; mi < 12; mi++) {
        double a = 2 * M_PI * mi / 12;
        for (int i = 0; i <= 20; i++) {
            double rho = 1.4 * i / 20, sx, sy;
            lift_xy(J, rho * cos(a), rho * sin(a), rho * rho, &sx, &sy);
            if (i) cairo_line_to(cr, sx, sy);
            else cairo_move_to(cr, sx, sy);
        }
    }
    cairo_stroke(cr);
}

/* The current triangle event's lifted plane, when it has one: its corners
 * in tv; 1 if drawn. */
static int draw_plane(const ctx *c, const proj *J, const pdt_rec *e, uint32_t tv[3])
{
    cairo_t *cr = c->cr;
    if (!e || !is_tri_event(e->ev.kind) || e->ev.a >= c->n || e->ev.b >= c->n || e->ev.c >= c->n)
        return 0;
    tv[0] = e->ev.a;
    tv[1] = e->ev.b;
    tv[2] = e->ev.c;
    double U[3], W[3], Z[3];
    for (int j = 0; j < 3; j++) {
        U[j] = (c->P[tv[j]].x - J->cx) / J->sc;
        W[j] = (c->P[tv[j]].y - J->cy) / J->sc;
        Z[j] = U[j] * U[j] + W[j] * W[j];
    }
    /* z = pa*u + pb*w + pc through the three lifted points */
    double d = (U[1] - U[0]) * (W[2] - W[0]) - (U[2] - U[0]) * (W[1] - W[0]);
    if (fabs(d) <= 1e-15) return 0;
    double pa = ((Z[1] - Z[0]) * (W[2] - W[0]) - (Z[2] - Z[0]) * (W[1] - W[0])) / d;
    double pb = ((U[1] - U[0]) * (Z[2] - Z[0]) - (U[2] - U[0]) * (Z[1] - Z[0])) / d;
    double pc = Z[0] - pa * U[0] - pb * W[0];
    static const double cu[4] = {-1.3, 1.3, 1.3, -1.3}, cw[4] = {-1.3, -1.3, 1.3, 1.3};
    for (int j = 0; j < 4; j++) {
        double sx, sy;
        lift_xy(J, cu[j], cw[j], pa * cu[j] + pb * cw[j] + pc, &sx, &sy);
        if (j) cairo_line_to(cr, sx, sy);
        else cairo_move_to(cr, sx, sy);
    }
    cairo_close_path(cr);
    rgb(cr, c->T->mark, 0.22);
    cairo_fill_preserve(cr);
    rgb(cr, c->T->disk, 0.7);
    cairo_set_line_width(cr, 1);
    cairo_stroke(cr);
    return 1;
}

/* Rank q's lifted faces filled as one path, their edges (into edges, made
 * unique) stroked once each as separate segments (no joins): a fraction of
 * the cost of stroking the closed triangles. */
static void draw_rank_faces(const ctx *c, const proj *J, int q, uint64_t *edges)
{
    cairo_t *cr = c->cr;
    size_t nt;
    const pdt_rtri *Tr = pdt_replay_tris(c->r, &nt);
    const pdt_rtri_hist *Hh = pdt_replay_tri_hist(c->r);
    size_t ne = 0;
    for (size_t t = 0; t < nt; t++) {
        uint32_t h = pdt_rstate_tri_entry(c->r, c->s, t);
        if (Tr[t].maker != (uint32_t)q || h == NONE32 || Hh[h].status == PDT_TS_DISCARDED) continue;
        if (c->v->clean && Hh[h].status != PDT_TS_FINAL) continue;
        for (int j = 0; j < 3; j++) {
            double sx, sy;
            lift_pt(J, &c->P[Tr[t].v[j]], &sx, &sy);
            if (j) cairo_line_to(cr, sx, sy);
            else cairo_move_to(cr, sx, sy);
            uint32_t a = Tr[t].v[j], b = Tr[t].v[(j + 1) % 3];
            edges[ne++] = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
        }
        cairo_close_path(cr);
    }
    if (!ne) return;
    set_rank(c, q, 0.22);
    cairo_fill(cr);
    ne = pdt_unique_edges(edges, ne);
    for (size_t i = 0; i < ne; i++) {
        double x0, y0, x1, y1;
        lift_pt(J, &c->P[edges[i] >> 32], &x0, &y0);
        lift_pt(J, &c->P[(uint32_t)edges[i]], &x1, &y1);
        cairo_move_to(cr, x0, y0);
        cairo_line_to(cr, x1, y1);
    }
    set_rank(c, q, 0.7);
    cairo_set_line_width(cr, 0.8);
    cairo_stroke(cr);
}

/* The lower hull: the lifted faces of the triangles drawn in the picture
 * (not discarded), coloured like them (Theorem 1.1: the Delaunay triangles
 * are the lower faces of the lifted points' hull); small runs only. */
static void draw_lower_hull(const ctx *c, const proj *J)
{
    size_t nt;
    pdt_replay_tris(c->r, &nt);
    uint64_t *edges = nt <= 20000 ? malloc((3 * nt + 1) * sizeof *edges) : NULL;
    if (!edges) return;
    cairo_set_line_cap(c->cr, CAIRO_LINE_CAP_BUTT);
    for (int q = 0; q < c->nranks; q++)
        if (shown(c, (uint32_t)q)) draw_rank_faces(c, J, q, edges);
    free(edges);
}

/* The points: lifted ones on the paraboloid, others faint on the floor;
 * those below the plane (ccw: the orientation of the plane's triangle tv,
 * 0 without one) in red, one fill per class. */
static void draw_points(const ctx *c, const proj *J, int ccw, const uint32_t tv[3])
{
    cairo_t *cr = c->cr;
    size_t step = c->n > 6000 ? c->n / 6000 : 1;
    double rad = c->n > 1000 ? 1.4 : 2.6;
    for (int cls = 0; cls < 3; cls++) { /* 0 floor, 1 lifted, 2 below the plane: one fill each */
        for (size_t p = 0; p < c->n; p += step) {
            int lifted = is_lifted(c, p);
            int below = ccw && lifted &&
                        ccw * pdt_incircle0(c->P[tv[0]], c->P[tv[1]], c->P[tv[2]], c->P[p]) > 0;
            if ((below ? 2 : lifted ? 1 : 0) != cls) continue;
            double sx, sy;
            lift_at(c, J, (uint32_t)p, lifted, &sx, &sy);
            double rr = below ? rad * 1.8 : rad;
            if (step > 1 || c->n > 2000) cairo_rectangle(cr, floor(sx) - 1, floor(sy) - 1, 2, 2);
            else {
                cairo_new_sub_path(cr);
                cairo_arc(cr, sx, sy, rr, 0, 2 * M_PI);
            }
        }
        if (cls == 2) rgb(cr, RED, 1);
        else if (cls == 1) rgb(cr, c->T->ink, 0.85);
        else rgb(cr, c->T->hollow, 0.5);
        cairo_fill(cr);
    }
}

/* The point event e names (lift, push, pop, sort), or NONE32. */
static uint32_t event_point(const pdt_rec *e)
{
    if (e && (e->ev.kind == PDT_EV_LIFT || e->ev.kind == PDT_EV_PUSH ||
              e->ev.kind == PDT_EV_POP || e->ev.kind == PDT_EV_SORT))
        return e->ev.a;
    return NONE32;
}

/* Does box b (x0, y0, x1, y1) meet one of the n boxes of bx? */
static int box_hit(double (*bx)[4], int n, const double b[4])
{
    for (int j = 0; j < n; j++)
        if (b[0] < bx[j][2] && bx[j][0] < b[2] && b[1] < bx[j][3] && bx[j][1] < b[3]) return 1;
    return 0;
}

/* Where the label of width tw at point (sx, sy) goes: right-up, left-up,
 * right-down, left-down (the first two for the others), the first place
 * that meets no label placed before; 0 when none is free. */
static int label_place(double (*bx)[4], int nb, double sx, double sy, double tw, double fs,
                       int tries, double b[4])
{
    for (int k = 0; k < tries; k++) {
        double x0 = k % 2 ? sx - 0.25 * fs - tw : sx + 0.25 * fs;
        double y1 = k < 2 ? sy - 0.25 * fs : sy + 1.0 * fs;
        double t[4] = {x0, y1 - 0.8 * fs, x0 + tw, y1 + 0.05 * fs};
        if (box_hit(bx, nb, t)) continue;
        memcpy(b, t, sizeof t);
        return 1;
    }
    return 0;
}

/* Labels of the lifted points (few points): the current event's point and
 * the plane's corners first, then the others in index order; a label that
 * would overlap one already placed (or the title, or the lines at the bottom)
 * moves, else gives way (the panel is small). */
static void draw_point_labels(const ctx *c, const proj *J, const pdt_rec *e, int have_plane,
                              const uint32_t tv[3])
{
    cairo_t *cr = c->cr;
    double fs = c->L.label, f = c->L.font;
    pdt_rect R = c->L.lifted;
    uint32_t first[4] = {event_point(e), NONE32, NONE32, NONE32};
    for (int j = 0; j < 3 && have_plane; j++) first[j + 1] = tv[j];
    /* the title row, and the plane's lines at the bottom (when drawn) */
    double bx[64][4] = {{R.x, R.y, R.x + R.w, R.y + 0.3 * f + 1.25 * 0.82 * f},
                        {R.x, R.y + R.h - 0.5 * f - 2.3 * fs, R.x + R.w, R.y + R.h}};
    int nb = have_plane ? 2 : 1;
    for (size_t i = 0; i < 4 + c->n; i++) {
        uint32_t p = i < 4 ? first[i] : (uint32_t)(i - 4);
        if (p >= c->n) continue;
        int dup = 0;
        for (size_t j = 0; j < 4 && j < i; j++) dup |= first[j] == p;
        if (dup) continue;
        int lifted = is_lifted(c, p);
        if (!lifted && i >= 4) continue;
        double sx, sy, b[4];
        lift_at(c, J, p, lifted, &sx, &sy);
        char lab[24];
        snprintf(lab, sizeof lab, "%u", p);
        if (!label_place(bx, nb, sx, sy, text_wb(cr, SANS, i < 4, fs, lab), fs, i < 4 ? 4 : 2, b))
            continue;
        if (nb < 64) memcpy(bx[nb++], b, sizeof b);
        rgb(cr, c->T->label, 1);
        text_at(cr, SANS, i < 4, fs, b[0], b[3] - 0.05 * fs, lab);
    }
}

/* A red ring round the current event's point. */
static void draw_event_point(const ctx *c, const proj *J, const pdt_rec *e, double f)
{
    uint32_t p = event_point(e);
    if (p >= c->n) return;
    double sx, sy;
    lift_at(c, J, p, is_lifted(c, p), &sx, &sy);
    cairo_new_sub_path(c->cr);
    cairo_arc(c->cr, sx, sy, 0.45 * f, 0, 2 * M_PI);
    rgb(c->cr, RED, 1);
    cairo_set_line_width(c->cr, 2.5);
    cairo_stroke(c->cr);
}

/* The plane's lifted triangle in its rank's colour, and how many input
 * points lie strictly inside its circle. */
static void draw_plane_triangle(const ctx *c, const proj *J, const pdt_rec *e, const uint32_t tv[3],
                                size_t ninside, pdt_rect R, double f)
{
    cairo_t *cr = c->cr;
    for (int j = 0; j < 3; j++) {
        double sx, sy;
        lift_at(c, J, tv[j], 1, &sx, &sy);
        if (j) cairo_line_to(cr, sx, sy);
        else cairo_move_to(cr, sx, sy);
    }
    cairo_close_path(cr);
    set_rank(c, (int)e->rank, 0.5);
    cairo_fill_preserve(cr);
    set_rank(c, (int)e->rank, 1);
    cairo_set_line_width(cr, 2);
    cairo_stroke(cr);
    char lab[128], lab2[64];
    double fs = c->L.label, room = R.w - f;
    snprintf(lab, sizeof lab, "%zu input point%s strictly inside the circle (exact, no tie rule)",
             ninside, ninside == 1 ? "" : "s");
    if (text_w(cr, SANS, fs, lab) > room)
        snprintf(lab, sizeof lab, "%zu point%s inside the circle", ninside, ninside == 1 ? "" : "s");
    snprintf(lab2, sizeof lab2, "%s", "those already lifted: below the plane (red)");
    if (text_w(cr, SANS, fs, lab2) > room) snprintf(lab2, sizeof lab2, "%s", "lifted ones: below (red)");
    rgb(cr, ninside ? RED : c->T->ink, 1);
    text_at(cr, SANS, 0, fs, R.x + 0.5 * f, R.y + R.h - 0.5 * f - 1.25 * fs, lab);
    rgb(cr, c->T->ink, 1);
    text_at(cr, SANS, 0, fs, R.x + 0.5 * f, R.y + R.h - 0.5 * f, lab2);
}

void pdt_draw_lifted(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.lifted;
    double f = c->L.font;
    panel(cr, c->T, R, "Lifted view: z = x² + y² (drag to rotate)", f);
    cairo_save(cr);
    clip_rect(cr, R);
    /* a small picture of many faces: fast antialiasing looks the same here
     * and costs a fraction (text is not affected) */
    cairo_set_antialias(cr, CAIRO_ANTIALIAS_FAST);
    proj J = projection(c, R, f);
    draw_paraboloid(c, &J);
    const pdt_rec *e = c->cur;
    uint32_t tv[3] = {0, 0, 0};
    int have_plane = draw_plane(c, &J, e, tv);
    draw_lower_hull(c, &J);
    /* inside the circle, exactly: every input point, lifted or not (the
     * drawing samples large inputs; the count does not) */
    int ccw = have_plane ? pdt_orient(c->P[tv[0]], c->P[tv[1]], c->P[tv[2]]) : 0;
    size_t ninside = ccw ? pdt_replay_inside_count(c->r, tv) : 0;
    draw_points(c, &J, ccw, tv);
    if (c->n <= 60 && !c->no_lift) draw_point_labels(c, &J, e, have_plane, tv);
    if (e && !c->v->clean) draw_event_point(c, &J, e, f);
    if (have_plane) draw_plane_triangle(c, &J, e, tv, ninside, R, f);
    if (c->no_lift) {
        rgb(cr, c->T->ink, 1);
        const char *t = "no lift-up in this run (points stay on the floor)";
        if (text_w(cr, SANS, c->L.label, t) > R.w - f) t = "no lift-up in this run";
        text_at(cr, SANS, 0, c->L.label, R.x + 0.5 * f, R.y + R.h - 0.5 * f, t);
    }
    cairo_restore(cr);
}
