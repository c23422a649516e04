/* pdt — internals of the cairo renderer, shared by its files (not installed,
 * not part of the API):
 *
 *   render.c    pdt_render(): the frame, the context, colours
 *   layout.c    view defaults, panel rectangles, screen <-> world
 *   geometry.c  the world picture (boxes, triangles, hulls, stacks, points,
 *               merges, the current event, the selection)
 *   panels.c    text panels: event line, pseudo-code, stacks, help
 *   legend.c    the legend
 *   lifted.c    the lifted view (paraboloid)
 *   timeline.c  the timeline and seeking by a click on it
 *   export.c    pdt_render_file(): PNG, SVG, PDF
 *   pick.c      what is under the mouse
 *   render_lod.c  millions of triangles drawn as their coverage per cell
 *
 * The questions about the replay these files ask (is a hull still live,
 * which pseudo-code line, ...) are the model's: pdt/view/query.h. */
#ifndef PDT_VIEW_RENDER_INT_H
#define PDT_VIEW_RENDER_INT_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pdt/view/query.h"
#include "pdt/view/render.h"
#include "pdt/view/textlog.h"

#define NONE32 UINT32_MAX
#define SANS "DejaVu Sans"
#define MONO "DejaVu Sans Mono"

#define PDT_UNUSED __attribute__((unused))
/* The status colours of palette.c (checked against the hues there). */
extern const double PDT_RED[3], PDT_SELECT[3], PDT_DISK[3];
#define RED PDT_RED

/* The colours of a theme (pdt_view.theme).  Rank colours are the same in
 * every theme (pdt_rank_rgb). */
typedef struct pdt_theme {
    double bg[3];       /* picture background */
    double panel[3];    /* panel background */
    double border[3];   /* panel border */
    double topbar[3];   /* event line background */
    double ink[3];      /* text, lifted points, hull-ish marks */
    double hollow[3];   /* points not yet lifted */
    double label[3];    /* point labels */
    double select[3];   /* the clicked point, edge or triangle */
    double disk[3];     /* circumdisk outline */
    double mark[3];     /* current code line, disk fill */
    double hull;        /* hull colour = rank colour mixed towards ink by this */
    double tint;        /* strip box tint (0: none) */
    double lwf;         /* line width factor */
} pdt_theme;

/* The theme of id PDT_THEME_* (light for an unknown id). */
const pdt_theme *pdt_theme_get(int id);

/* World -> screen of the geometry area: screen = (ox + s*x, oy - s*y). */
typedef struct xform {
    double s, ox, oy;
} xform;

/* The transform of the geometry area for a w x h picture (layout.c). */
xform pdt_geo_xform(const pdt_replay *r, const pdt_view *v, double w, double h);

/* A text's box on screen, pixels. */
typedef struct lbox {
    double x0, y0, x1, y1;
} lbox;

enum { TAKEN_MAX = 256 };

/* Everything one frame's drawing functions share. */
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
    const pdt_rec *cur;  /* the current event or NULL (&cur_copy: a kept index's
                          * pointer would not outlast the frame's other reads) */
    pdt_rec cur_copy;
    int all_lifted;      /* no lift events but triangles: show every point lifted */
    int no_lift;         /* no lift events and no triangles (a hull-only run) */
    double spacing;      /* typical distance between points, pixels */
    const pdt_theme *T;  /* colours */
    lbox taken[TAKEN_MAX]; /* the strip labels placed: point labels keep off them */
    int ntaken;
    struct {
        uint32_t p;
        double x, y;
    } named[5]; /* the named and selected points' labels, placed first (geometry.c) */
    int nnamed;
    /* groups of ranks (groups.c) */
    const pdt_ranktree *tree;  /* v->tree, or own_tree */
    pdt_ranktree *own_tree;
    int32_t groups[PDT_PALETTE_HUES]; /* the groups on screen, in rank order: hue i */
    size_t ngroups;
    uint8_t *hue;              /* per rank: its group's hue, or 255 (no group on
                                * screen); NULL: hue = rank */
    int32_t *rows;             /* the timeline's rows (tree nodes) */
    size_t nrows;
} ctx;

/* The top bar's height (event line and status rows) and the height of a
 * pseudo-code row, both from the layout's font (layout.c). */
