/* pdt — a lecturer's tools over the replay window (lecture.h): bookmarks,
 * the notes pane, a pointer, a pen, and a line that says what each key did.
 *
 * They are a shell hook (shell.h) like the editor: the hook sees every key
 * and mouse event first, takes its own (b, Shift+b, n, j, p, d, e; the mouse
 * while the pen is on) and lets the others through, remembering the key so
 * that the overlay can say what it did, from the state the frame shows. */
#include "lecture.h"
#include "beside.h"
#include "pdt/view/textlog.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* SDL keycodes the hook names (SDL_keycode.h values; this file has no SDL). */
enum {
    K_RIGHT = (1 << 30) | 79, K_LEFT = (1 << 30) | 80, K_PGUP = (1 << 30) | 75,
    K_PGDN = (1 << 30) | 78, K_HOME = (1 << 30) | 74, K_END = (1 << 30) | 77,
    K_F11 = (1 << 30) | 68
};

typedef struct mark {
    size_t k;
    char *title, *text;
} mark;

struct pdt_lecture {
    const pdt_replay *r;
    pdt_rstate *s;
    int moved;             /* the hook moved the cursor: the shell redraws */
    mark *m;
    size_t nm, cur;        /* bookmarks; the last one gone to (nm: none yet) */
    int pointer, pen, drawing, down;
    double mx, my;
    double *pts;           /* pen strokes: x, y pairs; NAN, NAN between strokes */
    size_t np, cap;
    int key, shift, ctrl;  /* the last key the shell handled (0: none) */
    char msg[200];         /* what the last key of the hook did */
    pdt_beside *beside;    /* a second run drawn beside the first, or NULL */
    double dx, dy;         /* beside: where the left button went down */
    int page, pages;       /* the notes pane's page (j, Shift+j) and how many the step takes */
    const void *page_of;   /* the step that page is of (another step: page 0) */
    pdt_shell_hook hook;
};

/* ---- bookmarks ------------------------------------------------------------------ */

