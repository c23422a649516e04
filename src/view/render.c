/* pdt — the cairo renderer (see pdt/render.h). */
#include "pdt/render.h"
#include "pdt/describe.h"
#include "pdt/predicates.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define NONE32 UINT32_MAX
#define SANS "DejaVu Sans"
#define MONO "DejaVu Sans Mono"

/* ---- colours ------------------------------------------------------------------ */

/* Okabe & Ito's colour-blind-safe palette, black left out (used for hulls
 * and text), yellow darkened to stay visible on white. */
static const double okabe_ito[8][3] = {
    {0.000, 0.447, 0.698}, /* blue */
    {0.902, 0.624, 0.000}, /* orange */
    {0.000, 0.620, 0.451}, /* bluish green */
    {0.800, 0.475, 0.655}, /* reddish purple */
    {0.337, 0.706, 0.914}, /* sky blue */
    {0.835, 0.369, 0.000}, /* vermillion */
    {0.741, 0.690, 0.000}, /* yellow, darkened */
    {0.400, 0.400, 0.400}, /* grey */
};

void pdt_rank_rgb(int rank, double rgb[3])
{
    if (rank < 0) rank = 0;
    const double *c = okabe_ito[rank % 8];
    int cycle = (rank / 8) % 3; /* 0 as is, 1 darker, 2 lighter */
    for (int i = 0; i < 3; i++)
        rgb[i] = cycle == 0 ? c[i] : cycle == 1 ? 0.55 * c[i] : c[i] + 0.5 * (1 - c[i]);
}

static void set_rank(cairo_t *cr, int rank, double alpha)
{
    double c[3];
    pdt_rank_rgb(rank, c);
    cairo_set_source_rgba(cr, c[0], c[1], c[2], alpha);
}

static const double RED[3] = {0.85, 0.0, 0.0};
static const double INK[3] = {0.1, 0.1, 0.12};

static void rgb(cairo_t *cr, const double c[3], double a) { cairo_set_source_rgba(cr, c[0], c[1], c[2], a); }

/* Phase colours for the timeline (muted, distinct from one another). */
static void phase_rgb(int ph, double c[3])
{
    static const double t[PDT_PH_COUNT][3] = {
        {0.85, 0.85, 0.85}, {0.75, 0.75, 0.75}, {0.70, 0.80, 0.90}, {0.55, 0.75, 0.95},
        {0.45, 0.65, 0.45}, {0.95, 0.80, 0.45}, {0.90, 0.65, 0.65}, {0.70, 0.55, 0.85},
        {0.75, 0.75, 0.60}, {0.60, 0.85, 0.80}, {0.95, 0.70, 0.40}, {0.80, 0.70, 0.55},
        {0.65, 0.65, 0.80},
    };
    const double *s = t[ph >= 0 && ph < PDT_PH_COUNT ? ph : 0];
    c[0] = s[0];
    c[1] = s[1];
    c[2] = s[2];
}

/* ---- view and layout ----------------------------------------------------------- */

void pdt_view_defaults(pdt_view *v)
{
    memset(v, 0, sizeof *v);
    v->zoom = 1;
    v->yaw = 0.5;
    v->pitch = 0.45;
    v->fade = 400;
    v->ev_class = PDT_EVC_STACK;
    v->sel_point = v->sel_tri = -1;
    v->sel_edge = -1;
    v->panels = PDT_PANEL_ALL;
}

int pdt_panels_parse(const char *list, unsigned *panels)
{
    static const struct { const char *name; unsigned bit; } names[] = {
        {"code", PDT_PANEL_CODE}, {"stack", PDT_PANEL_STACK}, {"lifted", PDT_PANEL_LIFTED},
        {"timeline", PDT_PANEL_TIMELINE}, {"all", PDT_PANEL_ALL}, {"none", 0}};
    unsigned bits = 0;
    const char *p = list;
    while (*p) {
        size_t len = strcspn(p, ",");
        size_t i;
        for (i = 0; i < sizeof names / sizeof *names; i++)
            if (strlen(names[i].name) == len && !strncmp(p, names[i].name, len)) break;
        if (i == sizeof names / sizeof *names) return -1;
        bits |= names[i].bit;
        p += len;
        if (*p == ',') p++;
    }
    *panels = bits;
    return 0;
}

void pdt_render_layout(double w, double h, int nranks, pdt_layout *L)
{
    pdt_render_layout_panels(w, h, nranks, PDT_PANEL_ALL, L);
}

void pdt_render_layout_panels(double w, double h, int nranks, unsigned panels, pdt_layout *L)
{
    double f = h / 46;
    if (f > w / 72) f = w / 72;
    if (f < 10) f = 10;
    L->font = f;
    double top = 2.0 * f;
    int rows = nranks < 1 ? 1 : nranks > 16 ? 16 : nranks;
    double tl = (rows + 1.6) * f * 1.15;
    if (tl > 0.28 * h) tl = 0.28 * h;
    if (!(panels & PDT_PANEL_TIMELINE)) tl = 0;
    double side = 0.34 * w;
    if (side < 22 * f) side = 22 * f;
    if (side > 0.5 * w) side = 0.5 * w;
    L->top = (pdt_rect){0, 0, w, top};
    L->timeline = (pdt_rect){0, h - tl, tl > 0 ? w : 0, tl};
    double mid = h - tl - top;
    L->geo = (pdt_rect){0, top, w - side, mid};
    double x = w - side, y = top;
    int has_code = (panels & PDT_PANEL_CODE) != 0, has_stack = (panels & PDT_PANEL_STACK) != 0,
        has_lifted = (panels & PDT_PANEL_LIFTED) != 0;
    double leg = 7.6 * f, code = has_code ? 12.2 * f * 0.9 : 0;
    double rest = mid - leg - code;
    if (has_code && rest < 10 * f) { /* small pictures: shrink the code panel first */
        code = mid - leg - 10 * f;
        if (code < 4 * f) code = 4 * f;
        rest = mid - leg - code;
    }
    double stk = has_stack ? (has_lifted ? rest * 0.38 : rest) : 0;
    double lifted = has_lifted ? rest - stk : 0;
    if (!has_stack && !has_lifted && has_code) code += rest; /* the code panel takes the column */
    L->legend = (pdt_rect){x, y, side, leg};
    L->code = (pdt_rect){x, y + leg, has_code ? side : 0, code};
    L->stack = (pdt_rect){x, y + leg + code, has_stack ? side : 0, stk};
    L->lifted = (pdt_rect){x, y + leg + code + stk, has_lifted ? side : 0, lifted};
    /* whole pixels: clipping to them stays a fast box clip */
    pdt_rect *all[] = {&L->top, &L->geo, &L->legend, &L->code, &L->stack, &L->lifted, &L->timeline};
    for (size_t i = 0; i < sizeof all / sizeof *all; i++) {
        double x1 = round(all[i]->x + all[i]->w), y1 = round(all[i]->y + all[i]->h);
        all[i]->x = round(all[i]->x);
        all[i]->y = round(all[i]->y);
        all[i]->w = x1 - all[i]->x;
        all[i]->h = y1 - all[i]->y;
    }
}

typedef struct xform {
    double s, ox, oy; /* screen = (ox + s*x, oy - s*y) */
} xform;

static xform geo_xform(const pdt_replay *r, const pdt_view *v, double w, double h)
{
    pdt_layout L;
    pdt_render_layout_panels(w, h, pdt_replay_nranks(r), v->panels, &L);
    pdt_point lo = {0, 0}, hi = {1, 1};
    pdt_replay_bbox(r, &lo, &hi);
    double bw = (double)hi.x - lo.x, bh = (double)hi.y - lo.y;
    if (bw < 1) bw = 1;
    if (bh < 1) bh = 1;
    double mx = 2.0 * L.font, my = 3.2 * L.font; /* room for the box labels */
    double s = fmin((L.geo.w - 2 * mx) / bw, (L.geo.h - 2 * my) / bh) * (v->zoom > 0 ? v->zoom : 1);
    double cx = v->centred ? v->cx : lo.x + bw / 2, cy = v->centred ? v->cy : lo.y + bh / 2;
    xform X = {s, L.geo.x + L.geo.w / 2 - s * cx, L.geo.y + L.geo.h / 2 + s * cy};
    return X;
}

void pdt_view_to_world(const pdt_replay *r, const pdt_view *v, double w, double h, double sx,
                       double sy, double *wx, double *wy)
{
    xform X = geo_xform(r, v, w, h);
    *wx = (sx - X.ox) / X.s;
    *wy = (X.oy - sy) / X.s;
}

void pdt_view_to_screen(const pdt_replay *r, const pdt_view *v, double w, double h, double wx,
                        double wy, double *sx, double *sy)
{
    xform X = geo_xform(r, v, w, h);
    *sx = X.ox + X.s * wx;
    *sy = X.oy - X.s * wy;
}

void pdt_view_zoom_at(const pdt_replay *r, pdt_view *v, double w, double h, double sx, double sy,
                      double f)
{
    double wx, wy, cx, cy;
    pdt_view_to_world(r, v, w, h, sx, sy, &wx, &wy);
    pdt_layout L;
    pdt_render_layout_panels(w, h, pdt_replay_nranks(r), v->panels, &L);
    pdt_view_to_world(r, v, w, h, L.geo.x + L.geo.w / 2, L.geo.y + L.geo.h / 2, &cx, &cy);
    v->zoom *= f;
    if (v->zoom < 0.05) v->zoom = 0.05;
    if (v->zoom > 1e6) v->zoom = 1e6;
    /* keep (wx,wy) under the cursor: move the centre towards it */
    double nx, ny;
    v->cx = cx;
    v->cy = cy;
    v->centred = 1;
    pdt_view_to_screen(r, v, w, h, wx, wy, &nx, &ny);
    xform X = geo_xform(r, v, w, h);
    v->cx += (nx - sx) / X.s;
    v->cy -= (ny - sy) / X.s;
}

/* ---- small drawing helpers ---------------------------------------------------------- */

