/* pdt — the viewer's timeline: one row per group of ranks (a subtree of the
 * merge tree; up to eight ranks, one row per rank), phases as bars,
 * messages as arrows, the cursor; and seeking by a click on it.
 *
 * A row is never shorter than its label (16 px at least): when the rows do
 * not fit they scroll (pdt_view.tl_row0).  The events shown are a window of
 * run's time (pdt_view.tl_t0 .. tl_t1, fractions of the span of its times:
 * pdt_ranktree_at; of its events when the trace has no times).  The window is
 * measured in "event units" (tl_geom.k0, k1: the fraction times the number of
 * events), so that zooming in stops at about eight events across.  A group's row shows each of its ranks'
 * phases as a thin strip; when the arrows between groups would be denser
 * than a few per row they are bundled, one arrow per pair of rows and
 * stretch of time, with its count. */
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

static int digits(int n)
{
    int d = 1;
    while (n >= 10) {
        n /= 10;
        d++;
    }
    return d;
}

void pdt_timeline_geom(pdt_rect R, double f, int nranks, size_t nrows, size_t m, const pdt_view *v,
                       tl_geom *g)
{
    g->fs = 0.82 * f; /* the layout's label size (pdt_layout.label) */
    double rmin = fmax(16, 1.2 * g->fs);
    /* the label column: "r3" up to eight ranks, "r512–1023" beyond */
    int len = nranks <= 10 ? 3 : 2 + 2 * digits(nranks - 1);
    g->x0 = R.x + 1.1 * f + (nranks <= 10 ? 2.1 * f : 0.64 * g->fs * len + 0.4 * f);
    g->x1 = R.x + R.w - 0.6 * f;
    g->y0 = R.y + 0.4 * f;
    g->y1 = R.y + R.h - 1.3 * f;
    double band = g->y1 - g->y0;
    int fit = (int)(band / rmin);
    if (fit < 1) fit = 1;
    int n = nrows ? (int)nrows : 1;
    g->nshow = n <= fit ? n : fit;
    g->rh = band / g->nshow;
    int r0 = v ? v->tl_row0 : 0;
    if (r0 > n - g->nshow) r0 = n - g->nshow;
    g->row0 = r0 < 0 ? 0 : r0;
    double t0 = v ? v->tl_t0 : 0, t1 = v ? v->tl_t1 : 1;
    if (!(t0 >= 0 && t1 <= 1 && t1 > t0)) t0 = 0, t1 = 1;
    g->k0 = t0 * (double)m;
    g->k1 = t1 * (double)m;
    if (g->k1 - g->k0 < 1) g->k1 = g->k0 + 1;
}

/* Texts placed in the timeline, so that no two overlap. */
typedef struct placed {
    pdt_rect r[256];
    int n;
} placed;

static int place(placed *P, double x, double y, double w, double h)
{
    for (int i = 0; i < P->n; i++) {
        const pdt_rect *q = &P->r[i];
        if (x < q->x + q->w && q->x < x + w && y < q->y + q->h && q->y < y + h) return 0;
    }
    if (P->n < 256) P->r[P->n++] = (pdt_rect){x, y, w, h};
    return 1;
}

/* Everything the drawing of one timeline shares. */
typedef struct tl {
    ctx *c;
    tl_geom g;
    const pdt_rtnode *N;
    int32_t *rowof;   /* per rank: its row among those shown, or -1 */
    double scale;     /* pixels per event unit */
    double m;         /* events: a time u of the clock is at u * m units */
    const double *pa, *ma;  /* the phases' and messages' ends on the clock */
    placed P;
} tl;

static double ev_x(const tl *t, double k)
{
    return t->g.x0 + t->scale * (k - t->g.k0);
}

