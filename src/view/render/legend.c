/* pdt — the viewer's legend: the ranks (or groups of ranks) on screen, the
 * triangle statuses, the hull, the point markers; a side panel, or a strip
 * under the picture when there is no side column. */
#include "render_int.h"

static void legend_line(cairo_t *cr, double x, double y, double len, int st, double lw,
                        const double col[3])
{
    pdt_status_style(cr, st, lw);
    cairo_move_to(cr, x, y);
    cairo_line_to(cr, x + len, y);
    rgb(cr, col, 1);
    cairo_stroke(cr);
    cairo_set_dash(cr, NULL, 0, 0);
}

/* The legend as a strip (no side column): its items flow left to right,
 * wrapping into rows. */
typedef struct flow {
    ctx *c;
    pdt_rect R;
    double x, y, f, fs;
} flow;

/* Room for an item of width w (swatch + text); wraps to the next row. */
static void flow_room(flow *F, double w)
{
    if (F->x + w > F->R.x + F->R.w - 0.5 * F->f && F->x > F->R.x + 0.6 * F->f) {
        F->x = F->R.x + 0.5 * F->f;
        F->y += 1.45 * F->f;
    }
}

static void flow_text(flow *F, const char *s, double alpha)
{
    rgb(F->c->cr, F->c->T->ink, alpha);
    text_at(F->c->cr, SANS, 0, F->fs, F->x, F->y, s);
    F->x += text_w(F->c->cr, SANS, F->fs, s) + 0.9 * F->f;
}

static void draw_legend_strip(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.legend;
    double f = c->L.font;
    panel(cr, c->T, R, NULL, f);
    cairo_save(cr);
    clip_rect(cr, R);
    flow F = {c, R, R.x + 0.5 * f, R.y + 1.3 * f, f, c->L.body};
    char lab[16];
    for (int q = 0; q < c->nranks && q < 64; q++) {
        snprintf(lab, sizeof lab, q ? "%d" : "rank %d", q);
        flow_room(&F, 1.1 * f + text_w(cr, SANS, F.fs, lab));
        cairo_rectangle(cr, F.x, F.y - 0.75 * f, 0.8 * f, 0.8 * f);
        set_rank(cr, q, shown(c, (uint32_t)q) ? 1 : 0.2);
        cairo_fill(cr);
        F.x += 1.0 * f;
        flow_text(&F, lab, shown(c, (uint32_t)q) ? 1 : 0.4);
    }
    static const char *const names[] = {"candidate", "final", "deferred (RA)", "shipped", "discarded"};
    static const int sts[] = {PDT_TS_CANDIDATE, PDT_TS_FINAL, PDT_TS_DEFERRED, PDT_TS_SHIPPED,
                              PDT_TS_DISCARDED};
    double col0[3], lw = fmax(1.5, 0.14 * f);
    pdt_rank_rgb(0, col0);
    for (int i = 0; i < 5; i++) {
        if (c->v->clean && sts[i] != PDT_TS_FINAL) continue;
        flow_room(&F, 2.6 * f + text_w(cr, SANS, F.fs, names[i]));
        legend_line(cr, F.x, F.y - 0.3 * f, 2.2 * f, sts[i], lw, col0);
        if (sts[i] == PDT_TS_DISCARDED) {
            cairo_set_line_width(cr, lw);
            cross(cr, F.x + 1.1 * f, F.y - 0.3 * f, 0.35 * f);
            rgb(cr, RED, 1);
            cairo_stroke(cr);
        }
        F.x += 2.6 * f;
        flow_text(&F, names[i], 1);
    }
    flow_room(&F, 2.6 * f + text_w(cr, SANS, F.fs, "hull / stack"));
    cairo_set_line_width(cr, 3.2 * lw);
    cairo_move_to(cr, F.x, F.y - 0.3 * f);
    cairo_line_to(cr, F.x + 2.2 * f, F.y - 0.3 * f);
    set_hull(c, 0, 1);
    cairo_stroke(cr);
    F.x += 2.6 * f;
    flow_text(&F, "hull / stack", 1);
    if (!c->v->clean) {
        flow_room(&F, 1.0 * f + text_w(cr, SANS, F.fs, "circumdisk (RA)"));
        cairo_new_sub_path(cr);
        cairo_arc(cr, F.x + 0.4 * f, F.y - 0.3 * f, 0.35 * f, 0, 2 * M_PI);
        rgb(cr, c->T->mark, 0.4);
        cairo_fill_preserve(cr);
        rgb(cr, c->T->disk, 1);
        cairo_set_line_width(cr, 1);
        cairo_stroke(cr);
        F.x += 1.0 * f;
        flow_text(&F, "circumdisk (RA)", 1);
    }
    cairo_restore(cr);
}

