/* pdt — the merge-tree panel (--panels tree): the merge steps as the binary
 * tree they form (pdt/view/ranktree.h), the root at the top, the ranks at
 * the bottom in rank order; each step with its time, its border set |B| and
 * the bytes its merge rank received, as far as labels fit without overlap;
 * the critical path (from the root, the child ready last) in the discard
 * colour and thicker; the steps under way at the cursor lit, those done
 * filled; a click on a step seeks to its beginning. */
#include "render_int.h"

void pdt_layout_tree_strip(pdt_layout *L, unsigned panels, double w, double h)
{
    (void)h;
    L->tree = (pdt_rect){w, L->top.h, 0, 0};
    if (!(panels & PDT_PANEL_TREE)) return;
    if (L->timeline.w > 0) { /* the right part of the bottom band */
        double tw = 0.4 * w;
        L->timeline.w = w - tw;
        L->tree = (pdt_rect){w - tw, L->timeline.y, tw, L->timeline.h};
        return;
    }
    double band = 0.3 * L->geo.h; /* else a band under the picture */
    L->geo.h -= band;
    L->tree = (pdt_rect){0, L->geo.y + L->geo.h, w, band};
}

/* Where the tree's nodes go in R. */
typedef struct tgeom {
    double x0, w, y0, dy, r;
    int nranks;
} tgeom;

static void tree_geom(pdt_rect R, double f, const pdt_ranktree *t, tgeom *g)
{
    size_t n;
    const pdt_rtnode *N = pdt_ranktree_nodes(t, &n);
    uint32_t depth = 1;
    for (size_t i = 0; i < n; i++)
        if (N[i].kid[0] >= 0 && N[i].depth + 1 > depth) depth = N[i].depth + 1;
    g->nranks = pdt_ranktree_nranks(t);
    g->x0 = R.x + 0.8 * f;
    g->w = R.w - 1.6 * f;
    g->y0 = R.y + 2.2 * f;
    g->dy = (R.h - 3.4 * f) / depth;
    g->r = fmax(3, fmin(0.35 * f, 0.3 * g->dy));
}

static void node_xy(const tgeom *g, const pdt_rtnode *d, double *x, double *y)
{
    *x = g->x0 + g->w * ((d->lo + d->hi) / 2.0) / g->nranks;
    *y = g->y0 + g->dy * d->depth;
}

/* 0: not begun, 1: under way at cursor k, 2: done. */
static int merge_state(const pdt_rmerge *m, size_t k)
{
    if (k <= m->begin_ev) return 0;
    if (m->end_ev == NONE32 || k <= m->end_ev) return 1;
    return 2;
}

static void fmt_bytes(uint64_t b, char *s, size_t cap)
{
    if (b >= 10u << 20) snprintf(s, cap, "%.0f MB", (double)b / 1048576.0);
    else if (b >= 10u << 10) snprintf(s, cap, "%.0f kB", (double)b / 1024.0);
    else snprintf(s, cap, "%llu B", (unsigned long long)b);
}

static void draw_edges(ctx *c, const tgeom *g, const pdt_rtnode *N, size_t n)
{
    cairo_t *cr = c->cr;
    for (int pass = 0; pass < 2; pass++) /* the critical path over the rest */
        for (size_t i = 0; i < n; i++) {
            const pdt_rtnode *d = &N[i];
            if (d->parent < 0 || (d->kid[0] < 0 && g->nranks > 64)) continue;
            int crit = d->critical && N[d->parent].critical;
            if (crit != pass) continue;
            double x, y, px, py;
            node_xy(g, d, &x, &y);
            node_xy(g, &N[d->parent], &px, &py);
            cairo_move_to(cr, px, py);
            cairo_line_to(cr, x, y);
            if (crit) rgb(cr, RED, 1);
            else rgb(cr, c->T->ink, 0.35);
            cairo_set_line_width(cr, crit ? fmax(2.5, 0.18 * c->L.font) : 1);
            cairo_stroke(cr);
        }
}

static void draw_nodes(ctx *c, const tgeom *g, const pdt_rtnode *N, size_t n)
{
    cairo_t *cr = c->cr;
    size_t nm;
    const pdt_rmerge *M = pdt_replay_merges(c->r, &nm);
    for (size_t i = 0; i < n; i++) {
        const pdt_rtnode *d = &N[i];
        if (d->merge < 0) continue;
        double x, y;
        node_xy(g, d, &x, &y);
        int st = merge_state(&M[d->merge], c->s->k);
        double rr = st == 1 ? 1.6 * g->r : g->r;
        cairo_new_sub_path(cr);
        cairo_arc(cr, x, y, rr, 0, 2 * M_PI);
        if (st == 1) rgb(cr, c->T->select, 1);
        else if (st == 2) set_rank(c, (int)d->lo, 1);
        else rgb(cr, c->T->panel, 1);
        cairo_fill_preserve(cr);
        if (d->critical) rgb(cr, RED, 1);
        else rgb(cr, c->T->ink, 0.8);
        cairo_set_line_width(cr, st == 1 ? 2.5 : 1.2);
        cairo_stroke(cr);
    }
}

