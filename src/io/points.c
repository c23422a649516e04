/* pdt — reading and writing point files: plain text "x y" and Triangle's .node. */
#include "pdt/io.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io_internal.h"
#include "pdt/bigmem.h"

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
    pdt_big_advise(p, cap * sizeof *p);
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

static inline int blank(char ch)
{
    return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\v' || ch == '\f';
}

/* The leading decimal digits of the 8 bytes at p (all readable): how many
 * (0 to 8), and in *val their value.  Branch-free (SWAR): a byte is a digit
 * when its high nibble is 3 and its low one at most 9; the digits are moved
 * to the top bytes, behind zeros, and the eight folded pairwise (the
 * number's length changes from line to line: a loop over its digits
 * mispredicted its end about once a number). */
static inline unsigned swar_digits(const char *p, uint32_t *val)
{
    uint64_t w;
    memcpy(&w, p, 8);
    const uint64_t hi = UINT64_C(0xF0F0F0F0F0F0F0F0), lo = UINT64_C(0x0F0F0F0F0F0F0F0F);
    uint64_t bad = ((w & hi) ^ UINT64_C(0x3030303030303030)) | (((w & lo) + UINT64_C(0x0606060606060606)) & hi);
    unsigned n = bad ? (unsigned)__builtin_ctzll(bad) / 8 : 8;
    uint64_t d = n ? (w & lo) << (8 * (8 - n)) : 0; /* the first digit in byte 8 - n */
    d = (d * 10 + (d >> 8)) & UINT64_C(0x00FF00FF00FF00FF);        /* pairs */
    d = (d * 100 + (d >> 16)) & UINT64_C(0x0000FFFF0000FFFF);      /* fours */
    *val = (uint32_t)((d * 10000 + (d >> 32)) & UINT64_C(0xFFFFFFFF)); /* eight */
    return n;
}

/* [+-]digits, at most 10 digits, fitting in int32: the byte after it, or
 * NULL (then the general path reads the token and names what is wrong).
 * end: the text's end; up to 7 digits go the branch-free way when 8 bytes
 * can be read. */
static inline const char *fast_int(const char *p, const char *end, int32_t *v)
{
    int neg = *p == '-';
    if (*p == '-' || *p == '+') p++;
    const char *s = p;
    uint64_t acc = 0;
    unsigned d;
    uint32_t w;
    unsigned n = end - p >= 8 ? swar_digits(p, &w) : 8;
    if (n - 1 < 7) { /* 1 to 7 digits, and the byte after them is none */
        acc = w;
        p += n;
    } else {
        while ((d = (unsigned)(unsigned char)*p - '0') <= 9 && p - s < 11) {
            acc = acc * 10 + d;
            p++;
        }
    }
    if (p == s || p - s > 10 || acc > (uint64_t)INT32_MAX + (uint64_t)neg) return NULL;
    *v = neg ? (int32_t)(-(int64_t)acc) : (int32_t)acc;
    return p;
}

/* The common line of a point text file, "x y" of plain integers separated
 * by blanks and at most one ',' or ';', nothing after them, read in one
 * pass (the cursor at its first byte; the text ends with a '\0', as
 * pdt_io_load and pdt_points_part_load leave it).  Returns 1 (the point
 * appended, the cursor on the next line) or 0 (nothing moved: the general
 * path reads the line). */
static int fast_xy(reader *r)
{
    pdt_io_cur *c = &r->cur;
    pdt_point pt;
    const char *p = fast_int(c->p, c->end, &pt.x), *q;
    if (!p) return 0;
    for (q = p; blank(*q); q++) {}
    if (*q == ',' || *q == ';')
        for (q++; blank(*q); q++) {}
    else if (q == p)
        return 0; /* "12x", "12#", "12" alone */
    if (!(p = fast_int(q, c->end, &pt.y))) return 0;
    for (q = p; q < c->end && blank(*q); q++) {}
    if (q < c->end && *q != '\n') return 0; /* more on the line, or "12 13x" */
    r->pts[r->n++] = pt;
    if (q < c->end) {
        c->p = q + 1;
        c->line++;
    } else {
        c->p = q;
    }
    return 1;
}

