/* pdt — the layout report (pdt/view/textlog.h): the texts of one frame,
 * recorded by the one place every text goes through (text_at, halo_text,
 * pdt_text_log_note), and written as JSON. */
#include <errno.h>
#include <stdarg.h>
#include <unistd.h>

#include "pdt/safefile.h"
#include "pdt/view/textlog.h"
#include "render_int.h"

struct pdt_text_log {
    pdt_text_rec *t;
    size_t n, cap;
    double w, h;
    const char *panel;   /* set by pdt_text_log_panel, or NULL */
    pdt_layout L;        /* the frame's panels, to find a text's panel */
    int have_layout;
};

static const cairo_user_data_key_t log_key;

pdt_text_log *pdt_text_log_new(void)
{
    return calloc(1, sizeof(pdt_text_log));
}

void pdt_text_log_clear(pdt_text_log *log, double w, double h)
{
    for (size_t i = 0; i < log->n; i++) free((char *)log->t[i].text);
    log->n = 0;
    log->w = w;
    log->h = h;
    log->panel = NULL;
    log->have_layout = 0;
}

void pdt_text_log_free(pdt_text_log *log)
{
    if (!log) return;
    pdt_text_log_clear(log, 0, 0);
    free(log->t);
    free(log);
}

const pdt_text_rec *pdt_text_log_texts(const pdt_text_log *log, size_t *n)
{
    *n = log->n;
    return log->t;
}

void pdt_text_log_attach(cairo_t *cr, pdt_text_log *log)
{
    cairo_set_user_data(cr, &log_key, log, NULL);
}

void pdt_text_log_panel(cairo_t *cr, const char *panel)
{
    pdt_text_log *log = cairo_get_user_data(cr, &log_key);
    if (log) log->panel = panel;
}

void pdt_text_log_layout(cairo_t *cr, const pdt_layout *L)
{
    pdt_text_log *log = cairo_get_user_data(cr, &log_key);
    if (!log) return;
    log->L = *L;
    log->have_layout = 1;
}

static int inside(pdt_rect R, double x, double y)
{
    return R.w > 0 && x >= R.x && x < R.x + R.w && y >= R.y && y < R.y + R.h;
}

/* The panel a text centred at (x, y) lies in, when none was set. */
static const char *panel_at(const pdt_text_log *log, double x, double y)
{
    if (!log->have_layout) return "picture";
    const pdt_layout *L = &log->L;
    const struct { pdt_rect R; const char *name; } parts[] = {
        {L->top, "event"},   {L->legend, "legend"},     {L->code, "code"},
        {L->stack, "stack"}, {L->lifted, "lifted"},     {L->timeline, "timeline"},
        {L->tree, "tree"},   {L->more, "more"},
    };
    for (size_t i = 0; i < sizeof parts / sizeof *parts; i++)
        if (inside(parts[i].R, x, y)) return parts[i].name;
    return "picture";
}

/* The ink box of s at (x, y) in device pixels; 0 when s has no ink. */
static int device_box(cairo_t *cr, double x, double y, const char *s, double b[4])
{
    cairo_text_extents_t te;
    cairo_text_extents(cr, s, &te);
    if (te.width <= 0 || te.height <= 0) return 0;
    double xs[2] = {x + te.x_bearing, x + te.x_bearing + te.width};
    double ys[2] = {y + te.y_bearing, y + te.y_bearing + te.height};
    b[0] = b[1] = INFINITY;
    b[2] = b[3] = -INFINITY;
    for (int i = 0; i < 4; i++) {
        double dx = xs[i & 1], dy = ys[i >> 1];
        cairo_user_to_device(cr, &dx, &dy);
        b[0] = fmin(b[0], dx);
        b[1] = fmin(b[1], dy);
        b[2] = fmax(b[2], dx);
        b[3] = fmax(b[3], dy);
    }
    return 1;
}

/* The clip's box in device pixels, cut to the frame. */
static void device_clip(cairo_t *cr, const pdt_text_log *log, double c[4])
{
    double x0, y0, x1, y1;
    cairo_clip_extents(cr, &x0, &y0, &x1, &y1);
    cairo_user_to_device(cr, &x0, &y0);
    cairo_user_to_device(cr, &x1, &y1);
    c[0] = fmax(0, fmin(x0, x1));
    c[1] = fmax(0, fmin(y0, y1));
    c[2] = fmin(log->w, fmax(x0, x1));
    c[3] = fmin(log->h, fmax(y0, y1));
}

void pdt_text_log_note(cairo_t *cr, double size, double x, double y, const char *s)
{
    pdt_text_log *log = cairo_get_user_data(cr, &log_key);
    double b[4], c[4];
    if (!log || !s || !device_box(cr, x, y, s, b)) return;
    device_clip(cr, log, c);
    if (b[2] <= c[0] || b[0] >= c[2] || b[3] <= c[1] || b[1] >= c[3]) return; /* not seen */
    if (log->n == log->cap) {
        size_t cap = log->cap ? 2 * log->cap : 256;
        pdt_text_rec *t = realloc(log->t, cap * sizeof *t);
        if (!t) return;
        log->t = t;
        log->cap = cap;
    }
    char *copy = strdup(s);
    if (!copy) return;
    double dx = 0, dy = size;
    cairo_user_to_device_distance(cr, &dx, &dy);
    const double eps = 0.5; /* antialiasing: half a pixel over the clip is not a cut */
    pdt_text_rec *t = &log->t[log->n++];
    *t = (pdt_text_rec){copy, b[0], b[1], b[2] - b[0], b[3] - b[1], hypot(dx, dy),
                        log->panel ? log->panel : panel_at(log, (b[0] + b[2]) / 2, (b[1] + b[3]) / 2),
                        b[0] < c[0] - eps || b[1] < c[1] - eps || b[2] > c[2] + eps ||
                            b[3] > c[3] + eps};
}

