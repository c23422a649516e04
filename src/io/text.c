/* pdt — loading a text file and scanning it line by line (see io_internal.h). */
#include "io_internal.h"

#include "pdt/bigmem.h"
#include "pdt/io.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- loading -------------------------------------------------------------- */

enum { MAP_MIN = 1 << 20 };

/* The line number of byte `at` of buf (1 + the newlines before it). */
static size_t line_of(const char *buf, size_t at)
{
    size_t line = 1;
    for (const char *p = buf, *e = buf + at; (p = memchr(p, '\n', (size_t)(e - p))); p++) line++;
    return line;
}

/* Read fd to its end into a malloc'd buffer (room for a '\0' after it):
 * cap bytes to start with, grown by doubling.  A stretch of more than
 * PDT_IO_LINE_SPAN bytes with no '\n' stops the read with an error naming
 * the line (a stream of /dev/zero or of garbage would otherwise be read
 * into memory without bound). */
static pdt_status read_stream(int fd, const char *name, size_t cap, pdt_io_text *t, pdt_err *err)
{
    char *buf = malloc(cap);
    if (!buf) return pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory (%zu bytes)", name, cap);
    pdt_big_advise(buf, cap);
    size_t len = 0, ls = 0; /* ls: where the last line seen starts */
    pdt_status st = PDT_OK;
    for (;;) {
        if (cap - len < 2) {
            size_t ncap = cap * 2;
            char *nb = ncap > cap ? realloc(buf, ncap) : NULL;
            if (!nb) {
                st = pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", name);
                break;
            }
            buf = nb;
            cap = ncap;
            pdt_big_advise(buf, cap);
        }
        ssize_t r = read(fd, buf + len, cap - len - 1);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) {
            st = pdt_err_set(err, PDT_ERR_IO, "%s: read error: %s", name, strerror(errno));
            break;
        }
        if (r == 0) break;
        const char *nl = memrchr(buf + len, '\n', (size_t)r);
        len += (size_t)r;
        if (nl) ls = (size_t)(nl - buf) + 1;
        if (len - ls > PDT_IO_LINE_SPAN) {
            st = pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: no end of line in %zu bytes: not a "
                             "text file of pdt's", name, line_of(buf, ls), PDT_IO_LINE_SPAN);
            break;
        }
    }
    if (st != PDT_OK) {
        free(buf);
        return st;
    }
    buf[len] = '\0';
    t->buf = buf;
    t->len = len;
    return PDT_OK;
}

pdt_status pdt_io_load(const char *path, pdt_io_text *t, pdt_err *err)
{
    t->buf = NULL;
    t->len = 0;
    t->mapped = 0;
    t->map_base = NULL;
    int is_stdin = strcmp(path, "-") == 0;
    const char *name = is_stdin ? "standard input" : path;
    char why[160];
    int fd = is_stdin ? STDIN_FILENO : pdt_open_input(path, why, sizeof why);
    if (fd < 0) return pdt_err_set(err, PDT_ERR_IO, "%s: %s", name, why);
    struct stat sb;
    if (fstat(fd, &sb) != 0) {
        int e = errno;
        if (!is_stdin) close(fd);
        return pdt_err_set(err, PDT_ERR_IO, "%s: cannot read: %s", name, strerror(e));
    }
    if (S_ISDIR(sb.st_mode)) {
        if (!is_stdin) close(fd);
        return pdt_err_set(err, PDT_ERR_IO, "%s: is a directory", name);
    }
    /* Large regular files: mapped (reading them copied the file into as
     * much fresh memory, whose first touch is dear: 0.2-0.3 s at 10^7
     * points on this project's VM).  Other regular files: one allocation
     * of the right size (room for the byte the read that finds the end asks
     * for, and the '\0'); standard input from a pipe or device: grow. */
    pdt_status st = PDT_OK;
    if (!(S_ISREG(sb.st_mode) && pdt_io_map_part(fd, 0, (uint64_t)sb.st_size, t) == 0))
        st = read_stream(fd, name,
                         S_ISREG(sb.st_mode) && sb.st_size > 0 ? (size_t)sb.st_size + 2 : 65536,
                         t, err);
    if (!is_stdin) close(fd);
    return st;
}

