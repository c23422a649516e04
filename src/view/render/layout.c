/* pdt — the viewer's layout: view defaults, panel rectangles, and the
 * transform between the screen and the world of the geometry area. */
#include "render_int.h"

static void layout_round(pdt_layout *L);
static void layout_column(double w, double h, double top, double tl, int nranks, unsigned panels,
                          int strip_ok, pdt_layout *L);
static void layout_all(double w, double h, int nranks, unsigned panels, double scale,
                       int overflow, pdt_layout *L);

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
    v->font_scale = 1;
    v->theme = PDT_THEME_LIGHT;
    v->tl_t1 = 1;
    v->follow = 1; /* applied while playing */
}

int pdt_theme_parse(const char *name, int *theme)
{
    static const char *const names[PDT_THEME_COUNT] = {"light", "dark", "contrast"};
    for (int i = 0; i < PDT_THEME_COUNT; i++)
        if (!strcmp(name, names[i])) {
            *theme = i;
            return 0;
        }
    return -1;
}

int pdt_panels_parse(const char *list, unsigned *panels)
{
    static const struct { const char *name; unsigned bit; } names[] = {
        {"code", PDT_PANEL_CODE}, {"stack", PDT_PANEL_STACK}, {"lifted", PDT_PANEL_LIFTED},
        {"timeline", PDT_PANEL_TIMELINE}, {"tree", PDT_PANEL_TREE}, {"all", PDT_PANEL_ALL},
        {"none", 0}, {"notes", PDT_PANEL_NOTES}};
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
    pdt_render_layout_scaled(w, h, nranks, panels, 1, L);
}

void pdt_render_layout_view(double w, double h, int nranks, const pdt_view *v, pdt_layout *L)
{
    layout_all(w, h, nranks, v ? v->panels : PDT_PANEL_ALL, v ? v->font_scale : 1,
               v ? v->overflow : 0, L);
}

/* The text sizes for a w x h picture at font scale `scale`: the base font
 * is 1/40 of the height or 1/54 of the width, whichever is smaller, but at
 * least 20 px on a screen from 600 px high (a projector at 1024x768: event
 * line 20 px, code 19 px, every other text 16.4 px); then scaled. */
static void layout_fonts(double w, double h, double scale, pdt_layout *L)
{
    if (!(scale > 0)) scale = 1;
    if (scale < 0.4) scale = 0.4;
    if (scale > 4) scale = 4;
    double f = fmax(fmin(h / 40, w / 54), fmin(20, h / 30)) * scale;
    if (f < 8) f = 8;
    L->font = f;
    L->body = 0.95 * f;
    L->label = 0.82 * f;
}

/* The heights the panels of the side column want and need (pixels). */
typedef struct column {
    double legend, code_want, code_mid, code_min, stack_min, lifted_min;
} column;

static column column_needs(const pdt_layout *L)
{
    double f = L->font, title = 1.8 * f, row = pdt_layout_code_row(L);
    return (column){0, title + 16 * row, title + 7 * row, title + 4 * row,
                    title + 1.95 * 1.3 * L->body, 6 * f};
}

/* Share the column's height `mid` (less the legend) among the code, the
 * stacks and the lifted view: the code keeps its lines first (it scrolls
 * to its lit line when short), the lifted view goes when even 7 code rows
 * and a stack would not fit beside it. */
static void column_split(double rest, const column *C, int code, int stack, int lifted,
                         double *hc, double *hs, double *hl)
{
    double want = (code ? C->code_want : 0) + (stack ? C->stack_min : 0);
    if (lifted && rest - want < C->lifted_min) {
        want = (code ? C->code_mid : 0) + (stack ? C->stack_min : 0);
        if (rest - want < C->lifted_min) lifted = 0;
    }
    /* beside the lifted view the code wants no more than leaves it a share */
    double share = lifted ? (stack ? 0.3 : 0.42) * rest : 0;
    double others = (lifted ? fmax(share, C->lifted_min) : 0) + (stack ? C->stack_min : 0);
    double code_want = fmax(C->code_mid, fmin(C->code_want, rest - others));
    *hc = code ? code_want : 0;
    *hs = stack ? C->stack_min : 0;
    *hl = lifted ? C->lifted_min : 0;
    double over = *hc + *hs + *hl - rest;
    if (over > 0 && code) { /* the code panel gives first, down to 4 lines */
        double give = fmin(over, *hc - C->code_min);
        *hc -= give;
        over -= give;
    }
    if (over > 0 && stack) *hs = fmax(0, *hs - over);
    if (over > 0 && code) *hc = fmax(0, rest - *hs - *hl);
    double extra = rest - *hc - *hs - *hl;
    if (extra <= 0) return;
    if (code && *hc < code_want) { /* the code's lines first */
        double give = fmin(extra, code_want - *hc);
        *hc += give;
        extra -= give;
    }
    if (lifted) *hl += stack ? 0.65 * extra : extra, *hs += stack ? 0.35 * extra : 0;
    else if (stack) *hs += extra;
    else *hc += extra;
}