static void text_at(cairo_t *cr, const char *face, int bold, double size, double x, double y,
                    const char *s)
{
    cairo_select_font_face(cr, face, CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
    cairo_move_to(cr, x, y);
    cairo_show_text(cr, s);
}

static double text_wb(cairo_t *cr, const char *face, int bold, double size, const char *s)
{
    cairo_text_extents_t te;
    cairo_select_font_face(cr, face, CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
    cairo_text_extents(cr, s, &te);
    return te.x_advance;
}

static double text_w(cairo_t *cr, const char *face, double size, const char *s)
{
    return text_wb(cr, face, 0, size, s);
}

static void panel(cairo_t *cr, pdt_rect R, const char *title, double f)
{
    cairo_rectangle(cr, R.x + 2, R.y + 2, R.w - 4, R.h - 4);
    cairo_set_source_rgb(cr, 0.975, 0.975, 0.97);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0.72, 0.72, 0.72);
    cairo_set_line_width(cr, 1);
    cairo_stroke(cr);
    if (title) {
        rgb(cr, INK, 1);
        text_at(cr, SANS, 1, 0.85 * f, R.x + 0.5 * f, R.y + 1.15 * f, title);
    }
}

static void clip_rect(cairo_t *cr, pdt_rect R)
{
    cairo_rectangle(cr, R.x, R.y, R.w, R.h);
    cairo_clip(cr);
}

/* Circumcircle in world coordinates; 0 if degenerate. */
static int circum(const pdt_point *P, const uint32_t v[3], double *ox, double *oy, double *rr)
{
    pdt_point A = P[v[0]], B = P[v[1]], C = P[v[2]];
    double bx = (double)B.x - A.x, by = (double)B.y - A.y, cx = (double)C.x - A.x,
           cy = (double)C.y - A.y;
    double d = 2 * (bx * cy - by * cx);
    if (d == 0) return 0;
    double ux = (cy * (bx * bx + by * by) - by * (cx * cx + cy * cy)) / d;
    double uy = (bx * (cx * cx + cy * cy) - cx * (bx * bx + by * by)) / d;
    *ox = A.x + ux;
    *oy = A.y + uy;
    *rr = sqrt(ux * ux + uy * uy);
    return 1;
}

static int disk_touches_box(double ox, double oy, double rr, pdt_point lo, pdt_point hi)
{
    double qx = fmax(lo.x, fmin(ox, hi.x)), qy = fmax(lo.y, fmin(oy, hi.y));
    return (qx - ox) * (qx - ox) + (qy - oy) * (qy - oy) <= rr * rr * (1 + 1e-9);
}

typedef struct ctx {
    cairo_t *cr;
    const pdt_replay *r;
    const pdt_rstate *s;
    const pdt_view *v;
    pdt_layout L;
    xform X;
    const pdt_point *P;
    size_t n;
    int nranks;
    double lw;      /* base line width */
    const pdt_rec *cur;  /* the current event or NULL */
    int all_lifted;      /* no lift events but triangles: show every point lifted */
    int no_lift;         /* no lift events and no triangles (a hull-only run) */
    double spacing;      /* typical distance between points, pixels */
} ctx;

static int shown(const ctx *c, uint32_t rank)
{
    return !c->v->hidden || rank >= (uint32_t)c->nranks || !c->v->hidden[rank];
}

static void wpt(const ctx *c, uint32_t p, double *x, double *y)
{
    *x = c->X.ox + c->X.s * c->P[p].x;
    *y = c->X.oy - c->X.s * c->P[p].y;
}

static void tri_path(const ctx *c, const uint32_t v[3])
{
    double x, y;
    wpt(c, v[0], &x, &y);
    cairo_move_to(c->cr, x, y);
    wpt(c, v[1], &x, &y);
    cairo_line_to(c->cr, x, y);
    wpt(c, v[2], &x, &y);
    cairo_line_to(c->cr, x, y);
    cairo_close_path(c->cr);
}

static int is_tri_event(int k)
{
    return k == PDT_EV_TRI_NEW || k == PDT_EV_TRI_FINAL || k == PDT_EV_RA_DEFER ||
           k == PDT_EV_SHIP || k == PDT_EV_DISCARD || k == PDT_EV_INCIRCLE;
}

/* Line style of a status: width factor and dash. */
static void status_style(cairo_t *cr, int st, double lw)
{
    static const double dash[] = {6, 4}, dot[] = {1.5, 3};
    switch (st) {
    case PDT_TS_CANDIDATE:
        cairo_set_line_width(cr, 0.6 * lw);
        cairo_set_dash(cr, NULL, 0, 0);
        break;
    case PDT_TS_FINAL:
        cairo_set_line_width(cr, 1.3 * lw);
        cairo_set_dash(cr, NULL, 0, 0);
        break;
    case PDT_TS_DEFERRED: {
        double d[2] = {dash[0] * lw, dash[1] * lw};
        cairo_set_line_width(cr, 1.3 * lw);
        cairo_set_dash(cr, d, 2, 0);
        break;
    }
    case PDT_TS_SHIPPED: {
        double d[2] = {dot[0] * lw, dot[1] * lw};
        cairo_set_line_width(cr, 1.6 * lw);
        cairo_set_dash(cr, d, 2, 0);
        break;
    }
    default:
        cairo_set_line_width(cr, 0.8 * lw);
        cairo_set_dash(cr, NULL, 0, 0);
    }
}

static void cross(cairo_t *cr, double x, double y, double a)
{
    cairo_move_to(cr, x - a, y - a);
    cairo_line_to(cr, x + a, y + a);
    cairo_move_to(cr, x - a, y + a);
    cairo_line_to(cr, x + a, y - a);
}

/* ---- the geometry --------------------------------------------------------------------- */

/* The strip boxes (labels = 0) or their labels (labels = 1, drawn last, on a
 * white ground so that edges and hulls do not hide them). */
static void draw_boxes(ctx *c, int cur_tri_ok, double ox, double oy, double rr, int labels)
{
    cairo_t *cr = c->cr;
    int cur_rank = c->cur ? (int)c->cur->rank : -1;
    for (int q = 0; q < c->nranks; q++) {
        pdt_point lo, hi;
        if (!shown(c, (uint32_t)q) || !pdt_replay_box(c->r, q, &lo, &hi)) continue;
        double x0 = c->X.ox + c->X.s * lo.x, x1 = c->X.ox + c->X.s * hi.x;
        double y0 = c->X.oy - c->X.s * hi.y, y1 = c->X.oy - c->X.s * lo.y;
        double pad = 0.4 * c->L.font;
        int touched = cur_tri_ok && q != cur_rank && disk_touches_box(ox, oy, rr, lo, hi);
        if (!labels) {
            cairo_rectangle(cr, x0 - pad, y0 - pad, x1 - x0 + 2 * pad, y1 - y0 + 2 * pad);
            /* opaque tint (rank colour over white): much cheaper than alpha on big areas */
            double col[3], a = touched ? 0.16 : 0.05;
            pdt_rank_rgb(q, col);
            cairo_set_source_rgb(cr, 1 - a + a * col[0], 1 - a + a * col[1], 1 - a + a * col[2]);
            cairo_fill_preserve(cr);
            set_rank(cr, q, touched ? 0.95 : 0.5);
            double d[2] = {4, 3};
            cairo_set_dash(cr, touched ? NULL : d, touched ? 0 : 2, 0);
            cairo_set_line_width(cr, touched ? 2.5 * c->lw : 1);
            cairo_stroke(cr);
            cairo_set_dash(cr, NULL, 0, 0);
            continue;
        }
        char lab[32];
        double fs = 0.8 * c->L.font;
        snprintf(lab, sizeof lab, touched ? "rank %d (touched)" : "rank %d", q);
        if (text_wb(cr, SANS, touched, fs, lab) > x1 - x0 + 2 * pad + 0.3 * c->L.font)
            snprintf(lab, sizeof lab, touched ? "r%d!" : "r%d", q); /* narrow strips */
        double tw = text_wb(cr, SANS, touched, fs, lab);
        double ly = q % 2 ? y1 + pad + 0.95 * c->L.font : y0 - pad - 0.25 * c->L.font;
        cairo_rectangle(cr, x0 - pad - 0.1 * fs, ly - 0.85 * fs, tw + 0.2 * fs, 1.1 * fs);
        cairo_set_source_rgba(cr, 1, 1, 1, 0.8);
        cairo_fill(cr);
        set_rank(cr, q, 1);
        text_at(cr, SANS, touched, fs, x0 - pad, ly, lab);
    }
}

static void draw_triangles(ctx *c)
{
    cairo_t *cr = c->cr;
    size_t nt;
    const pdt_rtri *T = pdt_replay_tris(c->r, &nt);
    const pdt_rtri_hist *H = pdt_replay_tri_hist(c->r);
    if (!nt) return;
    /* bucket by (status, maker) so that each bucket is one stroke */
    size_t nb = (size_t)PDT_TS_COUNT * (size_t)c->nranks;
    size_t *start = calloc(nb + 1, sizeof *start);
    uint32_t *order = malloc(nt * sizeof *order);
    if (!start || !order) {
        free(start);
        free(order);
        return;
    }
    for (size_t t = 0; t < nt; t++) {
        uint32_t h = pdt_rstate_tri_entry(c->r, c->s, t);
        if (h == NONE32 || !shown(c, T[t].maker)) continue;
        start[(size_t)H[h].status * (size_t)c->nranks + T[t].maker + 1]++;
    }
    for (size_t b = 0; b < nb; b++) start[b + 1] += start[b];
    size_t *fill = malloc((nb + 1) * sizeof *fill);
    if (!fill) {
        free(start);
        free(order);
        return;
    }
    memcpy(fill, start, (nb + 1) * sizeof *fill);
    for (size_t t = 0; t < nt; t++) {
        uint32_t h = pdt_rstate_tri_entry(c->r, c->s, t);
        if (h == NONE32 || !shown(c, T[t].maker)) continue;
        order[fill[(size_t)H[h].status * (size_t)c->nranks + T[t].maker]++] = (uint32_t)t;
    }
    free(fill);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    double gx0 = c->L.geo.x, gx1 = c->L.geo.x + c->L.geo.w, gy0 = c->L.geo.y, gy1 = c->L.geo.y + c->L.geo.h;
    /* dense pictures: thin lines without antialiasing (a mesh of 10^5 edges
     * looks the same and draws several times faster) */
    int dense = start[nb] > 10000;
    cairo_save(cr);
    cairo_set_line_cap(cr, dense ? CAIRO_LINE_CAP_BUTT : CAIRO_LINE_CAP_ROUND);
    if (dense) cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
    /* discarded first (underneath), fading; then candidate, shipped, deferred, final */
    static const int order_st[] = {PDT_TS_DISCARDED, PDT_TS_CANDIDATE, PDT_TS_SHIPPED,
                                   PDT_TS_DEFERRED, PDT_TS_FINAL};
    for (int oi = 0; oi < 5; oi++) {
        int st = order_st[oi];
        for (int q = 0; q < c->nranks; q++) {
            size_t b = (size_t)st * (size_t)c->nranks + (size_t)q;
            if (start[b] == start[b + 1]) continue;
            if (st == PDT_TS_DISCARDED) {
                for (size_t i = start[b]; i < start[b + 1]; i++) {
                    uint32_t t = order[i];
                    double age = (double)c->s->k - H[pdt_rstate_tri_entry(c->r, c->s, t)].ev;
                    double a = c->v->fade > 0 ? 1 - age / c->v->fade : 1;
                    if (a <= 0.02) continue;
                    status_style(cr, st, c->lw);
                    tri_path(c, T[t].v);
                    set_rank(cr, q, 0.6 * a);
                    cairo_stroke(cr);
                    double x = 0, y = 0, px, py;
                    for (int j = 0; j < 3; j++) {
                        wpt(c, T[t].v[j], &px, &py);
                        x += px / 3;
                        y += py / 3;
                    }
                    cairo_set_line_width(cr, 1.6 * c->lw);
                    cross(cr, x, y, 0.35 * c->L.font);
                    rgb(cr, RED, a);
                    cairo_stroke(cr);
                }
                continue;
            }
            status_style(cr, st, dense ? 0.8 : c->lw);
            set_rank(cr, q, st == PDT_TS_CANDIDATE ? 0.75 : 1);
            /* separate segments (no joins), stroked in chunks: much faster
             * than one long path of closed triangles */
            size_t seg = 0;
            for (size_t i = start[b]; i < start[b + 1]; i++) {
                const uint32_t *v = T[order[i]].v;
                double x[3], y[3];
                for (int j = 0; j < 3; j++) wpt(c, v[j], &x[j], &y[j]);
                if ((x[0] < gx0 && x[1] < gx0 && x[2] < gx0) || (x[0] > gx1 && x[1] > gx1 && x[2] > gx1) ||
                    (y[0] < gy0 && y[1] < gy0 && y[2] < gy0) || (y[0] > gy1 && y[1] > gy1 && y[2] > gy1))
                    continue;
                for (int j = 0; j < 3; j++) {
                    cairo_move_to(cr, x[j], y[j]);
                    cairo_line_to(cr, x[(j + 1) % 3], y[(j + 1) % 3]);
                }
                if ((seg += 3) >= 3000) {
                    cairo_stroke(cr);
                    seg = 0;
                }
            }
            cairo_stroke(cr);
        }
    }
    cairo_restore(cr);
    cairo_set_dash(cr, NULL, 0, 0);
    free(start);
    free(order);
}

static void draw_kernel_edges(ctx *c)
{
    size_t ne;
    const pdt_redge *E = pdt_replay_edges(c->r, &ne);
    if (!ne) return;
    cairo_t *cr = c->cr;
    size_t np;
    const pdt_rphase *Ph = pdt_replay_phases(c->r, &np);
    cairo_save(cr);
    cairo_set_line_width(cr, 0.5 * c->lw);
    if (ne > 20000) cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
    for (int q = 0; q < c->nranks; q++) {
        if (!shown(c, (uint32_t)q)) continue;
        /* the kernel's edges show its progress; once its phase is over the
         * triangles tell the story */
        int in_kernel = 0;
        for (int32_t p = pdt_rstate_slot(c->r, c->s, q, PDT_SLOT_PHASE); p >= 0; p = Ph[p].parent)
            if (Ph[p].phase == PDT_PH_KERNEL || Ph[p].phase == PDT_PH_MERGE) in_kernel = 1;
        if (!in_kernel) continue;
        int any = 0;
        for (size_t e = 0; e < ne; e++) {
            if (!c->s->ealive[e] || E[e].rank != (uint32_t)q) continue;
            double x, y;
            wpt(c, E[e].a, &x, &y);
            cairo_move_to(cr, x, y);
            wpt(c, E[e].b, &x, &y);
            cairo_line_to(cr, x, y);
            any = 1;
        }
        if (any) {
            set_rank(cr, q, 0.45);
            cairo_stroke(cr);
        }
    }
    cairo_restore(cr);
}

/* List a stack from its top node: writes points bottom..top into out, returns count. */
static size_t stack_list(const pdt_replay *r, int32_t top, uint32_t *out, size_t cap)
{
    size_t nn;
    const pdt_rnode *N = pdt_replay_nodes(r, &nn);
    size_t d = top >= 0 ? N[top].depth : 0;
    if (d > cap) d = cap;
    size_t i = d;
    for (int32_t t = top; t >= 0 && i > 0; t = N[t].parent) out[--i] = N[t].pt;
    return d;
}

/* Is hull h of rank q still the hull of q's group (no later merge that
 * covers q has reported its own hull yet)? */
static int hull_live(const ctx *c, int q, int32_t h)
{
    size_t nh, ng;
    const pdt_rhull *Hs = pdt_replay_hulls(c->r, &nh);
    const pdt_rmerge *M = pdt_replay_merges(c->r, &ng);
    for (size_t g = 0; g < ng; g++) {
        if (M[g].begin_ev <= Hs[h].ev || M[g].begin_ev >= c->s->k) continue;
        if ((uint32_t)q < M[g].gl || (uint32_t)q >= M[g].gend) continue;
        int32_t h2 = pdt_rstate_slot(c->r, c->s, (int)M[g].rank, PDT_SLOT_HULL);
        if (h2 >= 0 && h2 != h && Hs[h2].ev > M[g].begin_ev) return 0;
    }
    return 1;
}

/* Has rank q's last Graham scan (begun before the cursor) ended?  Graham's
 * Version B reports no HULL event: once the scan is over, its stack is the
 * hull and is drawn closed. */
static int graham_scan_ended(const ctx *c, int q)
{
    size_t np;
    const pdt_rphase *Ph = pdt_replay_phases(c->r, &np);
    int ended = 0;
    uint32_t last = 0;
    for (size_t i = 0; i < np; i++) {
        if (Ph[i].rank != (uint32_t)q || Ph[i].phase != PDT_PH_GRAHAM_SCAN) continue;
        if (Ph[i].begin_ev >= c->s->k || (ended && Ph[i].begin_ev < last)) continue;
        last = Ph[i].begin_ev;
        ended = Ph[i].end_ev != UINT32_MAX && Ph[i].end_ev < c->s->k;
    }
    return ended;
}

/* Is a stack (its top node) still being built: not yet reported as a hull? */
static int stack_open(const ctx *c, int32_t top)
{
    size_t nn;
    const pdt_rnode *N = pdt_replay_nodes(c->r, &nn);
    return N[top].hull_ev >= c->s->k;
}

static void draw_hulls_and_stacks(ctx *c, uint32_t *buf, size_t cap)
{
    cairo_t *cr = c->cr;
    size_t nh;
    const pdt_rhull *Hs = pdt_replay_hulls(c->r, &nh);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
    for (int q = 0; q < c->nranks; q++) {
        if (!shown(c, (uint32_t)q)) continue;
        int32_t h = pdt_rstate_slot(c->r, c->s, q, PDT_SLOT_HULL);
        if (h < 0 || !hull_live(c, q, h)) continue;
        /* the hull: the first stack bottom..top, then the second (upper chain) */
        size_t k = stack_list(c->r, Hs[h].top, buf, cap);
        size_t k2 = Hs[h].top2 >= 0 ? stack_list(c->r, Hs[h].top2, buf + k, cap - k) : 0;
        if (k + k2 < 2) continue;
        double x, y;
        for (size_t i = 0; i < k + k2; i++) {
            wpt(c, buf[i], &x, &y);
            if (i) cairo_line_to(cr, x, y);
            else cairo_move_to(cr, x, y);
        }
        if (!k2) cairo_close_path(cr);
        double col[3];
        pdt_rank_rgb(q, col);
        cairo_set_line_width(cr, 3.2 * c->lw);
        cairo_set_source_rgba(cr, 0.6 * col[0], 0.6 * col[1], 0.6 * col[2], 0.9);
        cairo_stroke(cr);
    }
    /* open stacks (not yet a reported hull): the chain bottom -> top, top marked */
    for (int q = 0; q < c->nranks; q++) {
        if (!shown(c, (uint32_t)q)) continue;
        for (int st = 0; st < 5; st++) {
            int32_t top = pdt_rstate_slot(c->r, c->s, q, PDT_SLOT_STACK0 + st);
            if (top < 0 || !stack_open(c, top)) continue;
            size_t k = stack_list(c->r, top, buf, cap);
            int closed = st == PDT_STACK_GRAHAM && k >= 3 && graham_scan_ended(c, q);
            double x, y;
            for (size_t i = 0; i < k; i++) {
                wpt(c, buf[i], &x, &y);
                if (i) cairo_line_to(cr, x, y);
                else cairo_move_to(cr, x, y);
            }
            if (closed) { /* the scan is over: the stack is the hull, drawn like one */
                cairo_close_path(cr);
                double col[3];
                pdt_rank_rgb(q, col);
                cairo_set_line_width(cr, 3.2 * c->lw);
                cairo_set_source_rgba(cr, 0.6 * col[0], 0.6 * col[1], 0.6 * col[2], 0.9);
                cairo_stroke(cr);
                continue;
            }
            set_rank(cr, q, 0.9);
            cairo_set_line_width(cr, 2.6 * c->lw);
            cairo_stroke(cr);
            if (k) { /* top marker: a filled triangle above the top point */
                wpt(c, buf[k - 1], &x, &y);
                double a = 0.55 * c->L.font;
                cairo_move_to(cr, x, y - 0.35 * a);
                cairo_line_to(cr, x - 0.6 * a, y - 1.5 * a);
                cairo_line_to(cr, x + 0.6 * a, y - 1.5 * a);
                cairo_close_path(cr);
                rgb(cr, INK, 1);
                cairo_fill(cr);
                double tw = text_wb(cr, SANS, 1, 0.7 * c->L.font, "top");
                text_at(cr, SANS, 1, 0.7 * c->L.font, x - 0.8 * a - tw, y - 1.0 * a, "top");
            }
        }
    }
}

static void draw_points(ctx *c)
{
    cairo_t *cr = c->cr;
    double rad = fmax(1.5, fmin(0.28 * c->L.font, c->spacing / 5));
    size_t nvis = 0;
    for (size_t p = 0; p < c->n; p++) {
        double x, y;
        wpt(c, (uint32_t)p, &x, &y);
        if (x < c->L.geo.x || x > c->L.geo.x + c->L.geo.w || y < c->L.geo.y ||
            y > c->L.geo.y + c->L.geo.h)
            continue;
        nvis++;
    }
    if (nvis > 4000) rad = fmin(rad, 1.5);
    if (nvis > 4000 && c->spacing < 5) return; /* the points would only hide the edges */
    /* not yet lifted: hollow grey; lifted: filled dark */
    for (int pass = 0; pass < 2; pass++) {
        for (size_t p = 0; p < c->n; p++) {
            int lifted = c->all_lifted || (c->s->pflags[p] & PDT_PF_LIFTED) != 0;
            if (lifted != pass) continue;
            double x, y;
            wpt(c, (uint32_t)p, &x, &y);
            if (nvis > 4000) /* pixel-aligned squares: cairo fills them as boxes, fast */
                cairo_rectangle(cr, floor(x) - 1, floor(y) - 1, 2, 2);
            else {
                cairo_new_sub_path(cr);
                cairo_arc(cr, x, y, rad, 0, 2 * M_PI);
            }
        }
        if (pass == 0) {
            cairo_set_source_rgba(cr, 0.55, 0.55, 0.55, 1);
            cairo_set_line_width(cr, 1);
            cairo_stroke(cr);
        } else {
            rgb(cr, INK, 1);
            cairo_fill(cr);
        }
    }
    /* Graham: angular numbers and deleted points */
    if (nvis > 600) return;
    double f = 0.72 * c->L.font;
    /* other runs: the input index beside each point, while few are on screen
     * and they are far enough apart for the labels not to pile up */
    if (nvis <= 60 && c->spacing >= 2.5 * f && pdt_replay_kind_count(c->r, PDT_EV_SORT) == 0) {
        cairo_set_source_rgba(cr, 0.0, 0.25, 0.55, 1);
        for (size_t p = 0; p < c->n; p++) {
            double x, y;
            char lab[24];
            wpt(c, (uint32_t)p, &x, &y);
            if (x < c->L.geo.x || x > c->L.geo.x + c->L.geo.w || y < c->L.geo.y ||
                y > c->L.geo.y + c->L.geo.h)
                continue;
            int crowded = 0; /* a point so close that its label would collide */
            for (size_t q = 0; q < c->n && !crowded; q++) {
                double qx, qy;
                wpt(c, (uint32_t)q, &qx, &qy);
                crowded = q != p && fabs(qx - x) < 1.6 * f && fabs(qy - y) < 0.9 * f;
            }
            if (crowded) continue;
            snprintf(lab, sizeof lab, "%zu", p);
            text_at(cr, SANS, 0, f, x + 0.45 * f, y - 0.3 * f, lab);
        }
    }
    for (size_t p = 0; p < c->n; p++) {
        uint8_t fl = c->s->pflags[p];
        double x, y;
        wpt(c, (uint32_t)p, &x, &y);
        if (fl & PDT_PF_SORTED) {
            char lab[24];
            int64_t pos = pdt_replay_sort_pos(c->r, p);
            if (pos == 0) snprintf(lab, sizeof lab, "p0");
            else snprintf(lab, sizeof lab, "%lld", (long long)pos);
            cairo_set_source_rgba(cr, 0.0, 0.25, 0.55, 1);
            text_at(cr, SANS, pos == 0, f, x + 0.45 * f, y - 0.3 * f, lab);
        }
        if (fl & PDT_PF_DELETED) {
            cairo_set_line_width(cr, 0.18 * f);
            cross(cr, x, y, 0.55 * f);
            rgb(cr, RED, 1);
            cairo_stroke(cr);
        }
    }
}

static void ring(ctx *c, uint32_t p, double rad, const double col[3], double lwf)
{
    double x, y;
    wpt(c, p, &x, &y);
    cairo_new_sub_path(c->cr);
    cairo_arc(c->cr, x, y, rad, 0, 2 * M_PI);
    rgb(c->cr, col, 1);
    cairo_set_line_width(c->cr, lwf);
    cairo_stroke(c->cr);
}

/* The merge step in progress on some rank: border set rings and group boxes. */
static void draw_merge(ctx *c)
{
    size_t ng;
    const pdt_rmerge *M = pdt_replay_merges(c->r, &ng);
    for (int q = 0; q < c->nranks; q++) {
        int32_t g = pdt_rstate_slot(c->r, c->s, q, PDT_SLOT_MERGE);
        if (g < 0 || !shown(c, (uint32_t)q)) continue;
        const pdt_rmerge *mg = &M[g];
        /* the two groups' boxes */
        for (int side = 0; side < 2; side++) {
            uint32_t a = side ? mg->gr : mg->gl, b = side ? mg->gend : mg->gr;
            int have = 0;
            pdt_point lo = {0, 0}, hi = {0, 0};
            for (uint32_t o = a; o < b; o++) {
                pdt_point l, h;
                if (!pdt_replay_box(c->r, (int)o, &l, &h)) continue;
                if (!have) lo = l, hi = h, have = 1;
                lo.x = l.x < lo.x ? l.x : lo.x;
                lo.y = l.y < lo.y ? l.y : lo.y;
                hi.x = h.x > hi.x ? h.x : hi.x;
                hi.y = h.y > hi.y ? h.y : hi.y;
            }
            if (!have) continue;
            double pad = 1.6 * c->L.font;
            double x0 = c->X.ox + c->X.s * lo.x - pad, x1 = c->X.ox + c->X.s * hi.x + pad;
            double y0 = c->X.oy - c->X.s * hi.y - pad, y1 = c->X.oy - c->X.s * lo.y + pad;
            cairo_rectangle(c->cr, x0, y0, x1 - x0, y1 - y0);
            rgb(c->cr, INK, 0.8);
            cairo_set_line_width(c->cr, 1.5);
            double d[2] = {10, 5};
            cairo_set_dash(c->cr, d, 2, 0);
            cairo_stroke(c->cr);
            cairo_set_dash(c->cr, NULL, 0, 0);
            char lab[64];
            snprintf(lab, sizeof lab, "%s", side ? "G_R" : "G_L");
            double tw = text_wb(c->cr, SANS, 1, 0.8 * c->L.font, lab);
            text_at(c->cr, SANS, 1, 0.8 * c->L.font, side ? x1 - tw : x0, y0 - 0.3 * c->L.font, lab);
        }
        /* the border set B: points the merge rank lifted since the merge began */
        size_t from = mg->begin_ev, to = c->s->k;
        if (to - from > 2000000) from = to - 2000000;
        double col[3] = {0.0, 0.0, 0.0};
        for (size_t i = from; i < to; i++) {
            const pdt_rec *e = pdt_replay_rec(c->r, i);
            if (e->rank == mg->rank && e->ev.kind == PDT_EV_LIFT && e->ev.a < c->n)
                ring(c, e->ev.a, 0.45 * c->L.font, col, 1.4);
        }
    }
}

/* The current event's highlight: circumdisk, turn, point rings. */
static void draw_current(ctx *c, uint32_t *buf, size_t cap)
{
    const pdt_rec *e = c->cur;
    if (!e) return;
    cairo_t *cr = c->cr;
    const pdt_event *ev = &e->ev;
    double hl[3] = {0.85, 0.1, 0.1};
    if (is_tri_event(ev->kind) && ev->a < c->n && ev->b < c->n && ev->c < c->n) {
        uint32_t v[3] = {ev->a, ev->b, ev->c};
        double ox, oy, rr;
        tri_path(c, v);
        set_rank(cr, (int)e->rank, 0.25);
        cairo_fill(cr);
        if (circum(c->P, v, &ox, &oy, &rr)) {
            cairo_new_sub_path(cr);
            cairo_arc(cr, c->X.ox + c->X.s * ox, c->X.oy - c->X.s * oy, c->X.s * rr, 0, 2 * M_PI);
            cairo_set_source_rgba(cr, 1.0, 0.85, 0.2, 0.18);
            cairo_fill_preserve(cr);
            cairo_set_source_rgba(cr, 0.8, 0.45, 0.0, 0.95);
            cairo_set_line_width(cr, 2 * c->lw);
            cairo_stroke(cr);
        }
        if (ev->kind == PDT_EV_DISCARD && ev->v >= 0 && (uint64_t)ev->v < c->n)
            ring(c, (uint32_t)ev->v, 0.7 * c->L.font, hl, 2.5);
        return;
    }
    if ((ev->kind == PDT_EV_PUSH || ev->kind == PDT_EV_POP || ev->kind == PDT_EV_LIFT ||
         ev->kind == PDT_EV_SORT || ev->kind == PDT_EV_DELETE) && ev->a < c->n) {
        ring(c, ev->a, 0.75 * c->L.font, hl, 2.5);
        if (ev->kind == PDT_EV_POP && ev->c < c->n) {
            /* the turn that caused the pop: below -> popped -> new point */
            int32_t top = pdt_rstate_slot(c->r, c->s, (int)e->rank, PDT_SLOT_STACK0 + ev->sub);
            size_t k = stack_list(c->r, top, buf, cap);
            if (k >= 1) {
                double x, y;
                wpt(c, buf[k - 1], &x, &y);
                cairo_move_to(cr, x, y);
                wpt(c, ev->a, &x, &y);
                cairo_line_to(cr, x, y);
                wpt(c, ev->c, &x, &y);
                cairo_line_to(cr, x, y);
                double d[2] = {5, 4};
                cairo_set_dash(cr, d, 2, 0);
                rgb(cr, hl, 0.9);
                cairo_set_line_width(cr, 2 * c->lw);
                cairo_stroke(cr);
                cairo_set_dash(cr, NULL, 0, 0);
            }
            ring(c, ev->c, 0.75 * c->L.font, (double[3]){0.0, 0.45, 0.0}, 2.5);
        }
        if (ev->kind == PDT_EV_DELETE && ev->b < c->n)
            ring(c, ev->b, 0.75 * c->L.font, (double[3]){0.0, 0.45, 0.0}, 2.5);
    }
    if ((ev->kind == PDT_EV_EDGE_ADD || ev->kind == PDT_EV_EDGE_DEL) && ev->a < c->n && ev->b < c->n) {
        double x, y;
        wpt(c, ev->a, &x, &y);
        cairo_move_to(cr, x, y);
        wpt(c, ev->b, &x, &y);
        cairo_line_to(cr, x, y);
        rgb(cr, hl, 0.8);
        cairo_set_line_width(cr, 3 * c->lw);
        cairo_stroke(cr);
    }
}

static void draw_selection(ctx *c)
{
    cairo_t *cr = c->cr;
    char lines[5][160];
    int nl = 0;
    if (c->v->sel_point >= 0 && (size_t)c->v->sel_point < c->n) {
        size_t p = (size_t)c->v->sel_point;
        pdt_point q = c->P[p];
        double col[3] = {0.0, 0.3, 0.9};
        ring(c, (uint32_t)p, 0.8 * c->L.font, col, 3);
        snprintf(lines[nl++], sizeof lines[0], "point %zu at (%d, %d)", p, q.x, q.y);
        snprintf(lines[nl++], sizeof lines[0], "lifted z = %lld%s",
                 (long long)((int64_t)q.x * q.x + (int64_t)q.y * q.y),
                 c->s->pflags[p] & PDT_PF_LIFTED ? "" : " (not lifted yet)");
        int64_t pos = pdt_replay_sort_pos(c->r, p);
        if (c->s->pflags[p] & PDT_PF_SORTED)
            snprintf(lines[nl++], sizeof lines[0], "angular position %lld%s", (long long)pos,
                     c->s->pflags[p] & PDT_PF_DELETED ? ", deleted" : "");
        for (int q2 = 0; q2 < c->nranks; q2++) {
            pdt_point lo, hi;
            if (pdt_replay_box(c->r, q2, &lo, &hi) && q.x >= lo.x && q.x <= hi.x && q.y >= lo.y &&
                q.y <= hi.y) {
                snprintf(lines[nl++], sizeof lines[0], "in the box of rank %d", q2);
                break;
            }
        }
    } else if (c->v->sel_tri >= 0) {
        size_t nt;
        const pdt_rtri *T = pdt_replay_tris(c->r, &nt);
        if ((size_t)c->v->sel_tri < nt) {
            const pdt_rtri *t = &T[c->v->sel_tri];
            static const char *const sn[] = {"not created", "candidate", "final", "deferred",
                                             "shipped", "discarded"};
            int e = c->v->sel_edge;
            if (e >= 0 && e < 3) {
                uint32_t a = t->v[e], b = t->v[(e + 1) % 3];
                double x, y;
                wpt(c, a, &x, &y);
                cairo_move_to(cr, x, y);
                wpt(c, b, &x, &y);
                cairo_line_to(cr, x, y);
                cairo_set_source_rgba(cr, 0.0, 0.3, 0.9, 0.9);
                cairo_set_line_width(cr, 5);
                cairo_stroke(cr);
                double dx = (double)c->P[b].x - c->P[a].x, dy = (double)c->P[b].y - c->P[a].y;
                snprintf(lines[nl++], sizeof lines[0], "edge %u–%u, length %.1f", a, b, sqrt(dx * dx + dy * dy));
            }
            tri_path(c, t->v);
            cairo_set_source_rgba(cr, 0.0, 0.3, 0.9, 0.9);
            cairo_set_line_width(cr, 3);
            cairo_stroke(cr);
            snprintf(lines[nl++], sizeof lines[0], "%s %u %u %u", e >= 0 ? "of triangle" : "triangle",
                     t->v[0], t->v[1], t->v[2]);
            snprintf(lines[nl++], sizeof lines[0], "made by rank %u, now %s", t->maker,
                     pdt_rstate_tri_visible(c->r, c->s, (size_t)c->v->sel_tri)
                         ? sn[pdt_replay_tri_hist(c->r)[pdt_rstate_tri_entry(c->r, c->s, (size_t)c->v->sel_tri)].status]
                         : "dropped by its merge");
            double ox, oy, rr;
            if (circum(c->P, t->v, &ox, &oy, &rr))
                snprintf(lines[nl++], sizeof lines[0], "circle centre (%.1f, %.1f) radius %.1f", ox,
                         oy, rr);
        }
    }
    if (!nl) return;
    double f = 0.85 * c->L.font, w = 0;
    for (int i = 0; i < nl; i++) w = fmax(w, text_w(cr, SANS, f, lines[i]));
    pdt_rect R = {c->L.geo.x + 0.5 * f, c->L.geo.y + c->L.geo.h - (nl + 0.8) * 1.3 * f, w + 1.2 * f,
                  (nl + 0.5) * 1.3 * f};
    cairo_rectangle(cr, R.x, R.y, R.w, R.h);
    cairo_set_source_rgba(cr, 1, 1, 1, 0.92);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0.0, 0.3, 0.9);
    cairo_set_line_width(cr, 1.5);
    cairo_stroke(cr);
    rgb(cr, INK, 1);
    for (int i = 0; i < nl; i++) text_at(cr, SANS, i == 0, f, R.x + 0.6 * f, R.y + (i + 1.1) * 1.3 * f, lines[i]);
}

