/* pdt — the viewer's cairo renderer: draws one replay state on any cairo
 * surface (the window's texture, PNG, SVG, PDF).  Knows nothing of windows or
 * input; the SDL2 shell and the headless mode both call pdt_render().
 *
 * The picture: the geometry (strip boxes, triangles styled by Delaunay
 * status and coloured by the rank that made them, kernel edges, hulls,
 * stacks, Graham's angular numbers, the current triangle's circumdisk and the
 * boxes it touches, merge sets), an event line at the top, a legend, a
 * pseudo-code panel, a stack panel and a lifted view on the right, and a
 * timeline at the bottom. */
#ifndef PDT_RENDER_H
#define PDT_RENDER_H

#include <cairo.h>

#include "pdt/view/ranktree.h"
#include "pdt/view/replay.h"

/* What the viewer shows and how (owned by the caller). */
typedef struct pdt_view {
    double zoom;          /* 1 = fit the points in the geometry area */
    double cx, cy;        /* world point at the centre of the geometry area */
    int centred;          /* 0: centre on the points' bounding box */
    const uint8_t *hidden;/* per rank: 1 = hidden (NULL: all shown) */
    double yaw, pitch;    /* lifted view rotation (radians) */
    int help;             /* draw the help overlay */
    int fade;             /* discarded triangles fade out over this many events */
    int ev_class;         /* pdt_ev_class selected for Shift+arrows */
    int64_t sel_point;    /* point whose details are shown, or -1 */
    int64_t sel_tri;      /* triangle whose details are shown, or -1 */
    int sel_edge;         /* 0..2: the edge v[e]-v[e+1] of sel_tri is selected, or -1 */
    const char *status;   /* short text for the status corner ("playing 8 ev/s"), or NULL */
    unsigned panels;      /* PDT_PANEL_* bits: the optional panels shown (legend always) */
    double font_scale;    /* all text (and the panels holding it) scaled by this; 1 = default */
    int theme;            /* PDT_THEME_* */
    int clean;            /* clean picture: only final triangles (by rank) and hulls, no
                           * crosses, faded discards, candidates or current-event marks */
    int circles;          /* draw the circumcircle of every drawn triangle */
    int voronoi;          /* draw the Voronoi diagram of the final triangles */
    const char *prompt;   /* a line being typed ("go to event: 75"), drawn over the
                           * picture, or NULL */
    const char *const (*help_more)[2]; /* the help overlay's second column (a layer
                           * that takes the mouse and the digits: the editor): help_nmore
                           * rows {keys, what they do} under help_more_title; the
                           * viewer's rows for click, drag and the digits are then left
                           * out.  NULL: the viewer's keys only */
    int help_nmore;
    const char *help_more_title;
    /* many ranks: groups of the merge tree (pdt/view/ranktree.h) */
    const pdt_ranktree *tree; /* the replay's rank tree, or NULL (then made per frame) */
    const uint8_t *tl_open;   /* per tree node: opened into its subgroups in the
                               * timeline (NULL: none) */
    double tl_t0, tl_t1;      /* the timeline's window, as fractions of the events
                               * (0 and 1: all of them) */
    int tl_row0;              /* the timeline's first row shown */
    int follow;               /* keep the current event's region in view (pdt_view_follow) */
    int overflow;             /* 0, or page 1 .. pdt_layout.pages of the panels that got no
                               * room (pdt_layout.hidden), shown over the picture and the
                               * column in place of them (Tab) */
    struct pdt_text_log *texts; /* the layout report of the last frame drawn
                           * (pdt/view/textlog.h), or NULL */
} pdt_view;

/* Colour themes (pdt_view.theme).  Every theme keeps the rank palette
 * (pdt_palette_rgb), checked for colour-blind viewers. */
enum {
    PDT_THEME_LIGHT = 0,  /* dark ink on white */
    PDT_THEME_DARK,       /* light ink on near-black (dim rooms) */
    PDT_THEME_CONTRAST,   /* black on white, thicker lines, no tints (washed-out projectors) */
    PDT_THEME_COUNT
};

/* "light", "dark" or "contrast" into *theme; -1 on another name. */
int pdt_theme_parse(const char *name, int *theme);

/* The optional panels (pdt_view.panels).  A hidden panel gets no room: the
 * geometry and the other panels grow instead. */