static pdt_status add_mark(pdt_lecture *L, size_t k, const char *title, const char *text,
                           pdt_err *err)
{
    mark *v = realloc(L->m, (L->nm + 1) * sizeof *v);
    if (!v) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    L->m = v;
    v[L->nm] = (mark){k, strdup(title), strdup(text)};
    if (!v[L->nm].title || !v[L->nm].text) {
        free(v[L->nm].title);
        free(v[L->nm].text);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    L->nm++;
    return PDT_OK;
}

/* One line "K<TAB>TITLE<TAB>TEXT" of a bookmarks file. */
static pdt_status read_mark(pdt_lecture *L, char *line, const char *path, size_t lineno,
                            pdt_err *err)
{
    line[strcspn(line, "\r\n")] = 0;
    if (!*line || *line == '#') return PDT_OK;
    char *t1 = strchr(line, '\t'), *t2 = t1 ? strchr(t1 + 1, '\t') : NULL, *end;
    unsigned long long k = strtoull(line, &end, 10);
    if (!t1 || end != t1 || k > pdt_replay_count(L->r))
        return pdt_err_set(err, PDT_ERR_PARSE,
                           "%s:%zu: not \"K<tab>title<tab>text\" with K from 0 to %zu", path,
                           lineno, pdt_replay_count(L->r));
    *t1 = 0;
    if (t2) *t2 = 0;
    return add_mark(L, (size_t)k, t1 + 1, t2 ? t2 + 1 : "", err);
}

pdt_status pdt_lecture_new(const pdt_replay *r, pdt_rstate *s, const char *bookmarks,
                           pdt_lecture **out, pdt_err *err)
{
    *out = NULL;
    pdt_lecture *L = calloc(1, sizeof *L);
    if (!L) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    L->r = r;
    L->s = s;
    FILE *f = bookmarks ? fopen(bookmarks, "r") : NULL;
    if (bookmarks && !f) {
        pdt_lecture_free(L);
        return pdt_err_set(err, PDT_ERR_IO, "%s: cannot open the bookmarks", bookmarks);
    }
    char line[8192];
    pdt_status st = PDT_OK;
    for (size_t no = 1; st == PDT_OK && f && fgets(line, sizeof line, f); no++)
        st = read_mark(L, line, bookmarks, no, err);
    if (f) fclose(f);
    if (st != PDT_OK) {
        pdt_lecture_free(L);
        return st;
    }
    L->cur = L->nm;
    *out = L;
    return PDT_OK;
}

void pdt_lecture_free(pdt_lecture *L)
{
    if (!L) return;
    for (size_t i = 0; i < L->nm; i++) {
        free(L->m[i].title);
        free(L->m[i].text);
    }
    free(L->m);
    free(L->pts);
    pdt_beside_free(L->beside);
    free(L);
}

/* b / Shift+b: the next / previous bookmark in the lesson's order. */
static void go_mark(pdt_lecture *L, int dir)
{
    if (!L->nm) {
        snprintf(L->msg, sizeof L->msg, "b: no bookmarks (pdtview --bookmarks FILE; make lesson writes them)");
        return;
    }
    if (L->cur == L->nm) L->cur = dir > 0 ? 0 : L->nm - 1;
    else L->cur = (L->cur + L->nm + (size_t)(dir > 0 ? 1 : -1)) % L->nm;
    const mark *m = &L->m[L->cur];
    pdt_replay_seek(L->r, L->s, m->k);
    L->moved = 1;
    snprintf(L->msg, sizeof L->msg, "%s: bookmark %zu of %zu, %s (event %zu)", dir > 0 ? "b" : "Shift+b",
             L->cur + 1, L->nm, m->title, m->k);
}

/* The bookmark whose text the notes pane shows: the last one gone to while
 * the cursor stays there, else the last (in the list) at or before it. */
static const mark *note_now(const pdt_lecture *L)
{
    if (L->cur < L->nm && L->m[L->cur].k == L->s->k) return &L->m[L->cur];
    const mark *best = NULL;
    for (size_t i = 0; i < L->nm; i++)
        if (L->m[i].k <= L->s->k && (!best || L->m[i].k >= best->k)) best = &L->m[i];
    return best;
}

/* ---- the pen -------------------------------------------------------------------- */

static void pen_add(pdt_lecture *L, double x, double y)
{
    if (L->np + 2 > L->cap) {
        size_t cap = L->cap ? 2 * L->cap : 256;
        double *p = realloc(L->pts, cap * sizeof *p);
        if (!p) return; /* out of memory: the stroke stops growing */
        L->pts = p;
        L->cap = cap;
    }
    L->pts[L->np++] = x;
    L->pts[L->np++] = y;
}

static int pen_mouse(pdt_lecture *L, const pdt_shell_input *in)
{
    if (in->type == PDT_IN_DOWN && in->button == 1) {
        L->drawing = 1;
        pen_add(L, NAN, NAN);
        pen_add(L, in->x, in->y);
        return 1;
    }
    if (in->type == PDT_IN_MOVE && L->drawing) {
        pen_add(L, in->x, in->y);
        return 1;
    }
    if (in->type == PDT_IN_UP && in->button == 1 && L->drawing) {
        L->drawing = 0;
        return 1;
    }
    return 0;
}

/* ---- input ---------------------------------------------------------------------- */

/* The hook's own keys: 1 if it took the key. */
static int own_key(pdt_lecture *L, const pdt_shell_input *in, pdt_view *v)
{
    if (in->ctrl) return 0;
    switch (in->key) {
    case 'b': go_mark(L, in->shift ? -1 : 1); return 1;
    case 'n':
        v->panels ^= PDT_PANEL_NOTES;
        snprintf(L->msg, sizeof L->msg, "n: notes pane %s", v->panels & PDT_PANEL_NOTES ? "on" : "off");
        return 1;
    case 'p':
        L->pointer = !L->pointer;
        snprintf(L->msg, sizeof L->msg, "p: pointer %s", L->pointer ? "on: a ring follows the mouse" : "off");
        return 1;
    case 'd':
        L->pen = !L->pen;
        snprintf(L->msg, sizeof L->msg, "d: pen %s", L->pen ? "on: drag to draw (e erases, d again: off)" : "off: drag pans again");
        return 1;
    case 'j':
        if (L->pages > 1) L->page = (L->page + (in->shift ? L->pages - 1 : 1)) % L->pages;
        snprintf(L->msg, sizeof L->msg, "%s: notes page %d of %d", in->shift ? "Shift+j" : "j",
                 L->page + 1, L->pages > 0 ? L->pages : 1);
        return 1;
    case 'e':
        L->np = 0;
        snprintf(L->msg, sizeof L->msg, "e: drawing erased");
        return 1;
    default: return 0;
    }
}

/* Beside: a click (the left button down and up in place) goes to the half
 * it falls in (pdt_beside_click), not to the whole window's layout; a drag
 * is the shell's (it pans both). */
static int beside_mouse(pdt_lecture *L, const pdt_shell_input *in, double w, double h, pdt_view *v)
{
    if (in->button != 1) return 0;
    if (in->type == PDT_IN_DOWN) {
        L->dx = in->x;
        L->dy = in->y;
        return 0;
    }
    if (in->type != PDT_IN_UP || fabs(in->x - L->dx) + fabs(in->y - L->dy) > 4) return 0;
    size_t k;
    if (pdt_beside_click(L->beside, L->r, L->s, v, w, h, in->x, in->y, &k)) {
        pdt_replay_seek(L->r, L->s, k);
        L->moved = 1;
    }
    L->down = 0;
    return 1; /* (the shell's own click would use the whole window's layout) */
}

static int hook_input(void *user, const pdt_shell_input *in, double w, double h, pdt_view *v)
{
    pdt_lecture *L = user;
    if (in->type != PDT_IN_KEY) {
        int follow = L->pointer && (in->x != L->mx || in->y != L->my);
        L->mx = in->x;
        L->my = in->y;
        if (L->pen && pen_mouse(L, in)) return 1;
        if (L->beside && beside_mouse(L, in, w, h, v)) return 1;
        if (in->type == PDT_IN_DOWN) L->down = 1;
        if (in->type == PDT_IN_UP) L->down = 0;
        /* the pointer follows the mouse: a frame for every move (while a
         * button is held the shell's drag takes the move and redraws) */
        return follow && in->type == PDT_IN_MOVE && !L->down;
    }
    L->key = 0;
    if (own_key(L, in, v)) return 1;
    L->msg[0] = 0;
    L->key = in->key;
    L->shift = in->shift;
    L->ctrl = in->ctrl;
    return 0;
}

static int hook_current(void *user, const pdt_replay **r, pdt_rstate **s)
{
    pdt_lecture *L = user;
    *r = L->r;
    *s = L->s;
    int moved = L->moved;
    L->moved = 0;
    return moved;
}

pdt_status pdt_lecture_beside(pdt_lecture *L, const pdt_replay *r2, pdt_rstate *s2, pdt_err *err)
{
    if (!(L->beside = pdt_beside_new(r2, s2))) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    return PDT_OK;
}

const pdt_shell_hook *pdt_lecture_hook(pdt_lecture *L)
{
    L->hook.user = L;
    L->hook.input = hook_input;
    L->hook.current = hook_current;
    L->hook.overlay = pdt_lecture_overlay;
    L->hook.title = NULL;
    return &L->hook;
}

/* ---- what a key of the shell did -------------------------------------------------- */

/* The phase PgDn / PgUp arrived at (the stop at the cursor), or NULL. */
static const char *stop_name(const pdt_lecture *L, char *buf, size_t cap)
{
    pdt_phase_stop st[128];
    size_t n = pdt_replay_phase_stops(L->r, st, 128);
    for (size_t i = 0; i < n && i < 128; i++)
        if (st[i].k == L->s->k) {
            const char *nm = pdt_phase_name((int)st[i].phase);
            if (st[i].sub) snprintf(buf, cap, "%s level %u", nm ? nm : "?", st[i].sub);
            else snprintf(buf, cap, "%s", nm ? nm : "?");
            return buf;
        }
    return NULL;
}

static const char *on_off(int b) { return b ? "on" : "off"; }

/* What the last key the shell handled did, said from the state shown. */
static void key_effect(const pdt_lecture *L, const pdt_view *v, char *buf, size_t cap)
{
    size_t k = L->s->k, m = pdt_replay_count(L->r);
    char ph[64];
    static const char *const themes[] = {"light", "dark", "high contrast"};
    const char *sh = L->shift ? "Shift+" : L->ctrl ? "Ctrl+" : "";
    switch (L->key) {
    case ' ': snprintf(buf, cap, "Space: play / pause"); break;
    case K_RIGHT:
    case K_LEFT:
        snprintf(buf, cap, "%s%s: event %zu of %zu%s%s", sh, L->key == K_RIGHT ? "→" : "←", k, m,
                 L->shift ? ", the selected kind: " : "",
                 L->shift ? pdt_ev_class_name(v->ev_class) : "");
        break;
    case K_PGDN:
    case K_PGUP:
        if (stop_name(L, ph, sizeof ph))
            snprintf(buf, cap, "%s: phase %s — every rank has begun it (event %zu)",
                     L->key == K_PGDN ? "PgDn" : "PgUp", ph, k);
        else snprintf(buf, cap, "%s: event %zu (no more phases)", L->key == K_PGDN ? "PgDn" : "PgUp", k);
        break;
    case K_HOME: snprintf(buf, cap, "Home: the start, before any event"); break;
    case K_END: snprintf(buf, cap, "End: every event applied (%zu)", m); break;
    case K_F11: snprintf(buf, cap, "F11: full screen on / off"); break;
    case 'k': snprintf(buf, cap, "k: Shift+→ jumps to the next %s", pdt_ev_class_name(v->ev_class)); break;
    case 'f': snprintf(buf, cap, "f: the points fit the window"); break;
    case 't': snprintf(buf, cap, "t: theme %s", themes[v->theme % 3]); break;
    case 'c': snprintf(buf, cap, "c: clean picture %s", on_off(v->clean)); break;
    case 'o': snprintf(buf, cap, "o: every circumcircle %s", on_off(v->circles)); break;
    case 'v': snprintf(buf, cap, "v: Voronoi diagram %s", on_off(v->voronoi)); break;
    case '\t': snprintf(buf, cap, "Tab: %s", v->overflow ? "the panels with no room, over the picture" : "the picture again"); break;
    case 'h': snprintf(buf, cap, "h: help %s", on_off(v->help)); break;
    case 's': snprintf(buf, cap, "s: screenshot written (the terminal names the file)"); break;
    case 'm': snprintf(buf, cap, "m: mark set at event %zu (r records from here)", k); break;
    case 'r': snprintf(buf, cap, "r: recording written (the terminal names the file)"); break;
    case '0': snprintf(buf, cap, "0: every rank shown"); break;
    case 'w': snprintf(buf, cap, "w: follow the current event %s", on_off(v->follow)); break;
    case 'u': snprintf(buf, cap, "u: the current event's group opened / closed in the timeline"); break;
    case '[': case ']':
        snprintf(buf, cap, "%s%c: timeline %s (events %.0f %% … %.0f %%)", sh, L->key,
                 L->shift ? "panned" : L->key == ']' ? "zoomed in" : "zoomed out", 100 * v->tl_t0,
                 100 * v->tl_t1);
        break;
    case '+': case '=': case '-':
        if (L->ctrl) snprintf(buf, cap, "Ctrl+%c: text size ×%.2f", L->key, v->font_scale);
        else snprintf(buf, cap, "%c: playback speed changed", L->key);
        break;
    default:
        if (L->key >= '1' && L->key <= '9' && v->hidden && L->key - '1' < pdt_replay_nranks(L->r))
            snprintf(buf, cap, "%c: rank %d %s", L->key, L->key - '1',
                     v->hidden[L->key - '1'] ? "hidden" : "shown");
        else buf[0] = 0;
    }
}

/* ---- the overlay ------------------------------------------------------------------ */

/* Text at (x, y) (baseline), DejaVu Sans of size fs; its width. */
static double say(cairo_t *cr, double x, double y, double fs, int bold, const char *t)
{
    cairo_text_extents_t te;
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, fs);
    cairo_text_extents(cr, t, &te);
    if (y >= 0) {
        pdt_text_log_note(cr, fs, x, y, t); /* the layout report has it too */
        cairo_move_to(cr, x, y);
        cairo_show_text(cr, t);
    }
    return te.x_advance;
}