static void draw_geometry(ctx *c)
{
    cairo_t *cr = c->cr;
    cairo_save(cr);
    clip_rect(cr, c->L.geo);

    size_t cap = c->n + 1;
    uint32_t *buf = malloc(2 * cap * sizeof *buf);
    int cur_tri = 0;
    double ox = 0, oy = 0, rr = 0;
    if (c->cur && is_tri_event(c->cur->ev.kind) && c->cur->ev.a < c->n && c->cur->ev.b < c->n &&
        c->cur->ev.c < c->n) {
        uint32_t v[3] = {c->cur->ev.a, c->cur->ev.b, c->cur->ev.c};
        cur_tri = circum(c->P, v, &ox, &oy, &rr);
    }
    draw_boxes(c, cur_tri, ox, oy, rr, 0);
    draw_kernel_edges(c);
    draw_triangles(c);
    if (buf) draw_hulls_and_stacks(c, buf, 2 * cap);
    draw_merge(c);
    draw_points(c);
    if (buf) draw_current(c, buf, 2 * cap);
    draw_boxes(c, cur_tri, ox, oy, rr, 1);
    draw_selection(c);
    free(buf);
    cairo_restore(cr);
}

/* ---- panels ----------------------------------------------------------------------------- */

static void draw_top(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.top;
    cairo_rectangle(cr, R.x, R.y, R.w, R.h);
    cairo_set_source_rgb(cr, 0.93, 0.94, 0.96);
    cairo_fill(cr);
    char line[512], head[64];
    pdt_replay_describe(c->r, c->s->k, line, sizeof line);
    snprintf(head, sizeof head, "%zu / %zu", c->s->k, pdt_replay_count(c->r));
    double f = c->L.font;
    rgb(cr, INK, 0.7);
    text_at(cr, MONO, 0, 0.9 * f, 0.5 * f, 1.35 * f, head);
    double x = 0.5 * f + text_w(cr, MONO, 0.9 * f, head) + 1.0 * f;
    if (c->cur) {
        set_rank(cr, (int)c->cur->rank, 1);
        cairo_rectangle(cr, x, 0.45 * f, 0.7 * f, 1.1 * f);
        cairo_fill(cr);
        x += 1.1 * f;
    }
    rgb(cr, INK, 1);
    text_at(cr, SANS, 1, 1.05 * f, x, 1.4 * f, line);
    if (c->v->status) {
        double tw = text_w(cr, SANS, 0.85 * f, c->v->status);
        rgb(cr, INK, 0.7);
        text_at(cr, SANS, 0, 0.85 * f, R.w - tw - 0.6 * f, 1.35 * f, c->v->status);
    }
}