/* (Also the whole file: lo = 0, hi = its size; the byte after its end is a
 * zero already, in its last page or in the anonymous page after it.)  The
 * page-cache pages are mapped in one call (MAP_POPULATE), not one fault per
 * 64 KiB as the parser reaches them. */
int pdt_io_map_part(int fd, uint64_t lo, uint64_t hi, pdt_io_text *t)
{
    size_t pg = (size_t)sysconf(_SC_PAGESIZE);
    struct stat sb;
    if (hi < lo || hi - lo < MAP_MIN || hi - lo >= SIZE_MAX / 2) return -1;
    if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode) || (uint64_t)sb.st_size < hi) return -1;
    uint64_t lo_al = lo / pg * pg;
    size_t span = (size_t)(hi - lo_al), fbytes = (span + pg - 1) / pg * pg;
    size_t total = span / pg * pg + pg; /* room for the zero byte at span */
    char *a = mmap(NULL, total, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (a == MAP_FAILED) return -1;
    if (mmap(a, fbytes, PROT_READ, MAP_PRIVATE | MAP_FIXED | MAP_POPULATE, fd, (off_t)lo_al) ==
        MAP_FAILED) {
        munmap(a, total);
        return -1;
    }
    madvise(a, fbytes, MADV_SEQUENTIAL);
    /* byte hi: past the file's end (zero), in the anonymous page (zero), or
     * the next part's first byte, in a page made private to hold the zero */
    char *z = a + span, *zp = a + span / pg * pg;
    if (*z != '\0') {
        if (mprotect(zp, pg, PROT_READ | PROT_WRITE) != 0) {
            munmap(a, total);
            return -1;
        }
        *z = '\0';
        mprotect(zp, pg, PROT_READ);
    }
    t->buf = a + (lo - lo_al);
    t->len = (size_t)(hi - lo);
    t->mapped = total;
    t->map_base = a;
    return 0;
}

void pdt_io_text_free(pdt_io_text *t)
{
    if (t->mapped) munmap(t->map_base ? t->map_base : t->buf, t->mapped);
    else free(t->buf);
    t->map_base = NULL;
    t->mapped = 0;
    t->buf = NULL;
    t->len = 0;
}

/* ---- the line cursor ------------------------------------------------------ */

static inline int is_blank(char ch)
{
    return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\v' || ch == '\f';
}

void pdt_io_cur_init(pdt_io_cur *c, const pdt_io_text *t, const char *name)
{
    c->p = t->buf;
    c->end = t->buf + t->len;
    c->name = name;
    c->line = 1;
    c->done = 0;
    c->fields = 0;
    /* A UTF-8 byte-order mark at the start is not part of the data. */
    if (t->len >= 3 && memcmp(t->buf, "\xEF\xBB\xBF", 3) == 0) c->p += 3;
}

void pdt_io_skip_line(pdt_io_cur *c)
{
    const char *nl = memchr(c->p, '\n', (size_t)(c->end - c->p));
    if (nl) {
        c->p = nl + 1;
        c->line++;
    } else {
        c->p = c->end;
    }
}

int pdt_io_next_line(pdt_io_cur *c)
{
    const char *p = c->p, *end = c->end;
    while (p < end) {
        while (p < end && is_blank(*p)) p++;
        if (p == end) break;
        if (*p == '\n') {
            p++;
            c->line++;
            continue;
        }
        if (*p == '#') {
            c->p = p;
            pdt_io_skip_line(c);
            p = c->p;
            continue;
        }
        c->p = p;
        return 1;
    }
    /* At the end: name the last line, not the empty one after its '\n'. */
    if (!c->done && c->line > 1 && end[-1] == '\n') c->line--;
    c->done = 1;
    c->p = end;
    return 0;
}

static inline int is_sep(char ch)
{
    return ch == ',' || ch == ';';
}

