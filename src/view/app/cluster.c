/* pdt — the viewer's keys and mouse for runs of many ranks (cluster.h). */
#include "cluster.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pdt/view/query.h"

struct pdt_cluster {
    const pdt_replay *r;    /* the replay it was made for */
    pdt_ranktree *tree;
    uint8_t *open;          /* per tree node */
    int down, dragged;      /* a press in the timeline, and whether it moved */
    double x0, y0, lx, ly;  /* where it was pressed, last seen */
};

pdt_cluster *pdt_cluster_new(const pdt_replay *r, pdt_view *v)
{
    pdt_cluster *cl = calloc(1, sizeof *cl);
    if (!cl) return NULL;
    cl->tree = pdt_ranktree_new(r);
    size_t n = 0;
    if (cl->tree) pdt_ranktree_nodes(cl->tree, &n);
    cl->open = calloc(n ? n : 1, 1);
    if (!cl->tree || !cl->open) {
        pdt_cluster_free(cl, v);
        return NULL;
    }
    cl->r = r;
    v->tree = cl->tree;
    v->tl_open = cl->open;
    return cl;
}

void pdt_cluster_take(pdt_cluster **cl, const pdt_replay *r, pdt_view *v)
{
    if (*cl && (*cl)->r == r) return;
    pdt_cluster_free(*cl, v);
    *cl = pdt_cluster_new(r, v);
}

void pdt_cluster_free(pdt_cluster *cl, pdt_view *v)
{
    if (!cl) return;
    if (v && v->tree == cl->tree) v->tree = NULL;
    if (v && v->tl_open == cl->open) v->tl_open = NULL;
    pdt_ranktree_free(cl->tree);
    free(cl->open);
    free(cl);
}

/* The group on screen that holds rank q, as the legend lists them. */
static int group_of(const pdt_replay *r, const pdt_view *v, double w, double h, uint32_t q,
                    uint32_t *lo, uint32_t *hi)
{
    uint32_t L[PDT_PALETTE_HUES], H[PDT_PALETTE_HUES];
    size_t n = pdt_render_screen_groups(r, v, w, h, L, H);
    for (size_t i = 0; i < n; i++)
        if (q >= L[i] && q < H[i]) {
            *lo = L[i];
            *hi = H[i];
            return 1;
        }
    return 0;
}

/* Digit d: hide the legend's group d (all its ranks), or show it again. */
static void toggle_group(const pdt_replay *r, const pdt_view *v, double w, double h, int d,
                         uint8_t *hidden)
{
    uint32_t L[PDT_PALETTE_HUES], H[PDT_PALETTE_HUES];
    size_t n = pdt_render_screen_groups(r, v, w, h, L, H);
    if (d < 0 || (size_t)d >= n) return;
    int any = 0;
    for (uint32_t q = L[d]; q < H[d]; q++) any |= !hidden[q];
    for (uint32_t q = L[d]; q < H[d]; q++) hidden[q] = (uint8_t)any;
}

/* Ctrl+arrows: the next / previous event of the current event's group. */
static size_t step_group(const pdt_replay *r, const pdt_rstate *s, const pdt_view *v, double w,
                         double h, int dir)
{
    int P = pdt_replay_nranks(r);
    uint32_t q = s->k ? pdt_replay_rank_of(r, s->k - 1) : 0, lo, hi;
    if (!group_of(r, v, w, h, q, &lo, &hi)) lo = q, hi = q + 1;
    uint8_t *vis = calloc((size_t)P + 1, 1);
    if (!vis) return SIZE_MAX;
    memset(vis + lo, 1, hi - lo);
    size_t k = pdt_replay_find(r, s->k, dir, PDT_EVC_ANY, vis);
    free(vis);
    return k;
}

/* The timeline row (tree node) holding rank q, or -1. */
static int32_t row_of(const pdt_cluster *cl, uint32_t q)
{
    int32_t cut[PDT_PALETTE_HUES];
    size_t nc = pdt_ranktree_cut(cl->tree, NULL, PDT_PALETTE_HUES, cut), n;
    size_t nr = pdt_ranktree_rows(cl->tree, cut, nc, cl->open, NULL, 0);
    int32_t *rows = malloc((nr ? nr : 1) * sizeof *rows), id = -1;
    if (!rows) return -1;
    pdt_ranktree_rows(cl->tree, cut, nc, cl->open, rows, nr);
    const pdt_rtnode *N = pdt_ranktree_nodes(cl->tree, &n);
    for (size_t i = 0; i < nr && id < 0; i++)
        if (q >= N[rows[i]].lo && q < N[rows[i]].hi) id = rows[i];
    free(rows);
    return id;
}

/* Open row id into its two subgroups, or, a rank's own row, close the
 * group it was opened from. */
