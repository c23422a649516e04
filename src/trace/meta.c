/* pdt — the run folder's manifest (text) and points.bin (binary). */
#include "tf_internal.h"
#include "pdt/io.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

void pdt_manifest_free(pdt_manifest *m)
{
    if (!m) return;
    free(m->command_line);
    free(m->input_name);
    free(m->clock_offset_ns);
    m->command_line = m->input_name = NULL;
    m->clock_offset_ns = NULL;
}

/* ---- atomic file writing: dir/name via dir/.name.tmp.PID -------------------- */

typedef struct afile {
    FILE *fp;
    char *path, *tmp;
} afile;

static pdt_status af_open(afile *f, const char *dir, const char *name, pdt_err *err)
{
    size_t len = strlen(dir) + strlen(name) + 48;
    f->fp = NULL;
    f->path = malloc(len);
    f->tmp = malloc(len);
    if (!f->path || !f->tmp) {
        free(f->path);
        free(f->tmp);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    snprintf(f->path, len, "%s/%s", dir, name);
    snprintf(f->tmp, len, "%s/.%s.tmp.%ld", dir, name, (long)getpid());
    (void)unlink(f->tmp); /* a fresh file, never through a link planted at the name */
    int fd = open(f->tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    f->fp = fd >= 0 ? fdopen(fd, "wb") : NULL;
    if (!f->fp) {
        if (fd >= 0) close(fd);
        pdt_status st =
            pdt_err_set(err, PDT_ERR_IO, "%s: cannot create: %s", f->tmp, strerror(errno));
        free(f->path);
        free(f->tmp);
        return st;
    }
    return PDT_OK;
}

static pdt_status af_commit(afile *f, pdt_err *err)
{
    pdt_status st = PDT_OK;
    int bad = ferror(f->fp);
    if (fclose(f->fp) != 0 || bad)
        st = pdt_err_set(err, PDT_ERR_IO, "%s: write failed: %s", f->tmp, strerror(errno));
    else if (pdt_replace_file(f->tmp, f->path) != 0)
        st = pdt_err_set(err, PDT_ERR_IO, "%s: cannot rename into place: %s", f->path,
                         strerror(errno));
    if (st != PDT_OK) remove(f->tmp);
    free(f->path);
    free(f->tmp);
    return st;
}

/* Write s with backslash, newline, carriage return escaped. */
static void put_escaped(FILE *fp, const char *s)
{
    for (; s && *s; s++) {
        if (*s == '\\') fputs("\\\\", fp);
        else if (*s == '\n') fputs("\\n", fp);
        else if (*s == '\r') fputs("\\r", fp);
        else fputc(*s, fp);
    }
}

void pdt_points_header(uint8_t *h, uint64_t n, uint32_t data_crc)
{
    memcpy(h, PTS_MAGIC, 8);
    tf_put64(h + 8, n);
    tf_put32(h + 16, data_crc);
    tf_put32(h + 20, pdt_crc32c(0, h, 20));
}

static pdt_status make_dir(const char *dir, pdt_err *err)
{
    if (mkdir(dir, 0777) != 0 && errno != EEXIST)
        return pdt_err_set(err, PDT_ERR_IO, "%s: cannot create folder: %s", dir,
                           strerror(errno));
    return PDT_OK;
}

pdt_status pdt_run_write_meta(const char *dir, const pdt_manifest *m, const pdt_point *pts,
                              size_t n, pdt_err *err)
{
    if (m->nranks < 1)
        return pdt_err_set(err, PDT_ERR_ARG, "manifest needs nranks >= 1");
    pdt_status st = make_dir(dir, err);
    if (st != PDT_OK) return st;
    /* points.bin: the header (with the data's checksum), then the data */
    afile f;
    st = af_open(&f, dir, "points.bin", err);
    if (st != PDT_OK) return st;
    uint8_t h[PTS_HEADER_SIZE], chunk[8 * 1024];
    uint32_t crc = 0;
    for (int pass = 0; pass < 2; pass++) { /* pass 0: checksum, pass 1: write */
        if (pass == 1) {
            pdt_points_header(h, n, crc);
            fwrite(h, 1, sizeof h, f.fp);
        }
        for (size_t i = 0; i < n;) {
            size_t k = n - i < sizeof chunk / 8 ? n - i : sizeof chunk / 8;
            pdt_points_encode(chunk, pts + i, k);
            if (pass == 0) crc = pdt_crc32c(crc, chunk, 8 * k);
            else fwrite(chunk, 1, 8 * k, f.fp);
            i += k;
        }
    }
    st = af_commit(&f, err);
    if (st != PDT_OK) return st;
    return pdt_run_write_manifest(dir, m, err);
}

pdt_status pdt_run_write_manifest(const char *dir, const pdt_manifest *m, pdt_err *err)
{
    if (m->nranks < 1)
        return pdt_err_set(err, PDT_ERR_ARG, "manifest needs nranks >= 1");
    afile f;
    pdt_status st;
    st = af_open(&f, dir, "manifest", err);
    if (st != PDT_OK) return st;
    FILE *fp = f.fp;
    fprintf(fp, "# pdt run folder manifest; format described in docs/trace-format.md\n");
    fprintf(fp, "format = %d.%d\n", PDT_TRACE_FORMAT_MAJOR, PDT_TRACE_FORMAT_MINOR);
    fprintf(fp, "program_version = ");
    put_escaped(fp, m->program_version[0] ? m->program_version : PDT_VERSION);
    fprintf(fp, "\ncommand = ");
    put_escaped(fp, m->command);
    fprintf(fp, "\ncommand_line = ");
    put_escaped(fp, m->command_line);
    fprintf(fp, "\ninput_name = ");
    put_escaped(fp, m->input_name);
    fprintf(fp, "\ninput_checksum = %s:%016" PRIx64 "\n",
            m->input_checksum_kind == PDT_CHECKSUM_FNV1A64 ? "fnv1a64" : "crc64",
            m->input_checksum);
    fprintf(fp, "n = %" PRIu64 "\n", m->n);
    fprintf(fp, "ranks = %d\n", m->nranks);
    fprintf(fp, "level = %d\n", m->level);
    if (m->partition == 1) fprintf(fp, "partition = bisect\n"); /* (strips: no line) */
    fprintf(fp, "wall_start_ns = %" PRIu64 "\n", m->wall_start_ns);
    fprintf(fp, "clock_offset_ns =");
    for (int r = 0; r < m->nranks; r++)
        fprintf(fp, " %" PRId64, m->clock_offset_ns ? m->clock_offset_ns[r] : 0);
    fprintf(fp, "\npoints_file = points.bin\n");
    return af_commit(&f, err);
}

/* ---- reading ---------------------------------------------------------------- */

static char *unescape_dup(const char *s)
{
    size_t n = strlen(s);
    char *d = malloc(n + 1), *o = d;
    if (!d) return NULL;
    for (; *s; s++) {
        if (*s == '\\' && s[1]) {
            s++;
            *o++ = *s == 'n' ? '\n' : *s == 'r' ? '\r' : *s;
        } else {
            *o++ = *s;
        }
    }
    *o = '\0';
    return d;
}

static void copy_field(char *dst, size_t cap, const char *src)
{
    snprintf(dst, cap, "%s", src);
}

/* The manifest being parsed: where (for the messages) and what so far. */
typedef struct mf_parse {
    const char *path;
    int line;
    pdt_manifest *m;
    char *offsets;       /* clock_offset_ns's value, parsed once ranks is known */
    int offsets_line;
    pdt_err *err;
} mf_parse;

static pdt_status mf_format(mf_parse *P, const char *v)
{
    char *end = NULL;
    long maj = strtol(v, &end, 10), min = 0;
    if (end == v || (*end != '.' && *end != '\0')) end = NULL;
    else if (*end == '.') min = strtol(end + 1, &end, 10);
    if (!end || *end != '\0' || maj < 0 || maj > 1000000 || min < 0 || min > 1000000)
        return pdt_err_set(P->err, PDT_ERR_FORMAT, "%s:%d: bad format version '%s'", P->path,
                           P->line, v);
    P->m->format_version = (int)maj;
    P->m->format_minor = (int)min;
    if (maj < PDT_TRACE_FORMAT_OLDEST || maj > PDT_TRACE_FORMAT_MAJOR)
        return pdt_err_set(P->err, PDT_ERR_FORMAT,
                           "%s:%d: run folder format %ld.%ld; this pdt reads formats "
                           "%d.x to %d.x", P->path, P->line, maj, min, PDT_TRACE_FORMAT_OLDEST,
                           PDT_TRACE_FORMAT_MAJOR);
    return PDT_OK;
}

/* command_line or input_name (k): escaped text. */
static pdt_status mf_text(mf_parse *P, const char *k, const char *v)
{
    char *d = unescape_dup(v);
    if (!d) return pdt_err_set(P->err, PDT_ERR_NOMEM, "out of memory");
    char **slot = !strcmp(k, "command_line") ? &P->m->command_line : &P->m->input_name;
    free(*slot);
    *slot = d;
    return PDT_OK;
}

/* The value names its algorithm; no name: format 1's FNV-1a 64. */
static pdt_status mf_checksum(mf_parse *P, const char *v)
{
    const char *h = v;
    char *end = NULL;
    P->m->input_checksum_kind = PDT_CHECKSUM_FNV1A64;
    if (!strncmp(v, "crc64:", 6)) {
        h = v + 6;
        P->m->input_checksum_kind = PDT_CHECKSUM_CRC64;
    } else if (!strncmp(v, "fnv1a64:", 8)) {
        h = v + 8;
    }
    errno = 0;
    P->m->input_checksum = strtoull(h, &end, 16);
    if (end == h || *end || errno || strspn(h, "0123456789abcdefABCDEF") != strlen(h))
        return pdt_err_set(P->err, PDT_ERR_FORMAT, "%s:%d: bad checksum '%s' (expected "
                           "crc64: or fnv1a64: and hex digits)", P->path, P->line, v);
    return PDT_OK;
}

/* n or wall_start_ns (k): a 64-bit count. */
static pdt_status mf_u64(mf_parse *P, const char *k, const char *v)
{
    char *end = NULL;
    errno = 0;
    uint64_t x = strtoull(v, &end, 10);
    if (end == v || *end || errno)
        return pdt_err_set(P->err, PDT_ERR_FORMAT, "%s:%d: bad number '%s'", P->path, P->line, v);
    if (k[0] == 'n') P->m->n = x;
    else P->m->wall_start_ns = x;
    return PDT_OK;
}

/* ranks or level (k): 0 .. 2^20. */
static pdt_status mf_small(mf_parse *P, const char *k, const char *v)
{
    char *end = NULL;
    long x = strtol(v, &end, 10);
    if (end == v || *end || x < 0 || x > (1L << 20))
        return pdt_err_set(P->err, PDT_ERR_FORMAT, "%s:%d: bad %s '%s'", P->path, P->line, k, v);
    if (k[0] == 'r') P->m->nranks = (int)x;
    else P->m->level = (int)x;
    return PDT_OK;
}

static pdt_status mf_partition(mf_parse *P, const char *v)
{
    if (strcmp(v, "strips") && strcmp(v, "bisect"))
        return pdt_err_set(P->err, PDT_ERR_FORMAT, "%s:%d: bad partition '%s' (expected "
                           "strips or bisect)", P->path, P->line, v);
    P->m->partition = v[0] == 'b';
    return PDT_OK;
}

/* One "key = value" line; unknown keys are ignored. */
static pdt_status mf_field(mf_parse *P, const char *k, char *v)
{
    pdt_manifest *m = P->m;
    if (!strcmp(k, "format")) return mf_format(P, v);
    if (!strcmp(k, "program_version")) copy_field(m->program_version, sizeof m->program_version, v);
    else if (!strcmp(k, "command")) copy_field(m->command, sizeof m->command, v);
    else if (!strcmp(k, "command_line") || !strcmp(k, "input_name")) return mf_text(P, k, v);
    else if (!strcmp(k, "input_checksum")) return mf_checksum(P, v);
    else if (!strcmp(k, "n") || !strcmp(k, "wall_start_ns")) return mf_u64(P, k, v);
    else if (!strcmp(k, "ranks") || !strcmp(k, "level")) return mf_small(P, k, v);
    else if (!strcmp(k, "partition")) return mf_partition(P, v);
    else if (!strcmp(k, "clock_offset_ns")) {
        P->offsets = v;
        P->offsets_line = P->line;
    }
    return PDT_OK;
}

/* Line s (its end cut): nothing (blank, comment), or its key and value. */
static pdt_status mf_line(mf_parse *P, char *s)
{
    size_t len = strlen(s);
    if (len && s[len - 1] == '\r') s[--len] = '\0';
    while (*s == ' ' || *s == '\t') s++;
    if (*s == '\0' || *s == '#') return PDT_OK;
    char *eq = strchr(s, '=');
    if (!eq) return pdt_err_set(P->err, PDT_ERR_FORMAT, "%s:%d: expected 'key = value'", P->path, P->line);
    char *ke = eq;
    while (ke > s && (ke[-1] == ' ' || ke[-1] == '\t')) ke--;
    *ke = '\0';
    char *v = eq + 1;
    while (*v == ' ' || *v == '\t') v++;
    return mf_field(P, s, v);
}

/* The per-rank clock offsets, one number a rank (none given: zeros). */
static pdt_status mf_offsets(mf_parse *P)
{
    pdt_manifest *m = P->m;
    m->clock_offset_ns = calloc((size_t)m->nranks, sizeof *m->clock_offset_ns);
    if (!m->clock_offset_ns) return pdt_err_set(P->err, PDT_ERR_NOMEM, "out of memory");
    char *p = P->offsets;
    for (int r = 0; p && r < m->nranks; r++) {
        char *end;
        errno = 0;
        long long x = strtoll(p, &end, 10);
        if (end == p || errno)
            return pdt_err_set(P->err, PDT_ERR_FORMAT,
                               "%s:%d: clock_offset_ns needs %d numbers, found %d", P->path,
                               P->offsets_line, m->nranks, r);
        m->clock_offset_ns[r] = x;
        p = end;
    }
    return PDT_OK;
}

pdt_status pdt_tf_manifest_parse(const char *path, char *text, pdt_manifest *m, pdt_err *err)
{
    memset(m, 0, sizeof *m);
    m->format_version = -1;
    m->nranks = -1;
    mf_parse P = {path, 0, m, NULL, 0, err};
    pdt_status st = PDT_OK;
    for (char *s = text, *next; st == PDT_OK && s && *s; s = next) {
        P.line++;
        next = strchr(s, '\n');
        if (next) *next++ = '\0';
        st = mf_line(&P, s);
    }
    if (st == PDT_OK && m->format_version < 0)
        st = pdt_err_set(err, PDT_ERR_FORMAT, "%s: no 'format' line: not a pdt manifest", path);
    if (st == PDT_OK && m->nranks < 1)
        st = pdt_err_set(err, PDT_ERR_FORMAT, "%s: no valid 'ranks' line", path);
    if (st == PDT_OK) st = mf_offsets(&P);
    if (st != PDT_OK) pdt_manifest_free(m);
    return st;
}

pdt_status pdt_tf_points_parse(const char *path, const uint8_t *p, size_t len, pdt_point **pts,
                               size_t *n, pdt_err *err)
{
    *pts = NULL;
    *n = 0;
    if (len < PTS_HEADER_SIZE || memcmp(p, PTS_MAGIC, 8) != 0)
        return pdt_err_set(err, PDT_ERR_FORMAT, "%s: not a pdt points file", path);
    if (tf_get32(p + 20) != pdt_crc32c(0, p, 20))
        return pdt_err_set(err, PDT_ERR_CORRUPT, "%s: header checksum mismatch", path);
    uint64_t cnt = tf_get64(p + 8);
    if (cnt > (len - PTS_HEADER_SIZE) / 8 || (len - PTS_HEADER_SIZE) != cnt * 8)
        return pdt_err_set(err, PDT_ERR_CORRUPT,
                           "%s: holds %zu bytes of points, header says %" PRIu64 " points",
                           path, len - PTS_HEADER_SIZE, cnt);
    const uint8_t *d = p + PTS_HEADER_SIZE;
    if (tf_get32(p + 16) != pdt_crc32c(0, d, (size_t)cnt * 8))
        return pdt_err_set(err, PDT_ERR_CORRUPT, "%s: checksum mismatch in the point data",
                           path);
    pdt_point *a = malloc((cnt ? (size_t)cnt : 1) * sizeof *a);
    if (!a) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < cnt; i++) {
        a[i].x = (int32_t)tf_get32(d + 8 * i);
        a[i].y = (int32_t)tf_get32(d + 8 * i + 4);
    }
    *pts = a;
    *n = (size_t)cnt;
    return PDT_OK;
}