/* A legend strip taller than this share of the height would leave a small
 * picture: the legend is hidden instead (named on the `more` line, Tab). */
#define STRIP_MAX 0.2
/* The picture's fair share of the room under the top bar (area). */
#define PICTURE_SHARE 0.35

/* No side column: the picture takes the whole width, the legend is a strip
 * under it (its items flow in rows). */
static void layout_strip(double w, double h, double top, double tl, int nranks, pdt_layout *L)
{
    double leg = pdt_legend_height(L, nranks, w, 1);
    if (leg > STRIP_MAX * h) {
        leg = 0;
        L->hidden |= PDT_PANEL_LEGEND;
    }
    double mid = h - tl - top - leg;
    L->legend_mode = 1;
    L->top = (pdt_rect){0, 0, w, top};
    L->geo = (pdt_rect){0, top, w, mid};
    L->legend = (pdt_rect){0, top + mid, leg > 0 ? w : 0, leg};
    L->timeline = (pdt_rect){0, h - tl, tl > 0 ? w : 0, tl};
    L->code = L->stack = L->lifted = (pdt_rect){w, top, 0, 0};
}

/* The timeline's height: its rows hold their labels (1.7 x the label
 * size), up to 16 rows, within 30 % of the height. */
static double timeline_height(const pdt_layout *L, int nranks, double h)
{
    int rows = nranks < 1 ? 1 : nranks > 16 ? 16 : nranks;
    return fmin(1.7 * L->font + rows * 1.7 * L->label, 0.3 * h);
}

/* The whole layout for h high (the `more` line under it excluded). */
static void layout_pass(double w, double h, int nranks, unsigned panels, pdt_layout *L)
{
    double top = pdt_layout_top_height(L);
    double tl = panels & PDT_PANEL_TIMELINE ? timeline_height(L, nranks, h) : 0;
    L->hidden = 0;
    if (!(panels & (PDT_PANEL_CODE | PDT_PANEL_STACK | PDT_PANEL_LIFTED))) {
        layout_strip(w, h, top, tl, nranks, L);
        pdt_layout_tree_strip(L, panels, w, h);
        return;
    }
    layout_column(w, h, top, tl, nranks, panels, 1, L);
    /* a legend strip that leaves the picture less than its fair share of
     * the room under the top bar: the legend is hidden instead */
    if (L->legend.w > 0 && L->legend_mode == 2 &&
        L->geo.w * L->geo.h < PICTURE_SHARE * w * (h - top)) {
        L->hidden = 0;
        layout_column(w, h, top, tl, nranks, panels, 0, L);
    }
}

/* The pages Tab shows the hidden panels on, over the picture and the
 * column (from under the top bar to the `more` line): the legend, the
 * stacks and the lifted view on the first, the timeline on its own page
 * when other panels are hidden too. */
static int cover_pages(unsigned hid)
{
    int others = (hid & (PDT_PANEL_LEGEND | PDT_PANEL_STACK | PDT_PANEL_LIFTED)) != 0;
    return others && (hid & PDT_PANEL_TIMELINE) ? 2 : hid ? 1 : 0;
}

/* Page `page` (1 ..) of the hidden panels: the legend (its items flowing)
 * at the left, the stacks over the lifted view at the right; the timeline
 * across.  The panels that had room give theirs. */
