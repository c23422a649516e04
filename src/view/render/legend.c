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

/* The groups the legend lists: those on screen (groups.c), or every rank
 * when there are none; group i's ranks [*lo, *hi).  Returns their number. */
static int legend_group(const ctx *c, int i, uint32_t *lo, uint32_t *hi)
{
    if (!c->hue || !c->tree) {
        *lo = (uint32_t)i;
        *hi = (uint32_t)i + 1;
        return c->nranks < 64 ? c->nranks : 64;
    }
    if (i < 0 || (size_t)i >= c->ngroups) { /* past the last */
        *lo = *hi = 0;
        return (int)c->ngroups;
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

/* The legend's items flow into rows: each a swatch `sw` wide, then its
 * text at the label size.  One pass measures (c NULL: for the layout, which
 * reserves the height) or measures and draws, so both agree. */
typedef struct flow {
    ctx *c;          /* NULL: measure only */
    cairo_t *cr;
    int nranks;
    double x0, x1;   /* a row's left and right edges */
    double x, y;     /* the pen; y is the baseline */
    double f, fs, pitch;
    int in_row, row; /* items in the current row; rows begun */
} flow;

static void flow_newline(flow *F, double x0)
{
    F->x0 = F->x = x0;
    F->y += F->pitch;
    F->in_row = 0;
    F->row++;
}

/* Width of an item: its swatch, its text. */
static double item_w(const flow *F, double sw, const char *s)
{
    return sw + text_w(F->cr, SANS, F->fs, s);
}

/* Places an item (drawing its text); returns the swatch's x. */
static double flow_item(flow *F, double sw, const char *s, double alpha)
{
    double w = item_w(F, sw, s);
    if (F->in_row && F->x + w > F->x1) flow_newline(F, F->x0);
    double x = F->x;
    if (F->c) {
        rgb(F->cr, F->c->T->ink, alpha);
        text_at(F->cr, SANS, 0, F->fs, x + sw, F->y, s);
    }
    F->x += w + 0.8 * F->fs;
    F->in_row++;
    return x;
}

/* Item i of the groups (ranks) and their count: those on screen, or when
 * measuring the widest a run of F->nranks ranks can show. */
static int group_item(const flow *F, int i, int first, char *lab, size_t cap, uint32_t *lo,
                      uint32_t *hi)
{
    if (F->c) {
        int n = legend_group(F->c, i, lo, hi);
        if (i < n) group_label(*lo, *hi, first, lab, cap);
        return n;
    }
    int n = F->nranks < 1 ? 1 : F->nranks;
    *lo = (uint32_t)i;
    *hi = (uint32_t)i + 1;
    if (n <= PDT_PALETTE_HUES) group_label(*lo, *hi, first, lab, cap);
    else snprintf(lab, cap, first ? "ranks %d–%d" : "%d–%d", n - 1, n - 1);
    return n < PDT_PALETTE_HUES ? n : PDT_PALETTE_HUES;
}

/* The groups' items, a swatch of their colour each; at most `rows` rows
 * (those the layout reserved: a "…" ends a longer list). */
static void flow_groups(flow *F, int strip, int rows)
{
    char lab[48];
    uint32_t lo, hi;
    double sw = 1.2 * F->fs;
    for (int i = 0; i < group_item(F, i, strip && i == 0, lab, sizeof lab, &lo, &hi); i++) {
        if (F->in_row && F->x + item_w(F, sw, lab) > F->x1 && F->row + 1 >= rows) {
            if (F->c && F->x + item_w(F, 0, "…") <= F->x1) flow_item(F, 0, "…", 1);
            return;
        }
        int on = F->c ? group_shown(F->c, lo, hi) : 1;
        double x = flow_item(F, sw, lab, on ? 1 : 0.4);
        if (!F->c) continue;
        cairo_rectangle(F->cr, x, F->y - 0.92 * F->fs, F->fs, F->fs);
        set_rank(F->c, (int)lo, on ? 1 : 0.2);
        cairo_fill(F->cr);
    }
}

static const char *const st_names[] = {"candidate", "final", "deferred (RA)", "shipped",
                                       "discarded", "hull / stack"};
static const int st_kind[] = {PDT_TS_CANDIDATE, PDT_TS_FINAL, PDT_TS_DEFERRED, PDT_TS_SHIPPED,
                              PDT_TS_DISCARDED, -1};

/* A status's (or, kind -1, the hull's) line swatch at x. */
static void status_swatch(flow *F, double x, int kind)
{
    ctx *c = F->c;
    cairo_t *cr = F->cr;
    double f = F->f, lw = fmax(1.5, 0.14 * f), ym = F->y - 0.3 * F->fs, col0[3];
    if (kind < 0) {
        cairo_set_line_width(cr, 3.2 * lw);
        cairo_move_to(cr, x, ym);
        cairo_line_to(cr, x + 2.2 * f, ym);
        set_hull(c, pdt_legend_hull_rank(c), 1);
        cairo_stroke(cr);
        return;
    }
    pdt_rank_rgb(0, col0);
    legend_line(cr, x, ym, 2.2 * f, kind, lw, col0);
    if (kind != PDT_TS_DISCARDED) return;
    cairo_set_line_width(cr, lw);
    cross(cr, x + 1.1 * f, ym, 0.35 * f);
    rgb(cr, RED, 1);
    cairo_stroke(cr);
}

/* The statuses and the hull: flowing (a strip), or in as many equal
 * columns as fit, at most two (the side panel). */
static void flow_statuses(flow *F, int columns)
{
    double sw = 2.6 * F->f, colw = 0;
    int clean = F->c && F->c->v->clean && !columns;
    for (int i = 0; i < 6; i++) colw = fmax(colw, item_w(F, sw, st_names[i]) + 0.8 * F->fs);
    int ncol = columns && F->x0 + 2 * colw - 0.8 * F->fs <= F->x1 ? 2 : 1;
    for (int i = 0, k = 0; i < 6; i++) {
        if (clean && st_kind[i] >= 0 && st_kind[i] != PDT_TS_FINAL) continue;
        if (columns) {
            if (k > 0 && k % ncol == 0) flow_newline(F, F->x0);
            F->x = F->x0 + (k % ncol) * colw;
            F->in_row = 0;
        }
        k++;
        double x = flow_item(F, sw, st_names[i], 1);
        if (F->c) status_swatch(F, x, st_kind[i]);
    }
}

/* A point marker's swatch at x: 0 lifted, 1 not yet, 2 deleted, 3 disk. */
static void marker_swatch(flow *F, double x, int kind)
{
    ctx *c = F->c;
    cairo_t *cr = F->cr;
    double f = F->f, cx = x + 0.4 * f, cy = F->y - 0.3 * F->fs;
    cairo_new_sub_path(cr);
    if (kind == 2) {
        cairo_set_line_width(cr, 0.15 * f);
        cross(cr, cx, cy, 0.3 * f);
        rgb(cr, RED, 1);
        cairo_stroke(cr);
        return;
    }
    cairo_arc(cr, cx, cy, (kind == 3 ? 0.35 : 0.25) * f, 0, 2 * M_PI);
    cairo_set_line_width(cr, 1);
    if (kind == 0) {
        rgb(cr, c->T->ink, 1);
        cairo_fill(cr);
    } else if (kind == 1) {
        rgb(cr, c->T->hollow, 1);
        cairo_stroke(cr);
    } else {
        rgb(cr, c->T->mark, 0.4);
        cairo_fill_preserve(cr);
        rgb(cr, c->T->disk, 1);
        cairo_stroke(cr);
    }
}

/* The point markers (a strip shows only the circumdisk, not when clean). */
static void flow_markers(flow *F, int strip)
{
    static const char *const names[] = {"lifted", "not yet", "deleted", "circumdisk (RA)"};
    for (int i = strip ? 3 : 0; i < 4; i++) {
        if (strip && F->c && F->c->v->clean) return;
        double x = flow_item(F, (i == 3 ? 0.95 : 0.9) * F->f, names[i], 1);
        if (F->c) marker_swatch(F, x, i);
    }
}

/* The whole legend in R (strip: items in one flow, the point markers but
 * the circumdisk only when 2; side: a title, the groups after their
 * heading, the statuses in columns, the markers);
 * returns its height.  `rows`: the rows the groups may take (0: all). */
static double legend_pass(flow *F, pdt_rect R, int strip, int rows)
{
    double f = F->f, fs = F->fs;
    F->pitch = 1.5 * fs;
    F->x0 = F->x = R.x + 0.5 * f;
    F->x1 = R.x + R.w - 0.5 * f;
    F->y = R.y + (strip ? 0.35 * f + 0.95 * fs : 1.3 * f + 1.1 * fs);
    F->in_row = F->row = 0;
    if (!rows) rows = 1 << 20;
    if (strip) {
        flow_groups(F, 1, rows);
        flow_statuses(F, 0);
        flow_markers(F, strip == 1);
        return F->y + 0.3 * fs + 0.35 * f - R.y;
    }
    int grouped = F->c ? F->c->hue && F->c->tree && F->c->nranks > PDT_PALETTE_HUES
                       : F->nranks > PDT_PALETTE_HUES;
    flow_item(F, 0, grouped ? "groups:" : "ranks:", 1);
    F->x0 = F->x; /* the groups' rows line up after the heading */
    flow_groups(F, 0, rows);
    flow_newline(F, R.x + 0.5 * f);
    flow_statuses(F, 1);
    flow_newline(F, R.x + 0.5 * f);
    flow_markers(F, 0);
    return F->y + 0.3 * fs + 0.5 * f - R.y;
}

/* The rows the groups of a run of `nranks` ranks may take in a legend
 * `width` wide, and the legend's height (a context only measures). */
static double legend_measure(cairo_t *cr, int nranks, double f, double fs, double width,
                             int strip, int *rows)
{
    flow F = {.cr = cr, .nranks = nranks, .f = f, .fs = fs};
    pdt_rect R = {0, 0, width, 0};
    F.pitch = 1.5 * fs;
    F.x0 = F.x = 0.5 * f;
    F.x1 = width - 0.5 * f;
    if (!strip) {
        flow_item(&F, 0, nranks > PDT_PALETTE_HUES ? "groups:" : "ranks:", 1);
        F.x0 = F.x;
    }
    flow_groups(&F, strip, 1 << 20);
    *rows = F.row + 1;
    return legend_pass(&F, R, strip, 0);
}

double pdt_legend_height(const pdt_layout *L, int nranks, double width, int strip)
{
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_A8, 1, 1);
    cairo_t *cr = cairo_create(s);
    int rows;
    double h = legend_measure(cr, nranks, L->font, L->label, width, strip, &rows);
    cairo_destroy(cr);
    cairo_surface_destroy(s);
    return h;
}

void pdt_draw_legend(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.legend;
    double f = c->L.font;
    if (!(R.w > 0 && R.h > 0)) return; /* no room: named on the `more` line */
    int strip = c->L.legend_mode; /* 1: under the picture, 2: under the column too */
    panel(cr, c->T, R, strip ? NULL : "Legend", f);
    cairo_save(cr);
    clip_rect(cr, R);
    int rows;
    legend_measure(cr, c->nranks, f, c->L.label, R.w, strip, &rows);
    flow F = {.c = c, .cr = cr, .nranks = c->nranks, .f = f, .fs = c->L.label};
    legend_pass(&F, R, strip, rows);
    cairo_restore(cr);
}