static void legend_line(cairo_t *cr, double x, double y, double len, int st, double lw,
                        const double col[3])
{
    status_style(cr, st, lw);
    cairo_move_to(cr, x, y);
    cairo_line_to(cr, x + len, y);
    rgb(cr, col, 1);
    cairo_stroke(cr);
    cairo_set_dash(cr, NULL, 0, 0);
}

static void draw_legend(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.legend;
    double f = c->L.font, fs = 0.8 * f;
    panel(cr, R, "Legend", f);
    cairo_save(cr);
    clip_rect(cr, R);
    /* ranks */
    double x = R.x + 0.5 * f, y = R.y + 2.3 * f;
    rgb(cr, INK, 1);
    text_at(cr, SANS, 0, fs, x, y, "ranks:");
    x += text_w(cr, SANS, fs, "ranks:") + 0.4 * f;
    for (int q = 0; q < c->nranks; q++) {
        char lab[16];
        snprintf(lab, sizeof lab, "%d", q);
        double tw = text_w(cr, SANS, fs, lab);
        if (x + 1.2 * f + tw > R.x + R.w - 0.5 * f) {
            text_at(cr, SANS, 0, fs, x, y, "…");
            break;
        }
        cairo_rectangle(cr, x, y - 0.75 * f, 0.8 * f, 0.8 * f);
        set_rank(cr, q, shown(c, (uint32_t)q) ? 1 : 0.2);
        cairo_fill(cr);
        rgb(cr, INK, shown(c, (uint32_t)q) ? 1 : 0.4);
        text_at(cr, SANS, 0, fs, x + 0.95 * f, y, lab);
        x += 1.3 * f + tw;
    }
    /* statuses, two columns */
    static const char *const names[] = {"candidate", "final", "deferred (RA)", "shipped",
                                        "discarded"};
    static const int sts[] = {PDT_TS_CANDIDATE, PDT_TS_FINAL, PDT_TS_DEFERRED, PDT_TS_SHIPPED,
                              PDT_TS_DISCARDED};
    double col0[3];
    pdt_rank_rgb(0, col0);
    double lw = fmax(1.5, 0.14 * f), colw = (R.w - f) / 2;
    for (int i = 0; i < 5; i++) {
        double lx = R.x + 0.5 * f + (i % 2) * colw, ly = R.y + (3.6 + 1.25 * (i / 2)) * f;
        legend_line(cr, lx, ly - 0.3 * f, 2.2 * f, sts[i], lw, col0);
        if (sts[i] == PDT_TS_DISCARDED) {
            cairo_set_line_width(cr, lw);
            cross(cr, lx + 1.1 * f, ly - 0.3 * f, 0.35 * f);
            rgb(cr, RED, 1);
            cairo_stroke(cr);
        }
        rgb(cr, INK, 1);
        text_at(cr, SANS, 0, fs, lx + 2.6 * f, ly, names[i]);
    }
    {   /* hull, in the sixth cell */
        double lx = R.x + 0.5 * f + colw, ly = R.y + (3.6 + 1.25 * 2) * f;
        cairo_set_line_width(cr, 3.2 * lw);
        cairo_move_to(cr, lx, ly - 0.3 * f);
        cairo_line_to(cr, lx + 2.2 * f, ly - 0.3 * f);
        cairo_set_source_rgb(cr, 0.6 * col0[0], 0.6 * col0[1], 0.6 * col0[2]);
        cairo_stroke(cr);
        rgb(cr, INK, 1);
        text_at(cr, SANS, 0, fs, lx + 2.6 * f, ly, "hull / stack");
    }
    /* markers */
    double ly = R.y + 7.05 * f, lx = R.x + 0.5 * f;
    cairo_new_sub_path(cr);
    cairo_arc(cr, lx + 0.4 * f, ly - 0.3 * f, 0.25 * f, 0, 2 * M_PI);
    rgb(cr, INK, 1);
    cairo_fill(cr);
    text_at(cr, SANS, 0, fs, lx + 0.9 * f, ly, "lifted");
    lx += 0.9 * f + text_w(cr, SANS, fs, "lifted") + 0.8 * f;
    cairo_new_sub_path(cr);
    cairo_arc(cr, lx + 0.4 * f, ly - 0.3 * f, 0.25 * f, 0, 2 * M_PI);
    cairo_set_source_rgb(cr, 0.55, 0.55, 0.55);
    cairo_set_line_width(cr, 1);
    cairo_stroke(cr);
    rgb(cr, INK, 1);
    text_at(cr, SANS, 0, fs, lx + 0.9 * f, ly, "not yet");
    lx += 0.9 * f + text_w(cr, SANS, fs, "not yet") + 0.8 * f;
    cairo_set_line_width(cr, 0.15 * f);
    cross(cr, lx + 0.4 * f, ly - 0.3 * f, 0.3 * f);
    rgb(cr, RED, 1);
    cairo_stroke(cr);
    rgb(cr, INK, 1);
    text_at(cr, SANS, 0, fs, lx + 0.9 * f, ly, "deleted");
    lx += 0.9 * f + text_w(cr, SANS, fs, "deleted") + 0.8 * f;
    cairo_new_sub_path(cr);
    cairo_arc(cr, lx + 0.4 * f, ly - 0.3 * f, 0.35 * f, 0, 2 * M_PI);
    cairo_set_source_rgba(cr, 1.0, 0.85, 0.2, 0.4);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0.8, 0.45, 0.0);
    cairo_stroke(cr);
    rgb(cr, INK, 1);
    text_at(cr, SANS, 0, fs, lx + 0.95 * f, ly, "circumdisk (RA)");
    cairo_restore(cr);
}