/* The point lines of a text file from the cursor on (after the header);
 * on failure r->n counts the points of the lines before the bad one. */
static pdt_status text_lines(reader *r)
{
    while (pdt_io_next_line(&r->cur)) {
        if (r->scale == 0 && r->n < r->cap && r->n < UINT32_MAX - 1 && fast_xy(r)) continue;
        size_t before = r->n;
        pdt_status st = point_xy(r);
        if (st == PDT_OK)
            st = pdt_io_end_line(&r->cur, "the coordinates (one point 'x y' per line)", r->err);
        if (st != PDT_OK) {
            r->n = before;
            return st;
        }
    }
    return PDT_OK;
}

/* One point per line: "x y", "x,y", "x;y" or "x<TAB>y", after an optional
 * header line naming the columns. */
static pdt_status read_text(reader *r)
{
    r->cur.fields = 1;
    if (pdt_io_next_line(&r->cur)) skip_header(r);
    return text_lines(r);
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

/* The .node header line (the cursor at its first byte): point count,
 * dimension 2, attribute and boundary-marker counts (the last two optional). */
static pdt_status node_header(reader *r, int64_t *count, int64_t *nattr, int64_t *nmark)
{
    pdt_io_cur *c = &r->cur;
    pdt_err *err = r->err;
    int64_t dim;
    pdt_status st;
    if ((st = header_int(c, "point count in the .node header", count, err)) != PDT_OK ||
        (st = header_int(c, "dimension in the .node header", &dim, err)) != PDT_OK)
        return st;
    if (dim != 2)
        return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: .node header says dimension %lld; only 2 "
                           "is supported", c->name, c->line, (long long)dim);
    /* Attributes and markers may be omitted (Triangle reads them as 0). */
    const char *save = c->p;
    const char *tok;
    size_t len;
    *nattr = *nmark = 0;
    if (pdt_io_token(c, &tok, &len)) {
        c->p = save;
        if ((st = header_int(c, "attribute count in the .node header", nattr, err)) != PDT_OK)
            return st;
        save = c->p;
        if (pdt_io_token(c, &tok, &len)) {
            c->p = save;
            if ((st = header_int(c, "boundary marker count in the .node header", nmark, err)) !=
                PDT_OK)
                return st;
            if (*nmark > 1)
                return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: .node header says %lld boundary "
                                   "markers; must be 0 or 1", c->name, c->line, (long long)*nmark);
        }
    }
    if (*count >= UINT32_MAX)  /* before pdt_io_end_line, which moves to the next line */
        return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: too many points (at most %u)", c->name,
                           c->line, (unsigned)(UINT32_MAX - 1));
    return pdt_io_end_line(&r->cur, "the .node header (count, 2, attributes, markers)", r->err);
}

/* Its index, checked against *base (the first point's index): point i of
 * the file (whole = 1: the first must be 0 or 1) or of a part (whole = 0:
 * the first index is any, checked later with pdt_points_part_check). */
static pdt_status node_index(reader *r, int64_t i, int64_t *base, int whole)
{
    pdt_io_cur *c = &r->cur;
    int64_t idx;
    pdt_status st = header_int(c, "point index", &idx, r->err);
    if (st != PDT_OK) return st;
    if (i == 0) {
        if (whole && idx != 0 && idx != 1)
            return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: first point index is %lld; must "
                               "be 0 or 1", c->name, c->line, (long long)idx);
        *base = idx;
    } else if (idx != *base + i) {
        return pdt_err_set(r->err, PDT_ERR_PARSE, "%s:%zu: point index %lld out of order "
                           "(expected %lld)", c->name, c->line, (long long)idx,
                           (long long)(*base + i));
    }
    return PDT_OK;
}

/* The rest of a point line of a .node file: "x y", attributes, marker. */
static pdt_status node_rest(reader *r, int64_t nattr, int64_t nmark)
{
    pdt_io_cur *c = &r->cur;
    pdt_err *err = r->err;
    const char *tok;
    size_t len;
    pdt_status st = point_xy(r);
    if (st != PDT_OK) return st;
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
    return pdt_io_end_line(&r->cur, "the point (index x y, attributes, marker)", r->err);
}