/* The text wrapped into width wd from (x, y), lines lh apart: its lines
 * from `skip` on drawn, no lower than ymax (draw = 0: only measure); the
 * number of lines in *nlines (NULL: not wanted). */
static void wrap(cairo_t *cr, const char *text, double x, double y, double wd, double fs,
                 double ymax, int draw, int skip, int *nlines)
{
    char line[1300] = "", word[256];
    double lh = 1.3 * fs;
    int no = 0;
    const char *p = text;
    while (*p) {
        size_t n = strcspn(p, " ");
        if (n >= sizeof word) n = sizeof word - 1;
        size_t j = 0;
        for (size_t i = 0; i < n; i++)
            if (p[i] != '`' && p[i] != '\\') word[j++] = p[i];
        word[j] = 0;
        p += strcspn(p, " ");
        p += strspn(p, " ");
        char next[1600];
        snprintf(next, sizeof next, "%s%s%s", line, *line ? " " : "", word);
        if (*line && say(cr, 0, -1, fs, 0, next) > wd) {
            if (no++ >= skip) {
                if (draw && y <= ymax) say(cr, x, y, fs, 0, line);
                y += lh;
            }
            snprintf(line, sizeof line, "%s", word);
        } else {
            size_t n2 = strlen(next) < sizeof line ? strlen(next) : sizeof line - 1;
            memcpy(line, next, n2); /* (a line wider than the pane is cut: 1300 bytes) */
            line[n2] = 0;
        }
    }
    if (*line && no++ >= skip && draw && y <= ymax) say(cr, x, y, fs, 0, line);
    if (nlines) *nlines = no;
}

