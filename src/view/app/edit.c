/* pdt — the viewer's point editor (edit.h). */
#include "edit.h"
#include "editnotes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "pdt/io.h"
#include "pdt/view/textlog.h"

/* SDL keycodes the hook needs (SDL_keycode.h values; edit.c has no SDL). */
enum {
    K_F1 = (1 << 30) | 58, K_F2, K_F3, K_F4
};

typedef struct snapshot {
    pdt_point *pts;
    size_t n;
} snapshot;

typedef struct history {
    snapshot *v;
    size_t n, cap;
} history;

struct pdt_editor {
    char *path;
    pdt_edit_notes *notes; /* the file's comments, kept on every save (NULL: none) */
    pdt_point *pts;
    size_t n, cap;
    history undo, redo;
    pdt_live_opts mode;
    pdt_live_result run;
    pdt_replay *r;
    pdt_rstate *s;
    int changed;          /* the replay changed since the shell last asked */
    double last_run_s;
    uint64_t rng;
    /* window state */
    pdt_shell_hook hook;
    int snap;             /* grid step in world units, 0 = off */
    int down, panning, moved;
    int64_t drag;         /* point being dragged, or -1 */
    double mx0, my0, mx, my;
    double per_px;        /* world units per pixel kept across a change */
    char msg[1100];
    char title[470];      /* the window title (hook_title) */
    const char *help[16][2]; /* the mode's keys (pdt_editor_help) */
};

/* ---- points and history --------------------------------------------------------- */

static pdt_status snap_push(history *h, const pdt_point *pts, size_t n, pdt_err *err)
{
    if (h->n == h->cap) {
        size_t cap = h->cap ? 2 * h->cap : 16;
        snapshot *v = realloc(h->v, cap * sizeof *v);
        if (!v) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
        h->v = v;
        h->cap = cap;
    }
    snapshot *s = &h->v[h->n];
    s->pts = malloc((n ? n : 1) * sizeof *pts);
    if (!s->pts) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    if (n) memcpy(s->pts, pts, n * sizeof *pts);
    s->n = n;
    h->n++;
    return PDT_OK;
}

static void history_clear(history *h)
{
    for (size_t i = 0; i < h->n; i++) free(h->v[i].pts);
    h->n = 0;
}

static void history_free(history *h)
{
    history_clear(h);
    free(h->v);
    memset(h, 0, sizeof *h);
}

static pdt_status reserve(pdt_editor *ed, size_t n, pdt_err *err)
{
    if (n <= ed->cap) return PDT_OK;
    size_t cap = ed->cap ? ed->cap : 64;
    while (cap < n) cap *= 2;
    pdt_point *p = realloc(ed->pts, cap * sizeof *p);
    if (!p) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    ed->pts = p;
    ed->cap = cap;
    return PDT_OK;
}

/* ---- run and reload ----------------------------------------------------------- */

/* Where cursor k of replay `old` is in terms of phases: the innermost phase
 * of rank 0 open at k (its id, level and the offset from its begin). */
static size_t same_place(const pdt_replay *old, const pdt_rstate *s, const pdt_replay *r)
{
    size_t m_old = pdt_replay_count(old), m = pdt_replay_count(r);
    if (s->k >= m_old) return m;
    int32_t ph = pdt_rstate_slot(old, s, 0, PDT_SLOT_PHASE);
    size_t np_old, np;
    const pdt_rphase *PO = pdt_replay_phases(old, &np_old), *P = pdt_replay_phases(r, &np);
    if (ph < 0 || (size_t)ph >= np_old) return s->k < m ? s->k : m;
    const pdt_rphase *a = &PO[ph];
    size_t off = s->k - a->begin_ev;
    for (size_t i = 0; i < np; i++) {
        if (P[i].rank != a->rank || P[i].phase != a->phase || P[i].sub != a->sub) continue;
        size_t k = P[i].begin_ev + off, end = P[i].end_ev == UINT32_MAX ? m : P[i].end_ev;
        return k < end ? k : end;
    }
    return m;
}

/* Run the algorithm on the current points and show the new replay at the
 * same place as the old one. */
static pdt_status rerun(pdt_editor *ed, pdt_err *err)
{
    double t0 = pdt_seconds();
    pdt_live_result run;
    pdt_replay *r = NULL;
    pdt_rstate *s = NULL;
    pdt_status st = pdt_live_run(ed->pts, ed->n, &ed->mode, &run, err);
    if (st == PDT_OK) st = pdt_replay_new(ed->pts, ed->n, run.recs, run.m, run.nranks, &r, err);
    if (st == PDT_OK && !(s = pdt_rstate_new(r)))
        st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    if (st != PDT_OK) {
        pdt_replay_free(r);
        pdt_live_free(&run);
        return st;
    }
    size_t k = ed->r ? same_place(ed->r, ed->s, r) : pdt_replay_count(r);
    pdt_replay_seek(r, s, k);
    pdt_rstate_free(ed->s);
    pdt_replay_free(ed->r);
    pdt_live_free(&ed->run);
    ed->run = run;
    ed->r = r;
    ed->s = s;
    ed->changed = 1;
    ed->last_run_s = pdt_seconds() - t0;
    return PDT_OK;
}

