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

/* The groups the legend lists: those on screen (groups.c), or every rank
 * when there are none; group i's ranks [*lo, *hi).  Returns their number. */
static int legend_group(const ctx *c, int i, uint32_t *lo, uint32_t *hi)
{
    if (!c->hue || !c->tree) {
        *lo = (uint32_t)i;
        *hi = (uint32_t)i + 1;
        return c->nranks < 64 ? c->nranks : 64;
    }
    size_t n;
    const pdt_rtnode *d = &pdt_ranktree_nodes(c->tree, &n)[c->groups[i]];
    *lo = d->lo;
    *hi = d->hi;
    return (int)c->ngroups;
}

/* Shown unless every rank of the group is hidden. */
static int group_shown(const ctx *c, uint32_t lo, uint32_t hi)
{
    for (uint32_t q = lo; q < hi; q++)
        if (shown(c, q)) return 1;
    return 0;
}

/* "3", or "0–127" for a group ("rank 3", "ranks 0–127" first in a strip). */
static void group_label(uint32_t lo, uint32_t hi, int first, char *lab, size_t cap)
{
    if (hi - lo == 1) snprintf(lab, cap, first ? "rank %u" : "%u", lo);
    else snprintf(lab, cap, first ? "ranks %u–%u" : "%u–%u", lo, hi - 1);
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
    char lab[40];
    uint32_t lo, hi;
    for (int i = 0; i < legend_group(c, i, &lo, &hi); i++) {
        group_label(lo, hi, i == 0, lab, sizeof lab);
        flow_room(&F, 1.1 * f + text_w(cr, SANS, F.fs, lab));
        cairo_rectangle(cr, F.x, F.y - 0.75 * f, 0.8 * f, 0.8 * f);
        set_rank(c, (int)lo, group_shown(c, lo, hi) ? 1 : 0.2);
        cairo_fill(cr);
        F.x += 1.0 * f;
        flow_text(&F, lab, group_shown(c, lo, hi) ? 1 : 0.4);
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
    set_hull(c, pdt_legend_hull_rank(c), 1);
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

/* The side legend's groups, after "ranks:", in up to three lines when the
 * run has more ranks than hues (the layout gives it the room); returns how
 * much lower than one line the statuses go. */
static double legend_side_groups(ctx *c, double fs)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.legend;
    double f = c->L.font, y0 = R.y + 2.3 * f, y = y0;
    int lines = c->nranks > PDT_PALETTE_HUES ? 3 : 1, line = 1;
    rgb(cr, c->T->ink, 1);
    const char *head = c->hue && c->tree && c->nranks > PDT_PALETTE_HUES ? "groups:" : "ranks:";
    text_at(cr, SANS, 0, fs, R.x + 0.5 * f, y, head);
    double x = R.x + 0.9 * f + text_w(cr, SANS, fs, head), xl = x;
    uint32_t lo, hi;
    for (int i = 0; i < legend_group(c, i, &lo, &hi); i++) {
        char lab[40];
        group_label(lo, hi, 0, lab, sizeof lab);
        double tw = text_w(cr, SANS, fs, lab);
        if (x + 1.2 * f + tw > R.x + R.w - 0.5 * f) {
            if (line == lines) {
                rgb(cr, c->T->ink, 1);
                text_at(cr, SANS, 0, fs, x, y, "…");
                break;
            }
            line++;
            x = xl;
            y += 1.3 * f;
        }
        cairo_rectangle(cr, x, y - 0.75 * f, 0.8 * f, 0.8 * f);
        set_rank(c, (int)lo, group_shown(c, lo, hi) ? 1 : 0.2);
        cairo_fill(cr);
        rgb(cr, c->T->ink, group_shown(c, lo, hi) ? 1 : 0.4);
        text_at(cr, SANS, 0, fs, x + 0.95 * f, y, lab);
        x += 1.3 * f + tw;
    }
    return lines > 1 ? pdt_legend_extra(c->nranks, f, R.w) : y - y0;
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
    double dy = legend_side_groups(c, fs);
    /* statuses, two columns */
    static const char *const names[] = {"candidate", "final", "deferred (RA)", "shipped",
                                        "discarded"};
    static const int sts[] = {PDT_TS_CANDIDATE, PDT_TS_FINAL, PDT_TS_DEFERRED, PDT_TS_SHIPPED,
                              PDT_TS_DISCARDED};
    double col0[3];
    pdt_rank_rgb(0, col0);
    double lw = fmax(1.5, 0.14 * f), colw = (R.w - f) / 2;
    for (int i = 0; i < 5; i++) {
        double lx = R.x + 0.5 * f + (i % 2) * colw, ly = R.y + dy + (3.6 + 1.25 * (i / 2)) * f;
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
        double lx = R.x + 0.5 * f + colw, ly = R.y + dy + (3.6 + 1.25 * 2) * f;
        cairo_set_line_width(cr, 3.2 * lw);
        cairo_move_to(cr, lx, ly - 0.3 * f);
        cairo_line_to(cr, lx + 2.2 * f, ly - 0.3 * f);
        set_hull(c, pdt_legend_hull_rank(c), 1);
        cairo_stroke(cr);
        rgb(cr, c->T->ink, 1);
        text_at(cr, SANS, 0, fs, lx + 2.6 * f, ly, "hull / stack");
    }
    /* markers */
    double ly = R.y + dy + 7.05 * f, lx = R.x + 0.5 * f;
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

double pdt_legend_extra(int nranks, double f, double width)
{
    if (nranks <= PDT_PALETTE_HUES) return 0;
    double fs = 0.8 * f, x = 0.9 * f + 3.9 * fs, right = width - 0.5 * f; /* after "groups:" */
    int lines = 1;
    for (int i = 0; i < PDT_PALETTE_HUES; i++) { /* eight even groups, digits 0.64 em, dash 0.5 */
        int lo = i * nranks / PDT_PALETTE_HUES, hi = (i + 1) * nranks / PDT_PALETTE_HUES - 1;
        char lab[40];
        snprintf(lab, sizeof lab, "%d%d", lo, hi);
        double tw = 0.64 * fs * (double)strlen(lab) + 0.5 * fs + 0.1 * f;
        if (x + 1.2 * f + tw > right) {
            lines++;
            x = 0.9 * f + 3.9 * fs;
        }
        x += 1.3 * f + tw;
    }
    return (lines > 3 ? 2 : lines - 1) * 1.3 * f;
}