enum {
    PDT_PANEL_CODE = 1,     /* pseudo-code */
    PDT_PANEL_STACK = 2,    /* stacks being built */
    PDT_PANEL_LIFTED = 4,   /* lifted view */
    PDT_PANEL_TIMELINE = 8, /* timeline */
    PDT_PANEL_ALL = 15,     /* the panels "all" names (the tree is named on its own) */
    PDT_PANEL_TREE = 16,    /* the merge tree */
    PDT_PANEL_NOTES = 32,   /* the lesson's notes (drawn by the window's lecture tools) */
    PDT_PANEL_LEGEND = 64   /* the legend: always asked for; only pdt_layout.hidden has it */
};

/* Parse a comma-separated list of panel names ("code,stack,lifted,timeline",
 * or "all" / "none") into PDT_PANEL_* bits.  Returns -1 on an unknown name. */
int pdt_panels_parse(const char *list, unsigned *panels);

/* Rectangles of the panels for a w x h picture (pixels). */
typedef struct pdt_rect {
    double x, y, w, h;
} pdt_rect;

typedef struct pdt_layout {
    double font;          /* base font size in pixels (event line) */
    double body;          /* panel text (legend, stacks, code), pixels */
    double label;         /* point and box labels, pixels */
    pdt_rect top, geo, legend, code, stack, lifted, timeline;
    pdt_rect tree;        /* the merge tree (PDT_PANEL_TREE), or zero-sized */
    unsigned hidden;      /* PDT_PANEL_* bits asked for (the legend always) that got no
                           * room at this size and font: named in `more` */
    pdt_rect more;        /* the line naming the hidden panels and the key (Tab) that
                           * shows them, at the bottom; zero-sized when none is hidden */
    int covered;          /* 0, or the page of hidden panels drawn over the picture and
                           * the column (pdt_view.overflow): the picture is then neither
                           * drawn nor clicked */
    int pages;            /* how many pages the hidden panels take (0: none hidden) */
    int legend_mode;      /* the legend: 0 a side panel, 1 a strip under the picture,
                           * 2 a strip across the picture and the column */
} pdt_layout;

/* Defaults: fit, all ranks, yaw 30°, pitch 25°, fade 400 events, font scale 1,
 * light theme. */
void pdt_view_defaults(pdt_view *v);

/* Layout with every panel shown. */
void pdt_render_layout(double w, double h, int nranks, pdt_layout *L);
/* Layout with the panels of `panels` (PDT_PANEL_* bits); hidden ones have
 * zero width and height.  When code, stack and lifted view are all hidden
 * the picture takes the whole width and the legend is a strip under it. */
void pdt_render_layout_panels(double w, double h, int nranks, unsigned panels, pdt_layout *L);
/* The same with the font scaled by `scale` (clamped to 0.4 .. 4). */
void pdt_render_layout_scaled(double w, double h, int nranks, unsigned panels, double scale,
                              pdt_layout *L);
/* The layout view v asks for (its panels and font scale; v NULL: defaults).
 * Every drawing, picking and timeline function uses this one. */
void pdt_render_layout_view(double w, double h, int nranks, const pdt_view *v, pdt_layout *L);

/* Draw state s of replay r on cr, in the rectangle (0,0)-(w,h).  Leaves the
 * cairo state as it found it.  Returns PDT_OK, or an error if cairo reports
 * one (err describes it). */
pdt_status pdt_render(cairo_t *cr, double w, double h, const pdt_replay *r, const pdt_rstate *s,
                      const pdt_view *v, pdt_err *err);

/* Draw into a file: the format comes from the extension (.png, .svg, .pdf);
 * written by the rule of pdt/safefile.h (a device such as /dev/null
 * directly). */
pdt_status pdt_render_file(const char *path, int w, int h, const pdt_replay *r,
                           const pdt_rstate *s, const pdt_view *v, pdt_err *err);
/* pdt_render_file with pdt_safe_open's flags (PDT_SAFE_NOFOLLOW for a file
 * pdtview names itself inside a folder: --frames). */
pdt_status pdt_render_file_ex(const char *path, int flags, int w, int h, const pdt_replay *r,
                              const pdt_rstate *s, const pdt_view *v, pdt_err *err);
/* What a window draws over the frame (its lecture tools, a layer): called
 * with the frame's cairo context, size and view after pdt_render. */
typedef void (*pdt_render_over)(void *user, cairo_t *cr, double w, double h, const pdt_view *v);
/* pdt_render_file_ex with over(user, ...) drawn over the frame (NULL: none),
 * so that a screenshot holds what the window shows. */
pdt_status pdt_render_file_over(const char *path, int flags, int w, int h, const pdt_replay *r,
                                const pdt_rstate *s, const pdt_view *v, pdt_render_over over,
                                void *user, pdt_err *err);