static void toggle_row(pdt_cluster *cl, int32_t id)
{
    size_t n;
    const pdt_rtnode *N = pdt_ranktree_nodes(cl->tree, &n);
    if (id < 0) return;
    if (N[id].kid[0] >= 0 && !cl->open[id]) cl->open[id] = 1;
    else if (N[id].parent >= 0) cl->open[N[id].parent] = 0;
}

int pdt_cluster_key(pdt_cluster *cl, const pdt_replay *r, const pdt_rstate *s, pdt_view *v,
                    SDL_Keycode k, int shift, int ctrl, double w, double h, uint8_t *hidden,
                    size_t *seek_to)
{
    *seek_to = SIZE_MAX;
    int many = pdt_replay_nranks(r) > PDT_PALETTE_HUES;
    if (ctrl) {
        if (!many || (k != SDLK_RIGHT && k != SDLK_LEFT)) return 0;
        *seek_to = step_group(r, s, v, w, h, k == SDLK_RIGHT ? 1 : -1);
        return 1;
    }
    switch (k) {
    case SDLK_LEFTBRACKET:
    case SDLK_RIGHTBRACKET:
        if (shift) pdt_view_timeline_pan(r, v, w, h, 0, k == SDLK_LEFTBRACKET ? -1 : 1);
        else pdt_view_timeline_zoom(r, v, w, h, 0.5 * w, k == SDLK_RIGHTBRACKET ? 2 : 0.5);
        return 1;
    case SDLK_u:
        if (cl && s->k) toggle_row(cl, row_of(cl, pdt_replay_rank_of(r, s->k - 1)));
        return 1;
    case SDLK_w: v->follow = !v->follow; return 1;
    default:
        if (many && k >= SDLK_1 && k <= SDLK_9) {
            toggle_group(r, v, w, h, (int)(k - SDLK_1), hidden);
            return 1;
        }
        return 0;
    }
}

/* A press, a drag or a release in the timeline. */
static int timeline_button(pdt_cluster *cl, const pdt_replay *r, pdt_view *v, const SDL_Event *e,
                           double x, double y, double w, double h, size_t *seek_to)
{
    if (e->type == SDL_MOUSEBUTTONDOWN) {
        cl->down = 1;
        cl->dragged = 0;
        cl->x0 = cl->lx = x;
        cl->y0 = cl->ly = y;
        return 1;
    }
    cl->down = 0;
    if (cl->dragged) return 1;
    int32_t id = pdt_render_timeline_row_at(r, v, w, h, x, y, 1);
    if (id >= 0) toggle_row(cl, id);
    else *seek_to = pdt_render_timeline_at(r, v, w, h, x, y);
    return 1;
}

int pdt_cluster_mouse(pdt_cluster *cl, const pdt_replay *r, pdt_view *v, const SDL_Event *e,
                      double sx, double sy, double w, double h, size_t *seek_to)
{
    *seek_to = SIZE_MAX;
    if (!cl) return 0;
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(r), v, &L);
    int mx, my;
    SDL_GetMouseState(&mx, &my);
    double x = (e->type == SDL_MOUSEWHEEL ? mx : e->type == SDL_MOUSEMOTION ? e->motion.x : e->button.x) * sx;
    double y = (e->type == SDL_MOUSEWHEEL ? my : e->type == SDL_MOUSEMOTION ? e->motion.y : e->button.y) * sy;
    pdt_rect T = L.timeline;
    int in_tl = T.w > 0 && x >= T.x && x <= T.x + T.w && y >= T.y && y <= T.y + T.h;
    switch (e->type) {
    case SDL_MOUSEWHEEL:
        if (!in_tl) return 0;
        if (SDL_GetModState() & KMOD_SHIFT) pdt_view_timeline_pan(r, v, w, h, 0, -e->wheel.y);
        else pdt_view_timeline_zoom(r, v, w, h, x, pow(1.25, e->wheel.y));
        return 1;
    case SDL_MOUSEMOTION:
        if (!cl->down) return 0;
        if (fabs(x - cl->x0) + fabs(y - cl->y0) > 4) cl->dragged = 1;
        if (cl->dragged) {
            int rows = (int)((cl->ly - y) / fmax(16, 0.9 * L.font));
            pdt_view_timeline_pan(r, v, w, h, x - cl->lx, rows);
            cl->lx = x;
            if (rows) cl->ly = y;
        }
        return 1;
    case SDL_MOUSEBUTTONDOWN:
    case SDL_MOUSEBUTTONUP:
        if (e->button.button != SDL_BUTTON_LEFT) return 0;
        if (e->type == SDL_MOUSEBUTTONUP && !cl->down) return 0;
        if (in_tl || cl->down) return timeline_button(cl, r, v, e, x, y, w, h, seek_to);
        if (e->type == SDL_MOUSEBUTTONDOWN) {
            int m = pdt_render_tree_at(r, v, w, h, x, y);
            if (m < 0) return 0;
            size_t nm;
            *seek_to = pdt_replay_merges(r, &nm)[m].begin_ev + 1;
            return 1;
        }
        return 0;
    default: return 0;
    }
}