static void box(cairo_t *cr, double x, double y, double w, double h, int dark)
{
    cairo_rectangle(cr, x, y, w, h);
    if (dark) cairo_set_source_rgba(cr, 0.12, 0.12, 0.14, 0.93);
    else cairo_set_source_rgba(cr, 1, 1, 0.97, 0.94);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0.55, 0.55, 0.6);
    cairo_set_line_width(cr, 1);
    cairo_stroke(cr);
}

/* The bookmarks in a row, the current one bold; the y of the next row.
 * When they would take more than two rows: only the current one. */
static double mark_row(cairo_t *cr, const pdt_lecture *L, const mark *now, double x, double y,
                       double wd, double fs)
{
    double y1 = y, cx = x + say(cr, x, -1, fs, 1, "Bookmarks (b, Shift+b):  ");
    for (size_t i = 0; i < L->nm; i++) { /* measure */
        char t[96];
        snprintf(t, sizeof t, "%s%s", L->m[i].title, i + 1 < L->nm ? " · " : "");
        double tw = say(cr, 0, -1, fs, &L->m[i] == now, t);
        if (cx + tw > x + wd) y1 += 1.3 * fs, cx = x;
        cx += tw;
    }
    if (y1 - y > 1.5 * fs) { /* three rows or more */
        char t[160];
        snprintf(t, sizeof t, "bookmark %zu of %zu (b)", now ? (size_t)(now - L->m) + 1 : 0, L->nm);
        if (y >= 0) say(cr, x, y, fs, 1, t);
        return y + 1.5 * fs;
    }
    cx = x + say(cr, x, y, fs, 1, "Bookmarks (b, Shift+b):  ");
    for (size_t i = 0; i < L->nm; i++) {
        char t[96];
        snprintf(t, sizeof t, "%s%s", L->m[i].title, i + 1 < L->nm ? " · " : "");
        double tw = say(cr, 0, -1, fs, &L->m[i] == now, t);
        if (cx + tw > x + wd) {
            y += 1.3 * fs;
            cx = x;
        }
        cx += say(cr, cx, y, fs, &L->m[i] == now, t);
    }
    return y + 1.5 * fs;
}