void pdt_draw_legend(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.legend;
    double f = c->L.font, fs = 0.8 * f;
    if (R.w >= c->L.geo.w && R.y >= c->L.geo.y + c->L.geo.h) { /* under the picture */
        draw_legend_strip(c);
        return;
    }
    panel(cr, c->T, R, "Legend", f);
    cairo_save(cr);
    clip_rect(cr, R);
    /* ranks */
    double x = R.x + 0.5 * f, y = R.y + 2.3 * f;
    rgb(cr, c->T->ink, 1);
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
        rgb(cr, c->T->ink, shown(c, (uint32_t)q) ? 1 : 0.4);
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
        rgb(cr, c->T->ink, 1);
        text_at(cr, SANS, 0, fs, lx + 2.6 * f, ly, names[i]);
    }
    {   /* hull, in the sixth cell */
        double lx = R.x + 0.5 * f + colw, ly = R.y + (3.6 + 1.25 * 2) * f;
        cairo_set_line_width(cr, 3.2 * lw);
        cairo_move_to(cr, lx, ly - 0.3 * f);
        cairo_line_to(cr, lx + 2.2 * f, ly - 0.3 * f);
        set_hull(c, 0, 1);
        cairo_stroke(cr);
        rgb(cr, c->T->ink, 1);
        text_at(cr, SANS, 0, fs, lx + 2.6 * f, ly, "hull / stack");
    }
    /* markers */
    double ly = R.y + 7.05 * f, lx = R.x + 0.5 * f;
    cairo_new_sub_path(cr);
    cairo_arc(cr, lx + 0.4 * f, ly - 0.3 * f, 0.25 * f, 0, 2 * M_PI);
    rgb(cr, c->T->ink, 1);
    cairo_fill(cr);
    text_at(cr, SANS, 0, fs, lx + 0.9 * f, ly, "lifted");
    lx += 0.9 * f + text_w(cr, SANS, fs, "lifted") + 0.8 * f;
    cairo_new_sub_path(cr);
    cairo_arc(cr, lx + 0.4 * f, ly - 0.3 * f, 0.25 * f, 0, 2 * M_PI);
    rgb(cr, c->T->hollow, 1);
    cairo_set_line_width(cr, 1);
    cairo_stroke(cr);
    rgb(cr, c->T->ink, 1);
    text_at(cr, SANS, 0, fs, lx + 0.9 * f, ly, "not yet");
    lx += 0.9 * f + text_w(cr, SANS, fs, "not yet") + 0.8 * f;
    cairo_set_line_width(cr, 0.15 * f);
    cross(cr, lx + 0.4 * f, ly - 0.3 * f, 0.3 * f);
    rgb(cr, RED, 1);
    cairo_stroke(cr);
    rgb(cr, c->T->ink, 1);
    text_at(cr, SANS, 0, fs, lx + 0.9 * f, ly, "deleted");
    lx += 0.9 * f + text_w(cr, SANS, fs, "deleted") + 0.8 * f;
    cairo_new_sub_path(cr);
    cairo_arc(cr, lx + 0.4 * f, ly - 0.3 * f, 0.35 * f, 0, 2 * M_PI);
    rgb(cr, c->T->mark, 0.4);
    cairo_fill_preserve(cr);
    rgb(cr, c->T->disk, 1);
    cairo_stroke(cr);
    rgb(cr, c->T->ink, 1);
    text_at(cr, SANS, 0, fs, lx + 0.95 * f, ly, "circumdisk (RA)");
    cairo_restore(cr);
}
