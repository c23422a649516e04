/* pdt — reading and writing point files: plain text "x y" and Triangle's .node. */
#include "pdt/io.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io_internal.h"

static int has_ext(const char *path, const char *ext)
{
    if (!path) return 0;
    size_t n = strlen(path), e = strlen(ext);
    return n >= e && strcmp(path + n - e, ext) == 0;
}

/* ---- the reader's state ------------------------------------------------------ */

typedef struct reader {
    pdt_io_cur cur;
    double scale;      /* 0 = integers only */
    pdt_point *pts;
    size_t n, cap;
    pdt_io_dec *orig;  /* scale > 0: the values as written, two per point */
    pdt_err *err;
} reader;

static pdt_status grow(reader *r)
{
    size_t cap = r->cap ? r->cap * 2 : 1024;
    pdt_point *p = realloc(r->pts, cap * sizeof *p);
    if (!p) return pdt_err_set(r->err, PDT_ERR_NOMEM, "%s: out of memory", r->cur.name);
    r->pts = p;
    if (r->scale > 0) {
        pdt_io_dec *o = realloc(r->orig, 2 * cap * sizeof *o);
        if (!o) return pdt_err_set(r->err, PDT_ERR_NOMEM, "%s: out of memory", r->cur.name);
        r->orig = o;
    }
    r->cap = cap;
    return PDT_OK;
}

/* One coordinate token -> int32 (scaled when --scale was given). */
static pdt_status coord(reader *r, const char *tok, size_t len, int32_t *v, pdt_io_dec *orig)
{
    char show[64];
    if (r->scale > 0) {
        if (pdt_io_parse_dec(tok, len, orig) != 0)
            return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: '%s' is not a number", r->cur.name,
                               r->cur.line, pdt_io_show(tok, len, show, sizeof show));
        if (pdt_io_scale_round(orig, tok, len, r->scale, v) != 0)
            return pdt_err_set(r->err, PDT_ERR_PARSE,
                               "%s:%zu: coordinate %s times scale %g does not fit in 32 bits",
                               r->cur.name, r->cur.line, pdt_io_show(tok, len, show, sizeof show),
                               r->scale);
        return PDT_OK;
    }
    int64_t x;
    int rc = pdt_io_parse_int(tok, len, &x);
    if (rc == 1) {
        if (pdt_io_is_decimal(tok, len))
            return pdt_err_set(r->err, PDT_ERR_PARSE,
                               "%s:%zu: coordinate %s is not an integer (decimal coordinates "
                               "need --scale K)",
                               r->cur.name, r->cur.line, pdt_io_show(tok, len, show, sizeof show));
        return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: '%s' is not a number", r->cur.name,
                           r->cur.line, pdt_io_show(tok, len, show, sizeof show));
    }
    if (rc == 2 || x < INT32_MIN || x > INT32_MAX)
        return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: coordinate %s does not fit in 32 bits",
                           r->cur.name, r->cur.line, pdt_io_show(tok, len, show, sizeof show));
    *v = (int32_t)x;
    return PDT_OK;
}

/* Read "x y" from the current line into point r->n (appended). */
static pdt_status point_xy(reader *r)
{
    const char *tok;
    size_t len;
    if (r->n == r->cap) {
        pdt_status gst = grow(r);
        if (gst != PDT_OK) return gst;
    }
    pdt_io_dec ox = { 0 }, oy = { 0 };
    pdt_point p;
    if (!pdt_io_token(&r->cur, &tok, &len))
        return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: missing x coordinate", r->cur.name,
                           r->cur.line);
    pdt_status st = coord(r, tok, len, &p.x, &ox);
    if (st != PDT_OK) return st;
    pdt_io_field_sep(&r->cur);
    if (!pdt_io_token(&r->cur, &tok, &len))
        return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: missing y coordinate", r->cur.name,
                           r->cur.line);
    st = coord(r, tok, len, &p.y, &oy);
    if (st != PDT_OK) return st;
    if (r->n >= UINT32_MAX)
        return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: too many points (at most %u)",
                           r->cur.name, r->cur.line, (unsigned)(UINT32_MAX - 1));
    if (r->scale > 0) {
        r->orig[2 * r->n] = ox;
        r->orig[2 * r->n + 1] = oy;
    }
    r->pts[r->n++] = p;
    return PDT_OK;
}

/* A column name of a header line: letters, digits and '_', starting with a
 * letter, optionally in double quotes ("x", X, "lon"). */