static pdt_status read_node(reader *r)
{
    pdt_io_cur *c = &r->cur;
    pdt_err *err = r->err;
    int64_t count, nattr, nmark;
    pdt_status st;
    if (!pdt_io_next_line(c))
        return PDT_OK; /* an empty file: no points */
    if ((st = node_header(r, &count, &nattr, &nmark)) != PDT_OK) return st;
    int64_t base = 0;
    for (int64_t i = 0; i < count; i++) {
        if (!pdt_io_next_line(c))
            return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: file ends after %lld of the %lld "
                               "points the header announces", c->name, c->line, (long long)i,
                               (long long)count);
        if ((st = node_index(r, i, &base, 1)) != PDT_OK ||
            (st = node_rest(r, nattr, nmark)) != PDT_OK)
            return st;
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

/* The number of newlines in b[0, len). */
/* The '\n' bytes of b[0, len): counted in blocks whose sums fit 32 bits, a
 * loop the compiler turns into vector instructions (a 70 MB part: 18 ms
 * instead of 43 with the plain byte loop). */
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("tree-vectorize", "vect-cost-model=dynamic")))
#endif
static uint64_t count_nl(const char *b, size_t len)
{
    uint64_t k = 0;
    for (size_t i = 0; i < len;) {
        size_t end = len - i > 65536 ? i + 65536 : len;
        uint32_t s = 0;
        for (; i < end; i++) s += (uint8_t)(b[i] == '\n');
        k += s;
    }
    return k;
}

/* Arrays below this are not worth a thread faulting them in. */
enum { PREFAULT_MIN = 8 << 20 };

/* With PDT_READ_PREFAULT, a thread that faults r's point array in ahead of
 * the parser (NULL: none). */
static pdt_prefault *prefault_points(const reader *r, int flags)
{
    size_t bytes = r->cap * sizeof *r->pts;
    if (!(flags & PDT_READ_PREFAULT) || bytes < PREFAULT_MIN) return NULL;
    pdt_range all = {r->pts, bytes};
    return pdt_prefault_start(&all, 1);
}

pdt_status pdt_read_points(const char *path, double scale, pdt_point **pts, size_t *n,
                           size_t *collisions, pdt_err *err)
{
    return pdt_read_points_ex(path, scale, 0, pts, n, collisions, err);
}

pdt_status pdt_read_points_ex(const char *path, double scale, int flags, pdt_point **pts,
                              size_t *n, size_t *collisions, pdt_err *err)
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
    const char *name = strcmp(path, "-") == 0 ? "standard input" : path;
    /* at most one point per line (lines end at '\n'): one allocation (growing
     * it by doubling copied it) */
    r.cap = (size_t)count_nl(t.buf, t.len) + 1;
    r.pts = malloc(r.cap * sizeof *r.pts);
    if (scale > 0) r.orig = malloc(2 * r.cap * sizeof *r.orig);
    if (!r.pts || (scale > 0 && !r.orig)) {
        pdt_io_text_free(&t);
        free(r.pts);
        free(r.orig);
        return pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", name);
    }
    pdt_big_advise(r.pts, r.cap * sizeof *r.pts);
    pdt_prefault *pf = prefault_points(&r, flags);
    pdt_io_cur_init(&r.cur, &t, name);
    st = has_ext(path, ".node") ? read_node(&r) : read_text(&r);
    pdt_prefault_stop(pf);
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

/* ---- a file read in parts (pdt/io.h; pdt_par_read) ----------------------------- */

/* Read len bytes at byte off of fd into buf. */
static pdt_status pread_full(int fd, char *buf, size_t len, uint64_t off, const char *name,
                             pdt_err *err)
{
    while (len) {
        ssize_t k = pread(fd, buf, len, (off_t)off);
        if (k < 0 && errno == EINTR) continue;
        if (k < 0)
            return pdt_err_set(err, PDT_ERR_IO, "%s: read error: %s", name, strerror(errno));
        if (k == 0)
            return pdt_err_set(err, PDT_ERR_IO, "%s: read error: the file became shorter",
                               name);
        buf += k;
        len -= (size_t)k;
        off += (uint64_t)k;
    }
    return PDT_OK;
}