/* Pseudo-code: Graham Version B or the SRM phases (pdt/describe.h), with the current line. */
static int code_line(const ctx *c, int *graham)
{
    const pdt_rec *e = c->cur;
    *graham = 0;
    if (!e) return -1;
    const pdt_event *ev = &e->ev;
    int32_t ph = pdt_rstate_slot(c->r, c->s, (int)e->rank, PDT_SLOT_PHASE);
    size_t np;
    const pdt_rphase *Ph = pdt_replay_phases(c->r, &np);
    int in_merge = pdt_rstate_slot(c->r, c->s, (int)e->rank, PDT_SLOT_MERGE) >= 0;
    int phase = -1;
    for (int32_t p = ph; p >= 0; p = Ph[p].parent) {
        if (phase < 0 && Ph[p].phase != PDT_PH_RUN) phase = (int)Ph[p].phase;
        if (Ph[p].phase == PDT_PH_MERGE) in_merge = 1;
    }
    if (ev->kind == PDT_EV_PHASE_BEGIN || ev->kind == PDT_EV_PHASE_END) phase = ev->sub;
    int gr = phase == PDT_PH_GRAHAM_SORT || phase == PDT_PH_GRAHAM_SCAN || ev->kind == PDT_EV_SORT ||
             ev->kind == PDT_EV_DELETE ||
             ((ev->kind == PDT_EV_PUSH || ev->kind == PDT_EV_POP) && ev->sub == PDT_STACK_GRAHAM);
    if (gr) {
        *graham = 1;
        switch (ev->kind) {
        case PDT_EV_SORT: return ev->b == 0 ? 0 : 1;
        case PDT_EV_DELETE: return 2;
        case PDT_EV_PUSH: return ev->b <= 2 ? 3 : 7;
        case PDT_EV_POP: return 8;
        case PDT_EV_HULL: return 9;
        case PDT_EV_PHASE_BEGIN: return phase == PDT_PH_GRAHAM_SCAN ? 4 : 0;
        case PDT_EV_PHASE_END: return phase == PDT_PH_GRAHAM_SCAN ? 9 : 2;
        default: return 5;
        }
    }
    switch (ev->kind) {
    case PDT_EV_LIFT: return in_merge ? 7 : 1;
    case PDT_EV_TRI_NEW: return in_merge ? 7 : 2;
    case PDT_EV_EDGE_ADD:
    case PDT_EV_EDGE_DEL:
    case PDT_EV_INCIRCLE: return in_merge ? 7 : 2;
    case PDT_EV_PUSH:
    case PDT_EV_POP:
    case PDT_EV_HULL: return in_merge ? 9 : 2;
    case PDT_EV_TRI_FINAL:
    case PDT_EV_RA_DEFER: return in_merge ? 9 : (ev->kind == PDT_EV_TRI_FINAL ? 3 : 4);
    case PDT_EV_SHIP:
    case PDT_EV_SEND:
    case PDT_EV_RECV:
        return phase == PDT_PH_OUTPUT || phase == PDT_PH_ORDER || phase == PDT_PH_WRITE ? 10 : 6;
    case PDT_EV_DISCARD: return 8;
    case PDT_EV_MERGE_BEGIN: return 7;
    case PDT_EV_MERGE_END: return 9;
    default: break;
    }
    switch (phase) {
    case PDT_PH_READ:
    case PDT_PH_PARTITION: return 0;
    case PDT_PH_LIFT: return 1;
    case PDT_PH_KERNEL:
    case PDT_PH_HULL: return 2;
    case PDT_PH_CLASSIFY: return 3;
    case PDT_PH_MERGE: return 5;
    case PDT_PH_OUTPUT:
    case PDT_PH_ORDER:
    case PDT_PH_WRITE: return 10;
    default: return -1;
    }
}