static int is_name(const char *tok, size_t len)
{
    if (len >= 2 && tok[0] == '"' && tok[len - 1] == '"') {
        tok++;
        len -= 2;
    }
    if (len == 0 || !((tok[0] | 0x20) >= 'a' && (tok[0] | 0x20) <= 'z')) return 0;
    for (size_t i = 0; i < len; i++) {
        char ch = tok[i];
        if (!(ch == '_' || (ch >= '0' && ch <= '9') || ((ch | 0x20) >= 'a' && (ch | 0x20) <= 'z')))
            return 0;
    }
    return 1;
}

/* The first line of a point text file may name the two columns ("x,y",
 * "X;Y", "x<TAB>y", "\"x\",\"y\""): skip it when it holds exactly two names. */
static void skip_header(reader *r)
{
    pdt_io_cur save = r->cur;
    const char *tok;
    size_t len;
    int two_names = pdt_io_token(&r->cur, &tok, &len) && is_name(tok, len);
    if (two_names) {
        pdt_io_field_sep(&r->cur);
        two_names = pdt_io_token(&r->cur, &tok, &len) && is_name(tok, len);
    }
    if (two_names && !pdt_io_token(&r->cur, &tok, &len) &&
        !(r->cur.p < r->cur.end && (*r->cur.p == ',' || *r->cur.p == ';'))) {
        pdt_io_skip_line(&r->cur);
        return;
    }
    r->cur = save;
}

/* One point per line: "x y", "x,y", "x;y" or "x<TAB>y", after an optional
 * header line naming the columns. */
static pdt_status read_text(reader *r)
{
    r->cur.fields = 1;
    if (pdt_io_next_line(&r->cur)) skip_header(r);
    while (pdt_io_next_line(&r->cur)) {
        pdt_status st = point_xy(r);
        if (st == PDT_OK)
            st = pdt_io_end_line(&r->cur, "the coordinates (one point 'x y' per line)", r->err);
        if (st != PDT_OK) return st;
    }
    return PDT_OK;
}

/* A non-negative integer field of a .node/.ele header or entry. */
static pdt_status header_int(pdt_io_cur *c, const char *what, int64_t *v, pdt_err *err)
{
    const char *tok;
    size_t len;
    char show[64];
    if (!pdt_io_token(c, &tok, &len))
        return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: missing %s", c->name, c->line, what);
    int rc = pdt_io_parse_int(tok, len, v);
    if (rc != 0 || *v < 0 || *v > UINT32_MAX)
        return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: bad %s '%s'", c->name, c->line, what,
                           pdt_io_show(tok, len, show, sizeof show));
    return PDT_OK;
}

static pdt_status read_node(reader *r)
{
    pdt_io_cur *c = &r->cur;
    pdt_err *err = r->err;
    int64_t count, dim, nattr, nmark;
    pdt_status st;
    if (!pdt_io_next_line(c))
        return PDT_OK; /* an empty file: no points */
    if ((st = header_int(c, "point count in the .node header", &count, err)) != PDT_OK ||
        (st = header_int(c, "dimension in the .node header", &dim, err)) != PDT_OK)
        return st;
    if (dim != 2)
        return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: .node header says dimension %lld; only 2 "
                           "is supported", c->name, c->line, (long long)dim);
    /* Attributes and markers may be omitted (Triangle reads them as 0). */
    const char *save = c->p;
    const char *tok;
    size_t len;
    nattr = nmark = 0;
    if (pdt_io_token(c, &tok, &len)) {
        c->p = save;
        if ((st = header_int(c, "attribute count in the .node header", &nattr, err)) != PDT_OK)
            return st;
        save = c->p;
        if (pdt_io_token(c, &tok, &len)) {
            c->p = save;
            if ((st = header_int(c, "boundary marker count in the .node header", &nmark, err)) !=
                PDT_OK)
                return st;
            if (nmark > 1)
                return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: .node header says %lld boundary "
                                   "markers; must be 0 or 1", c->name, c->line, (long long)nmark);
        }
    }
    if (count >= UINT32_MAX)  /* before pdt_io_end_line, which moves to the next line */
        return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: too many points (at most %u)", c->name,
                           c->line, (unsigned)(UINT32_MAX - 1));
    st = pdt_io_end_line(&r->cur, "the .node header (count, 2, attributes, markers)", r->err);
    if (st != PDT_OK) return st;

    int64_t base = 0;
    for (int64_t i = 0; i < count; i++) {
        if (!pdt_io_next_line(c))
            return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: file ends after %lld of the %lld "
                               "points the header announces", c->name, c->line, (long long)i,
                               (long long)count);
        int64_t idx;
        if ((st = header_int(c, "point index", &idx, err)) != PDT_OK) return st;
        if (i == 0) {
            if (idx != 0 && idx != 1)
                return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: first point index is %lld; must "
                                   "be 0 or 1", c->name, c->line, (long long)idx);
            base = idx;
        } else if (idx != base + i) {
            return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: point index %lld out of order "
                               "(expected %lld)", c->name, c->line, (long long)idx,
                               (long long)(base + i));
        }
        if ((st = point_xy(r)) != PDT_OK) return st;
        for (int64_t a = 0; a < nattr; a++) {
            char show[64];
            if (!pdt_io_token(c, &tok, &len))
                return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: missing attribute %lld of %lld",
                                   c->name, c->line, (long long)(a + 1), (long long)nattr);
            if (!pdt_io_is_decimal(tok, len))
                return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: attribute '%s' is not a number",
                                   c->name, c->line, pdt_io_show(tok, len, show, sizeof show));
        }
        if (nmark) {
            int64_t mk;
            char show[64];
            if (!pdt_io_token(c, &tok, &len))
                return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: missing boundary marker",
                                   c->name, c->line);
            if (pdt_io_parse_int(tok, len, &mk) != 0)
                return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: boundary marker '%s' is not an "
                                   "integer", c->name, c->line,
                                   pdt_io_show(tok, len, show, sizeof show));
        }
        st = pdt_io_end_line(&r->cur, "the point (index x y, attributes, marker)", r->err);
        if (st != PDT_OK) return st;
    }
    if (pdt_io_next_line(c))
        return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: more points than the %lld the header "
                           "announces", c->name, c->line, (long long)count);
    return PDT_OK;
}