static pdt_status open_input(const char *path, int *fd, pdt_err *err)
{
    char why[160];
    *fd = pdt_open_input(path, why, sizeof why);
    if (*fd < 0) return pdt_err_set(err, PDT_ERR_IO, "%s: %s", path, why);
    return PDT_OK;
}

/* The cursor of a part: the bytes [0, len) of buf, line numbers from line0
 * (no byte-order mark: that is the head's business). */
static void part_cursor(pdt_io_cur *c, const char *buf, size_t len, const char *name,
                        uint64_t line0, int node)
{
    c->p = buf;
    c->end = buf + len;
    c->name = name;
    c->line = (size_t)line0;
    c->done = 0;
    c->fields = !node;
}

/* Where the body starts after the text's first line that holds something
 * (the cursor at its first byte): after it if it is a header (text) or the
 * .node header, else at the cursor's start. */
static pdt_status head_body(reader *r, pdt_points_head *h, const char *buf)
{
    if (h->node) {
        pdt_status st = node_header(r, &h->count, &h->nattr, &h->nmark);
        if (st != PDT_OK) return st;
        h->body = (uint64_t)(r->cur.p - buf);
        return PDT_OK;
    }
    const char *at = r->cur.p;
    skip_header(r);
    h->body = r->cur.p != at ? (uint64_t)(r->cur.p - buf) : 0;
    return PDT_OK;
}

/* One look at the file's first len bytes, buf[0, len] (room for the zero
 * byte): 1 when its first line with something on it is whole (h->body,
 * body_nl and last_nl set; *st an error in that line, if any), 0 to look at
 * more, -1 when it is no text of pdt's (*st says so). */
static int head_try(char *buf, size_t len, const char *path, double scale, pdt_points_head *h,
                    pdt_status *st, pdt_err *err)
{
    buf[len] = '\0';
    pdt_io_text t = {buf, len, 0, NULL};
    reader r = {.scale = scale, .err = err};
    pdt_io_cur_init(&r.cur, &t, path);
    r.cur.fields = !h->node;
    int some = pdt_io_next_line(&r.cur);
    int whole = len == h->size;
    if (whole || (some && memchr(r.cur.p, '\n', (size_t)(r.cur.end - r.cur.p)))) {
        if (some) *st = head_body(&r, h, buf);
        else h->body = len;
        if (*st == PDT_OK && h->body == 0 && r.cur.end - buf >= 3 &&
            memcmp(buf, "\xEF\xBB\xBF", 3) == 0)
            h->body = 3;
        h->body_nl = count_nl(buf, (size_t)h->body);
        h->last_nl = buf[len - 1] == '\n';
        return 1;
    }
    if (len >= PDT_IO_LINE_SPAN && /* (a line of garbage: not read on to the end) */
        !memchr(buf + len - PDT_IO_LINE_SPAN, '\n', PDT_IO_LINE_SPAN)) {
        *st = pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: no end of line in %zu bytes: not a "
                          "text file of pdt's", path, (size_t)count_nl(buf, len) + 1,
                          PDT_IO_LINE_SPAN);
        return -1;
    }
    return 0;
}

/* The start of the regular file fd (h->size bytes), read longer until its
 * first line with something on it is whole (head_try); then whether the
 * file ends with a newline. */
static pdt_status head_scan(int fd, const char *path, double scale, pdt_points_head *h,
                            pdt_err *err)
{
    pdt_status st = PDT_OK;
    char *buf = NULL;
    size_t len = h->size < 65536 ? (size_t)h->size : 65536;
    for (;;) {
        char *nb = realloc(buf, len + 1);
        if (!nb) {
            st = pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", path);
            break;
        }
        buf = nb;
        if ((st = pread_full(fd, buf, len, 0, path, err)) != PDT_OK) break;
        if (head_try(buf, len, path, scale, h, &st, err) != 0) break;
        len = h->size - len < len ? (size_t)h->size : 2 * len;
    }
    free(buf);
    if (st == PDT_OK && len < h->size) {
        char last;
        st = pread_full(fd, &last, 1, h->size - 1, path, err);
        h->last_nl = last == '\n';
    }
    return st;
}

