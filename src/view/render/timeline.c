/* pdt — the viewer's timeline: one row per rank, phases as bars, messages
 * as arrows, the cursor; and seeking by a click on it. */
#include "render_int.h"

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

void pdt_timeline_axis(pdt_rect R, double f, double *x0, double *x1)
{
    *x0 = R.x + 3.2 * f; /* room for the rank labels */
    *x1 = R.x + R.w - 0.6 * f;
}

void pdt_draw_timeline(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.timeline;
    double f = c->L.font;
    panel(cr, c->T, R, NULL, f);
    cairo_save(cr);
    clip_rect(cr, R);
    size_t m = pdt_replay_count(c->r);
    int rows = c->nranks;
    double x0, x1;
    pdt_timeline_axis(R, f, &x0, &x1);
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
            cairo_set_source_rgba(cr, 0.1, 0.1, 0.12, 0.9); /* on the pastel bar, in every theme */
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
        rgb(cr, c->T->ink, 1);
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
        if (fl) rgb(cr, RED, 1);
        else rgb(cr, c->T->ink, 0.6);
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
    rgb(cr, c->T->ink, 0.75);
    text_at(cr, SANS, 0, 0.7 * f, x0, R.y + R.h - 0.35 * f, ax);
    cairo_restore(cr);
}

size_t pdt_render_timeline_at(const pdt_replay *r, const pdt_view *v, double w, double h, double sx,
                              double sy)
{
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(r), v, &L);
    pdt_rect R = L.timeline;
    if (R.w <= 0 || R.h <= 0) return (size_t)-1;
    if (sx < R.x || sx > R.x + R.w || sy < R.y || sy > R.y + R.h) return (size_t)-1;
    double x0, x1;
    pdt_timeline_axis(R, L.font, &x0, &x1);
    double t = (sx - x0) / (x1 - x0);
    if (t < 0) t = 0;
    if (t > 1) t = 1;
    size_t k = (size_t)(t * (double)pdt_replay_count(r) + 0.5);
    /* in a rank's row: that rank's event nearest the clicked time */
    int rows = pdt_replay_nranks(r);
    double y0 = R.y + 0.4 * L.font, y1 = R.y + R.h - 1.3 * L.font;
    double rh = (y1 - y0) / (rows ? rows : 1);
    if (rows > 0 && sy >= y0 && sy < y1) {
        int q = (int)((sy - y0) / rh);
        if (q >= rows) q = rows - 1;
        size_t kq = pdt_replay_nearest_of_rank(r, k, q);
        if (kq != (size_t)-1) return kq;
    }
    return k;
}