/* A label on a bar, if it fits in the bar and over no other label. */
static void bar_label(tl *t, double bx0, double bx1, double ry, const char *lb)
{
    cairo_t *cr = t->c->cr;
    double fs = t->c->L.label;
    if (fs > 0.8 * t->g.rh) return; /* the row is too thin for it */
    double lx = fmax(bx0, t->g.x0) + 2, tw = text_w(cr, SANS, fs, lb);
    if (fmin(bx1, t->g.x1) - lx < tw + 2) return;
    double by = ry + t->g.rh / 2 + 0.35 * fs;
    if (!place(&t->P, lx, by - 0.8 * fs, tw, fs)) return;
    cairo_set_source_rgba(cr, 0.1, 0.1, 0.12, 0.9); /* on the pastel bar, in every theme */
    text_at(cr, SANS, 0, fs, lx, by, lb);
}

static int phase_depth(const pdt_rphase *Ph, const pdt_rphase *p)
{
    int depth = 0;
    for (int32_t a = p->parent; a >= 0; a = Ph[a].parent)
        if (Ph[a].phase != PDT_PH_RUN) depth++;
    return depth;
}

/* The phases as bars: nested ones thinner in a rank's row, one thin strip
 * per rank in a group's row. */
static void draw_bars(tl *t)
{
    ctx *c = t->c;
    size_t np;
    const pdt_rphase *Ph = pdt_replay_phases(c->r, &np);
    for (size_t i = 0; i < np; i++) {
        const pdt_rphase *p = &Ph[i];
        if (p->phase == PDT_PH_RUN || p->rank >= (uint32_t)c->nranks || t->rowof[p->rank] < 0) continue;
        double bx0 = ev_x(t, t->m * t->pa[2 * i]), bx1 = ev_x(t, t->m * t->pa[2 * i + 1]);
        if (bx1 < t->g.x0 || bx0 > t->g.x1) continue;
        const pdt_rtnode *d = &t->N[c->rows[t->rowof[p->rank] + t->g.row0]];
        double ry = t->g.y0 + t->g.rh * t->rowof[p->rank], col[3];
        int depth = phase_depth(Ph, p), n = (int)(d->hi - d->lo);
        phase_rgb((int)p->phase, col);
        cairo_set_source_rgb(c->cr, col[0], col[1], col[2]);
        if (n > 1) {
            double sh = 0.8 * t->g.rh / n;
            cairo_rectangle(c->cr, bx0, ry + 0.1 * t->g.rh + sh * (p->rank - d->lo), fmax(bx1 - bx0, 1),
                            fmax(sh, 0.6));
            cairo_fill(c->cr);
            continue;
        }
        double inset = t->g.rh * (0.12 + 0.15 * (depth > 2 ? 2 : depth));
        cairo_rectangle(c->cr, bx0, ry + inset, fmax(bx1 - bx0, 1), t->g.rh - 2 * inset);
        cairo_fill(c->cr);
        const char *nm = pdt_phase_name((int)p->phase);
        char lb[32];
        if (p->phase == PDT_PH_MERGE) snprintf(lb, sizeof lb, "merge %u", p->sub);
        else snprintf(lb, sizeof lb, "%s", nm ? nm : "?");
        if (depth == 0) bar_label(t, bx0, bx1, ry, lb);
    }
}

/* A group's row: its own merge step named over its span. */
static void group_merges(tl *t)
{
    size_t nm;
    const pdt_rmerge *M = pdt_replay_merges(t->c->r, &nm);
    for (int i = 0; i < t->g.nshow; i++) {
        const pdt_rtnode *d = &t->N[t->c->rows[i + t->g.row0]];
        if (d->hi - d->lo < 2 || d->merge < 0) continue;
        const pdt_rmerge *g = &M[d->merge];
        char lb[32];
        snprintf(lb, sizeof lb, "merge %u", g->level);
        double bx0 = ev_x(t, t->m * pdt_ranktree_at(t->c->tree, g->begin_ev));
        double bx1 = ev_x(t, t->m * pdt_ranktree_at(t->c->tree, g->end_ev == NONE32 ? (size_t)t->m : g->end_ev));
        bar_label(t, bx0, bx1, t->g.y0 + t->g.rh * i, lb);
    }
}

