/* pdt — the groups of ranks a frame shows (pdt/view/ranktree.h): the ranks
 * on screen are those whose strip box meets the picture's view and those
 * in the timeline's rows shown; at most eight groups of the merge tree
 * cover them, one hue each.  Up to eight ranks, every rank is its own
 * group, in every view, so a small run keeps its colours. */
#include "render_int.h"

size_t pdt_timeline_rows(const pdt_ranktree *t, const pdt_view *v, int32_t **rows)
{
    int32_t cut[PDT_PALETTE_HUES];
    size_t nc = pdt_ranktree_cut(t, NULL, PDT_PALETTE_HUES, cut);
    const uint8_t *open = v ? v->tl_open : NULL;
    size_t n = pdt_ranktree_rows(t, cut, nc, open, NULL, 0);
    *rows = malloc((n ? n : 1) * sizeof **rows);
    if (!*rows) return 0;
    return pdt_ranktree_rows(t, cut, nc, open, *rows, n);
}

/* Ranks whose strip box meets the picture's view (or that have none). */
static void on_in_picture(const ctx *c, uint8_t *on)
{
    pdt_rect G = c->L.geo;
    if (G.w <= 0 || G.h <= 0) return;
    double wx0 = (G.x - c->X.ox) / c->X.s, wx1 = (G.x + G.w - c->X.ox) / c->X.s;
    double wy1 = (c->X.oy - G.y) / c->X.s, wy0 = (c->X.oy - G.y - G.h) / c->X.s;
    for (int q = 0; q < c->nranks; q++) {
        pdt_point lo, hi;
        if (!pdt_replay_box(c->r, q, &lo, &hi)) {
            on[q] = 1;
            continue;
        }
        if (hi.x >= wx0 && lo.x <= wx1 && hi.y >= wy0 && lo.y <= wy1) on[q] = 1;
    }
}

static void on_in_timeline(const ctx *c, uint8_t *on)
{
    if (c->L.timeline.w <= 0 || !c->rows) return;
    tl_geom g;
    pdt_timeline_geom(c->L.timeline, c->L.font, c->nranks, c->nrows, pdt_replay_count(c->r), c->v, &g);
    size_t n;
    const pdt_rtnode *N = pdt_ranktree_nodes(c->tree, &n);
    for (int i = g.row0; i < g.row0 + g.nshow && (size_t)i < c->nrows; i++)
        memset(on + N[c->rows[i]].lo, 1, N[c->rows[i]].hi - N[c->rows[i]].lo);
}

void pdt_frame_groups(ctx *c)
{
    c->tree = c->v->tree;
    if (!c->tree) c->tree = c->own_tree = pdt_ranktree_new(c->r);
    if (!c->tree || pdt_ranktree_nranks(c->tree) != (c->nranks > 0 ? c->nranks : 1)) {
        c->tree = NULL;
        return; /* colours by rank */
    }
    c->nrows = pdt_timeline_rows(c->tree, c->v, &c->rows);
    uint8_t *on = calloc((size_t)c->nranks + 1, 1);
    c->hue = malloc((size_t)c->nranks + 1);
    if (!on || !c->hue) {
        free(on);
        free(c->hue);
        c->hue = NULL;
        return;
    }
    if (c->nranks <= PDT_PALETTE_HUES) memset(on, 1, (size_t)c->nranks);
    on_in_picture(c, on);
    on_in_timeline(c, on);
    c->ngroups = pdt_ranktree_cut(c->tree, on, PDT_PALETTE_HUES, c->groups);
    memset(c->hue, 255, (size_t)c->nranks);
    size_t n;
    const pdt_rtnode *N = pdt_ranktree_nodes(c->tree, &n);
    for (size_t i = 0; i < c->ngroups; i++)
        memset(c->hue + N[c->groups[i]].lo, (int)i, N[c->groups[i]].hi - N[c->groups[i]].lo);
    free(on);
}

void pdt_frame_groups_done(ctx *c)
{
    free(c->hue);
    free(c->rows);
    pdt_ranktree_free(c->own_tree);
    c->hue = NULL;
    c->rows = NULL;
    c->own_tree = NULL;
}