int pdt_io_token(pdt_io_cur *c, const char **tok, size_t *len)
{
    const char *p = c->p, *end = c->end;
    while (p < end && is_blank(*p)) p++;
    if (p == end || *p == '\n' || *p == '#' || (c->fields && is_sep(*p))) {
        c->p = p;
        return 0;
    }
    const char *s = p;
    if (c->fields)
        while (p < end && !is_blank(*p) && *p != '\n' && *p != '#' && !is_sep(*p)) p++;
    else
        while (p < end && !is_blank(*p) && *p != '\n' && *p != '#') p++;
    *tok = s;
    *len = (size_t)(p - s);
    c->p = p;
    return 1;
}

void pdt_io_field_sep(pdt_io_cur *c)
{
    const char *p = c->p, *end = c->end;
    while (p < end && is_blank(*p)) p++;
    if (c->fields && p < end && is_sep(*p)) p++;
    c->p = p;
}

/* ---- numbers ---------------------------------------------------------------- */

int pdt_io_parse_int(const char *tok, size_t len, int64_t *v)
{
    size_t i = 0;
    int neg = 0;
    if (i < len && (tok[i] == '+' || tok[i] == '-')) neg = tok[i++] == '-';
    if (i == len) return 1;
    uint64_t acc = 0;
    int digits = 0, too_long = 0;
    for (; i < len; i++) {
        unsigned d = (unsigned)(unsigned char)tok[i] - '0';
        if (d > 9) return 1;
        if (acc == 0 && d == 0) continue; /* leading zeros do not count */
        if (++digits > 18) too_long = 1;
        else acc = acc * 10 + d;
    }
    if (too_long) {
        *v = neg ? INT64_MIN : INT64_MAX;
        return 2;
    }
    *v = neg ? -(int64_t)acc : (int64_t)acc;
    return 0;
}

/* The digits of a mantissa from tok[*i] on: the integer part, then a
 * fraction after a point, into d->m (at most 19 significant digits; a
 * dropped one sets d->inexact) with *e the power of ten they leave.
 * Returns whether there was any digit. */
static int dec_mantissa(const char *tok, size_t len, size_t *i, pdt_io_dec *d, int64_t *e)
{
    int sig = 0, seen_digit = 0;
    size_t k = *i;
    for (; k < len && tok[k] >= '0' && tok[k] <= '9'; k++) {
        seen_digit = 1;
        unsigned dg = (unsigned)(tok[k] - '0');
        if (d->m == 0 && dg == 0) continue;
        if (sig < 19) {
            d->m = d->m * 10 + dg;
            sig++;
        } else {
            (*e)++; /* a dropped digit before the point scales by 10 */
            if (dg) d->inexact = 1;
        }
    }
    if (k < len && tok[k] == '.') {
        for (k++; k < len && tok[k] >= '0' && tok[k] <= '9'; k++) {
            seen_digit = 1;
            unsigned dg = (unsigned)(tok[k] - '0');
            if (d->m == 0 && dg == 0) {
                (*e)--;
                continue;
            }
            if (sig < 19) {
                d->m = d->m * 10 + dg;
                sig++;
                (*e)--;
            } else if (dg) {
                d->inexact = 1;
            }
        }
    }
    *i = k;
    return seen_digit;
}

/* An exponent "e[+-]digits" at tok[*i], if there is one, added to *e
 * (digits stop counting once it reaches 10^8; the caller clamps e).
 * Returns 1 if it has no digits. */
static int dec_exponent(const char *tok, size_t len, size_t *i, int64_t *e)
{
    size_t k = *i;
    if (!(k < len && (tok[k] == 'e' || tok[k] == 'E'))) return 0;
    k++;
    int eneg = 0;
    if (k < len && (tok[k] == '+' || tok[k] == '-')) eneg = tok[k++] == '-';
    if (k == len) return 1;
    int64_t x = 0;
    for (; k < len && tok[k] >= '0' && tok[k] <= '9'; k++)
        if (x < 100000000) x = x * 10 + (tok[k] - '0');
    *e += eneg ? -x : x;
    *i = k;
    return 0;
}