double pdt_layout_top_height(const pdt_layout *L);
double pdt_layout_code_row(const pdt_layout *L);

/* The frame's panels, for the layout report to name a text's panel when
 * none was set (textlog.c). */
void pdt_text_log_layout(cairo_t *cr, const pdt_layout *L);

/* The parts of the frame, each clipped to its rectangle of c->L. */
void pdt_draw_geometry(ctx *c);                 /* geometry.c */
/* Sorts the packed edges e[0..n) (smaller vertex in the high half) and
 * removes repeats; returns how many distinct edges stay in front. */
size_t pdt_unique_edges(uint64_t *e, size_t n);
/* Level of detail (render_lod.c): when the triangles in the geometry area are
 * too many to draw one by one, paint their coverage per cell instead and
 * return 1; else draw nothing and return 0. */
int pdt_draw_lod(ctx *c);
void pdt_draw_top(ctx *c);                      /* panels.c */
/* The event line's rows that spill under the top bar, as a box the
 * picture's labels keep off (c->taken). */
void pdt_top_spill(ctx *c);
void pdt_draw_legend(ctx *c);                   /* legend.c */
/* How much taller than one line of ranks the side legend's groups are, for
 * nranks ranks, base font f, a legend width wide (layout.c sizes by it). */
/* The height the legend needs `width` wide for a run of `nranks` ranks at
 * the layout's font sizes (legend.c); strip 0: the side panel, 1: a strip
 * under the picture, 2: a strip under picture and column (all markers). */
double pdt_legend_height(const pdt_layout *L, int nranks, double width, int strip);
void pdt_draw_code(ctx *c);
void pdt_draw_stack_panel(ctx *c);
void pdt_draw_help(ctx *c, double w, double h);
/* The line naming the panels with no room and the key that shows them. */
void pdt_draw_more(ctx *c);
void pdt_draw_lifted(ctx *c);                   /* lifted.c */
void pdt_draw_timeline(ctx *c);                 /* timeline.c */
void pdt_draw_tree(ctx *c);                     /* tree.c */
/* The tree's rectangle when there is no side column (layout.c calls it). */
void pdt_layout_tree_strip(pdt_layout *L, unsigned panels, double w, double h);

/* The timeline's geometry, shared by the drawing, the click and the groups
 * on screen (timeline.c). */
typedef struct tl_geom {
    double x0, x1;       /* the event axis */
    double y0, y1;       /* the rows' band */
    double rh;           /* row height */
    double fs;           /* row label size */
    int row0, nshow;     /* the rows shown: row0 .. row0 + nshow - 1 */
    double k0, k1;       /* the events at x0 and x1 */
} tl_geom;
void pdt_timeline_geom(pdt_rect R, double f, int nranks, size_t nrows, size_t m, const pdt_view *v,
                       tl_geom *g);

/* The groups on screen and the timeline's rows (groups.c): fills c->tree,
 * c->groups, c->hue, c->rows; pdt_frame_groups_done frees them. */
void pdt_frame_groups(ctx *c);
void pdt_frame_groups_done(ctx *c);
/* When the groups on screen are not single ranks: one label per group over
 * the boxes of its ranks, instead of a label per box; returns 1 if drawn. */
int pdt_draw_group_labels(ctx *c);
/* The timeline rows of tree t for view v (all groups of the first cut, opened
 * by v->tl_open) into a new array *rows (the caller frees it); their number. */
size_t pdt_timeline_rows(const pdt_ranktree *t, const pdt_view *v, int32_t **rows);

/* ---- small drawing helpers ------------------------------------------------------ */

/* The colour of rank q on this screen: its group's hue. */
static inline void ctx_rank_rgb(const ctx *c, int q, double col[3])
{
    if (!c->hue) pdt_rank_rgb(q, col);
    else pdt_palette_rgb(q >= 0 && q < c->nranks ? c->hue[q] : 255, col);
}

static inline void set_rank(const ctx *c, int rank, double alpha)
{
    double col[3];
    ctx_rank_rgb(c, rank, col);
    cairo_set_source_rgba(c->cr, col[0], col[1], col[2], alpha);
}

static inline void rgb(cairo_t *cr, const double c[3], double a)
{
    cairo_set_source_rgba(cr, c[0], c[1], c[2], a);
}

