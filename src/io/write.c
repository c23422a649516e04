/* pdt — writers: points (text, .node) and triangles (.tri, .ele + .node, .off).
 * Numbers are formatted by hand into a large buffer: printf would cost more
 * than the triangulation itself on big outputs. */
#include "pdt/io.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

enum { WBUF = 1 << 20 };

typedef struct wbuf {
    FILE *fp;
    char b[WBUF];
    size_t n;
    int bad;
} wbuf;

static void wb_flush(wbuf *w)
{
    if (w->n && fwrite(w->b, 1, w->n, w->fp) != w->n) w->bad = 1;
    w->n = 0;
}

/* Make room for at least 64 more bytes. */
static inline char *wb_room(wbuf *w)
{
    if (w->n > WBUF - 64) wb_flush(w);
    return w->b + w->n;
}

/* "00" "01" ... "99": two digits per division by 100. */
static const char digits2[201] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

static const uint32_t pow10_32[10] = { 1u, 10u, 100u, 1000u, 10000u, 100000u, 1000000u,
                                       10000000u, 100000000u, 1000000000u };

/* Decimal digits of v: from its bit length (log10(2) ~ 1233 / 4096), then
 * one comparison. */
static inline int ndigits32(uint32_t v)
{
    uint32_t w = v | 1u; /* as many digits as v, and never 0 */
    int t = ((32 - __builtin_clz(w)) * 1233) >> 12;
    return t + (w >= pow10_32[t]);
}

/* v in decimal at p; returns the end.  The digits are written from the last
 * one backwards, two at a time (32-bit divisions by a constant: a multiply). */
static inline char *put_u32(char *p, uint32_t v)
{
    char *e = p + ndigits32(v), *q = e;
    while (v >= 100) {
        uint32_t r = v % 100;
        v /= 100;
        q -= 2;
        memcpy(q, digits2 + 2 * r, 2);
    }
    if (v >= 10) memcpy(q - 2, digits2 + 2 * v, 2);
    else q[-1] = (char)('0' + v);
    return e;
}