static pdt_status save(pdt_editor *ed, pdt_err *err)
{
    return pdt_edit_notes_write(ed->notes, ed->path, ed->pts, ed->n, err);
}

/* After a change to ed->pts: save, re-run. */
static pdt_status commit(pdt_editor *ed, pdt_err *err)
{
    pdt_err e2 = {0};
    pdt_status st = save(ed, &e2);
    pdt_status rs = rerun(ed, err);
    if (st != PDT_OK) {
        pdt_err_set(err, st, "%s (the change is kept in the window, not in the file)", e2.msg);
        return st;
    }
    return rs;
}

/* Before a change: the undo step; a new change forgets the redo steps. */
static pdt_status begin_change(pdt_editor *ed, pdt_err *err)
{
    pdt_status st = snap_push(&ed->undo, ed->pts, ed->n, err);
    if (st == PDT_OK) history_clear(&ed->redo);
    return st;
}

static int in_int32(int64_t v)
{
    return v >= INT32_MIN && v <= INT32_MAX;
}

/* ---- the model -------------------------------------------------------------------- */

pdt_status pdt_editor_open(const char *path, const pdt_live_opts *o, pdt_editor **out,
                           pdt_err *err)
{
    *out = NULL;
    pdt_editor *ed = calloc(1, sizeof *ed);
    if (!ed) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    ed->path = strdup(path);
    ed->mode = *o;
    size_t len = strlen(path);
    ed->mode.node = len >= 5 && !strcmp(path + len - 5, ".node"); /* the ranks' blocks follow the file */
    ed->drag = -1;
    ed->rng = 0x9E3779B97F4A7C15ull;
    pdt_status st = ed->path ? PDT_OK : pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    struct stat sb;
    if (st == PDT_OK && stat(path, &sb) != 0) {
        st = save(ed, err); /* a missing file is created, empty */
    } else if (st == PDT_OK) {
        size_t coll = 0;
        st = pdt_read_points(path, 0, &ed->pts, &ed->n, &coll, err);
        ed->cap = ed->n;
        if (st == PDT_OK && !ed->mode.node) st = pdt_edit_notes_read(path, &ed->notes, err);
    }
    if (st == PDT_OK) st = rerun(ed, err);
    if (st != PDT_OK) {
        pdt_editor_free(ed);
        return st;
    }
    snprintf(ed->msg, sizeof ed->msg, "click: add · drag: move · right click: delete · Ctrl+Z/Y · g snap · n random · F1-F4 presets · x hull · 1-8 ranks · h help");
    *out = ed;
    return PDT_OK;
}

void pdt_editor_free(pdt_editor *ed)
{
    if (!ed) return;
    history_free(&ed->undo);
    history_free(&ed->redo);
    pdt_rstate_free(ed->s);
    pdt_replay_free(ed->r);
    pdt_live_free(&ed->run);
    pdt_edit_notes_free(ed->notes);
    free(ed->pts);
    free(ed->path);
    free(ed);
}

pdt_status pdt_editor_add(pdt_editor *ed, int64_t x, int64_t y, pdt_err *err)
{
    if (!in_int32(x) || !in_int32(y))
        return pdt_err_set(err, PDT_ERR_ARG, "(%lld, %lld) is outside the 32-bit range: not placed",
                           (long long)x, (long long)y);
    pdt_status st = reserve(ed, ed->n + 1, err);
    if (st == PDT_OK) st = begin_change(ed, err);
    if (st != PDT_OK) return st;
    ed->pts[ed->n++] = (pdt_point){(int32_t)x, (int32_t)y};
    return commit(ed, err);
}

pdt_status pdt_editor_move(pdt_editor *ed, size_t i, int64_t x, int64_t y, pdt_err *err)
{
    if (i >= ed->n) return pdt_err_set(err, PDT_ERR_ARG, "no point %zu", i);
    if (!in_int32(x) || !in_int32(y))
        return pdt_err_set(err, PDT_ERR_ARG, "(%lld, %lld) is outside the 32-bit range: not moved",
                           (long long)x, (long long)y);
    pdt_status st = begin_change(ed, err);
    if (st != PDT_OK) return st;
    pdt_edit_notes_moved(ed->notes, ed->pts[i], (pdt_point){(int32_t)x, (int32_t)y});
    ed->pts[i] = (pdt_point){(int32_t)x, (int32_t)y};
    return commit(ed, err);
}