typedef struct tplaced {
    pdt_rect r[128];
    int n;
} tplaced;

static int tplace(tplaced *P, pdt_rect R, pdt_rect a)
{
    if (a.x < R.x + 2 || a.x + a.w > R.x + R.w - 2 || a.y < R.y + 2 || a.y + a.h > R.y + R.h - 2)
        return 0;
    for (int i = 0; i < P->n; i++) {
        const pdt_rect *q = &P->r[i];
        if (a.x < q->x + q->w && q->x < a.x + a.w && a.y < q->y + q->h && q->y < a.y + a.h) return 0;
    }
    if (P->n < 128) P->r[P->n++] = a;
    return 1;
}

/* Labels by depth, the root first; one that would overlap is left out. */
static void draw_labels(ctx *c, const tgeom *g, const pdt_rtnode *N, size_t n, tplaced *P)
{
    cairo_t *cr = c->cr;
    double fs = fmax(fmin(16, c->L.label), 0.62 * c->L.font); /* 16 px on a projector */
    for (uint32_t depth = 0; depth < 12; depth++)
        for (size_t i = 0; i < n; i++) {
            const pdt_rtnode *d = &N[i];
            if (d->merge < 0 || d->depth != depth) continue;
            char b[24], lb[80];
            fmt_bytes(d->bytes, b, sizeof b);
            snprintf(lb, sizeof lb, "%.1f ms · |B| %u · %s", (double)d->t_ns / 1e6,
                     pdt_replay_merges(c->r, &(size_t){0})[d->merge].border, b);
            double x, y, tw = text_wb(cr, SANS, d->critical, fs, lb); /* bold: critical */
            node_xy(g, d, &x, &y);
            pdt_rect a = {x - tw / 2, y + 1.4 * g->r, tw, 1.1 * fs};
            if (!tplace(P, c->L.tree, a)) continue;
            rgb(cr, c->T->panel, 0.85);
            cairo_rectangle(cr, a.x, a.y, a.w, a.h);
            cairo_fill(cr);
            rgb(cr, d->critical ? RED : c->T->ink, 1);
            text_at(cr, SANS, d->critical, fs, a.x, a.y + 0.85 * fs, lb);
        }
}

void pdt_draw_tree(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.tree;
    double f = c->L.font;
    panel(cr, c->T, R, "Merge tree (critical path in red)", f);
    if (!c->tree) return;
    cairo_save(cr);
    clip_rect(cr, R);
    size_t n;
    const pdt_rtnode *N = pdt_ranktree_nodes(c->tree, &n);
    tgeom g;
    tree_geom(R, f, c->tree, &g);
    tplaced P = {.n = 1};
    P.r[0] = (pdt_rect){R.x, R.y, R.w, 1.6 * f}; /* the title */
    draw_edges(c, &g, N, n);
    draw_nodes(c, &g, N, n);
    draw_labels(c, &g, N, n, &P);
    size_t nm;
    pdt_replay_merges(c->r, &nm);
    if (nm == 0) {
        rgb(cr, c->T->ink, 0.7);
        text_at(cr, SANS, 0, fmax(12, 0.7 * f), R.x + 0.5 * f, R.y + 2.6 * f, "no merge steps in this run");
    }
    cairo_restore(cr);
}

int pdt_render_tree_at(const pdt_replay *r, const pdt_view *v, double w, double h, double sx,
                       double sy)
{
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(r), v, &L);
    pdt_rect R = L.tree;
    if (R.w <= 0 || sx < R.x || sx > R.x + R.w || sy < R.y || sy > R.y + R.h) return -1;
    pdt_ranktree *own = NULL;
    const pdt_ranktree *t = v && v->tree ? v->tree : (own = pdt_ranktree_new(r));
    if (!t) return -1;
    tgeom g;
    tree_geom(R, L.font, t, &g);
    size_t n;
    const pdt_rtnode *N = pdt_ranktree_nodes(t, &n);
    int best = -1;
    double bd = fmax(0.8 * L.font, 2 * g.r);
    for (size_t i = 0; i < n; i++) {
        if (N[i].merge < 0) continue;
        double x, y;
        node_xy(&g, &N[i], &x, &y);
        double d = hypot(x - sx, y - sy);
        if (d < bd) bd = d, best = N[i].merge;
    }
    pdt_ranktree_free(own);
    return best;
}