static inline char *put_u64(char *p, uint64_t v)
{
    if (v <= UINT32_MAX) return put_u32(p, (uint32_t)v);
    char t[24];
    int k = 0;
    do {
        t[k++] = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    while (k) *p++ = t[--k];
    return p;
}

static inline char *put_i64(char *p, int64_t v)
{
    if (v < 0) {
        *p++ = '-';
        return put_u64(p, (uint64_t)0 - (uint64_t)v);
    }
    return put_u64(p, (uint64_t)v);
}

static void wb_str(wbuf *w, const char *s)
{
    size_t len = strlen(s);
    if (w->n + len > WBUF) wb_flush(w);
    if (len > WBUF) {
        if (fwrite(s, 1, len, w->fp) != len) w->bad = 1;
        return;
    }
    memcpy(w->b + w->n, s, len);
    w->n += len;
}

/* k integers separated by spaces, then a newline. */
static void wb_ints(wbuf *w, const int64_t *v, int k)
{
    char *p = wb_room(w), *s = p;
    for (int i = 0; i < k; i++) {
        if (i) *p++ = ' ';
        p = put_i64(p, v[i]);
    }
    *p++ = '\n';
    w->n += (size_t)(p - s);
}

static int has_ext(const char *path, const char *ext)
{
    if (!path) return 0;
    size_t n = strlen(path), e = strlen(ext);
    return n >= e && strcmp(path + n - e, ext) == 0;
}

static pdt_status finish(pdt_outfile *o, wbuf *w, pdt_err *err)
{
    wb_flush(w);
    if (w->bad) {
        int e = errno;
        const char *name = o->path ? o->path : "standard output";
        pdt_err_set(err, PDT_ERR_IO, "%s: write error: %s", name, strerror(e));
        pdt_out_abort(o);
        return PDT_ERR_IO;
    }
    return pdt_out_commit(o, err);
}

/* ---- points ---------------------------------------------------------------- */

static void emit_points(wbuf *w, const pdt_point *pts, size_t n, int node)
{
    if (node) {
        int64_t h[4] = { (int64_t)n, 2, 0, 0 };
        wb_str(w, "# pdt: points, 0-based indices\n");
        wb_ints(w, h, 4);
    }
    for (size_t i = 0; i < n; i++) {
        int64_t v[3] = { (int64_t)i, pts[i].x, pts[i].y };
        if (node) wb_ints(w, v, 3);
        else wb_ints(w, v + 1, 2);
    }
}

pdt_status pdt_write_points(const char *path, const pdt_point *pts, size_t n, pdt_err *err)
{
    pdt_outfile o;
    pdt_status st = pdt_out_open(&o, path, err);
    if (st != PDT_OK) return st;
    wbuf *w = malloc(sizeof *w);
    if (!w) {
        pdt_out_abort(&o);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    w->fp = o.fp;
    w->n = 0;
    w->bad = 0;
    emit_points(w, pts, n, has_ext(path, ".node"));
    st = finish(&o, w, err);
    free(w);
    return st;
}

/* ---- triangles ----------------------------------------------------------- */

pdt_tri_format pdt_tri_format_of(const char *path)
{
    if (has_ext(path, ".ele")) return PDT_FMT_ELE;
    if (has_ext(path, ".off")) return PDT_FMT_OFF;
    return PDT_FMT_TRI;
}

static void emit_tris(wbuf *w, pdt_tri_format fmt, const pdt_point *pts, size_t n,
                      const pdt_tri *t, size_t ntri)
{
    if (fmt == PDT_FMT_ELE) {
        int64_t h[3] = { (int64_t)ntri, 3, 0 };
        wb_str(w, "# pdt: triangles, 0-based indices into the .node file\n");
        wb_ints(w, h, 3);
    } else if (fmt == PDT_FMT_OFF) {
        int64_t h[3] = { (int64_t)n, (int64_t)ntri, 0 };
        wb_str(w, "OFF\n");
        wb_ints(w, h, 3);
        for (size_t i = 0; i < n; i++) {
            int64_t v[3] = { pts[i].x, pts[i].y, 0 };
            wb_ints(w, v, 3);
        }
    }
    if (fmt == PDT_FMT_TRI) {
        for (size_t i = 0; i < ntri; i++) { /* the common case, without the int64 detour */
            char *p = wb_room(w), *s = p;
            p = put_u32(p, t[i].v[0]);
            *p++ = ' ';
            p = put_u32(p, t[i].v[1]);
            *p++ = ' ';
            p = put_u32(p, t[i].v[2]);
            *p++ = '\n';
            w->n += (size_t)(p - s);
        }
        return;
    }
    for (size_t i = 0; i < ntri; i++) {
        int64_t v[4] = { fmt == PDT_FMT_OFF ? 3 : (int64_t)i, t[i].v[0], t[i].v[1], t[i].v[2] };
        wb_ints(w, v, 4);
    }
}

/* "X.ele" -> "X.node" (malloc'd). */
static char *node_path_of(const char *ele)
{
    size_t n = strlen(ele);
    size_t stem = has_ext(ele, ".ele") ? n - 4 : n;
    char *p = malloc(stem + 6);
    if (!p) return NULL;
    memcpy(p, ele, stem);
    memcpy(p + stem, ".node", 6);
    return p;
}

pdt_status pdt_write_tris(const char *path, pdt_tri_format fmt, const pdt_point *pts, size_t n,
                          const pdt_tri *tris, size_t ntri, pdt_err *err)
{
    if ((fmt == PDT_FMT_ELE || fmt == PDT_FMT_OFF) && !pts && n > 0)
        return pdt_err_set(err, PDT_ERR_ARG, "writing .ele or .off needs the points");
    if (fmt == PDT_FMT_ELE && (!path || strcmp(path, "-") == 0))
        return pdt_err_set(err, PDT_ERR_ARG, ".ele output needs a file name (the .node goes "
                           "beside it)");
    wbuf *w = malloc(sizeof *w);
    if (!w) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    pdt_outfile o, onode;
    char *npath = NULL;
    pdt_status st = PDT_OK;
    onode.fp = NULL;
    if (fmt == PDT_FMT_ELE) {
        /* The .node first, but renamed into place only after the .ele is done. */
        npath = node_path_of(path);
        if (!npath) {
            free(w);
            return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
        }
        st = pdt_out_open(&onode, npath, err);
        if (st == PDT_OK) {
            w->fp = onode.fp;
            w->n = 0;
            w->bad = 0;
            emit_points(w, pts, n, 1);
            wb_flush(w);
            if (w->bad || fflush(onode.fp) != 0)
                st = pdt_err_set(err, PDT_ERR_IO, "%s: write error: %s", npath, strerror(errno));
        }
        if (st != PDT_OK) {
            if (onode.fp) pdt_out_abort(&onode);
            free(npath);
            free(w);
            return st;
        }
    }
    st = pdt_out_open(&o, path, err);
    if (st == PDT_OK) {
        w->fp = o.fp;
        w->n = 0;
        w->bad = 0;
        emit_tris(w, fmt, pts, n, tris, ntri);
        st = finish(&o, w, err);
    }
    if (fmt == PDT_FMT_ELE) {
        if (st == PDT_OK) st = pdt_out_commit(&onode, err);
        else pdt_out_abort(&onode);
    }
    free(npath);
    free(w);
    return st;
}