/* The row labels: the group's colour, its name. */
static void draw_row_labels(tl *t)
{
    ctx *c = t->c;
    cairo_t *cr = c->cr;
    double f = c->L.font;
    for (int i = 0; i < t->g.nshow; i++) {
        int32_t id = c->rows[i + t->g.row0];
        const pdt_rtnode *d = &t->N[id];
        char lb[40];
        pdt_ranktree_name(c->tree, id, lb, sizeof lb);
        double ry = t->g.y0 + t->g.rh * i;
        set_rank(c, (int)d->lo, shown(c, d->lo) ? 1 : 0.3);
        cairo_rectangle(cr, c->L.timeline.x + 0.4 * f, ry + t->g.rh * 0.2, 0.5 * f, t->g.rh * 0.6);
        cairo_fill(cr);
        double fs = t->g.fs, y = ry + 0.5 * t->g.rh + 0.35 * fs;
        rgb(cr, c->T->ink, 1);
        text_at(cr, d->hi - d->lo > 1 ? SANS : SANS, d->hi - d->lo > 1, fs, c->L.timeline.x + 1.1 * f, y, lb);
        place(&t->P, c->L.timeline.x + 1.1 * f, y - 0.8 * fs, text_wb(cr, SANS, d->hi - d->lo > 1, fs, lb), fs);
    }
}

static void arrow(cairo_t *cr, double ax, double ay, double bx, double by, double a)
{
    cairo_move_to(cr, ax, ay);
    cairo_line_to(cr, bx, by);
    cairo_stroke(cr);
    double ang = atan2(by - ay, bx - ax);
    cairo_move_to(cr, bx, by);
    cairo_line_to(cr, bx - a * cos(ang - 0.4), by - a * sin(ang - 0.4));
    cairo_line_to(cr, bx - a * cos(ang + 0.4), by - a * sin(ang + 0.4));
    cairo_close_path(cr);
    cairo_fill(cr);
}

/* A message's arrow is shown when both ends are in rows shown, the rows
 * differ and it crosses the events shown. */
static int msg_shown(const tl *t, const pdt_rmsg *g, size_t i)
{
    if (g->send_ev == NONE32 || g->recv_ev == NONE32) return 0;
    if (g->src >= (uint32_t)t->c->nranks || g->dst >= (uint32_t)t->c->nranks) return 0;
    int a = t->rowof[g->src], b = t->rowof[g->dst];
    if (a < 0 || b < 0 || a == b) return 0;
    double lo = t->m * fmin(t->ma[2 * i], t->ma[2 * i + 1]), hi = t->m * fmax(t->ma[2 * i], t->ma[2 * i + 1]);
    return hi >= t->g.k0 && lo <= t->g.k1;
}

/* Each message its arrow; light when they are many (dense lines would
 * make a dark mass over the collectives). */
static void draw_msgs_each(tl *t, const pdt_rmsg *Ms, size_t nm, size_t shown_n)
{
    cairo_t *cr = t->c->cr;
    int many = shown_n > 8 * (size_t)t->g.nshow;
    double ink = many ? 0.3 : 0.6, head = many ? 0.25 : 0.35;
    cairo_set_line_width(cr, many ? 0.8 : 1);
    for (size_t i = 0; i < nm; i++) {
        const pdt_rmsg *g = &Ms[i];
        if (!msg_shown(t, g, i)) continue;
        if (t->c->s->mflight[i]) rgb(cr, RED, 1);
        else rgb(cr, t->c->T->ink, ink);
        arrow(cr, ev_x(t, t->m * t->ma[2 * i]), t->g.y0 + t->g.rh * (t->rowof[g->src] + 0.5),
              ev_x(t, t->m * t->ma[2 * i + 1]), t->g.y0 + t->g.rh * (t->rowof[g->dst] + 0.5),
              head * t->c->L.font);
    }
}

/* One bundle: the messages from one row to another sent in one stretch. */
typedef struct bundle {
    uint32_t n;
    double sx, rx;  /* sums of send and receive events */
} bundle;