static void layout_cover(double w, int page, pdt_layout *L, int nranks)
{
    unsigned hid = L->hidden;
    double y0 = L->top.h, y1 = L->more.y;
    pdt_rect none = {w, y0, 0, 0};
    L->covered = page;
    L->legend = L->code = L->stack = L->lifted = L->timeline = L->tree = none;
    if (cover_pages(hid) == 2) hid = page == 2 ? PDT_PANEL_TIMELINE : hid & ~PDT_PANEL_TIMELINE;
    if (hid & PDT_PANEL_TIMELINE) {
        double th = hid == PDT_PANEL_TIMELINE ? y1 - y0 : fmin(0.4 * (y1 - y0), 0.3 * w);
        L->timeline = (pdt_rect){0, y1 - th, w, th};
        y1 -= th;
    }
    double x = 0;
    int right = (hid & (PDT_PANEL_STACK | PDT_PANEL_LIFTED)) != 0;
    if (hid & PDT_PANEL_LEGEND) { /* its items flowing, in half the width if they fit */
        double lw = right ? w / 2 : w, lh = pdt_legend_height(L, nranks, lw, 2);
        L->legend_mode = 2;
        if (right && lh > y1 - y0) { /* across, above the others */
            lh = fmin(pdt_legend_height(L, nranks, w, 2), 0.5 * (y1 - y0));
            L->legend = (pdt_rect){0, y0, w, lh};
            y0 += lh;
        } else {
            L->legend = (pdt_rect){0, y0, lw, right ? y1 - y0 : fmin(lh, y1 - y0)};
            x = right ? lw : w;
        }
    }
    double sh = 0;
    if (hid & PDT_PANEL_STACK)
        sh = hid & PDT_PANEL_LIFTED ? fmin(0.4 * (y1 - y0), column_needs(L).stack_min * 1.4)
                                    : y1 - y0;
    if (hid & PDT_PANEL_STACK) L->stack = (pdt_rect){x, y0, w - x, sh};
    if (hid & PDT_PANEL_LIFTED) L->lifted = (pdt_rect){x, y0 + sh, w - x, y1 - y0 - sh};
}

static void layout_all(double w, double h, int nranks, unsigned panels, double scale,
                       int overflow, pdt_layout *L)
{
    memset(L, 0, sizeof *L);
    layout_fonts(w, h, scale, L);
    layout_pass(w, h, nranks, panels, L);
    if (L->hidden) { /* a line at the bottom names them: the panels share the rest */
        double bar = 1.6 * L->label;
        layout_pass(w, h - bar, nranks, panels, L);
        L->more = (pdt_rect){0, h - bar, L->hidden ? w : 0, bar};
        L->pages = cover_pages(L->hidden);
        if (overflow > 0 && L->pages)
            layout_cover(w, overflow > L->pages ? L->pages : overflow, L, nranks);
    }
    layout_round(L);
}

void pdt_render_layout_scaled(double w, double h, int nranks, unsigned panels, double scale,
                              pdt_layout *L)
{
    layout_all(w, h, nranks, panels, scale, 0, L);
}

/* The side column (legend, code, stacks, lifted view) beside the picture,
 * the timeline under both.  When the column cannot hold the legend, four
 * code rows and a stack, the legend becomes a strip across (or is hidden
 * when that strip would be tall), then the timeline gives its room, then
 * the stacks; each panel left out is named in L->hidden. */
static void layout_column(double w, double h, double top, double tl, int nranks, unsigned panels,
                          int strip_ok, pdt_layout *L)
{
    int has_code = (panels & PDT_PANEL_CODE) != 0, has_stack = (panels & PDT_PANEL_STACK) != 0,
        has_lifted = (panels & PDT_PANEL_LIFTED) != 0;
    double f = L->font, side = fmin(fmax(0.34 * w, 19 * f), 0.5 * w);
    column C = column_needs(L);
    C.legend = pdt_legend_height(L, nranks, side, 0); /* what its text needs */
    /* a legend too tall for the column beside four code lines and the
     * timeline: a strip across (the timeline keeps its rows), or hidden */
    double strip = 0;
    L->legend_mode = 0;
    if (C.legend + (has_code ? C.code_min : 0) > h - top - tl) {
        strip = pdt_legend_height(L, nranks, w, 2);
        C.legend = 0;
        L->legend_mode = 2;
        if (strip > STRIP_MAX * h || !strip_ok) {
            strip = 0;
            L->hidden |= PDT_PANEL_LEGEND;
        }
    }
    double need = C.legend + (has_code ? C.code_min : 0) + (has_stack ? C.stack_min : 0);
    if (h - top - tl - strip < need && tl > 0) {
        tl = h - top - strip - need;
        if (tl < 2.2 * f + 1.7 * L->label) tl = 0, L->hidden |= PDT_PANEL_TIMELINE;
    }
    if (h - top - tl - strip < need && has_stack) has_stack = 0, L->hidden |= PDT_PANEL_STACK;
    double mid = h - tl - top - strip;
    L->top = (pdt_rect){0, 0, w, top};
    L->timeline = (pdt_rect){0, h - tl, tl > 0 ? w : 0, tl};
    L->geo = (pdt_rect){0, top, w - side, mid};
    double x = w - side, y = top, leg = fmin(C.legend, mid), code, stk, lifted;
    /* the merge tree: a third of the column beside the stacks or the lifted
     * view, all but the code's four lines beside the code alone, else all */
    double tree = 0;
    if (panels & PDT_PANEL_TREE) {
        tree = mid - leg;
        if (has_stack || has_lifted) tree = fmax(6 * f, 0.34 * (mid - leg));
        else if (has_code) tree = fmax(6 * f, mid - leg - C.code_min);
    }
    column_split(mid - leg - tree, &C, has_code, has_stack, has_lifted, &code, &stk, &lifted);
    if (has_stack && !(stk > 0)) L->hidden |= PDT_PANEL_STACK;
    if (has_lifted && !(lifted > 0)) L->hidden |= PDT_PANEL_LIFTED;
    L->legend = strip > 0 ? (pdt_rect){0, top + mid, w, strip}
                          : (pdt_rect){x, y, leg > 0 ? side : 0, leg};
    L->code = (pdt_rect){x, y + leg, code > 0 ? side : 0, code};
    L->stack = (pdt_rect){x, y + leg + code, stk > 0 ? side : 0, stk};
    L->lifted = (pdt_rect){x, y + leg + code + stk, lifted > 0 ? side : 0, lifted};
    L->tree = (pdt_rect){x, y + leg + code + stk + lifted, tree > 0 ? side : 0, tree};
}