static void draw_code(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.code;
    double f = c->L.font;
    int graham;
    int line = code_line(c, &graham);
    int id = graham ? PDT_CODE_GRAHAM : PDT_CODE_SRM;
    panel(cr, R, pdt_code_title(id), f);
    cairo_save(cr);
    clip_rect(cr, R);
    int nl = (int)pdt_code_count(id);
    double lh = (R.h - 1.9 * f) / nl;
    if (lh > 1.15 * f) lh = 1.15 * f;
    double fs = fmin(0.78 * f, 0.92 * lh);
    /* shrink to fit the width */
    double wmax = 0;
    for (int i = 0; i < nl; i++) wmax = fmax(wmax, text_w(cr, MONO, fs, pdt_code_text(id, (size_t)i)));
    if (wmax > R.w - 1.2 * f) fs *= (R.w - 1.2 * f) / wmax;
    for (int i = 0; i < nl; i++) {
        double y = R.y + 1.7 * f + (i + 1) * lh;
        if (i == line) {
            cairo_rectangle(cr, R.x + 0.3 * f, y - 0.85 * lh, R.w - 0.6 * f, lh);
            cairo_set_source_rgba(cr, 1.0, 0.85, 0.2, 0.8);
            cairo_fill(cr);
        }
        rgb(cr, INK, 1);
        text_at(cr, MONO, i == line, fs, R.x + 0.6 * f, y - 0.18 * lh, pdt_code_text(id, (size_t)i));
    }
    cairo_restore(cr);
}

/* A stack element as text: p<angular number> on Graham's stack, else the index. */
static void stack_item(const ctx *c, int st, uint32_t p, int space, char *b, size_t cap)
{
    int64_t pos = st == PDT_STACK_GRAHAM ? pdt_replay_sort_pos(c->r, p) : -1;
    if (pos >= 0) snprintf(b, cap, space ? "p%lld " : "p%lld", (long long)pos);
    else snprintf(b, cap, space ? "%u " : "%u", p);
}

static void draw_stack_panel(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.stack;
    double f = c->L.font;
    panel(cr, R, "Stacks being built (top at the right ▸)", f);
    cairo_save(cr);
    clip_rect(cr, R);
    double fs = 0.75 * f, lh = 1.15 * fs, y = R.y + 1.6 * f + lh;
    uint32_t *buf = malloc((c->n + 1) * sizeof *buf);
    int any = 0;
    for (int q = 0; q < c->nranks && buf; q++) {
        if (!shown(c, (uint32_t)q)) continue;
        for (int st = 0; st < 5; st++) {
            if (y > R.y + R.h - 0.3 * f) break;
            int32_t top = pdt_rstate_slot(c->r, c->s, q, PDT_SLOT_STACK0 + st);
            if (top < 0 || !stack_open(c, top)) continue;
            size_t k = stack_list(c->r, top, buf, c->n + 1);
            char head[48];
            snprintf(head, sizeof head, "r%d %s (%zu):", q, pdt_stack_name(st), k);
            set_rank(cr, q, 1);
            text_at(cr, SANS, 1, fs, R.x + 0.5 * f, y, head);
            double x0 = R.x + 0.5 * f + text_wb(cr, SANS, 1, fs, head) + 0.4 * f;
            /* as many elements from the top as fit */
            double room = R.x + R.w - 0.5 * f - x0 - 1.5 * f;
            size_t first = k;
            double wsum = 0;
            char num[24];
            while (first > 0) {
                stack_item(c, st, buf[first - 1], 1, num, sizeof num);
                double tw = text_w(cr, MONO, fs, num);
                if (wsum + tw > room) break;
                wsum += tw;
                first--;
            }
            double x = x0;
            rgb(cr, INK, 1);
            if (first > 0) {
                text_at(cr, MONO, 0, fs, x, y, "…");
                x += text_w(cr, MONO, fs, "… ");
            }
            for (size_t i = first; i < k; i++) {
                stack_item(c, st, buf[i], i + 1 < k, num, sizeof num);
                text_at(cr, MONO, i + 1 == k, fs, x, y, num);
                x += text_w(cr, MONO, fs, num);
            }
            if (k) text_at(cr, SANS, 1, fs, x + 0.2 * f, y, "▸");
            y += lh;
            any = 1;
        }
    }
    if (!any) {
        rgb(cr, INK, 0.5);
        text_at(cr, SANS, 0, fs, R.x + 0.5 * f, y, "(no stack in use)");
    }
    free(buf);
    cairo_restore(cr);
}

/* ---- lifted view ----------------------------------------------------------------------------- */

typedef struct proj {
    double cx, cy, sc;      /* world -> unit square */
    double cy_, sy_, cp, sp;/* yaw and pitch */
    double ox, oy, s;       /* unit -> screen */
} proj;

size_t pdt_render_inside_count(const pdt_replay *r, const uint32_t v[3])
{
    size_t n;
    const pdt_point *P = pdt_replay_points(r, &n);
    if (v[0] >= n || v[1] >= n || v[2] >= n) return 0;
    int ccw = pdt_orient(P[v[0]], P[v[1]], P[v[2]]);
    size_t k = 0;
    if (ccw)
        for (size_t p = 0; p < n; p++) k += ccw * pdt_incircle0(P[v[0]], P[v[1]], P[v[2]], P[p]) > 0;
    return k;
}

static void lift_xy(const proj *J, double u, double w, double z, double *sx, double *sy)
{
    double X = u * J->cy_ - w * J->sy_, Y = u * J->sy_ + w * J->cy_;
    *sx = J->ox + J->s * X;
    *sy = J->oy - J->s * (z * J->cp + Y * J->sp);
}

