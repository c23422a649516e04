/* pdt — the viewer's text panels: the event line at the top, the legend,
 * the pseudo-code with the current line, the stacks being built, the help
 * overlay. */
#include "pdt/view/describe.h"
#include "render_int.h"

static void draw_prompt(ctx *c);


void pdt_draw_top(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.top;
    cairo_rectangle(cr, R.x, R.y, R.w, R.h);
    rgb(cr, c->T->topbar, 1);
    cairo_fill(cr);
    char line[512], head[64];
    pdt_replay_describe_state(c->r, c->s, c->s->k, line, sizeof line);
    snprintf(head, sizeof head, "%zu / %zu", c->s->k, pdt_replay_count(c->r));
    double f = c->L.font;
    rgb(cr, c->T->ink, 0.7);
    text_at(cr, MONO, 0, 0.9 * f, 0.5 * f, 1.35 * f, head);
    double x = 0.5 * f + text_w(cr, MONO, 0.9 * f, head) + 1.0 * f;
    if (c->cur) {
        set_rank(cr, (int)c->cur->rank, 1);
        cairo_rectangle(cr, x, 0.45 * f, 0.7 * f, 1.1 * f);
        cairo_fill(cr);
        x += 1.1 * f;
    }
    /* the event line gets the bar; the status goes under it, at the
     * picture's top right, when both do not fit */
    double room = R.w - x - 0.5 * f, sw = 0, sf = 0.85 * f;
    if (c->v->status) sw = text_w(cr, SANS, sf, c->v->status) + 1.2 * f;
    double fs = 1.05 * f, lw = text_wb(cr, SANS, 1, fs, line);
    int status_in_bar = c->v->status && lw + sw <= room;
    double avail = status_in_bar ? room - sw : room;
    if (lw > avail) fs = fmax(0.8 * f, fs * avail / lw);
    /* still too long at the smallest size: the words that fit stay in the
     * bar, the rest goes on a second line in a box under it (never cut) */
    char first[512];
    const char *rest = NULL;
    snprintf(first, sizeof first, "%s", line);
    if (text_wb(cr, SANS, 1, fs, first) > avail) {
        size_t len = strlen(first);
        while (len > 0) {
            while (len > 0 && first[len - 1] != ' ') len--;
            if (len == 0) break;
            first[len - 1] = 0;
            if (text_wb(cr, SANS, 1, fs, first) <= avail) break;
            len--;
        }
        if (len > 0) rest = line + len;
        else snprintf(first, sizeof first, "%s", line);
    }
    rgb(cr, c->T->ink, 1);
    cairo_save(cr);
    clip_rect(cr, (pdt_rect){R.x, R.y, x + avail, R.h});
    text_at(cr, SANS, 1, fs, x, 1.4 * f, first);
    cairo_restore(cr);
    if (rest) {
        double rw = text_wb(cr, SANS, 1, fs, rest);
        cairo_rectangle(cr, x - 0.3 * f, R.y + R.h, rw + 0.6 * f, 1.35 * fs);
        rgb(cr, c->T->topbar, 0.92);
        cairo_fill(cr);
        rgb(cr, c->T->ink, 1);
        text_at(cr, SANS, 1, fs, x, R.y + R.h + 1.05 * fs, rest);
    }
    if (c->v->status) {
        double tw = sw - 1.2 * f;
        double sx = R.w - tw - 0.6 * f, sy = status_in_bar ? 1.35 * f : R.y + R.h + 1.1 * f;
        if (!status_in_bar) {
            cairo_rectangle(cr, sx - 0.3 * f, sy - 0.95 * sf, tw + 0.6 * f, 1.3 * sf);
            rgb(cr, c->T->topbar, 0.9);
            cairo_fill(cr);
        }
        rgb(cr, c->T->ink, 0.75);
        text_at(cr, SANS, 0, sf, sx, sy, c->v->status);
    }
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

static void legend_line(cairo_t *cr, double x, double y, double len, int st, double lw,
                        const double col[3])
{
    pdt_status_style(cr, st, lw);
    cairo_move_to(cr, x, y);
    cairo_line_to(cr, x + len, y);
    rgb(cr, col, 1);
    cairo_stroke(cr);
    cairo_set_dash(cr, NULL, 0, 0);
}

/* The legend as a strip (no side column): its items flow left to right,
 * wrapping into rows. */
typedef struct flow {
    ctx *c;
    pdt_rect R;
    double x, y, f, fs;
} flow;

/* Room for an item of width w (swatch + text); wraps to the next row. */
static void flow_room(flow *F, double w)
{
    if (F->x + w > F->R.x + F->R.w - 0.5 * F->f && F->x > F->R.x + 0.6 * F->f) {
        F->x = F->R.x + 0.5 * F->f;
        F->y += 1.45 * F->f;
    }
}

static void flow_text(flow *F, const char *s, double alpha)
{
    rgb(F->c->cr, F->c->T->ink, alpha);
    text_at(F->c->cr, SANS, 0, F->fs, F->x, F->y, s);
    F->x += text_w(F->c->cr, SANS, F->fs, s) + 0.9 * F->f;
}

static void draw_legend_strip(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.legend;
    double f = c->L.font;
    panel(cr, c->T, R, NULL, f);
    cairo_save(cr);
    clip_rect(cr, R);
    flow F = {c, R, R.x + 0.5 * f, R.y + 1.3 * f, f, c->L.body};
    char lab[16];
    for (int q = 0; q < c->nranks && q < 64; q++) {
        snprintf(lab, sizeof lab, q ? "%d" : "rank %d", q);
        flow_room(&F, 1.1 * f + text_w(cr, SANS, F.fs, lab));
        cairo_rectangle(cr, F.x, F.y - 0.75 * f, 0.8 * f, 0.8 * f);
        set_rank(cr, q, shown(c, (uint32_t)q) ? 1 : 0.2);
        cairo_fill(cr);
        F.x += 1.0 * f;
        flow_text(&F, lab, shown(c, (uint32_t)q) ? 1 : 0.4);
    }
    static const char *const names[] = {"candidate", "final", "deferred (RA)", "shipped", "discarded"};
    static const int sts[] = {PDT_TS_CANDIDATE, PDT_TS_FINAL, PDT_TS_DEFERRED, PDT_TS_SHIPPED,
                              PDT_TS_DISCARDED};
    double col0[3], lw = fmax(1.5, 0.14 * f);
    pdt_rank_rgb(0, col0);
    for (int i = 0; i < 5; i++) {
        if (c->v->clean && sts[i] != PDT_TS_FINAL) continue;
        flow_room(&F, 2.6 * f + text_w(cr, SANS, F.fs, names[i]));
        legend_line(cr, F.x, F.y - 0.3 * f, 2.2 * f, sts[i], lw, col0);
        if (sts[i] == PDT_TS_DISCARDED) {
            cairo_set_line_width(cr, lw);
            cross(cr, F.x + 1.1 * f, F.y - 0.3 * f, 0.35 * f);
            rgb(cr, RED, 1);
            cairo_stroke(cr);
        }
        F.x += 2.6 * f;
        flow_text(&F, names[i], 1);
    }
    flow_room(&F, 2.6 * f + text_w(cr, SANS, F.fs, "hull / stack"));
    cairo_set_line_width(cr, 3.2 * lw);
    cairo_move_to(cr, F.x, F.y - 0.3 * f);
    cairo_line_to(cr, F.x + 2.2 * f, F.y - 0.3 * f);
    set_hull(c, pdt_legend_hull_rank(c), 1);
    cairo_stroke(cr);
    F.x += 2.6 * f;
    flow_text(&F, "hull / stack", 1);
    if (!c->v->clean) {
        flow_room(&F, 1.0 * f + text_w(cr, SANS, F.fs, "circumdisk (RA)"));
        cairo_new_sub_path(cr);
        cairo_arc(cr, F.x + 0.4 * f, F.y - 0.3 * f, 0.35 * f, 0, 2 * M_PI);
        rgb(cr, c->T->mark, 0.4);
        cairo_fill_preserve(cr);
        rgb(cr, c->T->disk, 1);
        cairo_set_line_width(cr, 1);
        cairo_stroke(cr);
        F.x += 1.0 * f;
        flow_text(&F, "circumdisk (RA)", 1);
    }
    cairo_restore(cr);
}

void pdt_draw_legend(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.legend;
    double f = c->L.font, fs = 0.8 * f;
    if (R.w >= c->L.geo.w && R.y >= c->L.geo.y + c->L.geo.h) { /* under the picture */
        draw_legend_strip(c);
        return;
    }
    panel(cr, c->T, R, "Legend", f);
    cairo_save(cr);
    clip_rect(cr, R);
    /* ranks */
    double x = R.x + 0.5 * f, y = R.y + 2.3 * f;
    rgb(cr, c->T->ink, 1);
    text_at(cr, SANS, 0, fs, x, y, "ranks:");
    x += text_w(cr, SANS, fs, "ranks:") + 0.4 * f;
    for (int q = 0; q < c->nranks; q++) {
        char lab[16];
        snprintf(lab, sizeof lab, "%d", q);
        double tw = text_w(cr, SANS, fs, lab);
        if (x + 1.2 * f + tw > R.x + R.w - 0.5 * f) {
            text_at(cr, SANS, 0, fs, x, y, "…");
            break;
        }
        cairo_rectangle(cr, x, y - 0.75 * f, 0.8 * f, 0.8 * f);
        set_rank(cr, q, shown(c, (uint32_t)q) ? 1 : 0.2);
        cairo_fill(cr);
        rgb(cr, c->T->ink, shown(c, (uint32_t)q) ? 1 : 0.4);
        text_at(cr, SANS, 0, fs, x + 0.95 * f, y, lab);
        x += 1.3 * f + tw;
    }
    /* statuses, two columns */
    static const char *const names[] = {"candidate", "final", "deferred (RA)", "shipped",
                                        "discarded"};
    static const int sts[] = {PDT_TS_CANDIDATE, PDT_TS_FINAL, PDT_TS_DEFERRED, PDT_TS_SHIPPED,
                              PDT_TS_DISCARDED};
    double col0[3];
    pdt_rank_rgb(0, col0);
    double lw = fmax(1.5, 0.14 * f), colw = (R.w - f) / 2;
    for (int i = 0; i < 5; i++) {
        double lx = R.x + 0.5 * f + (i % 2) * colw, ly = R.y + (3.6 + 1.25 * (i / 2)) * f;
        legend_line(cr, lx, ly - 0.3 * f, 2.2 * f, sts[i], lw, col0);
        if (sts[i] == PDT_TS_DISCARDED) {
            cairo_set_line_width(cr, lw);
            cross(cr, lx + 1.1 * f, ly - 0.3 * f, 0.35 * f);
            rgb(cr, RED, 1);
            cairo_stroke(cr);
        }
        rgb(cr, c->T->ink, 1);
        text_at(cr, SANS, 0, fs, lx + 2.6 * f, ly, names[i]);
    }
    {   /* hull, in the sixth cell */
        double lx = R.x + 0.5 * f + colw, ly = R.y + (3.6 + 1.25 * 2) * f;
        cairo_set_line_width(cr, 3.2 * lw);
        cairo_move_to(cr, lx, ly - 0.3 * f);
        cairo_line_to(cr, lx + 2.2 * f, ly - 0.3 * f);
        set_hull(c, pdt_legend_hull_rank(c), 1);
        cairo_stroke(cr);
        rgb(cr, c->T->ink, 1);
        text_at(cr, SANS, 0, fs, lx + 2.6 * f, ly, "hull / stack");
    }
    /* markers */
    double ly = R.y + 7.05 * f, lx = R.x + 0.5 * f;
    cairo_new_sub_path(cr);
    cairo_arc(cr, lx + 0.4 * f, ly - 0.3 * f, 0.25 * f, 0, 2 * M_PI);
    rgb(cr, c->T->ink, 1);
    cairo_fill(cr);
    text_at(cr, SANS, 0, fs, lx + 0.9 * f, ly, "lifted");
    lx += 0.9 * f + text_w(cr, SANS, fs, "lifted") + 0.8 * f;
    cairo_new_sub_path(cr);
    cairo_arc(cr, lx + 0.4 * f, ly - 0.3 * f, 0.25 * f, 0, 2 * M_PI);
    rgb(cr, c->T->hollow, 1);
    cairo_set_line_width(cr, 1);
    cairo_stroke(cr);
    rgb(cr, c->T->ink, 1);
    text_at(cr, SANS, 0, fs, lx + 0.9 * f, ly, "not yet");
    lx += 0.9 * f + text_w(cr, SANS, fs, "not yet") + 0.8 * f;
    cairo_set_line_width(cr, 0.15 * f);
    cross(cr, lx + 0.4 * f, ly - 0.3 * f, 0.3 * f);
    rgb(cr, RED, 1);
    cairo_stroke(cr);
    rgb(cr, c->T->ink, 1);
    text_at(cr, SANS, 0, fs, lx + 0.9 * f, ly, "deleted");
    lx += 0.9 * f + text_w(cr, SANS, fs, "deleted") + 0.8 * f;
    cairo_new_sub_path(cr);
    cairo_arc(cr, lx + 0.4 * f, ly - 0.3 * f, 0.35 * f, 0, 2 * M_PI);
    rgb(cr, c->T->mark, 0.4);
    cairo_fill_preserve(cr);
    rgb(cr, c->T->disk, 1);
    cairo_stroke(cr);
    rgb(cr, c->T->ink, 1);
    text_at(cr, SANS, 0, fs, lx + 0.95 * f, ly, "circumdisk (RA)");
    cairo_restore(cr);
}

void pdt_draw_code(ctx *c)
{
    cairo_t *cr = c->cr;
    pdt_rect R = c->L.code;
    double f = c->L.font;
    int id;
    int line = pdt_replay_code_line(c->r, c->s, &id);
    panel(cr, c->T, R, pdt_code_title(id), f);
    cairo_save(cr);
    clip_rect(cr, R);
    int nl = (int)pdt_code_count(id);
    double lh = (R.h - 1.9 * f) / nl;
    if (lh > 1.15 * f) lh = 1.15 * f;
    double fs = fmin(0.78 * f, 0.92 * lh);
    /* shrink to fit the width */
    double wmax = 0;
    for (int i = 0; i < nl; i++) wmax = fmax(wmax, text_w(cr, MONO, fs, pdt_code_text(id, (size_t)i)));
    if (wmax > R.w - 1.2 * f) fs *= (R.w - 1.2 * f) / wmax;
    for (int i = 0; i < nl; i++) {
        double y = R.y + 1.7 * f + (i + 1) * lh;
        if (i == line) {
            cairo_rectangle(cr, R.x + 0.3 * f, y - 0.85 * lh, R.w - 0.6 * f, lh);
            rgb(cr, c->T->mark, 0.8);
            cairo_fill(cr);
        }
        rgb(cr, c->T->ink, 1);
        text_at(cr, MONO, i == line, fs, R.x + 0.6 * f, y - 0.18 * lh, pdt_code_text(id, (size_t)i));
    }
    cairo_restore(cr);
}

/* A stack element as text: p<angular number> on Graham's stack, else the index. */
static void stack_item(const ctx *c, int st, uint32_t p, int space, char *b, size_t cap)
{
    int64_t pos = st == PDT_STACK_GRAHAM ? pdt_replay_sort_pos(c->r, p) : -1;
    if (pos >= 0) snprintf(b, cap, space ? "p%lld " : "p%lld", (long long)pos);
    else snprintf(b, cap, space ? "%u " : "%u", p);
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
    uint32_t *buf = malloc((c->n + 1) * sizeof *buf);
    int any = 0;
    for (int q = 0; q < c->nranks && buf; q++) {
        if (!shown(c, (uint32_t)q)) continue;
        for (int st = 0; st < 5; st++) {
            if (y > R.y + R.h - 0.3 * f) break;
            int32_t top = pdt_rstate_slot(c->r, c->s, q, PDT_SLOT_STACK0 + st);
            if (top < 0 || !pdt_replay_stack_open(c->r, c->s, top)) continue;
            size_t k = pdt_replay_stack_list(c->r, top, buf, c->n + 1);
            char head[48];
            snprintf(head, sizeof head, "r%d %s (%zu):", q, pdt_stack_name(st), k);
            set_rank(cr, q, 1);
            text_at(cr, SANS, 1, fs, R.x + 0.5 * f, y, head);
            double x0 = R.x + 0.5 * f + text_wb(cr, SANS, 1, fs, head) + 0.4 * f;
            /* as many elements from the top as fit */
            double room = R.x + R.w - 0.5 * f - x0 - 1.5 * f;
            size_t first = k;
            double wsum = 0;
            char num[24];
            while (first > 0) {
                stack_item(c, st, buf[first - 1], 1, num, sizeof num);
                double tw = text_w(cr, MONO, fs, num);
                if (wsum + tw > room) break;
                wsum += tw;
                first--;
            }
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
            if (k) text_at(cr, SANS, 1, fs, x + 0.2 * f, y, "▸");
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
    static const char *const taken[] = {"1 … 9", "0", "click", "drag", "g N Enter", "b  n  p  d  e"};
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
        {"1 … 9", "show / hide rank 0 … 8"},
        {"0", "show all ranks"},
        {"wheel", "zoom at the cursor"},
        {"drag", "pan (in the lifted view: rotate)"},
        {"click", "details of a point, edge or triangle (its circle drawn)"},
        {"f", "fit the points in the window"},
        {"Ctrl + =  −  0", "larger / smaller / default text"},
        {"F11", "full screen"},
        {"t", "theme: light, dark, high contrast"},
        {"c", "clean picture (final triangles by rank)"},
        {"o  v", "all circumcircles / Voronoi diagram"},
        {"h  ?", "this help"},
        {"s", "screenshot (PNG)"},
        {"b  n  p  d  e", "bookmark (Shift: back), notes, pointer, pen, erase"},
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
