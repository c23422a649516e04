/* pdt — the viewer's text panels: the event line at the top, the
 * pseudo-code with the current line, the stacks being built, the help
 * overlay. */
#include "pdt/view/describe.h"
#include "render_int.h"

static void draw_prompt(ctx *c);


/* How many bytes of s, cut after a whole word, fit in `room` pixels at
 * size fs (bold); all of s when it fits, at least its first word. */
static size_t fit_words(cairo_t *cr, const char *s, double fs, double room)
{
    char buf[512];
    size_t n = strlen(s), best = 0;
    if (n >= sizeof buf) n = sizeof buf - 1;
    memcpy(buf, s, n);
    buf[n] = 0;
    if (text_wb(cr, SANS, 1, fs, buf) <= room) return n;
    for (size_t i = 1; i < n; i++) {
        if (s[i] != ' ') continue;
        buf[i] = 0;
        if (text_wb(cr, SANS, 1, fs, buf) > room) break;
        buf[i] = ' ';
        best = i;
    }
    if (!best) best = strcspn(s, " ");
    return best;
}

/* The top bar's text, planned before it is drawn (the picture's labels
 * keep off the rows that spill under the bar): the counter, the status and
 * the event line's rows, the first two in the bar. */
enum { TOP_ROWS = 8 };
typedef struct top_plan {
    char head[64], status[512], row[TOP_ROWS][512];
    int nrows;
    double x, sx, y[TOP_ROWS], xr[TOP_ROWS]; /* xr: where each row starts */
} top_plan;

/* The status, ended by "…" when wider than the bar (a very narrow window). */
static void plan_status(ctx *c, top_plan *P)
{
    double f = c->L.font;
    snprintf(P->status, sizeof P->status, "%s", c->v->status ? c->v->status : "");
    for (size_t n = strlen(P->status); n > 1 && text_w(c->cr, SANS, c->L.label, P->status) > c->L.top.w - f;) {
        do n--; while (n > 1 && ((unsigned char)P->status[n] & 0xC0) == 0x80);
        snprintf(P->status + n, sizeof P->status - n, "…");
    }
    P->sx = c->L.top.w - 0.5 * f - (c->v->status ? text_w(c->cr, SANS, c->L.label, P->status) : 0);
}

/* Takes the row of `rest` that fits in room into P (at y); returns the rest. */
static const char *plan_row(ctx *c, top_plan *P, const char *rest, double room, double y)
{
    size_t n = fit_words(c->cr, rest, c->L.font, room);
    snprintf(P->row[P->nrows], sizeof P->row[0], "%.*s", (int)n, rest);
    P->xr[P->nrows] = P->x;
    P->y[P->nrows++] = y;
    return rest + n + (rest[n] == ' ');
}

static void plan_top(ctx *c, top_plan *P)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.top;
    double f = c->L.font, fs = f;
    char line[512];
    pdt_replay_describe_state(c->r, c->s, c->s->k, line, sizeof line);
    snprintf(P->head, sizeof P->head, "%zu / %zu", c->s->k, pdt_replay_count(c->r));
    P->x = 0.5 * f + text_w(cr, MONO, c->L.body, P->head) + 0.9 * f + (c->cur ? 1.1 * f : 0);
    plan_status(c, P);
    P->nrows = 0;
    const char *rest = plan_row(c, P, line, R.w - P->x - 0.5 * f, R.y + 1.35 * f);
    double room2 = P->sx - 1.0 * f - P->x;
    char word[512];
    snprintf(word, sizeof word, "%.*s", (int)strcspn(rest, " "), rest);
    if (*rest && text_wb(cr, SANS, 1, fs, word) <= room2) /* beside the status */
        rest = plan_row(c, P, rest, room2, R.y + 2.75 * f);
    if (*rest && c->L.covered && P->nrows > 0) { /* panels under the bar: the rest gives way */
        char *t = P->row[P->nrows - 1];
        double room_last = P->nrows > 1 ? room2 : R.w - P->x - 0.5 * f;
        size_t n = strlen(t);
        snprintf(t + n, sizeof P->row[0] - n, " …");
        while (n > 0 && text_wb(cr, SANS, 1, fs, t) > room_last) {
            while (n > 0 && t[n - 1] != ' ') n--; /* a word less */
            while (n > 0 && t[n - 1] == ' ') n--;
            snprintf(t + n, sizeof P->row[0] - n, " …");
        }
        return;
    }
    /* under the bar, over the picture: from under the event line, or from
     * the picture's left edge when the picture is narrow */
    double x0 = P->x, room = c->L.geo.x + c->L.geo.w - P->x - 0.5 * f;
    if (room < 8 * f) x0 = c->L.geo.x + 0.5 * f, room = c->L.geo.w - f;
    for (double y = R.y + R.h + 1.05 * fs; *rest && P->nrows < TOP_ROWS; y += 1.4 * fs) {
        rest = plan_row(c, P, rest, room, y);
        P->xr[P->nrows - 1] = x0;
    }
}

