/* pdt — the viewer's SDL2 shell: the window, the keys and mouse, the clock.
 *
 * One loop() per frame: handle the pending events (real ones, or the next
 * token of a --script), advance playback, draw one frame with the cairo
 * renderer into an image surface that wraps the streaming texture, present.
 * One quit path (shell_quit).  The frame is drawn at the drawable size, so
 * it is sharp on high-DPI screens; mouse positions are scaled to match. */
#include "shell.h"
#include "cluster.h"
#include "pdt/view/query.h"

#include "pdt/safefile.h"
#include "pdt/view/anim.h"
#include "pdt/view/textlog.h"
#include "window.h"

#include <SDL.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* hidden[] has room for this many ranks more than the first replay has (a
 * hook may switch to a replay with more ranks). */
enum { MAX_RANKS_SHOWN = 64 };

typedef struct shell {
    const pdt_replay *r;
    pdt_rstate *s;
    int cap_ranks;          /* room in hidden[] */
    pdt_view *v;
    const pdt_shell_opts *o;
    SDL_Window *win;
    SDL_Renderer *ren;
    SDL_Texture *tex;
    int tw, th;             /* texture size = drawable size */
    double sx, sy;          /* drawable / window scale */
    uint8_t *hidden;        /* writable copy of the view's hidden ranks */
    int nranks;
    int playing, quit, dirty, shots, recs;
    size_t mark;            /* `m`: one end of the next recording (SIZE_MAX: none) */
    double speed, acc;      /* events per second; fraction carried over */
    uint64_t last;          /* performance counter at the last frame */
    /* mouse */
    int down, dragged, drag_lifted;
    double mx0, my0, mx, my;
    /* script */
    const char *script;
    int wait_frames;
    char status[320];
    char note[160];         /* what the last m, r or s did, shown in the status */
    Uint32 note_until;      /* ... until this SDL tick */
    /* go to event N: the number being typed after `g` */
    int typing;
    char num[24], prompt[96];
    int fullscreen;
    pdt_window_saved saved; /* what full screen replaced */
    char title[480];        /* the hook's title last set */
    pdt_cluster *cl;        /* many ranks: groups, the timeline's window, the tree */
    /* the view before a click zoomed out to a selected triangle's circle:
     * given back at the next move of the cursor or click (auto_zoom 1) */
    int auto_zoom, az_centred;
    double az_zoom, az_cx, az_cy;
} shell;

/* Give back the view a click's zoom to a circle replaced (if it still stands). */
static void unzoom(shell *sh)
{
    if (!sh->auto_zoom) return;
    sh->auto_zoom = 0;
    sh->v->zoom = sh->az_zoom;
    sh->v->cx = sh->az_cx;
    sh->v->cy = sh->az_cy;
    sh->v->centred = sh->az_centred;
    sh->dirty = 1;
}

static void set_status(shell *sh)
{
    snprintf(sh->status, sizeof sh->status, "%s%s%s · %.0f ev/s · Shift+←/→: %s · h: help",
             sh->note, sh->note[0] ? " · " : "", sh->playing ? "playing" : "paused", sh->speed,
             pdt_ev_class_name(sh->v->ev_class));
    sh->v->status = sh->status;
}