static void draw_bundle(tl *t, int a, int b, const bundle *B)
{
    cairo_t *cr = t->c->cr;
    double f = t->c->L.font;
    double ax = ev_x(t, B->sx / B->n), bx = ev_x(t, B->rx / B->n);
    double ay = t->g.y0 + t->g.rh * (a + 0.5), by = t->g.y0 + t->g.rh * (b + 0.5);
    rgb(cr, t->c->T->ink, B->n > 1 ? 0.45 : 0.3); /* light: a thin line, a small head */
    cairo_set_line_width(cr, B->n > 1 ? 1.5 : 1);
    arrow(cr, ax, ay, bx, by, 0.3 * f);
    if (B->n < 2) return;
    char lb[24];
    snprintf(lb, sizeof lb, "×%u", B->n);
    double fs = t->c->L.label, tw = text_w(cr, SANS, fs, lb);
    double lx = (ax + bx) / 2 + 3, ly = (ay + by) / 2 - 2;
    if (lx + tw > t->g.x1 || ly - fs < t->g.y0 || ly > t->g.y1) return;
    if (!place(&t->P, lx - 1, ly - 0.8 * fs - 1, tw + 2, fs + 2)) return;
    cairo_rectangle(cr, lx - 1, ly - 0.8 * fs - 1, tw + 2, fs + 2);
    rgb(cr, t->c->T->panel, 0.7);
    cairo_fill(cr);
    rgb(cr, t->c->T->ink, 0.85);
    text_at(cr, SANS, 0, fs, lx, ly, lb);
}

/* Bundles per (sending row, receiving row, stretch of 12 font sizes): one
 * arrow from the mean send to the mean receive, with its count. */
static void draw_msgs_bundled(tl *t, const pdt_rmsg *Ms, size_t nm)
{
    int R = t->g.nshow, nb = (int)ceil((t->g.x1 - t->g.x0) / (12 * t->c->L.font));
    if (nb < 1) nb = 1;
    bundle *B = calloc((size_t)R * (size_t)R * (size_t)nb, sizeof *B);
    if (!B) return;
    for (size_t i = 0; i < nm; i++) {
        const pdt_rmsg *g = &Ms[i];
        if (!msg_shown(t, g, i)) continue;
        int s = (int)((ev_x(t, t->m * t->ma[2 * i]) - t->g.x0) / (t->g.x1 - t->g.x0) * nb);
        s = s < 0 ? 0 : s >= nb ? nb - 1 : s;
        bundle *b = &B[((size_t)t->rowof[g->src] * (size_t)R + (size_t)t->rowof[g->dst]) * (size_t)nb + (size_t)s];
        b->n++;
        b->sx += t->m * t->ma[2 * i];
        b->rx += t->m * t->ma[2 * i + 1];
    }
    for (int a = 0; a < R; a++)
        for (int b = 0; b < R; b++)
            for (int s = 0; s < nb; s++) {
                const bundle *x = &B[((size_t)a * (size_t)R + (size_t)b) * (size_t)nb + (size_t)s];
                if (x->n) draw_bundle(t, a, b, x);
            }
    free(B);
}

static void draw_msgs(tl *t)
{
    size_t nm, shown_n = 0;
    const pdt_rmsg *Ms = pdt_replay_msgs(t->c->r, &nm);
    for (size_t i = 0; i < nm; i++) shown_n += msg_shown(t, &Ms[i], i) != 0;
    if ((t->c->nranks > PDT_PALETTE_HUES && shown_n > 4 * (size_t)t->g.nshow) || shown_n > 3000)
        draw_msgs_bundled(t, Ms, nm);
    else draw_msgs_each(t, Ms, nm, shown_n);
}

/* The cursor: at the current event's time (the start before any event). */
static void draw_cursor(tl *t)
{
    ctx *c = t->c;
    cairo_t *cr = c->cr;
    double cx = ev_x(t, c->s->k ? t->m * pdt_ranktree_at(c->tree, c->s->k - 1) : 0);
    if (cx >= t->g.x0 - 1 && cx <= t->g.x1 + 1) {
        cairo_move_to(cr, cx, c->L.timeline.y + 0.2 * c->L.font);
        cairo_line_to(cr, cx, t->g.y1 + 0.2 * c->L.font);
        cairo_set_source_rgb(cr, 0.85, 0.0, 0.0);
        cairo_set_line_width(cr, 2);
        cairo_stroke(cr);
    }
}