void pdt_top_spill(ctx *c)
{
    top_plan *P = malloc(sizeof *P);
    if (!P) return;
    plan_top(c, P);
    double f = c->L.font, bottom = c->L.top.y + c->L.top.h, w = 0, x0 = P->x;
    for (int i = 0; i < P->nrows; i++)
        if (P->y[i] > bottom) {
            w = fmax(w, text_wb(c->cr, SANS, 1, f, P->row[i]));
            bottom = P->y[i] + 0.35 * f;
            x0 = P->xr[i];
        }
    if (w > 0 && c->ntaken < TAKEN_MAX)
        c->taken[c->ntaken++] = (lbox){x0 - 0.3 * f, c->L.top.y + c->L.top.h, x0 + w + 0.3 * f, bottom};
    free(P);
}

/* The top bar: the counter and the event line, then on its second row the
 * status at the right and what of the event line did not fit at the left.
 * Text keeps its size; the very rare rest goes in boxes under the bar. */
void pdt_draw_top(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.top;
    double f = c->L.font;
    top_plan *P = malloc(sizeof *P);
    if (!P) return;
    plan_top(c, P);
    cairo_rectangle(cr, R.x, R.y, R.w, R.h);
    rgb(cr, c->T->topbar, 1);
    cairo_fill(cr);
    rgb(cr, c->T->ink, 0.7);
    text_at(cr, MONO, 0, c->L.body, 0.5 * f, R.y + 1.35 * f, P->head);
    if (c->cur) {
        set_rank(c, (int)c->cur->rank, 1);
        cairo_rectangle(cr, P->x - 1.1 * f, R.y + 0.5 * f, 0.7 * f, 1.1 * f);
        cairo_fill(cr);
    }
    if (c->v->status) {
        rgb(cr, c->T->ink, 0.8);
        pdt_text_log_panel(cr, "status");
        text_at(cr, SANS, 0, c->L.label, P->sx, R.y + 2.75 * f, P->status);
        pdt_text_log_panel(cr, "event");
    }
    for (int i = 0; i < P->nrows; i++) {
        if (P->y[i] > R.y + R.h) {
            cairo_rectangle(cr, P->xr[i] - 0.3 * f, P->y[i] - 1.05 * f,
                            text_wb(cr, SANS, 1, f, P->row[i]) + 0.6 * f, 1.4 * f);
            rgb(cr, c->T->topbar, 0.92);
            cairo_fill(cr);
        }
        rgb(cr, c->T->ink, 1);
        text_at(cr, SANS, 1, f, P->xr[i], P->y[i], P->row[i]);
    }
    free(P);
    if (c->v->prompt) draw_prompt(c);
}

/* The line being typed (go to event N), in a box under the event line. */
static void draw_prompt(ctx *c)
{
    cairo_t *cr = c->cr;
    double f = c->L.font, fs = 1.2 * f;
    double tw = text_wb(cr, SANS, 1, fs, c->v->prompt);
    pdt_rect B = {c->L.geo.x + 0.6 * f, c->L.geo.y + 0.6 * f, tw + 1.4 * f, 1.9 * fs};
    cairo_rectangle(cr, B.x, B.y, B.w, B.h);
    rgb(cr, c->T->panel, 0.97);
    cairo_fill_preserve(cr);
    rgb(cr, c->T->select, 1);
    cairo_set_line_width(cr, 3);
    cairo_stroke(cr);
    rgb(cr, c->T->ink, 1);
    text_at(cr, SANS, 1, fs, B.x + 0.7 * f, B.y + 1.3 * fs, c->v->prompt);
}