/* The palette (palette.c): PDT_PALETTE_HUES hues for the groups of ranks a
 * screen shows, every pair of them and of the status colours at least
 * CIEDE2000 10 apart for normal, deuteranope and protanope vision.
 * pdt_palette_rgb: hue i (out of range: a neutral grey). */
enum { PDT_PALETTE_HUES = 8 };
void pdt_palette_rgb(int i, double rgb[3]);
/* Every colour a screen can show together (the hues, then the status
 * colours), into out[0..cap); returns their number. */
size_t pdt_palette_screen(double (*out)[3], size_t cap);
/* The colour of a rank drawn on its own, without groups (hue rank % 8;
 * beyond 8, the same hues darker or lighter), components in [0,1]. */
void pdt_rank_rgb(int rank, double rgb[3]);

/* Screen <-> world for the geometry area of a w x h picture. */
void pdt_view_to_world(const pdt_replay *r, const pdt_view *v, double w, double h, double sx,
                       double sy, double *wx, double *wy);
void pdt_view_to_screen(const pdt_replay *r, const pdt_view *v, double w, double h, double wx,
                        double wy, double *sx, double *sy);
/* Zoom by factor f keeping the world point under (sx,sy) fixed. */
void pdt_view_zoom_at(const pdt_replay *r, pdt_view *v, double w, double h, double sx, double sy,
                      double f);

/* If the circle (ox,oy,rr) in world coordinates does not fit in the
 * geometry area, centre the view on it and zoom out so that it does (its
 * diameter 90 % of the area's smaller side); returns 1 if the view
 * changed, 0 if the circle was already in view. */
int pdt_view_fit_circle(const pdt_replay *r, pdt_view *v, double w, double h, double ox, double oy,
                        double rr);

/* What is under screen point (sx,sy): the nearest point within `radius`
 * pixels (*point, else -1); otherwise the nearest edge within radius/2 of a
 * triangle drawn in state s (*tri and *edge = 0..2, the edge v[e]-v[e+1]);
 * otherwise a drawn triangle that contains it (*tri, *edge = -1); else all -1. */
void pdt_render_pick(const pdt_replay *r, const pdt_rstate *s, const pdt_view *v, double w,
                     double h, double sx, double sy, double radius, int64_t *point, int64_t *tri,
                     int *edge);

/* Cursor for a click at (sx,sy) in the timeline rectangle: in a rank's row,
 * just after that rank's event nearest the clicked time
 * (pdt_replay_nearest_of_rank); elsewhere the clicked time itself.
 * (size_t)-1 when (sx,sy) is not in the timeline. */
size_t pdt_render_timeline_at(const pdt_replay *r, const pdt_view *v, double w, double h, double sx,
                              double sy);
/* The tree node of the timeline row at (sx,sy) (in its label column only,
 * when label_only), or -1. */
int32_t pdt_render_timeline_row_at(const pdt_replay *r, const pdt_view *v, double w, double h,
                                   double sx, double sy, int label_only);
/* The timeline's rows: their number; *nshow: how many fit on screen. */
int pdt_render_timeline_rows(const pdt_replay *r, const pdt_view *v, double w, double h,
                             int *nshow);

/* The groups of ranks a w x h frame of view v shows (at most
 * PDT_PALETTE_HUES; the legend's, in its order): group i is the ranks
 * [lo[i], hi[i]).  Returns their number (0 when out of memory). */
size_t pdt_render_screen_groups(const pdt_replay *r, const pdt_view *v, double w, double h,
                                uint32_t *lo, uint32_t *hi);

/* The timeline's window and the view following the story (tlview.c). */
/* Zoom the timeline's events by factor f (> 1: in) keeping the event under
 * x fixed. */
void pdt_view_timeline_zoom(const pdt_replay *r, pdt_view *v, double w, double h, double x, double f);
/* Move the timeline's window by dx pixels in time and drow rows. */
void pdt_view_timeline_pan(const pdt_replay *r, pdt_view *v, double w, double h, double dx, int drow);
/* Keep the current event of state s in view (when v->follow): the picture
 * centred on its points when they left the picture, the timeline's window on
 * its event and its rank's row among those shown.  Returns 1 if the view
 * changed. */
int pdt_view_follow(const pdt_replay *r, const pdt_rstate *s, pdt_view *v, double w, double h);
/* The merge step (index into pdt_replay_merges) whose node of the tree
 * panel is at (sx,sy), or -1 (tree.c). */
int pdt_render_tree_at(const pdt_replay *r, const pdt_view *v, double w, double h, double sx,
                       double sy);

#endif