/* The screen box of group i's shown ranks; 0 when none has a box. */
static int group_box(const ctx *c, size_t i, double *x0, double *y0, double *x1, double *y1)
{
    size_t n;
    const pdt_rtnode *d = &pdt_ranktree_nodes(c->tree, &n)[c->groups[i]];
    int any = 0;
    for (uint32_t q = d->lo; q < d->hi; q++) {
        pdt_point lo, hi;
        if (!shown(c, q) || !pdt_replay_box(c->r, (int)q, &lo, &hi)) continue;
        double a = c->X.ox + c->X.s * lo.x, b = c->X.ox + c->X.s * hi.x;
        double e = c->X.oy - c->X.s * hi.y, f = c->X.oy - c->X.s * lo.y;
        if (!any) *x0 = a, *x1 = b, *y0 = e, *y1 = f;
        else *x0 = fmin(*x0, a), *x1 = fmax(*x1, b), *y0 = fmin(*y0, e), *y1 = fmax(*y1, f);
        any = 1;
    }
    return any;
}

int pdt_draw_group_labels(ctx *c)
{
    if (!c->hue || !c->tree || c->nranks <= PDT_PALETTE_HUES) return 0;
    cairo_t *cr = c->cr;
    double f = c->L.font, fs = 0.8 * f, pad = 0.4 * f;
    pdt_rect last[2] = {{0, 0, 0, 0}, {0, 0, 0, 0}}; /* the last label above, below */
    int merging = 0; /* a merge's G_L, G_R labels are above its boxes: groups' go below */
    for (int q = 0; q < c->nranks && !merging; q++)
        merging = pdt_rstate_slot(c->r, c->s, q, PDT_SLOT_MERGE) >= 0;
    for (size_t i = 0; i < c->ngroups; i++) {
        double x0, y0, x1, y1;
        if (!group_box(c, i, &x0, &y0, &x1, &y1)) continue;
        size_t n;
        const pdt_rtnode *d = &pdt_ranktree_nodes(c->tree, &n)[c->groups[i]];
        char lab[40];
        if (d->hi - d->lo == 1) snprintf(lab, sizeof lab, "rank %u", d->lo);
        else snprintf(lab, sizeof lab, "ranks %u–%u", d->lo, d->hi - 1);
        double tw = text_w(cr, SANS, fs, lab);
        if (tw > x1 - x0 + 2 * pad && d->hi - d->lo > 1) {
            snprintf(lab, sizeof lab, "%u–%u", d->lo, d->hi - 1);
            tw = text_w(cr, SANS, fs, lab);
        }
        int side = merging ? 1 : (int)(i % 2);
        double lx = fmax(x0 - pad, (x0 + x1) / 2 - tw / 2);
        if (last[side].w > 0 && lx < last[side].x + last[side].w + 0.3 * f) continue; /* thinned */
        double ly = side ? y1 + pad + 0.95 * f : y0 - pad - 0.25 * f;
        if (lx < c->L.geo.x || lx + tw > c->L.geo.x + c->L.geo.w) continue;
        if (ly - fs < c->L.geo.y || ly + 0.3 * fs > c->L.geo.y + c->L.geo.h) continue;
        int hit = 0; /* the event line's rows under the bar, the merges' G_L, G_R */
        for (int t = 0; t < c->ntaken && !hit; t++)
            hit = lx < c->taken[t].x1 && c->taken[t].x0 < lx + tw && ly - fs < c->taken[t].y1 &&
                  c->taken[t].y0 < ly + 0.3 * fs;
        if (hit) continue;
        last[side] = (pdt_rect){lx, ly - fs, tw, fs};
        if (c->ntaken < TAKEN_MAX) /* the point labels keep off it */
            c->taken[c->ntaken++] = (lbox){lx - 0.1 * fs, ly - fs, lx + tw + 0.1 * fs, ly + 0.3 * fs};
        cairo_rectangle(cr, lx - 0.1 * fs, ly - 0.85 * fs, tw + 0.2 * fs, 1.1 * fs);
        rgb(cr, c->T->bg, 0.8);
        cairo_fill(cr);
        set_rank(c, (int)d->lo, 1);
        text_at(cr, SANS, 0, fs, lx, ly, lab);
    }
    return 1;
}

size_t pdt_render_screen_groups(const pdt_replay *r, const pdt_view *v, double w, double h,
                                uint32_t *lo, uint32_t *hi)
{
    ctx c;
    memset(&c, 0, sizeof c);
    c.r = r;
    c.v = v;
    c.nranks = pdt_replay_nranks(r);
    pdt_render_layout_view(w, h, c.nranks, v, &c.L);
    c.X = pdt_geo_xform(r, v, w, h);
    pdt_frame_groups(&c);
    size_t n = c.hue ? c.ngroups : 0, nn;
    for (size_t i = 0; i < n; i++) {
        const pdt_rtnode *d = &pdt_ranktree_nodes(c.tree, &nn)[c.groups[i]];
        lo[i] = d->lo;
        hi[i] = d->hi;
    }
    pdt_frame_groups_done(&c);
    return n;
}