/* The pseudo-code as rows: each line wrapped at its words to `room`
 * pixels, its rest indented under the text; row r belongs to line of[r]. */
enum { CODE_ROWS = 96, CODE_COLS = 160 };

typedef struct code_rows {
    char t[CODE_ROWS][CODE_COLS];
    int of[CODE_ROWS];
    int n;
} code_rows;

/* The bytes of s (after the indent pre) that fit in room: up to the last
 * word end that fits; all of s when it fits or one word is too wide. */
static size_t code_cut(cairo_t *cr, const char *s, const char *pre, double fs, double room)
{
    char row[CODE_COLS];
    size_t len = strlen(s), best = 0;
    snprintf(row, sizeof row, "%s%s", pre, s);
    if (text_w(cr, MONO, fs, row) <= room) return len;
    for (size_t i = 1; i < len; i++) {
        if (s[i] != ' ' || s[i - 1] == ' ') continue;
        snprintf(row, sizeof row, "%s%.*s", pre, (int)i, s);
        if (text_w(cr, MONO, fs, row) > room) break;
        best = i;
    }
    return best ? best : len;
}

static void wrap_code(cairo_t *cr, int id, double fs, double room, code_rows *W)
{
    W->n = 0;
    int nl = (int)pdt_code_count(id);
    for (int i = 0; i < nl && W->n < CODE_ROWS; i++) {
        const char *s = pdt_code_text(id, (size_t)i);
        /* a wrapped line's rest goes under its text, two columns in */
        size_t num = strcspn(s, " "), ind = num + strspn(s + num, " ") + 2;
        char pre[24] = "", hang[24];
        snprintf(hang, sizeof hang, "%*s", (int)(ind < sizeof hang ? ind : sizeof hang - 1), "");
        for (; *s && W->n < CODE_ROWS; snprintf(pre, sizeof pre, "%s", hang)) {
            size_t cut = code_cut(cr, s, pre, fs, room);
            snprintf(W->t[W->n], CODE_COLS, "%s%.*s", pre, (int)cut, s);
            W->of[W->n++] = i;
            s += cut;
            while (*s == ' ') s++;
        }
    }
}

void pdt_draw_code(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.code;
    double f = c->L.font, fs = c->L.body, lh = pdt_layout_code_row(&c->L);
    int id;
    int line = pdt_replay_code_line(c->r, c->s, &id);
    panel(cr, c->T, R, NULL, f);
    cairo_save(cr);
    clip_rect(cr, R);
    code_rows *W = malloc(sizeof *W);
    if (!W) {
        cairo_restore(cr);
        return;
    }
    wrap_code(cr, id, fs, R.w - 1.2 * f, W);
    /* the rows that fit, scrolled so that the lit line is in view */
    int fit = (int)((R.h - 1.8 * f - 0.2 * f) / lh), first = 0, lit = -1;
    for (int r = 0; r < W->n && lit < 0; r++)
        if (W->of[r] == line) lit = r;
    if (fit < 1) fit = 1;
    if (W->n > fit && lit >= 0) first = lit - fit / 3;
    while (first > 0 && first < lit && W->of[first] == W->of[first - 1]) first++; /* a line's start */
    if (first > W->n - fit) first = W->n - fit;
    if (first < 0) first = 0;
    for (int r = first; r < W->n && r < first + fit; r++) {
        double top = R.y + 1.8 * f + (r - first) * lh;
        if (W->of[r] == line) {
            cairo_rectangle(cr, R.x + 0.3 * f, top, R.w - 0.6 * f, lh);
            rgb(cr, c->T->mark, 0.8);
            cairo_fill(cr);
        }
        rgb(cr, c->T->ink, 1);
        text_at(cr, MONO, W->of[r] == line, fs, R.x + 0.6 * f, top + 1.02 * fs, W->t[r]);
    }
    double aw = 0;
    if (first > 0 || first + fit < W->n) { /* more above / below: arrows by the title */
        rgb(cr, c->T->ink, 0.6);
        const char *mark = first > 0 && first + fit < W->n ? "▲▼" : first > 0 ? "▲" : "▼";
        aw = text_wb(cr, SANS, 1, fs, mark) + 0.5 * f;
        text_at(cr, SANS, 1, fs, R.x + R.w - aw - 0.1 * f, R.y + 1.25 * f, mark);
    }
    panel_title(cr, c->T, R, pdt_code_title(id), f, fs, R.w - 1.2 * f - aw);
    free(W);
    cairo_restore(cr);
}