/* The notes pane: the bookmarks, then the text of the step shown, in at
 * most 40 % of the picture's height: a longer text goes in pages (j,
 * Shift+j), its last line saying so. */
static void draw_notes(cairo_t *cr, pdt_lecture *L, pdt_rect G, double fs, int dark)
{
    const mark *now = note_now(L);
    double pad = 0.6 * fs, wd = G.w - 2 * pad, hmax = 0.4 * G.h, lh = 1.3 * fs;
    const char *text = now && *now->text ? now->text
                                         : "(no step of the lesson before this moment)";
    if (L->page_of != now) L->page = 0, L->page_of = now;
    int total;
    wrap(cr, text, 0, 0, wd, fs, 1e9, 0, 0, &total);
    double head = mark_row(cr, L, now, 0, -1e9, wd, fs) + 1e9 + (now ? lh : 0);
    double need = head + total * lh + 2 * pad;
    hmax = fmin(G.h, fmax(hmax, head + 4 * lh + 2 * pad)); /* four text lines at least */
    double h = fmin(need, hmax), y0 = G.y + G.h - h;
    int fit = (int)floor((h - pad - 1.3 * fs - head) / lh) + 1; /* text lines that fit */
    if (fit < 2) fit = 2;
    int per = total > fit ? fit - 1 : fit; /* one line says "more…" */
    L->pages = (total + per - 1) / per;
    if (L->page >= L->pages) L->page = 0;
    box(cr, G.x, y0, G.w, h, dark);
    cairo_save(cr);
    cairo_rectangle(cr, G.x, y0, G.w, h);
    cairo_clip(cr);
    if (dark) cairo_set_source_rgb(cr, 0.95, 0.95, 0.95);
    else cairo_set_source_rgb(cr, 0.1, 0.1, 0.12);
    double y = mark_row(cr, L, now, G.x + pad, y0 + pad + fs, wd, fs);
    if (now) say(cr, G.x + pad, y, fs, 1, now->title), y += lh;
    double ytext = y;
    wrap(cr, text, G.x + pad, y, wd, fs, ytext + (per - 1) * lh + 1, 1, L->page * per, NULL);
    if (L->pages > 1) {
        char more[96];
        snprintf(more, sizeof more, L->page + 1 < L->pages ? "more… j (page %d of %d)"
                                                          : "j: first page (%d of %d)",
                 L->page + 1, L->pages);
        say(cr, G.x + pad, ytext + per * lh, fs, 1, more);
    }
    cairo_restore(cr);
}