/* Points whose rounded value equals that of a point written differently. */
typedef struct { const pdt_io_dec *o; pdt_point p; } coll_item;

static int dec_cmp(const pdt_io_dec *a, const pdt_io_dec *b)
{
    if (a->neg != b->neg) return a->neg < b->neg ? -1 : 1;
    if (a->e != b->e) return a->e < b->e ? -1 : 1;
    if (a->m != b->m) return a->m < b->m ? -1 : 1;
    return 0;
}

static int coll_cmp(const void *pa, const void *pb)
{
    const coll_item *a = pa, *b = pb;
    uint64_t ka = pdt_key(a->p), kb = pdt_key(b->p);
    if (ka != kb) return ka < kb ? -1 : 1;
    int c = dec_cmp(&a->o[0], &b->o[0]);
    return c ? c : dec_cmp(&a->o[1], &b->o[1]);
}

static pdt_status count_collisions(reader *r, size_t *collisions)
{
    *collisions = 0;
    if (r->n < 2) return PDT_OK;
    coll_item *it = malloc(r->n * sizeof *it);
    if (!it) return pdt_err_set(r->err, PDT_ERR_NOMEM, "%s: out of memory", r->cur.name);
    for (size_t i = 0; i < r->n; i++) {
        it[i].o = &r->orig[2 * i];
        it[i].p = r->pts[i];
    }
    qsort(it, r->n, sizeof *it, coll_cmp);
    for (size_t i = 1; i < r->n; i++)
        if (pdt_key(it[i].p) == pdt_key(it[i - 1].p) && coll_cmp(&it[i], &it[i - 1]) != 0)
            (*collisions)++;
    free(it);
    return PDT_OK;
}

pdt_status pdt_read_points(const char *path, double scale, pdt_point **pts, size_t *n,
                           size_t *collisions, pdt_err *err)
{
    *pts = NULL;
    *n = 0;
    if (collisions) *collisions = 0;
    if (!path) return pdt_err_set(err, PDT_ERR_ARG, "no input file given");
    if (!(scale == 0 || (scale > 0 && isfinite(scale))))
        return pdt_err_set(err, PDT_ERR_ARG, "scale must be a positive number (got %g)", scale);
    pdt_io_text t;
    pdt_status st = pdt_io_load(path, &t, err);
    if (st != PDT_OK) return st;
    reader r = { .scale = scale, .err = err };
    pdt_io_cur_init(&r.cur, &t, strcmp(path, "-") == 0 ? "standard input" : path);
    st = has_ext(path, ".node") ? read_node(&r) : read_text(&r);
    if (st == PDT_OK && scale > 0 && collisions) st = count_collisions(&r, collisions);
    pdt_io_text_free(&t);
    free(r.orig);
    if (st != PDT_OK) {
        free(r.pts);
        return st;
    }
    *pts = r.pts;
    *n = r.n;
    return PDT_OK;
}