static void draw_lifted(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.lifted;
    double f = c->L.font;
    panel(cr, R, "Lifted view: z = x² + y² (drag to rotate)", f);
    cairo_save(cr);
    clip_rect(cr, R);
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
    double top = R.y + 1.6 * f, H = R.h - 1.9 * f;
    /* vertical extent: z in [0,2], Y in [-1.42,1.42] */
    double ext_y = 2 * J.cp + 2.9 * J.sp, ext_x = 2.9;
    J.s = fmin((R.w - f) / ext_x, H / ext_y);
    J.ox = R.x + R.w / 2;
    J.oy = top + H / 2 + J.s * (J.cp * 1.0);
    /* the paraboloid: rings and meridians */
    cairo_set_line_width(cr, 1);
    cairo_set_source_rgba(cr, 0.5, 0.55, 0.65, 0.5);
    for (int ring_i = 1; ring_i <= 5; ring_i++) {
        double rho = 0.28 * ring_i;
        for (int i = 0; i <= 48; i++) {
            double a = 2 * M_PI * i / 48, sx, sy;
            lift_xy(&J, rho * cos(a), rho * sin(a), rho * rho, &sx, &sy);
            if (i) cairo_line_to(cr, sx, sy);
            else cairo_move_to(cr, sx, sy);
        }
    }
    for (int mi = 0; mi < 12; mi++) {
        double a = 2 * M_PI * mi / 12;
        for (int i = 0; i <= 20; i++) {
            double rho = 1.4 * i / 20, sx, sy;
            lift_xy(&J, rho * cos(a), rho * sin(a), rho * rho, &sx, &sy);
            if (i) cairo_line_to(cr, sx, sy);
            else cairo_move_to(cr, sx, sy);
        }
    }
    cairo_stroke(cr);
    /* the current triangle's lifted plane */
    const pdt_rec *e = c->cur;
    int have_plane = 0;
    double pa = 0, pb = 0, pc = 0;
    uint32_t tv[3] = {0, 0, 0};
    if (e && is_tri_event(e->ev.kind) && e->ev.a < c->n && e->ev.b < c->n && e->ev.c < c->n) {
        tv[0] = e->ev.a;
        tv[1] = e->ev.b;
        tv[2] = e->ev.c;
        double U[3], W[3], Z[3];
        for (int j = 0; j < 3; j++) {
            U[j] = (c->P[tv[j]].x - J.cx) / J.sc;
            W[j] = (c->P[tv[j]].y - J.cy) / J.sc;
            Z[j] = U[j] * U[j] + W[j] * W[j];
        }
        /* z = pa*u + pb*w + pc through the three lifted points */
        double d = (U[1] - U[0]) * (W[2] - W[0]) - (U[2] - U[0]) * (W[1] - W[0]);
        if (fabs(d) > 1e-15) {
            pa = ((Z[1] - Z[0]) * (W[2] - W[0]) - (Z[2] - Z[0]) * (W[1] - W[0])) / d;
            pb = ((U[1] - U[0]) * (Z[2] - Z[0]) - (U[2] - U[0]) * (Z[1] - Z[0])) / d;
            pc = Z[0] - pa * U[0] - pb * W[0];
            have_plane = 1;
            static const double cu[4] = {-1.3, 1.3, 1.3, -1.3}, cw[4] = {-1.3, -1.3, 1.3, 1.3};
            for (int j = 0; j < 4; j++) {
                double sx, sy;
                lift_xy(&J, cu[j], cw[j], pa * cu[j] + pb * cw[j] + pc, &sx, &sy);
                if (j) cairo_line_to(cr, sx, sy);
                else cairo_move_to(cr, sx, sy);
            }
            cairo_close_path(cr);
            cairo_set_source_rgba(cr, 1.0, 0.8, 0.2, 0.22);
            cairo_fill_preserve(cr);
            cairo_set_source_rgba(cr, 0.8, 0.45, 0.0, 0.7);
            cairo_set_line_width(cr, 1);
            cairo_stroke(cr);
        }
    }
    /* the points: lifted ones on the paraboloid (rank colour of their box),
     * others faint on the floor; those below the plane in red */
    size_t step = c->n > 6000 ? c->n / 6000 : 1;
    double rad = c->n > 1000 ? 1.4 : 2.6;
    /* inside the circle, exactly: every input point, lifted or not (the
     * drawing below samples large inputs; the count does not) */
    int ccw = have_plane ? pdt_orient(c->P[tv[0]], c->P[tv[1]], c->P[tv[2]]) : 0;
    size_t ninside = ccw ? pdt_render_inside_count(c->r, tv) : 0;
    for (int cls = 0; cls < 3; cls++) { /* 0 floor, 1 lifted, 2 below the plane: one fill each */
        for (size_t p = 0; p < c->n; p += step) {
            double u = (c->P[p].x - J.cx) / J.sc, w = (c->P[p].y - J.cy) / J.sc, z = u * u + w * w;
            int lifted = c->all_lifted || (c->s->pflags[p] & PDT_PF_LIFTED) != 0;
            int below = ccw && lifted &&
                        ccw * pdt_incircle0(c->P[tv[0]], c->P[tv[1]], c->P[tv[2]], c->P[p]) > 0;
            if ((below ? 2 : lifted ? 1 : 0) != cls) continue;
            double sx, sy;
            lift_xy(&J, u, w, lifted ? z : 0, &sx, &sy);
            double rr = below ? rad * 1.8 : rad;
            if (step > 1 || c->n > 2000) cairo_rectangle(cr, floor(sx) - 1, floor(sy) - 1, 2, 2);
            else {
                cairo_new_sub_path(cr);
                cairo_arc(cr, sx, sy, rr, 0, 2 * M_PI);
            }
        }
        if (cls == 2) rgb(cr, RED, 1);
        else if (cls == 1) rgb(cr, INK, 0.85);
        else cairo_set_source_rgba(cr, 0.6, 0.6, 0.6, 0.5);
        cairo_fill(cr);
    }
    if (have_plane) {
        for (int j = 0; j < 3; j++) {
            double u = (c->P[tv[j]].x - J.cx) / J.sc, w = (c->P[tv[j]].y - J.cy) / J.sc, sx, sy;
            lift_xy(&J, u, w, u * u + w * w, &sx, &sy);
            if (j) cairo_line_to(cr, sx, sy);
            else cairo_move_to(cr, sx, sy);
        }
        cairo_close_path(cr);
        set_rank(cr, (int)e->rank, 0.5);
        cairo_fill_preserve(cr);
        set_rank(cr, (int)e->rank, 1);
        cairo_set_line_width(cr, 2);
        cairo_stroke(cr);
        char lab[128];
        snprintf(lab, sizeof lab, "%zu input point%s strictly inside the circle (exact, no tie rule)",
                 ninside, ninside == 1 ? "" : "s");
        rgb(cr, ninside ? RED : INK, 1);
        text_at(cr, SANS, 0, 0.72 * f, R.x + 0.5 * f, R.y + R.h - 1.4 * f, lab);
        rgb(cr, INK, 1);
        text_at(cr, SANS, 0, 0.72 * f, R.x + 0.5 * f, R.y + R.h - 0.5 * f,
                "those already lifted: below the plane (red)");
    }
    if (c->no_lift) {
        rgb(cr, INK, 1);
        text_at(cr, SANS, 0, 0.8 * f, R.x + 0.5 * f, R.y + R.h - 0.5 * f,
                "no lift-up in this run (points stay on the floor)");
    }
    cairo_restore(cr);
}

/* ---- timeline ----------------------------------------------------------------------------------- */

static void draw_timeline(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.timeline;
    double f = c->L.font;
    panel(cr, R, NULL, f);
    cairo_save(cr);
    clip_rect(cr, R);
    size_t m = pdt_replay_count(c->r);
    int rows = c->nranks;
    double lab = 3.2 * f, x0 = R.x + lab, x1 = R.x + R.w - 0.6 * f;
    double y0 = R.y + 0.4 * f, y1 = R.y + R.h - 1.3 * f;
    double rh = (y1 - y0) / (rows ? rows : 1);
    double scale = m ? (x1 - x0) / (double)m : 0;
    size_t np;
    const pdt_rphase *Ph = pdt_replay_phases(c->r, &np);
    /* phases as bars (nested ones thinner) */
    for (size_t i = 0; i < np; i++) {
        const pdt_rphase *p = &Ph[i];
        if (p->phase == PDT_PH_RUN || p->rank >= (uint32_t)rows) continue;
        int depth = 0;
        for (int32_t a = p->parent; a >= 0; a = Ph[a].parent)
            if (Ph[a].phase != PDT_PH_RUN) depth++;
        double bx0 = x0 + scale * p->begin_ev;
        double bx1 = x0 + scale * (double)(p->end_ev == NONE32 ? m : (size_t)p->end_ev + 1);
        double ry = y0 + rh * p->rank, inset = rh * (0.12 + 0.15 * (depth > 2 ? 2 : depth));
        double col[3];
        phase_rgb((int)p->phase, col);
        cairo_rectangle(cr, bx0, ry + inset, fmax(bx1 - bx0, 1), rh - 2 * inset);
        cairo_set_source_rgb(cr, col[0], col[1], col[2]);
        cairo_fill(cr);
        const char *nm = pdt_phase_name((int)p->phase);
        char lb[32];
        if (p->phase == PDT_PH_MERGE) snprintf(lb, sizeof lb, "merge %u", p->sub);
        else snprintf(lb, sizeof lb, "%s", nm ? nm : "?");
        double fs = fmin(0.7 * f, 0.6 * rh);
        if (bx1 - bx0 > text_w(cr, SANS, fs, lb) + 4 && depth == 0) {
            rgb(cr, INK, 0.85);
            text_at(cr, SANS, 0, fs, bx0 + 2, ry + rh / 2 + 0.35 * fs, lb);
        }
    }
    /* rank labels */
    for (int q = 0; q < rows; q++) {
        char lb[16];
        snprintf(lb, sizeof lb, "r%d", q);
        set_rank(cr, q, shown(c, (uint32_t)q) ? 1 : 0.3);
        cairo_rectangle(cr, R.x + 0.4 * f, y0 + rh * q + rh * 0.2, 0.5 * f, rh * 0.6);
        cairo_fill(cr);
        rgb(cr, INK, 1);
        text_at(cr, SANS, 0, fmin(0.75 * f, 0.8 * rh), R.x + 1.1 * f, y0 + rh * (q + 0.5) + 0.25 * fmin(0.75 * f, 0.8 * rh), lb);
    }
    /* messages as arrows */
    size_t nm;
    const pdt_rmsg *Ms = pdt_replay_msgs(c->r, &nm);
    size_t stride = nm > 3000 ? nm / 3000 : 1;
    cairo_set_line_width(cr, 1);
    for (size_t i = 0; i < nm; i += stride) {
        const pdt_rmsg *g = &Ms[i];
        if (g->send_ev == NONE32 || g->recv_ev == NONE32) continue;
        double ax = x0 + scale * (g->send_ev + 0.5), ay = y0 + rh * (g->src + 0.5);
        double bx = x0 + scale * (g->recv_ev + 0.5), by = y0 + rh * (g->dst + 0.5);
        cairo_move_to(cr, ax, ay);
        cairo_line_to(cr, bx, by);
        int fl = c->s->mflight[i];
        cairo_set_source_rgba(cr, fl ? 0.85 : 0.2, fl ? 0.1 : 0.2, fl ? 0.1 : 0.2, fl ? 1 : 0.6);
        cairo_stroke(cr);
        double ang = atan2(by - ay, bx - ax), a = 0.35 * f;
        cairo_move_to(cr, bx, by);
        cairo_line_to(cr, bx - a * cos(ang - 0.4), by - a * sin(ang - 0.4));
        cairo_line_to(cr, bx - a * cos(ang + 0.4), by - a * sin(ang + 0.4));
        cairo_close_path(cr);
        cairo_fill(cr);
    }
    /* cursor */
    double cx = x0 + scale * (double)c->s->k;
    cairo_move_to(cr, cx, R.y + 0.2 * f);
    cairo_line_to(cr, cx, y1 + 0.2 * f);
    cairo_set_source_rgb(cr, 0.85, 0.0, 0.0);
    cairo_set_line_width(cr, 2);
    cairo_stroke(cr);
    /* axis text */
    char ax[96];
    snprintf(ax, sizeof ax, "timeline: events 0 … %zu (bars = phases, arrows = messages; click to seek)", m);
    rgb(cr, INK, 0.75);
    text_at(cr, SANS, 0, 0.7 * f, x0, R.y + R.h - 0.35 * f, ax);
    cairo_restore(cr);
}