/* A stack element as text: p<angular number> on Graham's stack, else the index. */
static void stack_item(const ctx *c, int st, uint32_t p, int space, char *b, size_t cap)
{
    int64_t pos = st == PDT_STACK_GRAHAM ? pdt_replay_sort_pos(c->r, p) : -1;
    if (pos >= 0) snprintf(b, cap, space ? "p%lld " : "p%lld", (long long)pos);
    else snprintf(b, cap, space ? "%u " : "%u", p);
}

/* The first of the top elements of buf[0, k) that fit in `room` (k: none). */
static size_t stack_fit(const ctx *c, int st, const uint32_t *buf, size_t k, double room)
{
    size_t first = k;
    double wsum = 0;
    char num[24];
    while (first > 0) {
        stack_item(c, st, buf[first - 1], 1, num, sizeof num);
        double tw = text_w(c->cr, MONO, c->L.body, num);
        if (wsum + tw > room) break;
        wsum += tw;
        first--;
    }
    return first;
}

/* A stack's name on its line, "r3 merge-lower (11):", without the count or
 * then the kind of stack when that is too wide for `room`. */
static void stack_head(ctx *c, int q, int st, size_t k, double room, char *b, size_t cap)
{
    snprintf(b, cap, "r%d %s (%zu):", q, pdt_stack_name(st), k);
    if (text_wb(c->cr, SANS, 1, c->L.body, b) <= room) return;
    snprintf(b, cap, "r%d %s:", q, pdt_stack_name(st));
    if (text_wb(c->cr, SANS, 1, c->L.body, b) <= room) return;
    snprintf(b, cap, "r%d:", q);
}

/* The elements of one stack, buf[0, k), from x0 on the line at y up to the
 * right edge xr: as many from the top as fit, with "… " ahead of them when
 * some do not, and the "▸" at the top. 0 when not even the top one fits. */
static int stack_elements(ctx *c, int st, const uint32_t *buf, size_t k, double x0, double y,
                          double xr)
{
    cairo_t *cr = c->cr;
    double f = c->L.font, fs = c->L.body;
    double room = xr - x0 - 0.2 * f - text_wb(cr, SANS, 1, fs, "▸");
    size_t first = stack_fit(c, st, buf, k, room);
    if (first > 0) first = stack_fit(c, st, buf, k, room - text_w(cr, MONO, fs, "… "));
    if (first >= k) return 0;
    char num[24];
    double x = x0;
    rgb(cr, c->T->ink, 1);
    if (first > 0) {
        text_at(cr, MONO, 0, fs, x, y, "…");
        x += text_w(cr, MONO, fs, "… ");
    }
    for (size_t i = first; i < k; i++) {
        stack_item(c, st, buf[i], i + 1 < k, num, sizeof num);
        text_at(cr, MONO, i + 1 == k, fs, x, y, num);
        x += text_w(cr, MONO, fs, num);
    }
    text_at(cr, SANS, 1, fs, x + 0.2 * f, y, "▸");
    return 1;
}

/* The i-th of 0, 1, 2 ... with `first` moved to the front (first < 0: i). */
static int front(int i, int first)
{
    return first < 0 ? i : i == 0 ? first : i <= first ? i - 1 : i;
}

/* The stack a push or pop event works on, else -1. */
static int event_stack(const ctx *c)
{
    const pdt_event *e = &c->cur->ev;
    return (e->kind == PDT_EV_PUSH || e->kind == PDT_EV_POP) && e->sub < 5 ? e->sub : -1;
}