pdt_status pdt_editor_delete(pdt_editor *ed, size_t i, pdt_err *err)
{
    if (i >= ed->n) return pdt_err_set(err, PDT_ERR_ARG, "no point %zu", i);
    pdt_status st = begin_change(ed, err);
    if (st != PDT_OK) return st;
    memmove(ed->pts + i, ed->pts + i + 1, (ed->n - i - 1) * sizeof *ed->pts);
    ed->n--;
    return commit(ed, err);
}

static uint64_t next_rand(pdt_editor *ed)
{
    ed->rng ^= ed->rng << 13;
    ed->rng ^= ed->rng >> 7;
    ed->rng ^= ed->rng << 17;
    return ed->rng;
}

static int64_t clamp32(int64_t v)
{
    return v < INT32_MIN ? INT32_MIN : v > INT32_MAX ? INT32_MAX : v;
}

pdt_status pdt_editor_random(pdt_editor *ed, size_t k, int64_t x0, int64_t y0, int64_t x1,
                             int64_t y1, pdt_err *err)
{
    x0 = clamp32(x0), x1 = clamp32(x1), y0 = clamp32(y0), y1 = clamp32(y1);
    if (x1 < x0 || y1 < y0) return pdt_err_set(err, PDT_ERR_ARG, "empty box for random points");
    pdt_status st = reserve(ed, ed->n + k, err);
    if (st == PDT_OK) st = begin_change(ed, err);
    if (st != PDT_OK) return st;
    for (size_t i = 0; i < k; i++) {
        int64_t x = x0 + (int64_t)(next_rand(ed) % (uint64_t)(x1 - x0 + 1));
        int64_t y = y0 + (int64_t)(next_rand(ed) % (uint64_t)(y1 - y0 + 1));
        ed->pts[ed->n++] = (pdt_point){(int32_t)x, (int32_t)y};
    }
    return commit(ed, err);
}

pdt_status pdt_editor_preset(pdt_editor *ed, pdt_preset p, pdt_err *err)
{
    pdt_point buf[64];
    size_t n = 0;
    switch (p) {
    case PDT_PRESET_CIRCLE: /* x^2 + y^2 = 625 has 20 integer points */
        for (int x = -25; x <= 25; x++)
            for (int y = -25; y <= 25; y++)
                if (x * x + y * y == 625) buf[n++] = (pdt_point){50 + x, 50 + y};
        break;
    case PDT_PRESET_GRID:
        for (int i = 0; i < 6; i++)
            for (int j = 0; j < 6; j++) buf[n++] = (pdt_point){25 + 10 * i, 25 + 10 * j};
        break;
    case PDT_PRESET_COLLINEAR:
        for (int i = 0; i < 8; i++) buf[n++] = (pdt_point){10 + 10 * i, 20 + 5 * i};
        buf[n++] = (pdt_point){20, 70};
        buf[n++] = (pdt_point){60, 80};
        buf[n++] = (pdt_point){80, 20};
        break;
    case PDT_PRESET_DUPLICATES: {
        static const pdt_point d[] = {{20, 20}, {80, 25}, {50, 80}, {50, 45},
                                      {20, 20}, {35, 60}, {50, 45}, {70, 60}, {80, 25}};
        for (size_t i = 0; i < sizeof d / sizeof *d; i++) buf[n++] = d[i];
        break;
    }
    default: return pdt_err_set(err, PDT_ERR_ARG, "no preset %d", (int)p);
    }
    pdt_status st = reserve(ed, n, err);
    if (st == PDT_OK) st = begin_change(ed, err);
    if (st != PDT_OK) return st;
    memcpy(ed->pts, buf, n * sizeof *buf);
    ed->n = n;
    return commit(ed, err);
}

/* Move the top of `from` into the points, the points onto `to`. */
static pdt_status travel(pdt_editor *ed, history *from, history *to, const char *what,
                         pdt_err *err)
{
    if (from->n == 0) return pdt_err_set(err, PDT_ERR_ARG, "nothing to %s", what);
    snapshot *s = &from->v[from->n - 1];
    pdt_status st = reserve(ed, s->n, err);
    if (st == PDT_OK) st = snap_push(to, ed->pts, ed->n, err);
    if (st != PDT_OK) return st;
    if (s->n) memcpy(ed->pts, s->pts, s->n * sizeof *s->pts);
    ed->n = s->n;
    free(s->pts);
    from->n--;
    return commit(ed, err);
}

pdt_status pdt_editor_undo(pdt_editor *ed, pdt_err *err)
{
    return travel(ed, &ed->undo, &ed->redo, "undo", err);
}

pdt_status pdt_editor_redo(pdt_editor *ed, pdt_err *err)
{
    return travel(ed, &ed->redo, &ed->undo, "redo", err);
}