/* A key's result, on the terminal and for a few seconds in the status. */
static void say(shell *sh, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void say(shell *sh, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(sh->note, sizeof sh->note, fmt, ap);
    va_end(ap);
    sh->note_until = SDL_GetTicks() + 4000;
    sh->dirty = 1;
}

static void seek(shell *sh, size_t k)
{
    size_t m = pdt_replay_count(sh->r);
    if (k > m) k = m;
    unzoom(sh); /* a move of the cursor gives the view back */
    /* a few steps are cheaper than a seek; either gives the same state */
    if (k > sh->s->k && k - sh->s->k <= 64) {
        while (sh->s->k < k) pdt_replay_step(sh->r, sh->s, 1);
    } else if (k < sh->s->k && sh->s->k - k <= 64) {
        while (sh->s->k > k) pdt_replay_step(sh->r, sh->s, -1);
    } else {
        pdt_replay_seek(sh->r, sh->s, k);
    }
    sh->dirty = 1;
}

/* The file name of path, without its folders (for the status row). */
static const char *base_name(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

static int screenshot(shell *sh, const char *path)
{
    char name[64];
    if (!path) {
        snprintf(name, sizeof name, "pdtview-%03d.png", sh->shots++);
        path = name;
    }
    pdt_err err = {0};
    pdt_text_log *log = sh->v->texts; /* the report is the window's frame's */
    sh->v->texts = NULL;
    const pdt_shell_hook *hk = sh->o->hook; /* what the window draws over the frame too */
    pdt_status st = pdt_render_file_over(path, PDT_SAFE_DIRECT, sh->tw, sh->th, sh->r, sh->s,
                                         sh->v, hk ? hk->overlay : NULL, hk ? hk->user : NULL,
                                         &err);
    sh->v->texts = log;
    if (st == PDT_OK && log) st = pdt_text_log_write(log, sh->o->layout_report, &err);
    if (st != PDT_OK) {
        fprintf(stderr, "pdtview: %s\n", err.msg);
        say(sh, "screenshot failed (see the terminal)");
        return 0;
    }
    fprintf(stderr, "pdtview: screenshot %s (%dx%d, event %zu)\n", path, sh->tw, sh->th, sh->s->k);
    say(sh, "saved %.40s", base_name(path));
    return 1;
}

/* `r`: write the events between the mark (`m`; else the end) and the
 * current event as an animation, drawn as the window shows them. */
static void record(shell *sh)
{
    char name[64];
    const char *path = sh->o->record;
    if (!path) {
        snprintf(name, sizeof name, "pdtview-rec-%03d.gif", sh->recs++);
        path = name;
    }
    size_t a = sh->s->k, b = sh->mark == SIZE_MAX ? pdt_replay_count(sh->r) : sh->mark;
    pdt_anim_opts ao = {sh->tw & ~1, sh->th & ~1, sh->o->fps > 0 ? sh->o->fps : 10,
                        a < b ? a : b, a < b ? b : a, sh->o->every > 0 ? (size_t)sh->o->every : 1, -1};
    pdt_view v = *sh->v;
    v.status = NULL;
    v.help = 0;
    pdt_err err = {0};
    size_t frames = 0;
    pdt_rstate *scratch = pdt_rstate_new(sh->r);
    if (!scratch) pdt_err_set(&err, PDT_ERR_NOMEM, "out of memory");
    else pdt_anim_replay(path, &ao, sh->r, scratch, &v, &frames, &err);
    pdt_rstate_free(scratch);
    if (err.code != PDT_OK) {
        fprintf(stderr, "pdtview: %s\n", err.msg);
        say(sh, "recording failed (see the terminal)");
    } else {
        fprintf(stderr, "pdtview: recorded %s (%zu frames, events %zu to %zu)\n", path, frames,
                ao.from, ao.to);
        say(sh, "recorded %.40s (events %zu–%zu)", base_name(path), ao.from, ao.to);
    }
}

/* The `g` prompt: digits, Backspace, Enter (go), Esc (cancel).  Returns 1
 * if the key was the prompt's. */
static int goto_key(shell *sh, SDL_Keycode k)
{
    size_t len = strlen(sh->num);
    if (k >= SDLK_0 && k <= SDLK_9) {
        if (len + 1 < sizeof sh->num) sh->num[len] = (char)('0' + (k - SDLK_0)), sh->num[len + 1] = 0;
    } else if (k >= SDLK_KP_1 && k <= SDLK_KP_0) {
        int d = k == SDLK_KP_0 ? 0 : (int)(k - SDLK_KP_1) + 1;
        if (len + 1 < sizeof sh->num) sh->num[len] = (char)('0' + d), sh->num[len + 1] = 0;
    } else if (k == SDLK_BACKSPACE) {
        if (len) sh->num[len - 1] = 0;
    } else if (k == SDLK_RETURN || k == SDLK_KP_ENTER) {
        sh->typing = 0;
        sh->v->prompt = NULL;
        if (len) {
            sh->playing = 0;
            seek(sh, (size_t)strtoull(sh->num, NULL, 10));
        }
        return 1;
    } else if (k == SDLK_ESCAPE || k == SDLK_g) {
        sh->typing = 0;
        sh->v->prompt = NULL;
        return 1;
    } else if (k != SDLK_UNKNOWN) {
        return 1; /* other keys are ignored while typing */
    }
    snprintf(sh->prompt, sizeof sh->prompt, "go to event: %s▏  (Enter: go, Esc: cancel)", sh->num);
    sh->v->prompt = sh->prompt;
    return 1;
}

static void set_font_scale(shell *sh, double f)
{
    sh->v->font_scale = fmin(4, fmax(0.4, f));
}

/* Ctrl + key: font scale, and stepping by rank. */
static void ctrl_key(shell *sh, SDL_Keycode k)
{
    sh->dirty = 1;
    switch (k) {
    case SDLK_EQUALS:
    case SDLK_PLUS:
    case SDLK_KP_PLUS: set_font_scale(sh, sh->v->font_scale * 1.15); return;
    case SDLK_MINUS:
    case SDLK_KP_MINUS: set_font_scale(sh, sh->v->font_scale / 1.15); return;
    case SDLK_0:
    case SDLK_KP_0: set_font_scale(sh, 1); return;
    case SDLK_RIGHT:
    case SDLK_LEFT: {
        /* next / previous event of the current event's rank */
        size_t cur = sh->s->k;
        int q = cur ? (int)pdt_replay_rank_of(sh->r, cur - 1) : 0;
        sh->playing = 0;
        seek(sh, pdt_replay_find_rank(sh->r, cur, k == SDLK_RIGHT ? 1 : -1, q));
        return;
    }
    default: sh->dirty = 0; return;
    }
}

/* Right / left: a step; with Shift, the next event of the class shown
 * (k) among the visible ranks. */
static void arrow_key(shell *sh, SDL_Keycode k, int shift)
{
    int dir = k == SDLK_RIGHT ? 1 : -1;
    sh->playing = 0;
    if (!shift) {
        pdt_replay_step(sh->r, sh->s, dir);
        return;
    }
    uint8_t *vis = malloc((size_t)sh->nranks);
    if (vis)
        for (int q = 0; q < sh->nranks; q++) vis[q] = !sh->hidden[q];
    seek(sh, pdt_replay_find(sh->r, sh->s->k, dir, sh->v->ev_class, vis));
    free(vis);
}

/* The keys that move the cursor or the clock: 1 if k was one. */
static int move_key(shell *sh, SDL_Keycode k, int shift)
{
    size_t m = pdt_replay_count(sh->r), cur = sh->s->k;
    switch (k) {
    case SDLK_SPACE:
        sh->playing = !sh->playing;
        sh->acc = 0;
        return 1;
    case SDLK_RIGHT:
    case SDLK_LEFT: arrow_key(sh, k, shift); return 1;
    case SDLK_PAGEDOWN: seek(sh, pdt_replay_find_phase_stop(sh->r, cur, 1)); return 1;
    case SDLK_PAGEUP: seek(sh, pdt_replay_find_phase_stop(sh->r, cur, -1)); return 1;
    case SDLK_HOME: seek(sh, 0); return 1;
    case SDLK_END: seek(sh, m); return 1;
    case SDLK_PLUS:
    case SDLK_EQUALS:
    case SDLK_KP_PLUS: sh->speed = fmin(sh->speed * 2, 1e7); return 1;
    case SDLK_MINUS:
    case SDLK_KP_MINUS: sh->speed = fmax(sh->speed / 2, 0.25); return 1;
    case SDLK_g:
        sh->typing = 1;
        sh->num[0] = 0;
        goto_key(sh, SDLK_UNKNOWN);
        return 1;
    case SDLK_m:
        sh->mark = cur;
        fprintf(stderr, "pdtview: mark at event %zu (r records from here to the current event)\n", cur);
        say(sh, "mark at %zu (r: record to here)", cur);
        return 1;
    default: return 0;
    }
}

/* The keys that change the view or the window: 1 if k was one. */
static int view_key(shell *sh, SDL_Keycode k, int shift)
{
    switch (k) {
    case SDLK_ESCAPE:
    case SDLK_q: sh->quit = 1; return 1;
    case SDLK_k: sh->v->ev_class = sh->v->ev_class % (PDT_EVC_COUNT - 1) + 1; return 1;
    case SDLK_0: memset(sh->hidden, 0, (size_t)sh->nranks); return 1;
    case SDLK_f:
        sh->auto_zoom = 0;
        sh->v->zoom = 1;
        sh->v->centred = 0;
        return 1;
    case SDLK_h:
    case SDLK_QUESTION: sh->v->help = !sh->v->help; return 1;
    case SDLK_SLASH:
        if (shift) sh->v->help = !sh->v->help;
        return 1;
    case SDLK_s: screenshot(sh, sh->o->screenshot); return 1;
    case SDLK_r: record(sh); return 1;
    case SDLK_F11:
        sh->fullscreen = !sh->fullscreen;
        pdt_window_fullscreen(sh->win, sh->fullscreen, &sh->saved);
        return 1;
    case SDLK_t: sh->v->theme = (sh->v->theme + 1) % PDT_THEME_COUNT; return 1;
    case SDLK_c: sh->v->clean = !sh->v->clean; return 1;
    case SDLK_o: sh->v->circles = !sh->v->circles; return 1;
    case SDLK_v: sh->v->voronoi = !sh->v->voronoi; return 1;
    case SDLK_TAB: { /* the next page of the panels with no room, then the picture */
        pdt_layout L;
        pdt_render_layout_view(sh->tw, sh->th, sh->nranks, sh->v, &L);
        sh->v->overflow = sh->v->overflow >= L.pages ? 0 : sh->v->overflow + 1;
        return 1;
    }
    default:
        if (k >= SDLK_1 && k <= SDLK_9) {
            int q = (int)(k - SDLK_1);
            if (q < sh->nranks) sh->hidden[q] = !sh->hidden[q];
            return 1;
        }
        return 0;
    }
}

/* After a key or click of cluster.c: seek if it asked to, redraw. */
static void cluster_seek(shell *sh, size_t k)
{
    if (k != SIZE_MAX) {
        sh->playing = 0;
        seek(sh, k);
    }
    sh->dirty = 1;
}

static void key(shell *sh, SDL_Keycode k, Uint16 mod)
{
    int shift = (mod & KMOD_SHIFT) != 0, ctrl = (mod & KMOD_CTRL) != 0;
    size_t to;
    if (sh->typing) {
        goto_key(sh, k);
        sh->dirty = 1;
        return;
    }
    if (pdt_cluster_key(sh->cl, sh->r, sh->s, sh->v, k, shift, ctrl, sh->tw, sh->th, sh->hidden, &to))
        return cluster_seek(sh, to);
    if (ctrl) {
        ctrl_key(sh, k);
        return;
    }
    sh->dirty = move_key(sh, k, shift) || view_key(sh, k, shift);
}

static int in_rect(pdt_rect R, double x, double y);

static void click(shell *sh, double x, double y)
{
    size_t k = pdt_render_timeline_at(sh->r, sh->v, sh->tw, sh->th, x, y);
    if (k != (size_t)-1) {
        sh->playing = 0;
        seek(sh, k);
        return;
    }
    pdt_layout L;
    pdt_render_layout_view(sh->tw, sh->th, sh->nranks, sh->v, &L);
    if (L.covered || !in_rect(L.geo, x, y)) return; /* (covered: the picture is not shown) */
    unzoom(sh);
    pdt_render_pick(sh->r, sh->s, sh->v, sh->tw, sh->th, x, y, 0.8 * L.font, &sh->v->sel_point,
                    &sh->v->sel_tri, &sh->v->sel_edge);
    if (sh->v->sel_tri >= 0) { /* a large circle: zoom out to show it whole */
        size_t nt, n;
        const pdt_rtri *T = pdt_replay_tris(sh->r, &nt);
        const pdt_point *P = pdt_replay_points(sh->r, &n);
        const uint32_t *v = T[sh->v->sel_tri].v;
        double ax = P[v[0]].x, ay = P[v[0]].y, bx = P[v[1]].x - ax, by = P[v[1]].y - ay;
        double cx = P[v[2]].x - ax, cy = P[v[2]].y - ay, d = 2 * (bx * cy - by * cx);
        if (d != 0) {
            sh->auto_zoom = 1;
            sh->az_zoom = sh->v->zoom, sh->az_cx = sh->v->cx, sh->az_cy = sh->v->cy;
            sh->az_centred = sh->v->centred;
            double ux = (cy * (bx * bx + by * by) - by * (cx * cx + cy * cy)) / d;
            double uy = (bx * (cx * cx + cy * cy) - cx * (bx * bx + by * by)) / d;
            pdt_view_fit_circle(sh->r, sh->v, sh->tw, sh->th, ax + ux, ay + uy, sqrt(ux * ux + uy * uy));
        }
    }
    sh->dirty = 1;
}

static int in_rect(pdt_rect R, double x, double y)
{
    return x >= R.x && x <= R.x + R.w && y >= R.y && y <= R.y + R.h;
}

static void mouse(shell *sh, const SDL_Event *e)
{
    size_t to;
    if (pdt_cluster_mouse(sh->cl, sh->r, sh->v, e, sh->sx, sh->sy, sh->tw, sh->th, &to))
        return cluster_seek(sh, to);
    pdt_layout L;
    pdt_render_layout_view(sh->tw, sh->th, sh->nranks, sh->v, &L);
    switch (e->type) {
    case SDL_MOUSEBUTTONDOWN:
        if (e->button.button != SDL_BUTTON_LEFT) return;
        sh->down = 1;
        sh->dragged = 0;
        sh->mx0 = sh->mx = e->button.x * sh->sx;
        sh->my0 = sh->my = e->button.y * sh->sy;
        sh->drag_lifted = in_rect(L.lifted, sh->mx, sh->my);
        return;
    case SDL_MOUSEMOTION: {
        double x = e->motion.x * sh->sx, y = e->motion.y * sh->sy;
        if (sh->down) {
            if (fabs(x - sh->mx0) + fabs(y - sh->my0) > 4) sh->dragged = 1;
            if (sh->dragged) {
                if (sh->drag_lifted) {
                    sh->v->yaw += (x - sh->mx) * 0.01;
                    sh->v->pitch = fmin(1.5, fmax(0.05, sh->v->pitch + (y - sh->my) * 0.01));
                } else {
                    double ax, ay, bx, by;
                    pdt_view_to_world(sh->r, sh->v, sh->tw, sh->th, sh->mx, sh->my, &ax, &ay);
                    pdt_view_to_world(sh->r, sh->v, sh->tw, sh->th, x, y, &bx, &by);
                    double cx, cy;
                    pdt_view_to_world(sh->r, sh->v, sh->tw, sh->th, L.geo.x + L.geo.w / 2,
                                      L.geo.y + L.geo.h / 2, &cx, &cy);
                    sh->v->cx = cx - (bx - ax);
                    sh->v->cy = cy - (by - ay);
                    sh->v->centred = 1;
                    sh->auto_zoom = 0;
                }
                sh->dirty = 1;
            }
        }
        sh->mx = x;
        sh->my = y;
        return;
    }
    case SDL_MOUSEBUTTONUP:
        if (e->button.button != SDL_BUTTON_LEFT || !sh->down) return;
        sh->down = 0;
        if (!sh->dragged) click(sh, e->button.x * sh->sx, e->button.y * sh->sy);
        return;
    case SDL_MOUSEWHEEL: {
        int mx, my;
        SDL_GetMouseState(&mx, &my);
        double x = mx * sh->sx, y = my * sh->sy;
        if (L.covered || !in_rect(L.geo, x, y)) return;
        pdt_view_zoom_at(sh->r, sh->v, sh->tw, sh->th, x, y, pow(1.2, e->wheel.y));
        sh->auto_zoom = 0; /* the user's zoom from now on */
        sh->dirty = 1;
        return;
    }
    default: return;
    }
}

/* Feed the next script token as SDL events.  Tokens (space separated):
 * key names (space right left S-right S-left pgdn pgup home end plus minus
 * 0-9 h k f s m r q g enter bksp t c o v f11 C-plus C-minus C-0 C-right
 * C-left), key:NAME / key:C-NAME (any SDL key name, C- = with Ctrl), wait:N
 * (frames), click:X,Y, rclick:X,Y (right button) and wheel:X,Y,N (window
 * coordinates), drag:X0,Y0,X1,Y1. */
/* A key token of a script (a name of the table, a digit, key:NAME or
 * key:C-NAME with SDL's key names): pushed as a key press; 0 if tok is
 * not one. */
static int script_key(const char *tok)
{
    static const struct { const char *name; SDL_Keycode k; Uint16 mod; } keys[] = {
        {"space", SDLK_SPACE, 0},   {"right", SDLK_RIGHT, 0},  {"left", SDLK_LEFT, 0},
        {"S-right", SDLK_RIGHT, KMOD_LSHIFT}, {"S-left", SDLK_LEFT, KMOD_LSHIFT},
        {"pgdn", SDLK_PAGEDOWN, 0}, {"pgup", SDLK_PAGEUP, 0},  {"home", SDLK_HOME, 0},
        {"end", SDLK_END, 0},       {"plus", SDLK_PLUS, 0},    {"minus", SDLK_MINUS, 0},
        {"h", SDLK_h, 0},           {"k", SDLK_k, 0},          {"f", SDLK_f, 0},
        {"s", SDLK_s, 0},           {"q", SDLK_q, 0},          {"esc", SDLK_ESCAPE, 0},
        {"m", SDLK_m, 0},           {"r", SDLK_r, 0},
        {"g", SDLK_g, 0},           {"enter", SDLK_RETURN, 0}, {"bksp", SDLK_BACKSPACE, 0},
        {"t", SDLK_t, 0},           {"c", SDLK_c, 0},          {"o", SDLK_o, 0},
        {"v", SDLK_v, 0},           {"f11", SDLK_F11, 0},
        {"C-plus", SDLK_EQUALS, KMOD_LCTRL}, {"C-minus", SDLK_MINUS, KMOD_LCTRL},
        {"C-0", SDLK_0, KMOD_LCTRL}, {"C-right", SDLK_RIGHT, KMOD_LCTRL},
        {"C-left", SDLK_LEFT, KMOD_LCTRL},
    };
    SDL_Event e;
    memset(&e, 0, sizeof e);
    e.type = SDL_KEYDOWN;
    for (size_t i = 0; i < sizeof keys / sizeof *keys; i++)
        if (!strcmp(tok, keys[i].name)) {
            e.key.keysym.sym = keys[i].k;
            e.key.keysym.mod = keys[i].mod;
            SDL_PushEvent(&e);
            return 1;
        }
    if (tok[0] >= '0' && tok[0] <= '9' && !tok[1]) {
        e.key.keysym.sym = SDLK_0 + (tok[0] - '0');
        SDL_PushEvent(&e);
        return 1;
    }
    if (strncmp(tok, "key:", 4)) return 0;
    const char *name = tok + 4;
    int ctrl = !strncmp(name, "C-", 2), shift = !strncmp(name, "S-", 2); /* key:S-b: Shift+b */
    e.key.keysym.sym = SDL_GetKeyFromName(ctrl || shift ? name + 2 : name);
    e.key.keysym.mod = ctrl ? KMOD_LCTRL : shift ? KMOD_LSHIFT : 0;
    if (e.key.keysym.sym == SDLK_UNKNOWN) return 0;
    SDL_PushEvent(&e);
    return 1;
}

/* A press and release of mouse button `button` at (x, y). */
static void push_click(Uint8 button, int x, int y)
{
    SDL_Event e;
    memset(&e, 0, sizeof e);
    e.type = SDL_MOUSEBUTTONDOWN;
    e.button.button = button;
    e.button.x = x;
    e.button.y = y;
    SDL_PushEvent(&e);
    e.type = SDL_MOUSEBUTTONUP;
    SDL_PushEvent(&e);
}

/* A left-button drag from (a, b) to (c, d). */
static void push_drag(int a, int b, int c, int d)
{
    SDL_Event e;
    memset(&e, 0, sizeof e);
    e.type = SDL_MOUSEBUTTONDOWN;
    e.button.button = SDL_BUTTON_LEFT;
    e.button.x = a;
    e.button.y = b;
    SDL_PushEvent(&e);
    SDL_Event mv;
    memset(&mv, 0, sizeof mv);
    mv.type = SDL_MOUSEMOTION;
    mv.motion.x = c;
    mv.motion.y = d;
    SDL_PushEvent(&mv);
    e.type = SDL_MOUSEBUTTONUP;
    e.button.x = c;
    e.button.y = d;
    SDL_PushEvent(&e);
}

/* The mouse and timing tokens of a script (rclick, wait, click, drag,
 * wheel); an unknown token is reported. */
static void script_other(shell *sh, const char *tok)
{
    int a, b, c, d;
    if (sscanf(tok, "rclick:%d,%d", &a, &b) == 2) {
        push_click(SDL_BUTTON_RIGHT, a, b);
    } else if (sscanf(tok, "wait:%d", &a) == 1) {
        sh->wait_frames = a;
    } else if (sscanf(tok, "click:%d,%d", &a, &b) == 2) {
        push_click(SDL_BUTTON_LEFT, a, b);
    } else if (sscanf(tok, "drag:%d,%d,%d,%d", &a, &b, &c, &d) == 4) {
        push_drag(a, b, c, d);
    } else if (sscanf(tok, "wheel:%d,%d,%d", &a, &b, &c) == 3) {
        SDL_WarpMouseInWindow(sh->win, a, b);
        SDL_Event e;
        memset(&e, 0, sizeof e);
        e.type = SDL_MOUSEWHEEL;
        e.wheel.y = c;
        SDL_PushEvent(&e);
    } else {
        fprintf(stderr, "pdtview: script: unknown token \"%s\"\n", tok);
    }
}

/* The script's next token, as the events it stands for. */
static void script_step(shell *sh)
{
    if (!sh->script) return;
    if (sh->wait_frames > 0) {
        sh->wait_frames--;
        return;
    }
    while (*sh->script == ' ') sh->script++;
    if (!*sh->script) {
        sh->script = NULL;
        return;
    }
    char tok[64];
    size_t n = strcspn(sh->script, " ");
    if (n >= sizeof tok) n = sizeof tok - 1;
    memcpy(tok, sh->script, n);
    tok[n] = 0;
    sh->script += strcspn(sh->script, " ");
    if (!script_key(tok)) script_other(sh, tok);
}

static int make_texture(shell *sh);

/* Offer an SDL event to the hook; 1 if it took it. */
static int hook_input(shell *sh, const SDL_Event *e)
{
    const pdt_shell_hook *hk = sh->o->hook;
    if (!hk || !hk->input) return 0;
    /* input before the first frame: the hook needs the drawable size */
    if (!sh->tex && !make_texture(sh)) return 0;
    pdt_shell_input in;
    memset(&in, 0, sizeof in);
    SDL_Keymod mod = SDL_GetModState();
    switch (e->type) {
    case SDL_MOUSEBUTTONDOWN:
    case SDL_MOUSEBUTTONUP:
        in.type = e->type == SDL_MOUSEBUTTONDOWN ? PDT_IN_DOWN : PDT_IN_UP;
        in.button = e->button.button;
        in.x = e->button.x * sh->sx;
        in.y = e->button.y * sh->sy;
        break;
    case SDL_MOUSEMOTION:
        in.type = PDT_IN_MOVE;
        in.x = e->motion.x * sh->sx;
        in.y = e->motion.y * sh->sy;
        break;
    case SDL_KEYDOWN:
        in.type = PDT_IN_KEY;
        in.key = (int)e->key.keysym.sym;
        mod = (SDL_Keymod)(mod | e->key.keysym.mod);
        break;
    default: return 0;
    }
    in.ctrl = (mod & KMOD_CTRL) != 0;
    in.shift = (mod & KMOD_SHIFT) != 0;
    if (!hk->input(hk->user, &in, sh->tw, sh->th, sh->v)) return 0;
    if (in.type == PDT_IN_UP && in.button == 1) sh->down = 0; /* (its click: no drag after) */
    sh->dirty = 1;
    return 1;
}

/* The hook's window title, when it changed. */
static void hook_title(shell *sh)
{
    const pdt_shell_hook *hk = sh->o->hook;
    const char *t = hk && hk->title ? hk->title(hk->user) : NULL;
    if (!t || !strcmp(t, sh->title)) return;
    snprintf(sh->title, sizeof sh->title, "%s", t);
    char full[sizeof sh->title + 16];
    snprintf(full, sizeof full, "pdtview — %s", t);
    SDL_SetWindowTitle(sh->win, full);
}

/* Take the hook's replay if it changed. */
static void hook_current(shell *sh)
{
    const pdt_shell_hook *hk = sh->o->hook;
    hook_title(sh);
    if (!hk || !hk->current || !hk->current(hk->user, &sh->r, &sh->s)) return;
    pdt_cluster_take(&sh->cl, sh->r, sh->v);
    int n = pdt_replay_nranks(sh->r);
    sh->nranks = n < sh->cap_ranks ? n : sh->cap_ranks;
    sh->dirty = 1;
}

static int make_texture(shell *sh)
{
    int w, h, ww, wh;
    if (SDL_GetRendererOutputSize(sh->ren, &w, &h) != 0) return 0;
    SDL_GetWindowSize(sh->win, &ww, &wh);
    sh->sx = ww > 0 ? (double)w / ww : 1;
    sh->sy = wh > 0 ? (double)h / wh : 1;
    if (sh->tex && w == sh->tw && h == sh->th) return 1;
    if (sh->tex) SDL_DestroyTexture(sh->tex);
    sh->tex = SDL_CreateTexture(sh->ren, SDL_PIXELFORMAT_ARGB8888, SDL_TEXTUREACCESS_STREAMING, w, h);
    sh->tw = w;
    sh->th = h;
    sh->dirty = 1;
    return sh->tex != NULL;
}

static int draw(shell *sh)
{
    void *pix;
    int pitch;
    if (SDL_LockTexture(sh->tex, NULL, &pix, &pitch) != 0) return 0;
    cairo_surface_t *sf = cairo_image_surface_create_for_data(pix, CAIRO_FORMAT_RGB24, sh->tw,
                                                              sh->th, pitch);
    cairo_t *cr = cairo_create(sf);
    pdt_err err = {0};
    set_status(sh);
    pdt_status st = pdt_render(cr, sh->tw, sh->th, sh->r, sh->s, sh->v, &err);
    const pdt_shell_hook *hk = sh->o->hook;
    if (st == PDT_OK && hk && hk->overlay) hk->overlay(hk->user, cr, sh->tw, sh->th, sh->v);
    cairo_destroy(cr);
    cairo_surface_flush(sf);
    cairo_surface_destroy(sf);
    SDL_UnlockTexture(sh->tex);
    if (st != PDT_OK) fprintf(stderr, "pdtview: %s\n", err.msg);
    return 1;
}

/* The clock: playback advances, a status note expires. */
static void tick(shell *sh)
{
    if (sh->note[0] && SDL_TICKS_PASSED(SDL_GetTicks(), sh->note_until)) {
        sh->note[0] = 0;
        sh->dirty = 1;
    }
    uint64_t now = SDL_GetPerformanceCounter();
    double dt = (double)(now - sh->last) / (double)SDL_GetPerformanceFrequency();
    sh->last = now;
    if (sh->playing) {
        sh->acc += fmin(dt, 0.25) * sh->speed;
        size_t adv = (size_t)sh->acc;
        sh->acc -= (double)adv;
        if (adv) seek(sh, sh->s->k + adv);
        if (adv) pdt_view_follow(sh->r, sh->s, sh->v, sh->tw, sh->th);
        if (sh->s->k >= pdt_replay_count(sh->r)) sh->playing = 0;
        sh->dirty = 1;
    }
}

/* One frame: events, playback, draw, present. */
static void loop(shell *sh)
{
    SDL_Event e;
    script_step(sh);
    int got = sh->playing || sh->dirty || sh->script ? SDL_PollEvent(&e)
                                                    : SDL_WaitEventTimeout(&e, 100);
    while (got) {
        if (hook_input(sh, &e)) {
            got = SDL_PollEvent(&e);
            continue;
        }
        switch (e.type) {
        case SDL_QUIT: sh->quit = 1; break;
        case SDL_KEYDOWN: key(sh, e.key.keysym.sym, e.key.keysym.mod); break;
        case SDL_TEXTINPUT:
            if (!strcmp(e.text.text, "?")) {
                sh->v->help = !sh->v->help;
                sh->dirty = 1;
            } else if (!strcmp(e.text.text, "+")) {
                /* '+' typed with Shift on layouts where it is not SDLK_PLUS:
                 * handled as SDLK_EQUALS already */
            }
            break;
        case SDL_WINDOWEVENT:
            if (e.window.event == SDL_WINDOWEVENT_SIZE_CHANGED ||
                e.window.event == SDL_WINDOWEVENT_EXPOSED)
                sh->dirty = 1;
            break;
        case SDL_MOUSEBUTTONDOWN:
        case SDL_MOUSEBUTTONUP:
        case SDL_MOUSEMOTION:
        case SDL_MOUSEWHEEL: mouse(sh, &e); break;
        default: break;
        }
        got = SDL_PollEvent(&e);
    }
    hook_current(sh);
    tick(sh);
    if (!make_texture(sh)) {
        fprintf(stderr, "pdtview: texture: %s\n", SDL_GetError());
        sh->quit = 1;
        return;
    }
    if (sh->dirty) {
        if (!draw(sh)) {
            fprintf(stderr, "pdtview: draw: %s\n", SDL_GetError());
            sh->quit = 1;
            return;
        }
        sh->dirty = 0;
    }
    SDL_RenderClear(sh->ren);
    SDL_RenderCopy(sh->ren, sh->tex, NULL, NULL);
    SDL_RenderPresent(sh->ren);
}

/* --layout-report without --screenshot: the texts of the last frame shown. */
static void write_report(shell *sh)
{
    pdt_err err = {0};
    if (pdt_text_log_write(sh->v->texts, sh->o->layout_report, &err) != PDT_OK)
        fprintf(stderr, "pdtview: %s\n", err.msg);
}

/* The one teardown path. */
static int shell_quit(shell *sh, int rc)
{
    if (rc == 0 && sh->o->screenshot && sh->tex) screenshot(sh, sh->o->screenshot);
    else if (rc == 0 && sh->v->texts && sh->tex) write_report(sh);
    pdt_text_log_free(sh->v->texts);
    sh->v->texts = NULL;
    pdt_cluster_free(sh->cl, sh->v);
    sh->cl = NULL;
    if (sh->tex) SDL_DestroyTexture(sh->tex);
    if (sh->ren) SDL_DestroyRenderer(sh->ren);
    if (sh->win) SDL_DestroyWindow(sh->win);
    free(sh->hidden);
    SDL_Quit();
    return rc;
}

/* When no X or Wayland server answers, SDL falls back to drivers that draw
 * nowhere (offscreen, dummy), and a viewer would run unseen: those only
 * when $SDL_VIDEODRIVER names them. */
int pdt_shell_video_init(void)
{
    if (SDL_WasInit(SDL_INIT_VIDEO)) return 1;
    SDL_SetHint(SDL_HINT_VIDEO_X11_NET_WM_BYPASS_COMPOSITOR, "0");
    if (SDL_Init(SDL_INIT_VIDEO) != 0) {
        fprintf(stderr, "pdtview: SDL_Init: %s\n", SDL_GetError());
        return 0;
    }
    const char *drv = SDL_GetCurrentVideoDriver(), *want = getenv("SDL_VIDEODRIVER");
    int unseen = drv && (!strcmp(drv, "offscreen") || !strcmp(drv, "dummy"));
    if (unseen && !(want && strstr(want, drv))) {
        const char *d = getenv("DISPLAY"), *w = getenv("WAYLAND_DISPLAY");
        fprintf(stderr, "pdtview: cannot open a window: no display answers (DISPLAY=%s, WAYLAND_DISPLAY=%s);"
                        " --headless draws to files without one\n", d ? d : "(unset)", w ? w : "(unset)");
        return 0;
    }
    return 1;
}

int pdt_shell_run(const pdt_replay *r, pdt_rstate *s, pdt_view *v, const pdt_shell_opts *o)
{
    shell sh;
    memset(&sh, 0, sizeof sh);
    sh.r = r;
    sh.s = s;
    sh.v = v;
    sh.o = o;
    sh.nranks = pdt_replay_nranks(r);
    sh.speed = o->speed > 0 ? o->speed : 20;
    sh.script = o->script;
    sh.mark = SIZE_MAX;
    sh.hidden = calloc(MAX_RANKS_SHOWN + (size_t)sh.nranks + 1, 1);
    if (!sh.hidden) return 1;
    sh.cap_ranks = MAX_RANKS_SHOWN + sh.nranks;
    if (v->hidden) memcpy(sh.hidden, v->hidden, (size_t)sh.nranks);
    v->hidden = sh.hidden;
    v->texts = o->layout_report ? pdt_text_log_new() : NULL;
    pdt_cluster_take(&sh.cl, r, v); /* made again when a hook's replay changes */
    if (!pdt_shell_video_init()) return shell_quit(&sh, 1);
    char title[512];
    snprintf(title, sizeof title, "pdtview — %s", o->title ? o->title : "");
    sh.fullscreen = o->fullscreen;
    sh.win = pdt_window_open(title, o->w, o->h, &sh.saved);
    if (!sh.win) {
        fprintf(stderr, "pdtview: window: %s\n", SDL_GetError());
        return shell_quit(&sh, 1);
    }
    sh.ren = SDL_CreateRenderer(sh.win, -1, SDL_RENDERER_PRESENTVSYNC);
    if (!sh.ren) sh.ren = SDL_CreateRenderer(sh.win, -1, 0);
    if (!sh.ren) {
        fprintf(stderr, "pdtview: renderer: %s\n", SDL_GetError());
        return shell_quit(&sh, 1);
    }
    SDL_ShowWindow(sh.win); /* (after the renderer, which may make the window again) */
    pdt_window_settle(sh.win, o->fullscreen, &sh.saved);
    SDL_StartTextInput();
    sh.last = SDL_GetPerformanceCounter();
    sh.dirty = 1;
    while (!sh.quit) loop(&sh);
    return shell_quit(&sh, 0);
}