static inline void text_at(cairo_t *cr, const char *face, int bold, double size, double x,
                           double y, const char *s)
{
    cairo_select_font_face(cr, face, CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
    pdt_text_log_note(cr, size, x, y, s);
    cairo_move_to(cr, x, y);
    cairo_show_text(cr, s);
}

static inline double text_wb(cairo_t *cr, const char *face, int bold, double size, const char *s)
{
    cairo_text_extents_t te;
    cairo_select_font_face(cr, face, CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
    cairo_text_extents(cr, s, &te);
    return te.x_advance;
}

static inline double text_w(cairo_t *cr, const char *face, double size, const char *s)
{
    return text_wb(cr, face, 0, size, s);
}

/* A panel's title in its first row at the label size (never smaller): a
 * title wider than room loses its end. */
static inline void panel_title(cairo_t *cr, const pdt_theme *T, pdt_rect R, const char *title,
                               double f, double fs, double room)
{
    char t[160];
    snprintf(t, sizeof t, "%s", title);
    for (size_t n = strlen(t); n > 1 && text_wb(cr, SANS, 1, fs, t) > room;) {
        do n--; while (n > 1 && ((unsigned char)t[n] & 0xC0) == 0x80);
        snprintf(t + n, sizeof t - n, "…");
    }
    rgb(cr, T->ink, 1);
    text_at(cr, SANS, 1, fs, R.x + 0.5 * f, R.y + 0.3 * f + 0.9 * fs, t);
}

static inline void panel(cairo_t *cr, const pdt_theme *T, pdt_rect R, const char *title, double f)
{
    cairo_rectangle(cr, R.x + 2, R.y + 2, R.w - 4, R.h - 4);
    rgb(cr, T->panel, 1);
    cairo_fill_preserve(cr);
    rgb(cr, T->border, 1);
    cairo_set_line_width(cr, 1);
    cairo_stroke(cr);
    if (title) panel_title(cr, T, R, title, f, 0.82 * f, R.w - 1.2 * f);
}

static inline void clip_rect(cairo_t *cr, pdt_rect R)
{
    cairo_rectangle(cr, R.x, R.y, R.w, R.h);
    cairo_clip(cr);
}

/* Circumcircle in world coordinates; 0 if degenerate. */
static inline int circum(const pdt_point *P, const uint32_t v[3], double *ox, double *oy,
                         double *rr)
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

static inline int shown(const ctx *c, uint32_t rank)
{
    return !c->v->hidden || rank >= (uint32_t)c->nranks || !c->v->hidden[rank];
}

static inline void wpt(const ctx *c, uint32_t p, double *x, double *y)
{
    *x = c->X.ox + c->X.s * c->P[p].x;
    *y = c->X.oy - c->X.s * c->P[p].y;
}

static inline void tri_path(const ctx *c, const uint32_t v[3])
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

static inline int is_tri_event(int k)
{
    return k == PDT_EV_TRI_NEW || k == PDT_EV_TRI_FINAL || k == PDT_EV_RA_DEFER ||
           k == PDT_EV_SHIP || k == PDT_EV_DISCARD || k == PDT_EV_INCIRCLE;
}

static inline void cross(cairo_t *cr, double x, double y, double a)
{
    cairo_move_to(cr, x - a, y - a);
    cairo_line_to(cr, x + a, y + a);
    cairo_move_to(cr, x - a, y + a);
    cairo_line_to(cr, x + a, y - a);
}

/* The colour of rank q's hulls: its rank colour mixed towards the ink. */
static inline void set_hull(const ctx *c, int q, double alpha)
{
    double col[3];
    ctx_rank_rgb(c, q, col);
    double m = c->T->hull;
    cairo_set_source_rgba(c->cr, (1 - m) * col[0] + m * c->T->ink[0], (1 - m) * col[1] + m * c->T->ink[1],
                          (1 - m) * col[2] + m * c->T->ink[2], alpha);
}

/* The rank whose colour the legend's hull swatch takes (the last hull's). */
static inline int pdt_legend_hull_rank(const ctx *c) { return pdt_replay_hull_rank(c->r, c->s->k); }

/* Line style of a triangle status: width and dash (render.c). */
void pdt_status_style(cairo_t *cr, int st, double lw);

#endif