pdt_status pdt_editor_set_mode(pdt_editor *ed, int hull, int ranks, pdt_err *err)
{
    pdt_live_opts old = ed->mode;
    ed->mode.hull = hull;
    ed->mode.ranks = ranks;
    pdt_status st = rerun(ed, err);
    if (st != PDT_OK) ed->mode = old;
    return st;
}

const pdt_point *pdt_editor_points(const pdt_editor *ed, size_t *n)
{
    *n = ed->n;
    return ed->pts;
}

const pdt_live_result *pdt_editor_run(const pdt_editor *ed)
{
    return &ed->run;
}

const pdt_replay *pdt_editor_replay(const pdt_editor *ed)
{
    return ed->r;
}

pdt_rstate *pdt_editor_state(pdt_editor *ed)
{
    return ed->s;
}

double pdt_editor_last_run_s(const pdt_editor *ed)
{
    return ed->last_run_s;
}

/* ---- the window ------------------------------------------------------------------ */

static void report(pdt_editor *ed, pdt_status st, const pdt_err *err, const char *ok)
{
    if (st != PDT_OK) snprintf(ed->msg, sizeof ed->msg, "%s", err->msg);
    else snprintf(ed->msg, sizeof ed->msg, "%s", ok);
}

static int in_geo(double w, double h, const pdt_replay *r, const pdt_view *v, double x, double y)
{
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(r), v, &L);
    return x >= L.geo.x && x <= L.geo.x + L.geo.w && y >= L.geo.y && y <= L.geo.y + L.geo.h;
}

/* The point within reach of screen (x, y), or -1. */
static int64_t point_at(pdt_editor *ed, double w, double h, const pdt_view *v, double x, double y)
{
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(ed->r), v, &L);
    int64_t best = -1;
    double bd = 0.8 * L.font * 0.8 * L.font;
    for (size_t i = 0; i < ed->n; i++) {
        double sx, sy;
        pdt_view_to_screen(ed->r, v, w, h, ed->pts[i].x, ed->pts[i].y, &sx, &sy);
        double d = (sx - x) * (sx - x) + (sy - y) * (sy - y);
        if (d <= bd) {
            bd = d;
            best = (int64_t)i;
        }
    }
    return best;
}

/* Integer world coordinates under the screen point (snapped to the grid). */
static void world_at(const pdt_editor *ed, double w, double h, const pdt_view *v, double x,
                     double y, int64_t *wx, int64_t *wy)
{
    double fx, fy;
    pdt_view_to_world(ed->r, v, w, h, x, y, &fx, &fy);
    if (ed->snap > 0) {
        fx = ed->snap * floor(fx / ed->snap + 0.5);
        fy = ed->snap * floor(fy / ed->snap + 0.5);
    }
    *wx = fx > 9e18 ? INT64_MAX : fx < -9e18 ? INT64_MIN : (int64_t)floor(fx + 0.5);
    *wy = fy > 9e18 ? INT64_MAX : fy < -9e18 ? INT64_MIN : (int64_t)floor(fy + 0.5);
}

/* Freeze the world frame: the view keeps its centre and scale when the
 * points (and so their bounding box) change. */
static void freeze_frame(pdt_editor *ed, double w, double h, pdt_view *v)
{
    if (v->centred) return;
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(ed->r), v, &L);
    double cx, cy, ax, ay, bx, by;
    pdt_view_to_world(ed->r, v, w, h, L.geo.x + L.geo.w / 2, L.geo.y + L.geo.h / 2, &cx, &cy);
    pdt_view_to_world(ed->r, v, w, h, 0, 0, &ax, &ay);
    pdt_view_to_world(ed->r, v, w, h, 100, 0, &bx, &by);
    double per_px = (bx - ax) / 100;  /* world units per pixel */
    if (ed->n < 2) {                  /* nothing to fit: a 0..100 square */
        cx = cy = 50;
        per_px = 110.0 / fmin(L.geo.w, L.geo.h);
    }
    v->centred = 1;
    v->cx = cx;
    v->cy = cy;
    v->zoom = 1;
    pdt_view_to_world(ed->r, v, w, h, 0, 0, &ax, &ay);
    pdt_view_to_world(ed->r, v, w, h, 100, 0, &bx, &by);
    v->zoom = ((bx - ax) / 100) / per_px;
}

/* Around a change: the world frame (centre, units per pixel) stays put while
 * the points, and so the fit the zoom is relative to, change. */
static void frame_begin(pdt_editor *ed, double w, double h, pdt_view *v)
{
    freeze_frame(ed, w, h, v);
    double ax, ay, bx, by;
    pdt_view_to_world(ed->r, v, w, h, 0, 0, &ax, &ay);
    pdt_view_to_world(ed->r, v, w, h, 100, 0, &bx, &by);
    ed->per_px = (bx - ax) / 100;
}

