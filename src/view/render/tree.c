/* pdt — the merge-tree panel (--panels tree): the merge steps as the binary
 * tree they form (pdt/view/ranktree.h), the root at the top, the ranks at
 * the bottom in rank order; each step with its time, its border set |B| and
 * the bytes its merge rank received, as far as labels fit without overlap;
 * the critical path (from the root, the child ready last) in the discard
 * colour and thicker; the steps under way at the cursor lit, those done
 * filled; a click on a step seeks to its beginning. */
#include "render_int.h"

#define TREE_LEVELS 40

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

/* Where the tree's nodes go in R: the first nl levels (from the root) with
 * room for a label under each node, the deeper ones packed below them; a
 * line at the bottom for the step under way. */
typedef struct tgeom {
    double x0, w, r, rs, fs;
    double y[TREE_LEVELS];  /* each level's centre line */
    int levels, nl;         /* levels (leaves included), of them labelled */
    int nranks;
    double foot;            /* the bottom line's baseline */
} tgeom;

static void tree_geom(pdt_rect R, double f, double label, const pdt_ranktree *t, tgeom *g)
{
    size_t n;
    const pdt_rtnode *N = pdt_ranktree_nodes(t, &n);
    int depth = 1;
    for (size_t i = 0; i < n; i++)
        if (N[i].kid[0] >= 0 && (int)N[i].depth + 1 > depth) depth = (int)N[i].depth + 1;
    if (depth > TREE_LEVELS - 1) depth = TREE_LEVELS - 1;
    g->levels = depth + 1;
    g->nranks = pdt_ranktree_nranks(t);
    g->fs = fmax(16, 0.8 * label);
    g->x0 = R.x + 0.8 * f;
    g->w = R.w - 1.6 * f;
    g->r = fmax(4, 0.3 * g->fs);
    double top = R.y + 1.6 * f + g->r, bottom = R.y + R.h - 1.5 * g->fs - g->r;
    g->foot = R.y + R.h - 0.4 * g->fs;
    double avail = bottom - top, dyl = 2.2 * g->r + 1.5 * g->fs;
    int nl = 0; /* labelled levels: the rest packed, 6 px a level at least */
    while (nl < depth && (nl + 1) * dyl + (depth - nl - 1) * 6.0 <= avail) nl++;
    g->nl = nl;
    double dys = depth > nl ? (avail - nl * dyl) / (depth - nl) : 0;
    if (nl == depth) dyl = avail / fmax(1, depth);
    g->rs = fmin(g->r, fmax(1.2, 0.4 * dys));
    g->y[0] = top;
    for (int d = 1; d < g->levels; d++) g->y[d] = g->y[d - 1] + (d <= nl ? dyl : dys);
}

static void node_xy(const tgeom *g, const pdt_rtnode *d, double *x, double *y)
{
    *x = g->x0 + g->w * ((d->lo + d->hi) / 2.0) / g->nranks;
    *y = g->y[d->depth < (uint32_t)g->levels ? d->depth : (uint32_t)g->levels - 1];
}

static double node_r(const tgeom *g, const pdt_rtnode *d)
{
    return (int)d->depth < g->nl ? g->r : g->rs;
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
        double rr = st == 1 ? fmax(1.6 * node_r(g, d), 5) : node_r(g, d);
        cairo_new_sub_path(cr);
        cairo_arc(cr, x, y, rr, 0, 2 * M_PI);
        if (st == 1) rgb(cr, c->T->select, 1);
        else if (st == 2) set_rank(c, (int)d->lo, 1);
        else rgb(cr, c->T->panel, 1);
        cairo_fill_preserve(cr);
        if (d->critical) rgb(cr, RED, 1);
        else rgb(cr, c->T->ink, 0.8);
        cairo_set_line_width(cr, st == 1 ? 2.5 : rr < 3 ? 0.8 : 1.2);
        cairo_stroke(cr);
    }
}

typedef struct tplaced {
    pdt_rect r[128];
    int n;
} tplaced;

/* Place box a in R over no box placed, a gap of 4 px between boxes. */
static int tplace(tplaced *P, pdt_rect R, pdt_rect a)
{
    if (a.x < R.x + 2 || a.x + a.w > R.x + R.w - 2 || a.y < R.y + 2 || a.y + a.h > R.y + R.h - 2)
        return 0;
    for (int i = 0; i < P->n; i++) {
        const pdt_rect *q = &P->r[i];
        if (a.x < q->x + q->w + 4 && q->x < a.x + a.w + 4 && a.y < q->y + q->h + 2 && q->y < a.y + a.h + 2)
            return 0;
    }
    if (P->n < 128) P->r[P->n++] = a;
    return 1;
}