/* Whose stacks the panel lists first: the rank of the current event (the
 * stack it pushes on or pops from ahead of its others) when the open stacks
 * might not all get a line each (two with their elements below the name),
 * else -1 (rank order). */
static int stack_first_rank(const ctx *c, int lines)
{
    if (!c->cur || c->cur->rank >= (uint32_t)c->nranks || !shown(c, c->cur->rank)) return -1;
    int open = 0;
    for (int q = 0; q < c->nranks && 2 * open <= lines; q++) {
        if (!shown(c, (uint32_t)q)) continue;
        for (int st = 0; st < 5; st++) {
            int32_t top = pdt_rstate_slot(c->r, c->s, q, PDT_SLOT_STACK0 + st);
            open += top >= 0 && pdt_replay_stack_open(c->r, c->s, top);
        }
    }
    return 2 * open > lines ? (int)c->cur->rank : -1;
}

void pdt_draw_stack_panel(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.stack;
    double f = c->L.font;
    panel(cr, c->T, R, "Stacks being built (top at the right ▸)", f);
    cairo_save(cr);
    clip_rect(cr, R);
    double fs = c->L.body, lh = 1.2 * fs, y = R.y + 1.6 * f + lh;
    double xr = R.x + R.w - 0.5 * f, ybot = R.y + R.h - 0.3 * f;
    uint32_t *buf = malloc((c->n + 1) * sizeof *buf);
    int any = 0;
    int first = stack_first_rank(c, (int)((ybot - y) / lh) + 1);
    for (int i = 0; i < c->nranks && buf; i++) {
        int q = front(i, first);
        if (!shown(c, (uint32_t)q)) continue;
        int fst = q == first ? event_stack(c) : -1;
        for (int j = 0; j < 5; j++) {
            int st = front(j, fst);
            if (y > ybot) break;
            int32_t top = pdt_rstate_slot(c->r, c->s, q, PDT_SLOT_STACK0 + st);
            if (top < 0 || !pdt_replay_stack_open(c->r, c->s, top)) continue;
            size_t k = pdt_replay_stack_list(c->r, top, buf, c->n + 1);
            char head[48];
            stack_head(c, q, st, k, xr - R.x - 0.5 * f, head, sizeof head);
            set_rank(c, q, 1);
            text_at(cr, SANS, 1, fs, R.x + 0.5 * f, y, head);
            double x0 = R.x + 0.5 * f + text_wb(cr, SANS, 1, fs, head) + 0.4 * f;
            /* no room after the name (large fonts): the elements on a line
             * of their own, indented, when there is one */
            if (k && !stack_elements(c, st, buf, k, x0, y, xr) && y + lh <= ybot &&
                stack_elements(c, st, buf, k, R.x + 1.5 * f, y + lh, xr))
                y += lh;
            y += lh;
            any = 1;
        }
    }
    if (!any) {
        rgb(cr, c->T->ink, 0.5);
        text_at(cr, SANS, 0, fs, R.x + 0.5 * f, y, "(no stack in use)");
    }
    free(buf);
    cairo_restore(cr);
}

/* Is base row `key` one the layer of v->help_more takes over? */
static int help_taken(const pdt_view *v, const char *key)
{
    static const char *const taken[] = {"1 … 9", "0", "click", "drag", "g N Enter", "b  n  j  p  d  e"};
    if (!v->help_more) return 0;
    for (size_t i = 0; i < sizeof taken / sizeof *taken; i++)
        if (!strcmp(key, taken[i])) return 1;
    return 0;
}

/* One column of key rows at (x, y0): title, then {keys, text} rows; kw is
 * the keys' width. */
static void help_column(cairo_t *cr, double f, double x, double y0, double kw, const char *title,
                        const char *sub, const char *const (*rows)[2], int n, const pdt_view *v)
{
    text_at(cr, SANS, 1, 1.2 * f, x, y0 + 1.7 * f, title);
    if (sub) text_at(cr, SANS, 0, 0.85 * f, x + text_wb(cr, SANS, 1, 1.2 * f, title) + f, y0 + 1.7 * f, sub);
    int i = 0;
    for (int r = 0; r < n; r++) {
        if (help_taken(v, rows[r][0]) && rows != v->help_more) continue;
        double y = y0 + (i + 2.4) * 1.45 * f + 0.4 * f;
        text_at(cr, MONO, 1, 0.9 * f, x, y, rows[r][0]);
        text_at(cr, SANS, 0, 0.9 * f, x + kw + 1.5 * f, y, rows[r][1]);
        i++;
    }
}