/* After a change with status st: the same frame in the new replay, and the
 * message (the error, or `ok`). */
static void frame_end(pdt_editor *ed, double w, double h, pdt_view *v, pdt_status st,
                      const pdt_err *err, const char *ok)
{
    v->zoom = 1;
    double ax, ay, bx, by;
    pdt_view_to_world(ed->r, v, w, h, 0, 0, &ax, &ay);
    pdt_view_to_world(ed->r, v, w, h, 100, 0, &bx, &by);
    if (ed->per_px > 0) v->zoom = ((bx - ax) / 100) / ed->per_px;
    report(ed, st, err, ok);
}

/* The editor's keys: what each does while triangulating and in Graham's
 * mode (x).  `hull` NULL: the same in both; "": not a key of Graham's mode. */
static const struct {
    const char *key, *tri, *hull;
} editor_keys[] = {
    {"click", "add a point (integer coordinates)", NULL},
    {"drag", "move a point (elsewhere: pan)", NULL},
    {"right click", "delete a point (later points' labels move down one)", NULL},
    {"Ctrl + Z  Y", "undo / redo", NULL},
    {"g", "grid snap on / off", NULL},
    {"n", "add 10 random points in the view", NULL},
    {"F1 … F4", "presets: circle, grid, collinear, duplicates", NULL},
    {"x", "Graham's scan only (pdt hull)", "back to the triangulation (pdt triangulate)"},
    {"1 … 8", "simulated ranks of the live run",
     "ranks the triangulation will use (Graham's scan runs on one)"},
    {"0", "show all ranks", ""},
    {"9", "show / hide rank 8", ""},
};
enum { EDITOR_NKEYS = (int)(sizeof editor_keys / sizeof *editor_keys) };

const char *const (*pdt_editor_help(pdt_editor *ed, int *n))[2]
{
    int hull = ed->mode.hull, k = 0;
    for (int i = 0; i < EDITOR_NKEYS; i++) {
        const char *what = hull && editor_keys[i].hull ? editor_keys[i].hull : editor_keys[i].tri;
        if (!*what) continue;
        ed->help[k][0] = editor_keys[i].key;
        ed->help[k][1] = what;
        k++;
    }
    *n = k;
    return (const char *const (*)[2])ed->help;
}

/* g: grid snap off, or on with a 1-2-5 step of about 25 pixels. */
static void snap_key(pdt_editor *ed, double w, double h, pdt_view *v)
{
    if (ed->snap) {
        ed->snap = 0;
    } else {
        double ax, ay, bx, by;
        freeze_frame(ed, w, h, v);
        pdt_view_to_world(ed->r, v, w, h, 0, 0, &ax, &ay);
        pdt_view_to_world(ed->r, v, w, h, 25, 0, &bx, &by);
        double want = fabs(bx - ax), step = 1;
        while (step * 10 <= want) step *= 10;
        if (step * 5 <= want) step *= 5;
        else if (step * 2 <= want) step *= 2;
        ed->snap = step > 1e9 ? 1000000000 : (int)step;
    }
    if (ed->snap) snprintf(ed->msg, sizeof ed->msg, "grid snap on: step %d", ed->snap);
    else snprintf(ed->msg, sizeof ed->msg, "grid snap off");
}

/* n: 10 random points in the middle of the view. */
static void random_key(pdt_editor *ed, double w, double h, pdt_view *v)
{
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(ed->r), v, &L);
    freeze_frame(ed, w, h, v);
    int64_t x0, y0, x1, y1;
    world_at(ed, w, h, v, L.geo.x + 0.1 * L.geo.w, L.geo.y + 0.9 * L.geo.h, &x0, &y0);
    world_at(ed, w, h, v, L.geo.x + 0.9 * L.geo.w, L.geo.y + 0.1 * L.geo.h, &x1, &y1);
    pdt_err e = {0};
    frame_begin(ed, w, h, v);
    pdt_status st = pdt_editor_random(ed, 10, x0, y0, x1, y1, &e);
    frame_end(ed, w, h, v, st, &e, "10 random points added");
}

/* x, 1 … 8: Graham's scan only or the triangulation, on `ranks` ranks. */
static void mode_key(pdt_editor *ed, int hull, int ranks, double w, double h, pdt_view *v)
{
    char ok[160];
    if (hull == ed->mode.hull && hull)
        snprintf(ok, sizeof ok, "%d rank%s for the triangulation (x); Graham's scan runs on one",
                 ranks, ranks > 1 ? "s" : "");
    else if (hull == ed->mode.hull)
        snprintf(ok, sizeof ok, "%d simulated rank%s", ranks, ranks > 1 ? "s" : "");
    else
        snprintf(ok, sizeof ok, "%s", hull ? "Graham's scan only (pdt hull)"
                                           : "Delaunay triangulation (pdt triangulate)");
    pdt_err e = {0};
    frame_begin(ed, w, h, v);
    pdt_status st = pdt_editor_set_mode(ed, hull, ranks, &e);
    frame_end(ed, w, h, v, st, &e, ok);
}