pdt_status pdt_points_head_read(const char *path, double scale, pdt_points_head *h,
                                pdt_err *err)
{
    memset(h, 0, sizeof *h);
    h->count = -1;
    if (!path) return pdt_err_set(err, PDT_ERR_ARG, "no input file given");
    if (!(scale == 0 || (scale > 0 && isfinite(scale))))
        return pdt_err_set(err, PDT_ERR_ARG, "scale must be a positive number (got %g)", scale);
    if (strcmp(path, "-") == 0) return PDT_OK;
    int fd;
    pdt_status st = open_input(path, &fd, err);
    if (st != PDT_OK) return st;
    struct stat sb;
    if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode) || sb.st_size <= 0) {
        close(fd); /* read whole (pdt_read_points names what is wrong) */
        return PDT_OK;
    }
    h->parts = 1;
    h->node = has_ext(path, ".node");
    h->size = (uint64_t)sb.st_size;
    st = head_scan(fd, path, scale, h, err);
    close(fd);
    return st;
}

/* The first byte at or after s that starts a line: 0, 1 + the first '\n'
 * at or after s - 1, or the size. */
static pdt_status line_start(int fd, uint64_t size, uint64_t s, uint64_t *ls, const char *name,
                             pdt_err *err)
{
    char blk[4096];
    if (s == 0 || s >= size) {
        *ls = s == 0 ? 0 : size;
        return PDT_OK;
    }
    for (uint64_t at = s - 1; at < size; at += sizeof blk) {
        size_t k = size - at < sizeof blk ? (size_t)(size - at) : sizeof blk;
        pdt_status st = pread_full(fd, blk, k, at, name, err);
        if (st != PDT_OK) return st;
        const char *nl = memchr(blk, '\n', k);
        if (nl) {
            *ls = at + (uint64_t)(nl - blk) + 1;
            return PDT_OK;
        }
    }
    *ls = size;
    return PDT_OK;
}

pdt_status pdt_points_part_load(const char *path, const pdt_points_head *h, int q, int p,
                                pdt_points_part *pt, pdt_err *err)
{
    memset(pt, 0, sizeof *pt);
    pt->err_key = 0;
    int fd;
    pdt_status st = open_input(path, &fd, err);
    if (st != PDT_OK) return st;
    uint64_t s0 = (uint64_t)((unsigned __int128)h->size * (unsigned)q / (unsigned)p);
    uint64_t s1 = (uint64_t)((unsigned __int128)h->size * (unsigned)(q + 1) / (unsigned)p);
    uint64_t lo = 0, hi = h->size;
    st = line_start(fd, h->size, s0, &lo, path, err);
    if (st == PDT_OK && q + 1 < p) st = line_start(fd, h->size, s1, &hi, path, err);
    if (st == PDT_OK) {
        if (lo < h->body) lo = h->body;
        if (hi < lo) hi = lo;
        pt->lo = lo;
        pt->hi = hi;
    }
    pdt_io_text map;
    if (st == PDT_OK && pdt_io_map_part(fd, lo, hi, &map) == 0) {
        /* the file's page-cache pages as they are: no fresh memory */
        close(fd);
        pt->buf = map.buf;
        pt->map = map.map_base;
        pt->maplen = map.mapped;
        pt->nl = count_nl(pt->buf, (size_t)(hi - lo));
        pt->err_key = UINT64_MAX;
        return PDT_OK;
    }
    if (st == PDT_OK) {
        if (!(pt->buf = malloc((size_t)(hi - lo) + 1)))
            st = pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory (%llu bytes)", path,
                             (unsigned long long)(hi - lo));
        else
            pdt_big_advise(pt->buf, (size_t)(hi - lo) + 1);
    }
    if (st == PDT_OK) st = pread_full(fd, pt->buf, (size_t)(hi - lo), lo, path, err);
    close(fd);
    if (st != PDT_OK) {
        free(pt->buf);
        pt->buf = NULL;
        return st;
    }
    pt->buf[hi - lo] = '\0';
    pt->nl = count_nl(pt->buf, (size_t)(hi - lo));
    pt->err_key = UINT64_MAX;
    return PDT_OK;
}