/* ---- JSON ------------------------------------------------------------------------ */

typedef struct buf {
    char *p;
    size_t n, cap;
    int oom;
} buf;

static void put(buf *B, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(buf *B, const char *fmt, ...)
{
    va_list ap;
    for (int pass = 0; pass < 2 && !B->oom; pass++) {
        va_start(ap, fmt);
        int k = vsnprintf(B->p ? B->p + B->n : NULL, B->p ? B->cap - B->n : 0, fmt, ap);
        va_end(ap);
        if (k < 0) {
            B->oom = 1;
            return;
        }
        if (B->p && B->n + (size_t)k < B->cap) {
            B->n += (size_t)k;
            return;
        }
        size_t cap = 2 * (B->cap + (size_t)k) + 64;
        char *p = realloc(B->p, cap);
        if (!p) B->oom = 1;
        else B->p = p, B->cap = cap;
    }
}

static void put_string(buf *B, const char *s)
{
    put(B, "\"");
    for (; *s; s++) {
        unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\') put(B, "\\%c", ch);
        else if (ch < 0x20) put(B, "\\u%04x", ch);
        else put(B, "%c", ch);
    }
    put(B, "\"");
}

/* The frame's panels (those with room) and the names of the hidden ones. */
static void put_panels(buf *B, const pdt_layout *L)
{
    const struct { pdt_rect R; const char *name; } parts[] = {
        {L->top, "event"},     {L->geo, "picture"},   {L->legend, "legend"}, {L->code, "code"},
        {L->stack, "stack"},   {L->lifted, "lifted"}, {L->timeline, "timeline"},
        {L->tree, "tree"},     {L->more, "more"},
    };
    static const struct { unsigned bit; const char *name; } bits[] = {
        {PDT_PANEL_LEGEND, "legend"}, {PDT_PANEL_CODE, "code"}, {PDT_PANEL_STACK, "stack"},
        {PDT_PANEL_LIFTED, "lifted"}, {PDT_PANEL_TIMELINE, "timeline"},
    };
    put(B, "\"panels\": {");
    int first = 1;
    for (size_t i = 0; i < sizeof parts / sizeof *parts; i++) {
        pdt_rect R = parts[i].R;
        if (!(R.w > 0 && R.h > 0) || (L->covered && !strcmp(parts[i].name, "picture"))) continue;
        put(B, "%s\"%s\": [%.0f, %.0f, %.0f, %.0f]", first ? "" : ", ", parts[i].name, R.x, R.y,
            R.w, R.h);
        first = 0;
    }
    put(B, "}, \"hidden\": [");
    first = 1;
    for (size_t i = 0; i < sizeof bits / sizeof *bits; i++)
        if (L->hidden & bits[i].bit) {
            put(B, "%s\"%s\"", first ? "" : ", ", bits[i].name);
            first = 0;
        }
    put(B, "], \"covered\": %s, ", L->covered ? "true" : "false");
}

static void put_log(buf *B, const pdt_text_log *log)
{
    put(B, "{\"width\": %.0f, \"height\": %.0f, ", log->w, log->h);
    if (log->have_layout) put_panels(B, &log->L);
    put(B, "\"texts\": [");
    for (size_t i = 0; i < log->n; i++) {
        const pdt_text_rec *t = &log->t[i];
        put(B, "%s\n  {\"text\": ", i ? "," : "");
        put_string(B, t->text);
        put(B, ", \"x\": %.1f, \"y\": %.1f, \"w\": %.1f, \"h\": %.1f, \"px\": %.1f, \"panel\": ",
            t->x, t->y, t->w, t->h, t->px);
        put_string(B, t->panel);
        put(B, ", \"clipped\": %s}", t->clipped ? "true" : "false");
    }
    put(B, "\n]}\n");
}

static pdt_status write_all(int fd, const char *p, size_t n, const char *path, pdt_err *err)
{
    while (n > 0) {
        ssize_t w = write(fd, p, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return pdt_err_set(err, PDT_ERR_IO, "%s: %s", path, strerror(w < 0 ? errno : EIO));
        p += w;
        n -= (size_t)w;
    }
    return PDT_OK;
}

pdt_status pdt_text_log_write(const pdt_text_log *log, const char *path, pdt_err *err)
{
    buf B = {0};
    put_log(&B, log);
    if (B.oom) {
        free(B.p);
        return pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", path);
    }
    pdt_safe_file f;
    pdt_status st = pdt_safe_open(&f, path, PDT_SAFE_DIRECT, err);
    if (st == PDT_OK) {
        st = write_all(f.fd, B.p, B.n, path, err);
        if (st == PDT_OK) st = pdt_safe_commit(&f, err);
        else pdt_safe_abort(&f);
    }
    free(B.p);
    return st;
}