void pdt_draw_help(ctx *c, double w, double h)
{
    static const char *const keys[][2] = {
        {"Space", "play / pause"},
        {"→  ←", "one event forwards / backwards"},
        {"Shift + → ←", "next / previous event of the selected kind"},
        {"k", "select the kind: push/pop, lift-up, rejection, merge, triangle"},
        {"PgDn  PgUp", "next / previous phase"},
        {"Home  End", "first / last event"},
        {"g N Enter", "go to event N (cursor N)"},
        {"Ctrl + → ←", "next / previous event of the current event's rank"},
        {"timeline click", "seek to the clicked rank's nearest event"},
        {"+  −", "faster / slower playback"},
        {"1 … 9", "show / hide rank 0 … 8 (many ranks: group 1 … 9)"},
        {"[  ]  u  w", "timeline zoom; open a group; follow the event"},
        {"0", "show all ranks"},
        {"wheel", "zoom at the cursor"},
        {"drag", "pan (in the lifted view: rotate)"},
        {"click", "details of a point, edge or triangle (its circle drawn)"},
        {"f", "fit the points in the window"},
        {"Ctrl + =  −  0", "larger / smaller / default text"},
        {"F11", "full screen"},
        {"Tab", "the panels with no room, over the picture / back"},
        {"t", "theme: light, dark, high contrast"},
        {"c", "clean picture (final triangles by rank)"},
        {"o  v", "all circumcircles / Voronoi diagram"},
        {"h  ?", "this help"},
        {"s", "screenshot (PNG)"},
        {"b  n  j  p  d  e", "bookmark (Shift: back), notes, notes page, pointer, pen, erase"},
        {"m  r", "mark an event; record mark → current as GIF/video"},
        {"Esc  q", "quit"},
    };
    const pdt_view *v = c->v;
    int nk = (int)(sizeof keys / sizeof *keys), shown = 0;
    int nm = v->help_more ? v->help_nmore : 0;
    for (int i = 0; i < nk; i++) shown += !help_taken(v, keys[i][0]);
    int rows = shown > nm ? shown : nm;
    cairo_t *cr = c->cr;
    /* measured at size 1, then the largest size that fits both ways */
    double kw = 0, dw = 0, kw2 = 0, dw2 = 0;
    for (int i = 0; i < nk; i++) {
        if (help_taken(v, keys[i][0])) continue;
        kw = fmax(kw, text_wb(cr, MONO, 1, 0.9, keys[i][0]));
        dw = fmax(dw, text_w(cr, SANS, 0.9, keys[i][1]));
    }
    for (int i = 0; i < nm; i++) {
        kw2 = fmax(kw2, text_wb(cr, MONO, 1, 0.9, v->help_more[i][0]));
        dw2 = fmax(dw2, text_w(cr, SANS, 0.9, v->help_more[i][1]));
    }
    double unit_w = kw + dw + 3.5 + (nm ? kw2 + dw2 + 3.5 : 0);
    double f = fmin(c->L.font * 1.05, 0.96 * h / ((rows + 2.6) * 1.45));
    f = fmin(f, 0.96 * w / unit_w);
    double bw = unit_w * f, bh = (rows + 2.6) * 1.45 * f;
    double bx = (w - bw) / 2, by = (h - bh) / 2;
    cairo_rectangle(cr, 0, 0, w, h);
    cairo_set_source_rgba(cr, 0, 0, 0, 0.35);
    cairo_fill(cr);
    cairo_rectangle(cr, bx, by, bw, bh);
    rgb(cr, c->T->panel, 0.97);
    cairo_fill_preserve(cr);
    rgb(cr, c->T->ink, 1);
    cairo_set_line_width(cr, 2);
    cairo_stroke(cr);
    char sel[96];
    snprintf(sel, sizeof sel, "(selected kind: %s)", pdt_ev_class_name(v->ev_class));
    help_column(cr, f, bx + f, by, kw * f, "Keys", sel, keys, nk, v);
    if (nm) {
        double x2 = bx + (kw + dw + 3.5) * f;
        cairo_move_to(cr, x2 - 0.75 * f, by + 0.6 * f);
        cairo_line_to(cr, x2 - 0.75 * f, by + bh - 0.6 * f);
        cairo_set_line_width(cr, 1);
        cairo_stroke(cr);
        help_column(cr, f, x2 + 0.25 * f, by, kw2 * f, v->help_more_title ? v->help_more_title : "More",
                    NULL, v->help_more, nm, v);
    }
}