/* The points of a .node part: whole lines "index x y [attributes] [marker]". */
static pdt_status part_node(reader *r, const pdt_points_head *h, pdt_points_part *pt)
{
    int64_t base = 0;
    for (int64_t i = 0; pdt_io_next_line(&r->cur); i++) {
        pdt_status st = node_index(r, i, &base, 0);
        if (st == PDT_OK && i == 0) {
            pt->has_idx0 = 1;
            pt->idx0 = base;
        }
        if (st == PDT_OK) st = node_rest(r, h->nattr, h->nmark);
        if (st != PDT_OK) {
            r->n = (size_t)i; /* the points of the lines before the bad one */
            return st;
        }
    }
    return PDT_OK;
}

pdt_status pdt_points_part_parse(pdt_points_part *pt, const char *path, const pdt_points_head *h,
                                 double scale, uint64_t line0, int flags, pdt_err *err)
{
    reader r = {.scale = scale, .err = err};
    size_t len = (size_t)(pt->hi - pt->lo);
    part_cursor(&r.cur, pt->buf, len, path, line0, h->node);
    pt->line0 = line0;
    /* at most one point per line: one allocation */
    r.cap = (size_t)pt->nl + 1;
    r.pts = malloc(r.cap * sizeof *r.pts);
    if (r.pts) pdt_big_advise(r.pts, r.cap * sizeof *r.pts);
    if (scale > 0) r.orig = malloc(2 * r.cap * sizeof *r.orig);
    pdt_status st = PDT_OK;
    pdt_prefault *pf = r.pts ? prefault_points(&r, flags) : NULL;
    if (!r.pts || (scale > 0 && !r.orig)) {
        st = pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", path);
        pt->err_key = 0;
    } else if (len == 0) {
        /* no line starts here */
    } else if (h->node) {
        st = part_node(&r, h, pt);
    } else {
        st = text_lines(&r);
    }
    pdt_prefault_stop(pf);
    if (st != PDT_OK && pt->err_key != 0)
        pt->err_key = st == PDT_ERR_PARSE ? (uint64_t)r.cur.line * 4 + 2 : 0;
    pt->pts = r.pts;
    pt->orig = r.orig;
    pt->n = r.n;
    return st;
}

/* The line of the part's point k (k <= points parsed). */
static uint64_t part_point_line(const pdt_points_part *pt, const pdt_points_head *h, size_t k)
{
    pdt_io_cur c;
    if (pt->hi == pt->lo) return pt->line0;
    part_cursor(&c, pt->buf, (size_t)(pt->hi - pt->lo), "", pt->line0, h->node);
    for (size_t i = 0; pdt_io_next_line(&c) && i < k; i++) pdt_io_skip_line(&c);
    return c.line;
}

/* Keep the failure of smallest key: *key and *err become (k, e) if k is smaller. */
static void keep_first(uint64_t *key, pdt_err *err, uint64_t k, const pdt_err *e)
{
    if (k < *key) {
        *key = k;
        *err = *e;
    }
}