/* The pen's strokes and the pointer's ring. */
static void draw_marks(cairo_t *cr, const pdt_lecture *L, double fs)
{
    cairo_set_source_rgba(cr, 0.85, 0.1, 0.1, 0.9);
    cairo_set_line_width(cr, fmax(3, 0.22 * fs));
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    for (size_t i = 0; i + 1 < L->np; i += 2) {
        double x = L->pts[i], y = L->pts[i + 1];
        if (isnan(x)) continue;
        if (i >= 2 && !isnan(L->pts[i - 2])) cairo_line_to(cr, x, y);
        else cairo_move_to(cr, x, y), cairo_line_to(cr, x, y);
    }
    cairo_stroke(cr);
    if (!L->pointer) return;
    cairo_arc(cr, L->mx, L->my, 1.3 * fs, 0, 2 * M_PI);
    cairo_set_source_rgba(cr, 1, 0.2, 0.1, 0.18);
    cairo_fill_preserve(cr);
    cairo_set_source_rgba(cr, 0.9, 0.1, 0.05, 0.95);
    cairo_set_line_width(cr, fmax(3, 0.2 * fs));
    cairo_stroke(cr);
}

void pdt_lecture_overlay(void *user, cairo_t *cr, double w, double h, const pdt_view *v)
{
    pdt_lecture *L = user;
    pdt_layout Ly;
    pdt_render_layout_view(w, h, pdt_replay_nranks(L->r), v, &Ly);
    double fs = fmax(16, Ly.body);
    int dark = v->theme != PDT_THEME_LIGHT;
    if (L->beside) pdt_beside_draw(L->beside, cr, w, h, L->r, L->s, v);
    cairo_save(cr);
    pdt_rect G = Ly.geo; /* a narrow picture: the notes over the column too */
    if (G.w < 0.6 * w) G.w = w - G.x;
    pdt_text_log_panel(cr, "notes");
    if (v->panels & PDT_PANEL_NOTES) draw_notes(cr, L, G, fs, dark);
    else L->pages = 0;
    pdt_text_log_panel(cr, "keys");
    char eff[240];
    if (L->msg[0]) snprintf(eff, sizeof eff, "%s", L->msg);
    else key_effect(L, v, eff, sizeof eff);
    if (eff[0] && !Ly.covered) { /* (covered: the `more` line says what Tab did) */
        double pad = 0.4 * fs, tw = say(cr, 0, -1, fs, 0, eff), room = Ly.geo.w - 2 * pad;
        double es = tw > room ? fmax(16, fs * room / tw) : fs; /* smaller, not under 16 px */
        tw = fmin(say(cr, 0, -1, es, 0, eff), room);
        box(cr, Ly.geo.x, Ly.geo.y, tw + 2 * pad, 1.5 * fs, dark);
        cairo_save(cr);
        cairo_rectangle(cr, Ly.geo.x, Ly.geo.y, tw + 2 * pad, 1.5 * fs);
        cairo_clip(cr);
        if (dark) cairo_set_source_rgb(cr, 0.95, 0.95, 0.95);
        else cairo_set_source_rgb(cr, 0.1, 0.1, 0.12);
        say(cr, Ly.geo.x + pad, Ly.geo.y + 0.75 * fs + 0.36 * es, es, 0, eff);
        cairo_restore(cr);
    }
    draw_marks(cr, L, fs);
    pdt_text_log_panel(cr, NULL);
    cairo_restore(cr);
}