/* F1 … F4: a preset, the view fitted to its points. */
static void preset_key(pdt_editor *ed, int p, pdt_view *v)
{
    static const char *const names[] = {"circle: 20 cocircular points", "6 x 6 grid",
                                        "8 collinear points and 3 more", "duplicates"};
    pdt_err e = {0};
    pdt_status st = pdt_editor_preset(ed, (pdt_preset)p, &e);
    v->centred = 0;
    v->zoom = 1;
    report(ed, st, &e, names[p]);
}

static int edit_key(pdt_editor *ed, const pdt_shell_input *in, double w, double h, pdt_view *v)
{
    if (in->ctrl && (in->key == 'z' || in->key == 'y')) {
        char ok[160];
        int redo = in->key == 'y' || in->shift;
        pdt_err e = {0};
        frame_begin(ed, w, h, v);
        pdt_status st = redo ? pdt_editor_redo(ed, &e) : pdt_editor_undo(ed, &e);
        snprintf(ok, sizeof ok, "%s: %zu points", redo ? "redone" : "undone", ed->n);
        frame_end(ed, w, h, v, st, &e, ok);
        return 1;
    }
    if (in->ctrl) return 0;
    if (in->key == 'g') snap_key(ed, w, h, v);
    else if (in->key == 'n') random_key(ed, w, h, v);
    else if (in->key == 'x') mode_key(ed, !ed->mode.hull, ed->mode.ranks, w, h, v);
    else if (in->key >= '1' && in->key <= '8') mode_key(ed, ed->mode.hull, in->key - '0', w, h, v);
    else if (in->key >= K_F1 && in->key <= K_F4) preset_key(ed, in->key - K_F1, v);
    else return 0;
    return 1;
}

/* What deleting point i does to the labels: every later point moves down one. */
static void delete_message(const pdt_editor *ed, size_t i, char *buf, size_t cap)
{
    int n = snprintf(buf, cap, "deleted point %zu (%d, %d)", i, ed->pts[i].x, ed->pts[i].y);
    if (n < 0 || (size_t)n >= cap) return;
    if (i + 1 == ed->n)
        snprintf(buf + n, cap - (size_t)n, ", the last: no other label changes");
    else if (i + 2 == ed->n)
        snprintf(buf + n, cap - (size_t)n, ": point %zu is now %zu", i + 1, i);
    else
        snprintf(buf + n, cap - (size_t)n, ": points %zu … %zu are now %zu … %zu", i + 1, ed->n - 1,
                 i, ed->n - 2);
}

/* A right click deletes the point under it; a left press starts a drag. */
static int mouse_down(pdt_editor *ed, const pdt_shell_input *in, double w, double h, pdt_view *v)
{
    freeze_frame(ed, w, h, v);
    if (in->button == 3) {
        int64_t i = point_at(ed, w, h, v, in->x, in->y);
        if (i >= 0) {
            char ok[200];
            delete_message(ed, (size_t)i, ok, sizeof ok);
            pdt_err e = {0};
            frame_begin(ed, w, h, v);
            pdt_status st = pdt_editor_delete(ed, (size_t)i, &e);
            frame_end(ed, w, h, v, st, &e, ok);
        }
        return 1;
    }
    ed->down = 1;
    ed->moved = 0;
    ed->mx0 = ed->mx = in->x;
    ed->my0 = ed->my = in->y;
    ed->drag = point_at(ed, w, h, v, in->x, in->y);
    return 1;
}

/* A drag moves the point under the press (one undo step for the whole
 * drag), or pans. */
static int mouse_move(pdt_editor *ed, const pdt_shell_input *in, double w, double h, pdt_view *v)
{
    if (fabs(in->x - ed->mx0) + fabs(in->y - ed->my0) > 4) ed->moved = 1;
    if (ed->moved && ed->drag >= 0 && (size_t)ed->drag < ed->n) {
        int64_t x, y;
        world_at(ed, w, h, v, in->x, in->y, &x, &y);
        if (in_int32(x) && in_int32(y) && (x != ed->pts[ed->drag].x || y != ed->pts[ed->drag].y)) {
            pdt_err e = {0};
            if (ed->moved == 1 && begin_change(ed, &e) != PDT_OK) return 1;
            ed->moved = 2;
            pdt_point to = {(int32_t)x, (int32_t)y};
            pdt_edit_notes_moved(ed->notes, ed->pts[ed->drag], to);
            ed->pts[ed->drag] = to;
            frame_begin(ed, w, h, v);
            pdt_status st = rerun(ed, &e);
            frame_end(ed, w, h, v, st, &e, "moving");
        }
    } else if (ed->moved) { /* pan */
        double ax, ay, bx, by;
        pdt_view_to_world(ed->r, v, w, h, ed->mx, ed->my, &ax, &ay);
        pdt_view_to_world(ed->r, v, w, h, in->x, in->y, &bx, &by);
        v->cx -= bx - ax;
        v->cy -= by - ay;
    }
    ed->mx = in->x;
    ed->my = in->y;
    return 1;
}