pdt_status pdt_points_part_check(pdt_points_part *pt, const char *path, const pdt_points_head *h,
                                 uint64_t first, uint64_t total, int64_t base, int last,
                                 uint64_t last_line, pdt_err *err)
{
    if (!h->node || pt->err_key == 0) return pt->err_key == UINT64_MAX ? PDT_OK : err->code;
    pdt_err e;
    uint64_t count = (uint64_t)h->count, line;
    int parse_failed = pt->err_key != UINT64_MAX;
    /* as a whole read: the line after the count is "more points" whatever it holds */
    if (h->count >= 0 && count >= first &&
        (count - first < pt->n || (parse_failed && count - first == pt->n))) {
        line = count - first < pt->n ? part_point_line(pt, h, (size_t)(count - first))
                                     : pt->err_key / 4;
        pdt_err_clear(&e);
        pdt_err_set(&e, PDT_ERR_PARSE, "%s:%llu: more points than the %lld the header "
                    "announces", path, (unsigned long long)line, (long long)h->count);
        keep_first(&pt->err_key, err, line * 4, &e);
    }
    if (pt->has_idx0 && first == 0 && pt->idx0 != 0 && pt->idx0 != 1) {
        line = part_point_line(pt, h, 0);
        pdt_err_clear(&e);
        pdt_err_set(&e, PDT_ERR_PARSE, "%s:%llu: first point index is %lld; must be 0 or 1",
                    path, (unsigned long long)line, (long long)pt->idx0);
        keep_first(&pt->err_key, err, line * 4 + 1, &e);
    } else if (pt->has_idx0 && first > 0 && pt->idx0 != base + (int64_t)first) {
        line = part_point_line(pt, h, 0);
        pdt_err_clear(&e);
        pdt_err_set(&e, PDT_ERR_PARSE, "%s:%llu: point index %lld out of order (expected %lld)",
                    path, (unsigned long long)line, (long long)pt->idx0,
                    (long long)(base + (int64_t)first));
        keep_first(&pt->err_key, err, line * 4 + 1, &e);
    }
    if (last && h->count >= 0 && total < count) {
        pdt_err_clear(&e);
        pdt_err_set(&e, PDT_ERR_PARSE, "%s:%llu: file ends after %llu of the %lld points the "
                    "header announces", path, (unsigned long long)last_line,
                    (unsigned long long)total, (long long)h->count);
        keep_first(&pt->err_key, err, last_line * 4 + 3, &e);
    }
    return pt->err_key == UINT64_MAX ? PDT_OK : err->code;
}

_Static_assert(sizeof(pdt_io_dec) == 16, "two values as written fill as_written");

pdt_status pdt_points_part_written(const pdt_points_part *pt, pdt_points_written **w,
                                   pdt_err *err)
{
    *w = calloc(pt->n + 1, sizeof **w);
    if (!*w) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    const pdt_io_dec *o = pt->orig;
    for (size_t i = 0; i < pt->n; i++) {
        (*w)[i].p = pt->pts[i];
        for (int k = 0; k < 2; k++) { /* field by field: no padding bytes of ours */
            pdt_io_dec d;
            memset(&d, 0, sizeof d);
            d.m = o[2 * i + k].m;
            d.e = o[2 * i + k].e;
            d.neg = o[2 * i + k].neg;
            d.inexact = o[2 * i + k].inexact;
            memcpy((*w)[i].as_written + 16 * k, &d, sizeof d);
        }
    }
    return PDT_OK;
}

static int written_cmp(const void *pa, const void *pb)
{
    const pdt_points_written *a = pa, *b = pb;
    uint64_t ka = pdt_key(a->p), kb = pdt_key(b->p);
    if (ka != kb) return ka < kb ? -1 : 1;
    pdt_io_dec da[2], db[2];
    memcpy(da, a->as_written, sizeof da);
    memcpy(db, b->as_written, sizeof db);
    int c = dec_cmp(&da[0], &db[0]);
    return c ? c : dec_cmp(&da[1], &db[1]);
}

pdt_status pdt_points_collisions(pdt_points_written *w, size_t n, uint64_t *collisions,
                                 pdt_err *err)
{
    (void)err;
    *collisions = 0;
    if (n < 2) return PDT_OK;
    qsort(w, n, sizeof *w, written_cmp);
    for (size_t i = 1; i < n; i++)
        if (pdt_key(w[i].p) == pdt_key(w[i - 1].p) && written_cmp(&w[i], &w[i - 1]) != 0)
            (*collisions)++;
    return PDT_OK;
}

void pdt_points_part_free(pdt_points_part *pt)
{
    if (pt->maplen) munmap(pt->map, pt->maplen);
    else free(pt->buf);
    free(pt->pts);
    free(pt->orig);
    memset(pt, 0, sizeof *pt);
}