size_t pdt_render_timeline_at(const pdt_replay *r, const pdt_view *v, double w, double h, double sx,
                              double sy)
{
    pdt_layout L;
    pdt_render_layout_panels(w, h, pdt_replay_nranks(r), v ? v->panels : PDT_PANEL_ALL, &L);
    pdt_rect R = L.timeline;
    if (R.w <= 0 || R.h <= 0) return (size_t)-1;
    if (sx < R.x || sx > R.x + R.w || sy < R.y || sy > R.y + R.h) return (size_t)-1;
    double x0 = R.x + 3.2 * L.font, x1 = R.x + R.w - 0.6 * L.font;
    double t = (sx - x0) / (x1 - x0);
    if (t < 0) t = 0;
    if (t > 1) t = 1;
    return (size_t)(t * (double)pdt_replay_count(r) + 0.5);
}

/* ---- help overlay ------------------------------------------------------------------------------ */

static void draw_help(ctx *c, double w, double h)
{
    static const char *const keys[][2] = {
        {"Space", "play / pause"},
        {"→  ←", "one event forwards / backwards"},
        {"Shift + → ←", "next / previous event of the selected kind"},
        {"k", "select the kind: push/pop, lift-up, rejection, merge, triangle"},
        {"PgDn  PgUp", "next / previous phase"},
        {"Home  End", "first / last event"},
        {"+  −", "faster / slower playback"},
        {"1 … 9", "show / hide rank 0 … 8"},
        {"0", "show all ranks"},
        {"wheel", "zoom at the cursor"},
        {"drag", "pan (in the lifted view: rotate)"},
        {"click", "details of a point, edge or triangle; timeline: seek"},
        {"f", "fit the points in the window"},
        {"h  ?", "this help"},
        {"s", "screenshot (PNG)"},
        {"Esc  q", "quit"},
    };
    int nk = (int)(sizeof keys / sizeof *keys);
    cairo_t *cr = c->cr;
    double f = c->L.font * 1.05, kw = 0, dw = 0;
    for (int i = 0; i < nk; i++) {
        kw = fmax(kw, text_wb(cr, MONO, 1, 0.9 * f, keys[i][0]));
        dw = fmax(dw, text_w(cr, SANS, 0.9 * f, keys[i][1]));
    }
    double bw = fmin(w * 0.96, kw + dw + 3.5 * f), bh = (nk + 2.6) * 1.45 * f;
    double bx = (w - bw) / 2, by = (h - bh) / 2;
    cairo_rectangle(cr, 0, 0, w, h);
    cairo_set_source_rgba(cr, 0, 0, 0, 0.35);
    cairo_fill(cr);
    cairo_rectangle(cr, bx, by, bw, bh);
    cairo_set_source_rgba(cr, 1, 1, 1, 0.97);
    cairo_fill_preserve(cr);
    rgb(cr, INK, 1);
    cairo_set_line_width(cr, 2);
    cairo_stroke(cr);
    text_at(cr, SANS, 1, 1.2 * f, bx + f, by + 1.7 * f, "Keys");
    char sel[96];
    snprintf(sel, sizeof sel, "(selected kind: %s)", pdt_ev_class_name(c->v->ev_class));
    text_at(cr, SANS, 0, 0.85 * f, bx + 5 * f, by + 1.7 * f, sel);
    for (int i = 0; i < nk; i++) {
        double y = by + (i + 2.4) * 1.45 * f + 0.4 * f;
        text_at(cr, MONO, 1, 0.9 * f, bx + f, y, keys[i][0]);
        text_at(cr, SANS, 0, 0.9 * f, bx + kw + 2.5 * f, y, keys[i][1]);
    }
}

/* ---- entry points ------------------------------------------------------------------------------ */

pdt_status pdt_render(cairo_t *cr, double w, double h, const pdt_replay *r, const pdt_rstate *s,
                      const pdt_view *v, pdt_err *err)
{
    ctx c;
    memset(&c, 0, sizeof c);
    c.cr = cr;
    c.r = r;
    c.s = s;
    c.v = v;
    c.nranks = pdt_replay_nranks(r);
    c.P = pdt_replay_points(r, &c.n);
    pdt_render_layout_panels(w, h, c.nranks, v->panels, &c.L);
    c.X = geo_xform(r, v, w, h);
    c.cur = s->k ? pdt_replay_rec(r, s->k - 1) : NULL;
    c.all_lifted = pdt_replay_kind_count(r, PDT_EV_LIFT) == 0 &&
                   pdt_replay_kind_count(r, PDT_EV_TRI_NEW) > 0;
    c.no_lift = pdt_replay_kind_count(r, PDT_EV_LIFT) == 0 && !c.all_lifted;
    /* line width: thick on a projector, thinner when edges are dense */
    size_t nt;
    pdt_replay_tris(r, &nt);
    double spacing = c.n ? c.X.s * sqrt(1.0 / (double)c.n) : 10;
    pdt_point lo, hi;
    if (pdt_replay_bbox(r, &lo, &hi))
        spacing = c.X.s * sqrt(fmax(1.0, ((double)hi.x - lo.x) * ((double)hi.y - lo.y)) / (double)(c.n ? c.n : 1));
    c.lw = fmax(0.5, fmin(0.16 * c.L.font, spacing / 9));
    c.spacing = spacing;

    cairo_save(cr);
    cairo_rectangle(cr, 0, 0, w, h);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_fill(cr);
    draw_geometry(&c);
    draw_top(&c);
    draw_legend(&c);
    if (c.L.code.w > 0) draw_code(&c);
    if (c.L.stack.w > 0) draw_stack_panel(&c);
    if (c.L.lifted.w > 0) draw_lifted(&c);
    if (c.L.timeline.w > 0) draw_timeline(&c);
    if (v->help) draw_help(&c, w, h);
    cairo_restore(cr);
    cairo_status_t cs = cairo_status(cr);
    if (cs != CAIRO_STATUS_SUCCESS)
        return pdt_err_set(err, PDT_ERR_IO, "cairo: %s",
                           cairo_status_to_string(cs));
    return PDT_OK;
}

static int ends_with(const char *s, const char *suf)
{
    size_t a = strlen(s), b = strlen(suf);
    return a >= b && !strcasecmp(s + a - b, suf);
}

pdt_status pdt_render_file(const char *path, int w, int h, const pdt_replay *r,
                           const pdt_rstate *s, const pdt_view *v, pdt_err *err)
{
    cairo_surface_t *sf;
    int png = 0;
    if (ends_with(path, ".png")) {
        sf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h);
        png = 1;
    } else if (ends_with(path, ".svg")) {
        sf = cairo_svg_surface_create(path, w, h);
    } else if (ends_with(path, ".pdf")) {
        sf = cairo_pdf_surface_create(path, w, h);
    } else {
        return pdt_err_set(err, PDT_ERR_ARG, "%s: unknown picture format (use .png, .svg or .pdf)",
                           path);
    }
    if (cairo_surface_status(sf) != CAIRO_STATUS_SUCCESS) {
        pdt_status st = pdt_err_set(err, PDT_ERR_IO, "%s: %s", path,
                                    cairo_status_to_string(cairo_surface_status(sf)));
        cairo_surface_destroy(sf);
        return st;
    }
    cairo_t *cr = cairo_create(sf);
    pdt_status st = pdt_render(cr, w, h, r, s, v, err);
    cairo_destroy(cr);
    if (st == PDT_OK && png) {
        cairo_status_t cs = cairo_surface_write_to_png(sf, path);
        if (cs != CAIRO_STATUS_SUCCESS)
            st = pdt_err_set(err, PDT_ERR_IO, "%s: %s", path, cairo_status_to_string(cs));
    }
    cairo_surface_finish(sf);
    if (st == PDT_OK && cairo_surface_status(sf) != CAIRO_STATUS_SUCCESS)
        st = pdt_err_set(err, PDT_ERR_IO, "%s: %s", path,
                         cairo_status_to_string(cairo_surface_status(sf)));
    cairo_surface_destroy(sf);
    return st;
}

/* ---- picking ----------------------------------------------------------------------------------- */

void pdt_render_pick(const pdt_replay *r, const pdt_rstate *s, const pdt_view *v, double w,
                     double h, double sx, double sy, double radius, int64_t *point, int64_t *tri,
                     int *edge)
{
    *point = *tri = -1;
    *edge = -1;
    size_t n;
    const pdt_point *P = pdt_replay_points(r, &n);
    xform X = geo_xform(r, v, w, h);
    double best = radius * radius;
    for (size_t p = 0; p < n; p++) {
        double dx = X.ox + X.s * P[p].x - sx, dy = X.oy - X.s * P[p].y - sy;
        if (dx * dx + dy * dy <= best) {
            best = dx * dx + dy * dy;
            *point = (int64_t)p;
        }
    }
    if (*point >= 0) return;
    double wx = (sx - X.ox) / X.s, wy = (X.oy - sy) / X.s;
    size_t nt;
    const pdt_rtri *T = pdt_replay_tris(r, &nt);
    const pdt_rtri_hist *H = pdt_replay_tri_hist(r);
    int nr = pdt_replay_nranks(r);
    double best_e = radius * radius / 4;
    int64_t inside = -1;
    for (size_t t = 0; t < nt; t++) {
        uint32_t he = pdt_rstate_tri_entry(r, s, t);
        if (he == UINT32_MAX || H[he].status == PDT_TS_DISCARDED) continue;
        if (v->hidden && T[t].maker < (uint32_t)nr && v->hidden[T[t].maker]) continue;
        int pos = 0, neg = 0;
        for (int j = 0; j < 3; j++) {
            pdt_point a = P[T[t].v[j]], b = P[T[t].v[(j + 1) % 3]];
            double o = ((double)b.x - a.x) * (wy - a.y) - ((double)b.y - a.y) * (wx - a.x);
            pos |= o > 0;
            neg |= o < 0;
            /* distance on screen from the click to the segment a-b */
            double ax = X.ox + X.s * a.x, ay = X.oy - X.s * a.y, bx = X.ox + X.s * b.x,
                   by = X.oy - X.s * b.y;
            double ex = bx - ax, ey = by - ay, l2 = ex * ex + ey * ey;
            double u = l2 > 0 ? ((sx - ax) * ex + (sy - ay) * ey) / l2 : 0;
            u = u < 0 ? 0 : u > 1 ? 1 : u;
            double qx = ax + u * ex - sx, qy = ay + u * ey - sy;
            if (qx * qx + qy * qy < best_e) {
                best_e = qx * qx + qy * qy;
                *tri = (int64_t)t;
                *edge = j;
            }
        }
        if (!(pos && neg) && (inside < 0 || H[he].status == PDT_TS_FINAL)) inside = (int64_t)t;
    }
    if (*edge < 0) *tri = inside;
}