/* The end of a drag saves the moved point; a click without a drag adds one. */
static int mouse_up(pdt_editor *ed, const pdt_shell_input *in, double w, double h, pdt_view *v)
{
    ed->down = 0;
    char ok[96];
    pdt_err e = {0};
    if (ed->drag >= 0 && ed->moved == 2) {
        pdt_status st = save(ed, &e);
        snprintf(ok, sizeof ok, "moved point %lld to (%d, %d)", (long long)ed->drag,
                 ed->pts[ed->drag].x, ed->pts[ed->drag].y);
        report(ed, st, &e, ok);
    } else if (!ed->moved && ed->drag < 0) {
        int64_t x, y;
        world_at(ed, w, h, v, in->x, in->y, &x, &y);
        snprintf(ok, sizeof ok, "added (%lld, %lld): %zu points", (long long)x, (long long)y,
                 ed->n + 1);
        frame_begin(ed, w, h, v);
        pdt_status st = pdt_editor_add(ed, x, y, &e);
        frame_end(ed, w, h, v, st, &e, ok);
    }
    ed->drag = -1;
    return 1;
}

static int edit_mouse(pdt_editor *ed, const pdt_shell_input *in, double w, double h, pdt_view *v)
{
    switch (in->type) {
    case PDT_IN_DOWN:
        if (!in_geo(w, h, ed->r, v, in->x, in->y) || (in->button != 1 && in->button != 3)) return 0;
        return mouse_down(ed, in, w, h, v);
    case PDT_IN_MOVE: return ed->down ? mouse_move(ed, in, w, h, v) : 0;
    case PDT_IN_UP: return ed->down && in->button == 1 ? mouse_up(ed, in, w, h, v) : 0;
    default: return 0;
    }
}

static int hook_input(void *user, const pdt_shell_input *in, double w, double h, pdt_view *v)
{
    pdt_editor *ed = user;
    int took = in->type == PDT_IN_KEY ? edit_key(ed, in, w, h, v) : edit_mouse(ed, in, w, h, v);
    if (v->help_more) v->help_more = pdt_editor_help(ed, &v->help_nmore); /* the mode's keys */
    return took;
}

static int hook_current(void *user, const pdt_replay **r, pdt_rstate **s)
{
    pdt_editor *ed = user;
    int changed = ed->changed || *r != ed->r;
    *r = ed->r;
    *s = ed->s;
    ed->changed = 0;
    return changed;
}

/* One line on a white band at (x, y), shrunk to fit max_w pixels but not
 * below the viewer's label size (0.82 of the font); what still does not
 * fit ends in "…". */
static void overlay_text(cairo_t *cr, double x, double y, double size, double max_w, const char *t,
                         double r, double g, double b)
{
    char s[512];
    snprintf(s, sizeof s, "%s", t);
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
    cairo_set_font_size(cr, size);
    cairo_text_extents_t te;
    cairo_text_extents(cr, s, &te);
    if (te.x_advance + 0.6 * size > max_w && te.x_advance > 0) {
        size *= fmax(0.965, (max_w - 0.6 * size) / te.x_advance);
        cairo_set_font_size(cr, size);
        cairo_text_extents(cr, s, &te);
    }
    for (size_t n = strlen(s); n > 1 && te.x_advance + 0.6 * size > max_w;) {
        do n--; while (n > 1 && ((unsigned char)s[n] & 0xC0) == 0x80);
        snprintf(s + n, sizeof s - n, "…");
        cairo_text_extents(cr, s, &te);
    }
    cairo_set_source_rgba(cr, 1, 1, 1, 0.85);
    cairo_rectangle(cr, x - 0.3 * size, y - size, te.x_advance + 0.6 * size, 1.35 * size);
    cairo_fill(cr);
    cairo_set_source_rgb(cr, r, g, b);
    pdt_text_log_note(cr, size, x, y, s);
    cairo_move_to(cr, x, y);
    cairo_show_text(cr, s);
}