double pdt_layout_top_height(const pdt_layout *L)
{
    return 3.35 * L->font; /* the event line, then the status (or the event's rest) */
}

double pdt_layout_code_row(const pdt_layout *L)
{
    return 1.4 * L->body; /* an underscore stays on its own line */
}

/* Whole pixels: clipping to them stays a fast box clip. */
static void layout_round(pdt_layout *L)
{
    pdt_rect *all[] = {&L->top,    &L->geo,    &L->legend,   &L->code,
                       &L->stack,  &L->lifted, &L->timeline, &L->tree, &L->more};
    for (size_t i = 0; i < sizeof all / sizeof *all; i++) {
        double x1 = round(all[i]->x + all[i]->w), y1 = round(all[i]->y + all[i]->h);
        all[i]->x = round(all[i]->x);
        all[i]->y = round(all[i]->y);
        all[i]->w = x1 - all[i]->x;
        all[i]->h = y1 - all[i]->y;
    }
}

xform pdt_geo_xform(const pdt_replay *r, const pdt_view *v, double w, double h)
{
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(r), v, &L);
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
    xform X = pdt_geo_xform(r, v, w, h);
    *wx = (sx - X.ox) / X.s;
    *wy = (X.oy - sy) / X.s;
}

void pdt_view_to_screen(const pdt_replay *r, const pdt_view *v, double w, double h, double wx,
                        double wy, double *sx, double *sy)
{
    xform X = pdt_geo_xform(r, v, w, h);
    *sx = X.ox + X.s * wx;
    *sy = X.oy - X.s * wy;
}

void pdt_view_zoom_at(const pdt_replay *r, pdt_view *v, double w, double h, double sx, double sy,
                      double f)
{
    double wx, wy, cx, cy;
    pdt_view_to_world(r, v, w, h, sx, sy, &wx, &wy);
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(r), v, &L);
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
    xform X = pdt_geo_xform(r, v, w, h);
    v->cx += (nx - sx) / X.s;
    v->cy -= (ny - sy) / X.s;
}

int pdt_view_fit_circle(const pdt_replay *r, pdt_view *v, double w, double h, double ox, double oy,
                        double rr)
{
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(r), v, &L);
    xform X = pdt_geo_xform(r, v, w, h);
    double sx = X.ox + X.s * ox, sy = X.oy - X.s * oy, sr = X.s * rr;
    if (sx - sr >= L.geo.x && sx + sr <= L.geo.x + L.geo.w && sy - sr >= L.geo.y &&
        sy + sr <= L.geo.y + L.geo.h)
        return 0;
    /* centre on the circle and zoom out until its diameter takes 90 % of
     * the smaller side */
    double want = 0.9 * fmin(L.geo.w, L.geo.h) / (2 * rr);
    v->cx = ox;
    v->cy = oy;
    v->centred = 1;
    v->zoom = 1;
    xform X1 = pdt_geo_xform(r, v, w, h);
    v->zoom = fmin(1, want / X1.s);
    return 1;
}