int pdt_io_parse_dec(const char *tok, size_t len, pdt_io_dec *d)
{
    size_t i = 0;
    d->m = 0;
    d->e = 0;
    d->neg = 0;
    d->inexact = 0;
    if (i < len && (tok[i] == '+' || tok[i] == '-')) d->neg = tok[i++] == '-';
    int64_t e = 0;
    if (!dec_mantissa(tok, len, &i, d, &e)) return 1;
    if (dec_exponent(tok, len, &i, &e) || i != len) return 1;
    if (d->m == 0) { /* one zero: no sign, no exponent */
        d->e = 0;
        d->neg = 0;
        return 0;
    }
    while (d->m % 10 == 0) {
        d->m /= 10;
        e++;
    }
    if (e > 1000000000) e = 1000000000;
    if (e < -1000000000) e = -1000000000;
    d->e = (int32_t)e;
    return 0;
}

int pdt_io_is_decimal(const char *tok, size_t len)
{
    pdt_io_dec d;
    return pdt_io_parse_dec(tok, len, &d) == 0;
}

int pdt_io_scale_round(const pdt_io_dec *d, const char *tok, size_t len, double scale,
                       int32_t *v)
{
    const __int128 lim = (__int128)1 << 33; /* well past int32: "out of range" */
    if (d->m == 0) {
        *v = 0;
        return 0;
    }
    if (!d->inexact && scale >= 1 && scale <= 4294967296.0 && scale == floor(scale)) {
        /* Exact: m * K * 10^e with m < 10^19 and K <= 2^32, so m*K < 2^96. */
        __int128 q = (__int128)d->m * (__int128)(uint64_t)scale;
        if (d->e >= 0) {
            for (int32_t k = 0; k < d->e && q < lim; k++) q *= 10;
        } else if (d->e < -38) {
            q = 0; /* m*K < 2^96 < 10^38 / 2 */
        } else {
            __int128 p10 = 1;
            for (int32_t k = 0; k < -d->e; k++) p10 *= 10;
            __int128 r = q % p10;
            q /= p10;
            if (2 * r >= p10) q++; /* halves away from zero */
        }
        if (d->neg) q = -q;
        if (q > INT32_MAX || q < INT32_MIN) return 1;
        *v = (int32_t)q;
        return 0;
    }
    /* General case: the token's value in double times the scale. */
    char small[128];
    char *s = len < sizeof small ? small : malloc(len + 1);
    if (!s) return 1;
    memcpy(s, tok, len);
    s[len] = '\0';
    double x = strtod(s, NULL) * scale;
    if (s != small) free(s);
    x = round(x);
    if (!(x >= (double)INT32_MIN && x <= (double)INT32_MAX)) return 1;
    *v = (int32_t)x;
    return 0;
}

const char *pdt_io_show(const char *tok, size_t len, char *buf, size_t cap)
{
    static const char hex[] = "0123456789abcdef";
    size_t o = 0;
    for (size_t i = 0; i < len; i++) {
        unsigned char ch = (unsigned char)tok[i];
        if (o + 8 >= cap || i >= 40) {
            memcpy(buf + o, "...", 3);
            o += 3;
            break;
        }
        if (ch >= 0x20 && ch < 0x7f) {
            buf[o++] = (char)ch;
        } else {
            buf[o++] = '\\';
            buf[o++] = 'x';
            buf[o++] = hex[ch >> 4];
            buf[o++] = hex[ch & 15];
        }
    }
    buf[o] = '\0';
    return buf;
}

pdt_status pdt_io_end_line(pdt_io_cur *c, const char *what, pdt_err *err)
{
    const char *tok;
    size_t len;
    char show[64];
    int more = pdt_io_token(c, &tok, &len);
    if (!more && c->fields && c->p < c->end && is_sep(*c->p)) { /* "x,y,z": show ",z" */
        const char *e = c->p + 1;
        while (e < c->end && *e != '\n' && *e != '#') e++;
        while (e > c->p + 1 && is_blank(e[-1])) e--;
        tok = c->p;
        len = (size_t)(e - c->p);
        more = 1;
    }
    if (more)
        return pdt_err_set(err, PDT_ERR_PARSE, "%s:%zu: unexpected '%s' after %s", c->name,
                           c->line, pdt_io_show(tok, len, show, sizeof show), what);
    pdt_io_skip_line(c);
    return PDT_OK;
}