static void hook_overlay(void *user, cairo_t *cr, double w, double h, const pdt_view *v)
{
    pdt_editor *ed = user;
    if (v->help) return; /* the help box is on top */
    pdt_layout L;
    pdt_render_layout_view(w, h, pdt_replay_nranks(ed->r), v, &L);
    cairo_save(cr);
    cairo_rectangle(cr, L.geo.x, L.geo.y, L.geo.w, L.geo.h);
    cairo_clip(cr);
    /* grid dots when snapping */
    if (ed->snap > 0) {
        double ax, ay, bx, by;
        pdt_view_to_world(ed->r, v, w, h, L.geo.x, L.geo.y + L.geo.h, &ax, &ay);
        pdt_view_to_world(ed->r, v, w, h, L.geo.x + L.geo.w, L.geo.y, &bx, &by);
        double s = ed->snap;
        if ((bx - ax) / s < 400 && (by - ay) / s < 400) {
            cairo_set_source_rgba(cr, 0.3, 0.3, 0.3, 0.45);
            for (double gx = s * ceil(ax / s); gx <= bx; gx += s)
                for (double gy = s * ceil(ay / s); gy <= by; gy += s) {
                    double sx, sy;
                    pdt_view_to_screen(ed->r, v, w, h, gx, gy, &sx, &sy);
                    cairo_rectangle(cr, sx - 1, sy - 1, 2, 2);
                }
            cairo_fill(cr);
        }
    }
    /* the edges the tie rule chose (at the end of the run) */
    if (ed->s->k == pdt_replay_count(ed->r) && ed->run.nties) {
        cairo_set_source_rgba(cr, 0.8, 0.0, 0.6, 0.9);
        cairo_set_line_width(cr, fmax(2, 0.18 * L.font));
        double dash[2] = {0.5 * L.font, 0.35 * L.font};
        cairo_set_dash(cr, dash, 2, 0);
        for (size_t i = 0; i < ed->run.nties; i++) {
            pdt_point a = ed->pts[ed->run.ties[2 * i]], b = ed->pts[ed->run.ties[2 * i + 1]];
            double x0, y0, x1, y1;
            pdt_view_to_screen(ed->r, v, w, h, a.x, a.y, &x0, &y0);
            pdt_view_to_screen(ed->r, v, w, h, b.x, b.y, &x1, &y1);
            cairo_move_to(cr, x0, y0);
            cairo_line_to(cr, x1, y1);
        }
        cairo_stroke(cr);
        cairo_set_dash(cr, NULL, 0, 0);
    }
    /* the banner: file, mode, message; the cocircular warning */
    double f = L.font;
    char line[512];
    int ranks = ed->mode.hull ? 1 : ed->mode.ranks;
    snprintf(line, sizeof line, "EDIT %s · %zu points · %s · %d rank%s%s · re-run %.1f ms", ed->path,
             ed->n, ed->mode.hull ? "hull (Graham)" : "triangulate", ranks,
             ranks > 1 ? "s" : "", ed->snap ? " · snap" : "", 1e3 * ed->last_run_s);
    overlay_text(cr, L.geo.x + 0.6 * f, L.geo.y + L.geo.h - 2.9 * f, 0.85 * f, L.geo.w - 1.2 * f, line, 0.1, 0.1, 0.1);
    overlay_text(cr, L.geo.x + 0.6 * f, L.geo.y + L.geo.h - 1.6 * f, 0.85 * f, L.geo.w - 1.2 * f, ed->msg, 0.1, 0.3, 0.6);
    if (!ed->mode.hull && ed->run.nties) {
        snprintf(line, sizeof line, "cocircular: the tie rule chose %zu edge%s (dashed magenta; "
                 "the other diagonal%s would be Delaunay too)", ed->run.nties,
                 ed->run.nties == 1 ? "" : "s", ed->run.nties == 1 ? "" : "s");
        overlay_text(cr, L.geo.x + 0.6 * f, L.geo.y + 1.2 * f, 0.85 * f, L.geo.w - 1.2 * f, line, 0.7, 0.0, 0.5);
    }
    cairo_restore(cr);
}

static const char *hook_title(void *user)
{
    pdt_editor *ed = user;
    snprintf(ed->title, sizeof ed->title, "editing %s · %s", ed->path,
             ed->mode.hull ? "hull (Graham), 1 rank" : "triangulate");
    if (!ed->mode.hull) {
        size_t len = strlen(ed->title);
        snprintf(ed->title + len, sizeof ed->title - len, ", %d rank%s", ed->mode.ranks,
                 ed->mode.ranks > 1 ? "s" : "");
    }
    return ed->title;
}

const pdt_shell_hook *pdt_editor_hook(pdt_editor *ed)
{
    ed->hook.user = ed;
    ed->hook.input = hook_input;
    ed->hook.current = hook_current;
    ed->hook.overlay = hook_overlay;
    ed->hook.title = hook_title;
    return &ed->hook;
}