/* "12.5 ms" (or µs, s) for ns nanoseconds; digits enough for step. */
static void fmt_time(double ns, double step, char *s, size_t cap)
{
    double unit = 1e6;
    const char *u = "ms";
    if (step < 1e3) unit = 1e3, u = "µs";
    else if (step >= 1e9) unit = 1e9, u = "s";
    int dec = step / unit >= 1 ? 0 : step / unit >= 0.1 ? 1 : step / unit >= 0.01 ? 2 : 3;
    snprintf(s, cap, "%.*f %s", dec, ns / unit, u);
}

/* The ticks' step: a round number of ns (1, 2 or 5 times a power of ten),
 * the smallest whose labels keep 1.5 label sizes apart. */
static double tick_step(const tl *t, double span_ns, double fs)
{
    double a = t->g.k0 / t->m * span_ns, b = t->g.k1 / t->m * span_ns, px = t->g.x1 - t->g.x0;
    if (!(b > a) || px <= 0) return 0;
    double step = pow(10, floor(log10((b - a) / fmax(1, px / (3 * fs)))));
    for (int i = 0; i < 12; i++) {
        char lb[32];
        fmt_time(b, step, lb, sizeof lb);
        if (step / (b - a) * px >= text_w(t->c->cr, SANS, fs, lb) + 1.5 * fs) break;
        double d = step / pow(10, floor(log10(step)) + 1e-9); /* 1, 2 or 5 */
        step *= d < 1.5 ? 2 : d < 3 ? 2.5 : 2;
    }
    return step;
}

/* Ticks of the clock along the bottom, labelled where there is room. */
static void draw_ticks(tl *t, double span_ns, double step, double fs, double base)
{
    cairo_t *cr = t->c->cr;
    double a = t->g.k0 / t->m * span_ns, b = t->g.k1 / t->m * span_ns, px = t->g.x1 - t->g.x0;
    if (!(step > 0)) return;
    double lastx = -1e9;
    for (double v = ceil(a / step) * step; v <= b; v += step) {
        double x = t->g.x0 + (v - a) / (b - a) * px;
        rgb(cr, t->c->T->ink, 0.5);
        cairo_set_line_width(cr, 1);
        cairo_move_to(cr, x, t->g.y1);
        cairo_line_to(cr, x, t->g.y1 + 0.25 * fs);
        cairo_stroke(cr);
        char lb[32];
        fmt_time(v, step, lb, sizeof lb);
        double tw = text_w(cr, SANS, fs, lb), lx = x - tw / 2;
        if (lx < lastx + 0.8 * fs || lx < t->g.x0 || lx + tw > t->g.x1) continue;
        if (!place(&t->P, lx, base - 0.8 * fs, tw, fs)) continue;
        rgb(cr, t->c->T->ink, 0.75);
        text_at(cr, SANS, 0, fs, lx, base, lb);
        lastx = lx + tw;
    }
}

/* The axis: ticks in time (or the events' numbers for a trace without
 * times), and what the window shows where the ticks leave room. */
