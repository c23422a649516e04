/* pdt — reading triangle files: canonical .tri ("i j k" per line, 0-based)
 * and Triangle's .ele (header "count 3 attributes", then "index a b c [attrs]";
 * the first index, 0 or 1, is the base of the point indices too). */
#include "pdt/io.h"

#include <stdlib.h>
#include <string.h>

#include "io_internal.h"

typedef struct treader {
    pdt_io_cur cur;
    size_t npts;       /* SIZE_MAX: no range check */
    pdt_tri *t;
    size_t n, cap;
    pdt_err *err;
} treader;

static pdt_status uint_field(treader *r, const char *what, int64_t *v)
{
    const char *tok;
    size_t len;
    char show[64];
    pdt_io_cur *c = &r->cur;
    if (!pdt_io_token(c, &tok, &len))
        return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: missing %s", c->name, c->line, what);
    int rc = pdt_io_parse_int(tok, len, v);
    if (rc == 1)
        return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: %s '%s' is not a whole number",
                           c->name, c->line, what, pdt_io_show(tok, len, show, sizeof show));
    if (rc == 2 || *v < 0 || *v >= UINT32_MAX)
        return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: %s %s is out of range", c->name,
                           c->line, what, pdt_io_show(tok, len, show, sizeof show));
    return PDT_OK;
}

/* Three point indices (minus base) appended as one triangle. */
static pdt_status tri_fields(treader *r, int64_t base)
{
    if (r->n == r->cap) {
        size_t cap = r->cap ? 2 * r->cap : 1024;
        pdt_tri *t = realloc(r->t, cap * sizeof *t);
        if (!t) return pdt_err_set(r->err, PDT_ERR_NOMEM, "%s: out of memory", r->cur.name);
        r->t = t;
        r->cap = cap;
    }
    pdt_tri tri;
    for (int k = 0; k < 3; k++) {
        int64_t v;
        pdt_status st = uint_field(r, "point index", &v);
        if (st != PDT_OK) return st;
        if (v < base)
            return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: point index %lld is below the "
                               "first index %lld", r->cur.name, r->cur.line, (long long)v,
                               (long long)base);
        v -= base;
        if (r->npts != SIZE_MAX && (uint64_t)v >= r->npts)
            return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: point index %lld out of range "
                               "(%zu points)", r->cur.name, r->cur.line, (long long)(v + base),
                               r->npts);
        tri.v[k] = (uint32_t)v;
    }
    if (r->n >= UINT32_MAX)
        return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: too many triangles", r->cur.name,
                           r->cur.line);
    r->t[r->n++] = tri;
    return PDT_OK;
}

static pdt_status read_tri(treader *r)
{
    while (pdt_io_next_line(&r->cur)) {
        pdt_status st = tri_fields(r, 0);
        if (st == PDT_OK)
            st = pdt_io_end_line(&r->cur, "the three point indices (one triangle 'i j k' per line)",
                                 r->err);
        if (st != PDT_OK) return st;
    }
    return PDT_OK;
}

static pdt_status read_ele(treader *r)
{
    pdt_io_cur *c = &r->cur;
    pdt_status st;
    int64_t count, per, nattr = 0;
    if (!pdt_io_next_line(c)) return PDT_OK;
    if ((st = uint_field(r, "triangle count in the .ele header", &count)) != PDT_OK ||
        (st = uint_field(r, "points per triangle in the .ele header", &per)) != PDT_OK)
        return st;
    if (per != 3)
        return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: .ele header says %lld points per "
                           "triangle; only 3 is supported", c->name, c->line, (long long)per);
    const char *save = c->p, *tok;
    size_t len;
    if (pdt_io_token(c, &tok, &len)) {
        c->p = save;
        if ((st = uint_field(r, "attribute count in the .ele header", &nattr)) != PDT_OK)
            return st;
    }
    if ((st = pdt_io_end_line(&r->cur, "the .ele header (count, 3, attributes)", r->err)) != PDT_OK)
        return st;
    int64_t base = 0;
    for (int64_t i = 0; i < count; i++) {
        if (!pdt_io_next_line(c))
            return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: file ends after %lld of the %lld "
                               "triangles the header announces", c->name, c->line, (long long)i,
                               (long long)count);
        int64_t idx;
        if ((st = uint_field(r, "triangle index", &idx)) != PDT_OK) return st;
        if (i == 0) {
            if (idx != 0 && idx != 1)
                return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: first triangle index is "
                                   "%lld; must be 0 or 1", c->name, c->line, (long long)idx);
            base = idx;
        } else if (idx != base + i) {
            return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: triangle index %lld out of order "
                               "(expected %lld)", c->name, c->line, (long long)idx,
                               (long long)(base + i));
        }
        if ((st = tri_fields(r, base)) != PDT_OK) return st;
        for (int64_t a = 0; a < nattr; a++) {
            char show[64];
            if (!pdt_io_token(c, &tok, &len))
                return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: missing attribute %lld of "
                                   "%lld", c->name, c->line, (long long)(a + 1), (long long)nattr);
            if (!pdt_io_is_decimal(tok, len))
                return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: attribute '%s' is not a "
                                   "number", c->name, c->line,
                                   pdt_io_show(tok, len, show, sizeof show));
        }
        st = pdt_io_end_line(&r->cur, "the triangle (index a b c, attributes)", r->err);
        if (st != PDT_OK) return st;
    }
    if (pdt_io_next_line(c))
        return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: more triangles than the %lld the "
                           "header announces", c->name, c->line, (long long)count);
    return PDT_OK;
}

pdt_status pdt_read_tris_n(const char *path, size_t npts, pdt_tri **tris, size_t *ntri,
                           pdt_err *err)
{
    *tris = NULL;
    *ntri = 0;
    if (!path) return pdt_err_set(err, PDT_ERR_ARG, "no triangle file given");
    pdt_io_text t;
    pdt_status st = pdt_io_load(path, &t, err);
    if (st != PDT_OK) return st;
    treader r = { .npts = npts, .err = err };
    pdt_io_cur_init(&r.cur, &t, strcmp(path, "-") == 0 ? "standard input" : path);
    size_t plen = strlen(path);
    int ele = plen >= 4 && strcmp(path + plen - 4, ".ele") == 0;
    st = ele ? read_ele(&r) : read_tri(&r);
    pdt_io_text_free(&t);
    if (st != PDT_OK) {
        free(r.t);
        return st;
    }
    *tris = r.t;
    *ntri = r.n;
    return PDT_OK;
}

pdt_status pdt_read_tris(const char *path, pdt_tri **tris, size_t *ntri, pdt_err *err)
{
    return pdt_read_tris_n(path, SIZE_MAX, tris, ntri, err);
}