/* A step's facts: "1.8 ms · |B| 155 · 18 kB" (full) or "1.8 ms". */
static void step_text(const ctx *c, const pdt_rtnode *d, int full, char *lb, size_t cap)
{
    size_t nm;
    const pdt_rmerge *M = pdt_replay_merges(c->r, &nm);
    char b[24];
    fmt_bytes(d->bytes, b, sizeof b);
    if (full) snprintf(lb, cap, "%.1f ms · |B| %u · %s", (double)d->t_ns / 1e6, M[d->merge].border, b);
    else snprintf(lb, cap, "%.1f ms", (double)d->t_ns / 1e6);
}

/* Node d's label under it, the full facts if they fit, else its time. */
static void label_node(ctx *c, const tgeom *g, const pdt_rtnode *d, tplaced *P)
{
    cairo_t *cr = c->cr;
    double fs = g->fs, x, y;
    node_xy(g, d, &x, &y);
    for (int full = 1; full >= 0; full--) {
        char lb[80];
        step_text(c, d, full, lb, sizeof lb);
        double tw = text_wb(cr, SANS, d->critical, fs, lb); /* bold: critical */
        pdt_rect a = {x - tw / 2, y + node_r(g, d) + 2, tw, 1.1 * fs};
        if (!tplace(P, c->L.tree, a)) continue;
        rgb(cr, c->T->panel, 0.85);
        cairo_rectangle(cr, a.x, a.y, a.w, a.h);
        cairo_fill(cr);
        rgb(cr, d->critical ? RED : c->T->ink, 1);
        text_at(cr, SANS, d->critical, fs, a.x, a.y + 0.85 * fs, lb);
        return;
    }
}

/* Labels on the labelled levels: the steps under way first, then the
 * critical path, then the rest by depth; one that would overlap is left
 * out (the bottom line names the step under way). */
static void draw_labels(ctx *c, const tgeom *g, const pdt_rtnode *N, size_t n, tplaced *P)
{
    size_t nm;
    const pdt_rmerge *M = pdt_replay_merges(c->r, &nm);
    for (int pass = 0; pass < 3; pass++)
        for (int depth = 0; depth < g->nl; depth++)
            for (size_t i = 0; i < n; i++) {
                const pdt_rtnode *d = &N[i];
                if (d->merge < 0 || (int)d->depth != depth) continue;
                int lit = merge_state(&M[d->merge], c->s->k) == 1;
                int want = pass == 0 ? lit : pass == 1 ? !lit && d->critical : !lit && !d->critical;
                if (want) label_node(c, g, d, P);
            }
}

/* The bottom line: the step under way (the one of the current event's rank,
 * else the deepest), or what a click does. */
static void draw_foot(ctx *c, const tgeom *g, const pdt_rtnode *N, size_t n)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.tree;
    size_t nm;
    const pdt_rmerge *M = pdt_replay_merges(c->r, &nm);
    uint32_t q = c->s->k ? pdt_replay_rank_of(c->r, c->s->k - 1) : UINT32_MAX;
    const pdt_rtnode *best = NULL;
    for (size_t i = 0; i < n; i++) {
        const pdt_rtnode *d = &N[i];
        if (d->merge < 0 || merge_state(&M[d->merge], c->s->k) != 1) continue;
        int mine = M[d->merge].rank == q, bmine = best && M[best->merge].rank == q;
        if (!best || (mine && !bmine) || (mine == bmine && d->depth > best->depth)) best = d;
    }
    char lb[160], name[40], facts[80];
    if (best) {
        pdt_ranktree_name(c->tree, (int32_t)(best - N), name, sizeof name);
        step_text(c, best, 1, facts, sizeof facts);
        snprintf(lb, sizeof lb, "now: merge level %u of %s · %s", M[best->merge].level, name, facts);
    } else snprintf(lb, sizeof lb, "%s", nm ? "click a step to go to it" : "no merge steps in this run");
    double fs = g->fs, room = R.w - 1.2 * c->L.font;
    if (text_wb(cr, SANS, 0, fs, lb) > room && best) {
        snprintf(lb, sizeof lb, "now: %s · %s", name, facts);
        if (text_wb(cr, SANS, 0, fs, lb) > room) {
            step_text(c, best, 0, facts, sizeof facts);
            snprintf(lb, sizeof lb, "now: %s · %s", name, facts);
        }
    }
    if (text_wb(cr, SANS, 0, fs, lb) > room) return;
    rgb(cr, c->T->ink, best ? 1 : 0.7);
    text_at(cr, SANS, 0, fs, R.x + 0.6 * c->L.font, g->foot, lb);
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
    tree_geom(R, f, c->L.label, c->tree, &g);
    tplaced P = {.n = 2};
    P.r[0] = (pdt_rect){R.x, R.y, R.w, 1.6 * f}; /* the title */
    P.r[1] = (pdt_rect){R.x, g.foot - 1.1 * g.fs, R.w, 1.4 * g.fs}; /* the bottom line */
    draw_edges(c, &g, N, n);
    draw_nodes(c, &g, N, n);
    draw_labels(c, &g, N, n, &P);
    draw_foot(c, &g, N, n);
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
    tree_geom(R, L.font, L.label, t, &g);
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