static void draw_axis(tl *t)
{
    ctx *c = t->c;
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.timeline;
    double f = c->L.font, fs = c->L.label, span, room = t->g.x1 - t->g.x0;
    double base = R.y + R.h - 0.35 * f;
    draw_cursor(t);
    size_t m = pdt_replay_count(c->r);
    char ax[3][160];
    int all = t->g.k0 <= 0 && t->g.k1 >= (double)m;
    cairo_save(cr);
    clip_rect(cr, (pdt_rect){t->g.x0, R.y, room, R.h});
    if (m && pdt_ranktree_timed(c->tree, &span)) {
        double st = tick_step(t, span, fs);
        char a[32], b[32];
        fmt_time(t->g.k0 / t->m * span, st, a, sizeof a);
        fmt_time(t->g.k1 / t->m * span, st, b, sizeof b);
        if (!all) { /* the window at the right end, if the ticks leave room */
            if ((size_t)t->g.nshow < c->nrows)
                snprintf(ax[0], sizeof ax[0], "%s … %s · rows %d–%d of %zu", a, b, t->g.row0 + 1,
                         t->g.row0 + t->g.nshow, c->nrows);
            else snprintf(ax[0], sizeof ax[0], "%s … %s", a, b);
            double tw = text_w(cr, SANS, fs, ax[0]), lx = t->g.x1 - tw;
            rgb(cr, c->T->panel, 0.9);
            cairo_rectangle(cr, lx - 4, base - 0.85 * fs, tw + 4, 1.05 * fs);
            cairo_fill(cr);
            rgb(cr, c->T->ink, 0.75);
            text_at(cr, SANS, 0, fs, lx, base, ax[0]);
            place(&t->P, lx - 4, base - 0.8 * fs, tw + 4, fs);
        }
        draw_ticks(t, span, st, fs, base);
        cairo_restore(cr);
        return;
    }
    if (all && c->nrows == (size_t)c->nranks && c->nranks <= PDT_PALETTE_HUES)
        snprintf(ax[0], sizeof ax[0], "timeline: events 0 … %zu (bars = phases, arrows = messages; click to seek)", m);
    else
        snprintf(ax[0], sizeof ax[0], "events %.0f … %.0f of %zu · rows %d–%d of %zu (wheel, drag, [ ] zoom; u opens)",
                 t->g.k0, t->g.k1, m, t->g.row0 + 1, t->g.row0 + t->g.nshow, c->nrows);
    snprintf(ax[1], sizeof ax[1], "events %.0f … %.0f of %zu · rows %d–%d of %zu", t->g.k0, t->g.k1, m,
             t->g.row0 + 1, t->g.row0 + t->g.nshow, c->nrows);
    snprintf(ax[2], sizeof ax[2], "%.0f … %.0f / %zu", t->g.k0, t->g.k1, m);
    int i = 0; /* at the label size: the longest form that fits */
    while (i < 2 && text_w(cr, SANS, fs, ax[i]) > room) i++;
    rgb(cr, c->T->ink, 0.75);
    text_at(cr, SANS, 0, fs, t->g.x0, base, ax[i]);
    cairo_restore(cr);
}

void pdt_draw_timeline(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.timeline;
    panel(cr, c->T, R, NULL, c->L.font);
    if (!c->tree || !c->rows || !c->nrows) return;
    tl *t = calloc(1, sizeof *t);
    if (!t) return;
    t->c = c;
    pdt_timeline_geom(R, c->L.font, c->nranks, c->nrows, pdt_replay_count(c->r), c->v, &t->g);
    size_t nn;
    t->N = pdt_ranktree_nodes(c->tree, &nn);
    t->scale = (t->g.x1 - t->g.x0) / (t->g.k1 - t->g.k0);
    t->m = (double)pdt_replay_count(c->r);
    t->pa = pdt_ranktree_phase_at(c->tree);
    t->ma = pdt_ranktree_msg_at(c->tree);
    t->rowof = malloc((size_t)c->nranks * sizeof *t->rowof);
    if (!t->rowof) {
        free(t);
        return;
    }
    for (int q = 0; q < c->nranks; q++) t->rowof[q] = -1;
    for (int i = 0; i < t->g.nshow; i++)
        for (uint32_t q = t->N[c->rows[i + t->g.row0]].lo; q < t->N[c->rows[i + t->g.row0]].hi; q++)
            t->rowof[q] = i;
    cairo_save(cr);
    clip_rect(cr, R);
    draw_row_labels(t);
    cairo_save(cr);
    clip_rect(cr, (pdt_rect){t->g.x0, R.y, t->g.x1 - t->g.x0 + 0.5 * c->L.font, R.h});
    draw_bars(t);
    group_merges(t);
    draw_msgs(t);
    cairo_restore(cr);
    draw_axis(t);
    cairo_restore(cr);
    free(t->rowof);
    free(t);
}

/* The timeline's geometry and rows for view v of a w x h picture; NULL
 * rows (and 0) when the timeline is hidden or out of memory.  *own is the
 * tree to free, if one was made. */