/* ---- the panels with no room ------------------------------------------------------ */

/* "legend, timeline, stacks" from the hidden bits; the number named. */
static int hidden_names(unsigned hid, char *b, size_t cap)
{
    static const struct { unsigned bit; const char *name; } names[] = {
        {PDT_PANEL_LEGEND, "legend"},     {PDT_PANEL_TIMELINE, "timeline"},
        {PDT_PANEL_STACK, "stacks"},      {PDT_PANEL_LIFTED, "lifted view"},
        {PDT_PANEL_CODE, "pseudo-code"},
    };
    int n = 0;
    b[0] = 0;
    for (size_t i = 0; i < sizeof names / sizeof *names; i++)
        if (hid & names[i].bit) {
            size_t len = strlen(b);
            snprintf(b + len, cap - len, "%s%s", n++ ? ", " : "", names[i].name);
        }
    return n;
}

/* The `more` line: which panels got no room at this size and font, and
 * Tab, which shows them over the picture (and back).  The longest wording
 * that fits at the label size; the shortest one, smaller, down to 16 px. */
void pdt_draw_more(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.more;
    double f = c->L.font, fs = c->L.label, room = R.w - f;
    char names[128], t[3][200];
    unsigned shown = 0; /* covered: the page's panels */
    const pdt_layout *Ly = &c->L;
    shown |= Ly->legend.w > 0 ? PDT_PANEL_LEGEND : 0;
    shown |= Ly->timeline.w > 0 ? PDT_PANEL_TIMELINE : 0;
    shown |= Ly->stack.w > 0 ? PDT_PANEL_STACK : 0;
    shown |= Ly->lifted.w > 0 ? PDT_PANEL_LIFTED : 0;
    int n = hidden_names(Ly->covered ? shown : Ly->hidden, names, sizeof names);
    const char *them = n > 1 ? "them" : "it";
    if (c->L.covered) {
        const char *next = c->L.covered < c->L.pages ? "Tab: next page" : "Tab: the picture";
        char pg[32] = "";
        if (c->L.pages > 1) snprintf(pg, sizeof pg, " (%d of %d)", c->L.covered, c->L.pages);
        snprintf(t[0], sizeof t[0], "Over the picture%s: %s — %s", pg, names, next);
        snprintf(t[1], sizeof t[1], "Shown%s: %s — %s", pg, names, next);
        snprintf(t[2], sizeof t[2], "%s", next);
    } else {
        snprintf(t[0], sizeof t[0], "No room for the %s — Tab shows %s over the picture", names, them);
        snprintf(t[1], sizeof t[1], "No room: %s — Tab shows %s", names, them);
        snprintf(t[2], sizeof t[2], "Hidden: %s (Tab)", names);
    }
    int i = 0;
    while (i < 2 && text_w(cr, SANS, fs, t[i]) > room) i++;
    double w = text_w(cr, SANS, fs, t[i]);
    if (w > room) fs = fmax(fmin(16, fs), fs * room / w);
    cairo_rectangle(cr, R.x, R.y, R.w, R.h);
    rgb(cr, c->T->topbar, 1);
    cairo_fill(cr);
    cairo_save(cr);
    clip_rect(cr, R);
    rgb(cr, c->T->ink, 1);
    text_at(cr, SANS, 0, fs, R.x + 0.5 * f, R.y + 0.5 * (R.h + 0.72 * fs), t[i]);
    cairo_restore(cr);
}