static size_t tl_setup(const pdt_replay *r, const pdt_view *v, double w, double h, pdt_layout *L,
                       tl_geom *g, pdt_ranktree **own, const pdt_ranktree **tree, int32_t **rows)
{
    pdt_render_layout_view(w, h, pdt_replay_nranks(r), v, L);
    *own = NULL;
    *rows = NULL;
    *tree = v ? v->tree : NULL;
    if (L->timeline.w <= 0 || L->timeline.h <= 0) return 0;
    if (!*tree) *tree = *own = pdt_ranktree_new(r);
    if (!*tree) return 0;
    size_t n = pdt_timeline_rows(*tree, v, rows);
    pdt_timeline_geom(L->timeline, L->font, pdt_replay_nranks(r), n, pdt_replay_count(r), v, g);
    return n;
}

/* The event nearest k on the ranks [lo, hi) (at most 256 of them looked at). */
static size_t nearest_in(const pdt_replay *r, size_t k, uint32_t lo, uint32_t hi)
{
    size_t best = (size_t)-1, bd = (size_t)-1;
    uint32_t step = (hi - lo + 255) / 256;
    for (uint32_t q = lo; q < hi; q += step ? step : 1) {
        size_t kq = pdt_replay_nearest_of_rank(r, k, (int)q);
        if (kq == (size_t)-1) continue;
        size_t d = kq > k ? kq - k : k - kq;
        if (d < bd) bd = d, best = kq;
    }
    return best;
}

size_t pdt_render_timeline_at(const pdt_replay *r, const pdt_view *v, double w, double h, double sx,
                              double sy)
{
    pdt_layout L;
    tl_geom g;
    pdt_ranktree *own;
    const pdt_ranktree *tree;
    int32_t *rows;
    size_t n = tl_setup(r, v, w, h, &L, &g, &own, &tree, &rows), k = (size_t)-1;
    pdt_rect R = L.timeline;
    if (n && sx >= R.x && sx <= R.x + R.w && sy >= R.y && sy <= R.y + R.h) {
        double t = (sx - g.x0) / (g.x1 - g.x0), m = (double)pdt_replay_count(r);
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        double u = m > 0 ? (g.k0 + t * (g.k1 - g.k0)) / m : 0; /* the clicked time */
        k = u >= 1 ? (size_t)m : pdt_ranktree_event_at(tree, u); /* the events before it applied */
        /* in a row: that row's ranks' event nearest the clicked time */
        int i = (int)floor((sy - g.y0) / g.rh);
        if (sy >= g.y0 && i >= 0 && i < g.nshow) {
            size_t nn;
            const pdt_rtnode *d = &pdt_ranktree_nodes(tree, &nn)[rows[i + g.row0]];
            size_t kq = nearest_in(r, k, d->lo, d->hi);
            if (kq != (size_t)-1) k = kq;
        }
    }
    free(rows);
    pdt_ranktree_free(own);
    return k;
}

int32_t pdt_render_timeline_row_at(const pdt_replay *r, const pdt_view *v, double w, double h,
                                   double sx, double sy, int label_only)
{
    pdt_layout L;
    tl_geom g;
    pdt_ranktree *own;
    const pdt_ranktree *tree;
    int32_t *rows, id = -1;
    size_t n = tl_setup(r, v, w, h, &L, &g, &own, &tree, &rows);
    int i = (int)floor((sy - g.y0) / g.rh);
    if (n && sx >= L.timeline.x && sx <= (label_only ? g.x0 : g.x1) && sy >= g.y0 && i >= 0 &&
        i < g.nshow)
        id = rows[i + g.row0];
    free(rows);
    pdt_ranktree_free(own);
    return id;
}

int pdt_render_timeline_rows(const pdt_replay *r, const pdt_view *v, double w, double h,
                             int *nshow)
{
    pdt_layout L;
    tl_geom g;
    pdt_ranktree *own;
    const pdt_ranktree *tree;
    int32_t *rows;
    size_t n = tl_setup(r, v, w, h, &L, &g, &own, &tree, &rows);
    *nshow = n ? g.nshow : 0;
    free(rows);
    pdt_ranktree_free(own);
    return (int)n;
}
