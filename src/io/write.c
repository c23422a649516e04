/* pdt — writers: points (text, .node) and triangles (.tri, .ele + .node, .off).
 * Numbers are formatted by hand into a large buffer: printf would cost more
 * than the triangulation itself on big outputs. */
#include "pdt/io.h"
#include "pdt/tmpfile.h"

#include "pdt/bigmem.h"
#include "pdt/testhook.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

enum { WBUF = 1 << 20 };

typedef struct wbuf {
    FILE *fp;
    char b[WBUF];
    size_t n;
    int bad;
    int err; /* errno of the first failed write */
} wbuf;

static void wb_fail(wbuf *w, int e)
{
    if (!w->bad) w->err = e;
    w->bad = 1;
}

static void wb_flush(wbuf *w)
{
    if (w->n && fwrite(w->b, 1, w->n, w->fp) != w->n) wb_fail(w, errno);
    w->n = 0;
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

/* v < 10^8 in decimal at p, returns the end; writes 8 bytes at p whatever
 * v's digits (the caller has room: PDT_LINE_MAX per line).  All eight digits
 * at once, in the lanes of one 64-bit word (SWAR), with no branch: v/10^4 and
 * v%10^4 in two 32-bit lanes, each split by 100 into 16-bit lanes
 * (x * 10486 >> 20 is x / 100 for x < 43 699), each of those by 10 into
 * bytes (x * 103 >> 10 is x / 10 for x < 179), in printing order from the
 * low byte (little endian); the leading zeros are shifted out.  One cost for
 * every length: at 10^7 points most indices have 7 digits, at 10^6 six, and
 * the digit-pair loop below took one more round for each two digits. */
static inline char *put_u32_8(char *p, uint32_t v)
{
    uint64_t x = (uint64_t)(v / 10000u) | (uint64_t)(v % 10000u) << 32;
    uint64_t q = ((x * 10486u) >> 20) & 0x0000007F0000007Full;
    x = q | (x - q * 100u) << 16;
    q = ((x * 103u) >> 10) & 0x000F000F000F000Full;
    x = q | (x - q * 10u) << 8;
    int zeros = __builtin_ctzll(x | (1ull << 56)) >> 3; /* leading zero digits (7 for v = 0) */
    x = (x + 0x3030303030303030ull) >> (8 * zeros);
    memcpy(p, &x, 8);
    return p + 8 - zeros;
}

/* v in decimal at p; returns the end.  Below 10^8, put_u32_8; above, the
 * digits are written from the last one backwards, two at a time (32-bit
 * divisions by a constant: a multiply). */
static inline char *put_u32(char *p, uint32_t v)
{
    if (v < 100000000u) return put_u32_8(p, v);
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

static inline char *put_i32(char *p, int32_t v)
{
    if (v < 0) {
        *p++ = '-';
        return put_u32(p, (uint32_t)0 - (uint32_t)v);
    }
    return put_u32(p, (uint32_t)v);
}

static inline int ndigits64(uint64_t v)
{
    if (v <= UINT32_MAX) return ndigits32((uint32_t)v);
    int k = 10;
    for (v /= 10000000000u; v; v /= 10) k++;
    return k;
}

static inline int nchars_i32(int32_t v)
{
    return v < 0 ? 1 + ndigits32((uint32_t)0 - (uint32_t)v) : ndigits32((uint32_t)v);
}

/* ---- formatting (pdt_format_*: the lines of every output format) ---------------- */

size_t pdt_format_lines(char *buf, pdt_lines kind, const void *items, size_t n, uint64_t first)
{
    const pdt_tri *t = items;
    const pdt_point *q = items;
    char *p = buf;
    switch (kind) {
    case PDT_LINES_TRI:
    case PDT_LINES_ELE:
    case PDT_LINES_OFF_TRI:
        for (size_t i = 0; i < n; i++) {
            if (kind == PDT_LINES_ELE) {
                p = put_u64(p, first + i);
                *p++ = ' ';
            } else if (kind == PDT_LINES_OFF_TRI) {
                memcpy(p, "3 ", 2);
                p += 2;
            }
            p = put_u32(p, t[i].v[0]);
            *p++ = ' ';
            p = put_u32(p, t[i].v[1]);
            *p++ = ' ';
            p = put_u32(p, t[i].v[2]);
            *p++ = '\n';
        }
        break;
    case PDT_LINES_NODE:
    case PDT_LINES_OFF_POINT:
    case PDT_LINES_XY:
        for (size_t i = 0; i < n; i++) {
            if (kind == PDT_LINES_NODE) {
                p = put_u64(p, first + i);
                *p++ = ' ';
            }
            p = put_i32(p, q[i].x);
            *p++ = ' ';
            p = put_i32(p, q[i].y);
            if (kind == PDT_LINES_OFF_POINT) {
                memcpy(p, " 0", 2);
                p += 2;
            }
            *p++ = '\n';
        }
        break;
    }
    return (size_t)(p - buf);
}

/* The decimal digits of v[0, n) added up: a sum of comparisons, which the
 * compiler turns into vector instructions (ndigits32's table look-up cannot
 * be), in blocks whose sums fit 32 bits.  A parallel run counts its bytes
 * before it writes: 3 indices a triangle, 6*10^7 at 10^7 points. */
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("tree-vectorize", "vect-cost-model=dynamic")))
#endif
static uint64_t digits_sum(const uint32_t *v, size_t n)
{
    uint64_t total = 0;
    for (size_t i = 0; i < n;) {
        size_t end = n - i > (1u << 20) ? i + (1u << 20) : n;
        uint32_t s = 0;
        for (; i < end; i++) {
            uint32_t x = v[i];
            s += 1u + (x >= 10u) + (x >= 100u) + (x >= 1000u) + (x >= 10000u) + (x >= 100000u) +
                 (x >= 1000000u) + (x >= 10000000u) + (x >= 100000000u) + (x >= 1000000000u);
        }
        total += s;
    }
    return total;
}

uint64_t pdt_lines_bytes(pdt_lines kind, const void *items, size_t n, uint64_t first)
{
    const pdt_point *q = items;
    uint64_t b = 0;
    _Static_assert(sizeof(pdt_tri) == 3 * sizeof(uint32_t), "pdt_tri is three packed words");
    switch (kind) {
    case PDT_LINES_TRI:
    case PDT_LINES_ELE:
    case PDT_LINES_OFF_TRI:
        b += digits_sum((const uint32_t *)items, 3 * n);
        b += 3 * (uint64_t)n; /* two spaces and the newline */
        if (kind == PDT_LINES_OFF_TRI) b += 2 * (uint64_t)n;
        if (kind == PDT_LINES_ELE)
            for (size_t i = 0; i < n; i++) b += (uint64_t)ndigits64(first + i) + 1;
        break;
    case PDT_LINES_NODE:
    case PDT_LINES_OFF_POINT:
    case PDT_LINES_XY:
        for (size_t i = 0; i < n; i++) b += (uint64_t)(nchars_i32(q[i].x) + nchars_i32(q[i].y));
        b += 2 * (uint64_t)n; /* the space and the newline */
        if (kind == PDT_LINES_OFF_POINT) b += 2 * (uint64_t)n;
        if (kind == PDT_LINES_NODE)
            for (size_t i = 0; i < n; i++) b += (uint64_t)ndigits64(first + i) + 1;
        break;
    }
    return b;
}

/* k integers separated by spaces, then a newline. */
static char *put_ints(char *p, const uint64_t *v, int k)
{
    for (int i = 0; i < k; i++) {
        if (i) *p++ = ' ';
        p = put_u64(p, v[i]);
    }
    *p++ = '\n';
    return p;
}

size_t pdt_format_tri_header(char *buf, pdt_tri_format fmt, uint64_t npts, uint64_t ntri)
{
    char *p = buf;
    if (fmt == PDT_FMT_ELE) {
        static const char c[] = "# pdt: triangles, 0-based indices into the .node file\n";
        uint64_t h[3] = { ntri, 3, 0 };
        memcpy(p, c, sizeof c - 1);
        p = put_ints(p + sizeof c - 1, h, 3);
    } else if (fmt == PDT_FMT_OFF) {
        uint64_t h[3] = { npts, ntri, 0 };
        memcpy(p, "OFF\n", 4);
        p = put_ints(p + 4, h, 3);
    }
    return (size_t)(p - buf);
}

size_t pdt_format_node_header(char *buf, uint64_t npts)
{
    static const char c[] = "# pdt: points, 0-based indices\n";
    uint64_t h[4] = { npts, 2, 0, 0 };
    memcpy(buf, c, sizeof c - 1);
    return (size_t)(put_ints(buf + sizeof c - 1, h, 4) - buf);
}

/* ---- the plain writer: the same lines through a buffer ------------------------ */

/* ---- long sections on several threads ------------------------------------------
 *
 * Printing numbers is most of a big write (0.24 of the 0.30 s that 2*10^7
 * triangles take here), and the copy into the page cache is the rest; on a
 * plain run every other core is idle by then.  So a long section of a regular
 * file is cut into chunks of `chunk` items, and T threads take turns: thread t
 * prints chunks t, t + T, ... into its own buffer, waits until chunk j - 1 has
 * claimed its bytes, claims the next ones and writes them at their offset
 * (pwrite) while the others print.  The bytes are those of the one-thread
 * loop. */

/* At most SEC_MAX_THREADS: the copies into the page cache of one file take
 * turns on its lock (ext4), and printing, 9.4 ns a triangle on one thread
 * here, is below that copy's time from 4 threads on. */
enum { SEC_CHUNK = WBUF / PDT_LINE_MAX, SEC_MIN_ITEMS = 1 << 18, SEC_MAX_THREADS = 4 };

/* pdt_write_tris_releasing: the triangles already printed are given back
 * RELEASE_STEP items at a time or more (whole 2 MiB pages:
 * pdt_big_release_front).  The page cache of the file being written then
 * takes memory that was in use a moment before rather than memory the host
 * has taken back, which on a virtual machine makes the write's time steadier
 * and shorter (the triangles are half the file's size: the other half still
 * comes from the free lists). */
enum { RELEASE_STEP = 1 << 18 };

static void release_items(const char *items, size_t elem, size_t from, size_t to)
{
    if (to > from) pdt_big_release_front((void *)(uintptr_t)items, from * elem, to * elem);
}

typedef struct section_job {
    int fd;
    pdt_lines kind;
    const char *items;
    size_t elem, n, chunk;
    int nthreads;
    pthread_mutex_t mu;
    pthread_cond_t turn;
    size_t claimed;  /* chunks [0, claimed) have their offsets */
    uint64_t end;    /* the file offset after them */
    int failed, err; /* a write failed (errno): everyone stops */
    int release;     /* give back the items' pages once printed */
    size_t released; /* items [0, released) given back */
} section_job;

typedef struct section_worker {
    section_job *job;
    int t;
} section_worker;

static int write_all_at(int fd, const char *b, size_t len, uint64_t off)
{
    return pdt_pwrite_all(fd, b, len, off) ? 0 : errno;
}

/* Chunk j's turn: wait for chunks before it, take their end as its offset.
 * Every chunk up to j is printed by then: with `release`, [*rel, *rel_end)
 * are items no one has given back yet. */
static int section_claim(section_job *jb, size_t j, size_t len, uint64_t *off, size_t *rel,
                         size_t *rel_end)
{
    pthread_mutex_lock(&jb->mu);
    while (jb->claimed != j && !jb->failed) pthread_cond_wait(&jb->turn, &jb->mu);
    int ok = !jb->failed;
    if (ok) {
        *off = jb->end;
        jb->end += len;
        jb->claimed = j + 1;
        *rel = *rel_end = jb->released;
        size_t printed = (j + 1) * jb->chunk < jb->n ? (j + 1) * jb->chunk : jb->n;
        if (jb->release && printed - jb->released >= RELEASE_STEP)
            *rel_end = jb->released = printed;
        pthread_cond_broadcast(&jb->turn);
    }
    pthread_mutex_unlock(&jb->mu);
    return ok;
}

static void section_fail(section_job *jb, int e)
{
    pthread_mutex_lock(&jb->mu);
    if (!jb->failed) jb->err = e;
    jb->failed = 1;
    pthread_cond_broadcast(&jb->turn);
    pthread_mutex_unlock(&jb->mu);
}

static void *section_work(void *arg)
{
    section_worker *wk = arg;
    section_job *jb = wk->job;
    char *buf = malloc(jb->chunk * PDT_LINE_MAX);
    if (!buf) {
        section_fail(jb, ENOMEM);
        return NULL;
    }
    size_t nchunks = (jb->n + jb->chunk - 1) / jb->chunk;
    for (size_t j = (size_t)wk->t; j < nchunks; j += (size_t)jb->nthreads) {
        size_t i = j * jb->chunk, k = jb->n - i < jb->chunk ? jb->n - i : jb->chunk;
        size_t len = pdt_format_lines(buf, jb->kind, jb->items + i * jb->elem, k, i);
        uint64_t off;
        size_t rel, rel_end;
        if (!section_claim(jb, j, len, &off, &rel, &rel_end)) break;
        release_items(jb->items, jb->elem, rel, rel_end);
        int e = write_all_at(jb->fd, buf, len, off);
        if (e) {
            section_fail(jb, e);
            break;
        }
    }
    free(buf);
    return NULL;
}

/* PDT_WRITE_THREADS=N if set (1 = the one-thread loop), else the CPUs
 * online, at most SEC_MAX_THREADS.  (A process that mpirun bound to one core
 * has its helpers started on the others: pdt_helper_start.) */
static int section_threads(void)
{
    const char *e = getenv("PDT_WRITE_THREADS");
    long t = e && *e ? atol(e) : sysconf(_SC_NPROCESSORS_ONLN);
    return t < 1 ? 1 : t > SEC_MAX_THREADS ? SEC_MAX_THREADS : (int)t;
}

/* Items per chunk: SEC_CHUNK, or PDT_TEST_WRITE_CHUNK (tests: many chunks on
 * small inputs, every thread's turn taken). */
static size_t section_chunk(void)
{
    const char *e = pdt_test_hook("PDT_TEST_WRITE_CHUNK");
    long c = e ? atol(e) : 0;
    return c > 0 && (size_t)c < SEC_CHUNK ? (size_t)c : SEC_CHUNK;
}

/* The descriptor for pwrite if w writes a regular file at a position pwrite
 * can honour, else -1 (a pipe, a terminal; a file opened for appending, as
 * standard output is with >>: pwrite would append whatever its offset). */
static int section_fd(const wbuf *w)
{
    int fd = fileno(w->fp);
    struct stat sb;
    if (fd < 0 || fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) return -1;
    int fl = fcntl(fd, F_GETFL);
    return fl < 0 || (fl & O_APPEND) ? -1 : fd;
}

/* Run the job on its threads (the caller's is thread 0).  Returns 0, having
 * written and given back nothing, if a helper could not be started (its
 * chunks would have waited forever: everyone is stopped before chunk 0). */
static int section_run(section_job *jb)
{
    section_worker wk[SEC_MAX_THREADS];
    pthread_t th[SEC_MAX_THREADS];
    int started = 1;
    for (int t = 0; t < jb->nthreads; t++) wk[t] = (section_worker){ jb, t };
    const char *cap = pdt_test_hook("PDT_TEST_WRITE_HELPERS"); /* tests: helpers that can start */
    int most = cap && *cap ? atoi(cap) : SEC_MAX_THREADS;
    for (; started < jb->nthreads; started++) {
        if (started > most ||
            pdt_helper_start(&th[started], section_work, &wk[started]) != 0)
            break;
    }
    int all = started == jb->nthreads;
    if (all) section_work(&wk[0]);
    else section_fail(jb, EAGAIN);
    for (int t = 1; t < started; t++) pthread_join(th[t], NULL);
    return all;
}

/* Try the section on threads; returns 0 if it is not for threads (short, one
 * CPU, not a file pwrite can place bytes in), and then nothing was written
 * or given back. */
static int wb_lines_threaded(wbuf *w, pdt_lines kind, const void *items, size_t elem, size_t n,
                             int release)
{
    size_t chunk = section_chunk();
    int nt = section_threads(), fd;
    if (nt < 2 || (n < SEC_MIN_ITEMS && chunk == SEC_CHUNK) || (fd = section_fd(w)) < 0) return 0;
    wb_flush(w);
    if (!w->bad && fflush(w->fp) != 0) wb_fail(w, errno);
    if (w->bad) return 1;
    off_t start = ftello(w->fp);
    if (start < 0) return 0;
    section_job jb = { .fd = fd, .kind = kind, .items = items, .elem = elem, .n = n,
                       .chunk = chunk, .nthreads = nt, .end = (uint64_t)start,
                       .release = release };
    pthread_mutex_init(&jb.mu, NULL);
    pthread_cond_init(&jb.turn, NULL);
    int ran = section_run(&jb);
    pthread_mutex_destroy(&jb.mu);
    pthread_cond_destroy(&jb.turn);
    if (!ran) return 0; /* the one-thread loop writes it from `start` */
    if (jb.failed) wb_fail(w, jb.err);
    else if (fseeko(w->fp, (off_t)jb.end, SEEK_SET) != 0) wb_fail(w, errno);
    return 1;
}

/* items[0..n) as lines of `kind`: on several threads when long enough, else a
 * buffer's worth at a time; with `release`, the items' pages are given back
 * once printed. */
static void wb_lines(wbuf *w, pdt_lines kind, const void *items, size_t elem, size_t n,
                     int release)
{
    if (wb_lines_threaded(w, kind, items, elem, n, release)) return;
    const size_t step = WBUF / PDT_LINE_MAX;
    size_t released = 0;
    for (size_t i = 0; i < n; i += step) {
        size_t k = n - i < step ? n - i : step;
        if (w->n + k * PDT_LINE_MAX > WBUF) wb_flush(w);
        w->n += pdt_format_lines(w->b + w->n, kind, (const char *)items + i * elem, k, i);
        if (release && i + k - released >= RELEASE_STEP) {
            release_items(items, elem, released, i + k);
            released = i + k;
        }
    }
}

static void wb_header(wbuf *w, const char *h, size_t len)
{
    if (w->n + len > WBUF) wb_flush(w);
    memcpy(w->b + w->n, h, len);
    w->n += len;
}

static int has_ext(const char *path, const char *ext)
{
    if (!path) return 0;
    size_t n = strlen(path), e = strlen(ext);
    return n >= e && strcmp(path + n - e, ext) == 0;
}

/* Flush w into o; on a write error, remove o's temporary. */
static pdt_status flushed(pdt_outfile *o, wbuf *w, pdt_err *err)
{
    wb_flush(w);
    if (w->bad) {
        int e = w->err;
        const char *name = o->path ? o->path : "standard output";
        pdt_err_set(err, PDT_ERR_IO, "%s: write error: %s", name, strerror(e));
        pdt_out_abort(o);
        return PDT_ERR_IO;
    }
    return PDT_OK;
}

static pdt_status finish(pdt_outfile *o, wbuf *w, pdt_err *err)
{
    pdt_status st = flushed(o, w, err);
    return st == PDT_OK ? pdt_out_commit(o, err) : st;
}

/* ---- points ---------------------------------------------------------------- */

static void emit_points(wbuf *w, const pdt_point *pts, size_t n, int node)
{
    if (node) {
        char h[256];
        wb_header(w, h, pdt_format_node_header(h, n));
    }
    wb_lines(w, node ? PDT_LINES_NODE : PDT_LINES_XY, pts, sizeof *pts, n, 0);
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
    w->bad = w->err = 0;
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
                      const pdt_tri *t, size_t ntri, int release)
{
    char h[256];
    wb_header(w, h, pdt_format_tri_header(h, fmt, n, ntri));
    if (fmt == PDT_FMT_OFF) wb_lines(w, PDT_LINES_OFF_POINT, pts, sizeof *pts, n, 0);
    wb_lines(w, fmt == PDT_FMT_ELE ? PDT_LINES_ELE : fmt == PDT_FMT_OFF ? PDT_LINES_OFF_TRI
                                                                         : PDT_LINES_TRI,
             t, sizeof *t, ntri, release);
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

/* Write the triangles; put the file(s) in place, or leave them in *defer
 * (when not NULL) for the caller to. */
static pdt_status write_tris(const char *path, pdt_tri_format fmt, const pdt_point *pts, size_t n,
                             const pdt_tri *tris, size_t ntri, int release,
                             pdt_pending_write *defer, pdt_err *err)
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
        /* The .node first; both replaced together once the .ele is done. */
        npath = node_path_of(path);
        if (!npath) {
            free(w);
            return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
        }
        st = pdt_out_open(&onode, npath, err);
        if (st == PDT_OK) {
            w->fp = onode.fp;
            w->n = 0;
            w->bad = w->err = 0;
            emit_points(w, pts, n, 1);
            wb_flush(w);
            if (!w->bad && fflush(onode.fp) != 0) wb_fail(w, errno);
            if (w->bad)
                st = pdt_err_set(err, PDT_ERR_IO, "%s: write error: %s", npath, strerror(w->err));
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
        w->bad = w->err = 0;
        emit_tris(w, fmt, pts, n, tris, ntri, release);
        st = flushed(&o, w, err);
    }
    pdt_outfile *node = fmt == PDT_FMT_ELE ? &onode : NULL;
    if (st == PDT_OK && defer) st = pdt_out_finish_pair(&o, node, defer, err);
    else if (st == PDT_OK) st = pdt_out_commit_pair(&o, node, err);
    else if (node) pdt_out_abort(node);
    free(npath);
    free(w);
    return st;
}

pdt_status pdt_write_tris(const char *path, pdt_tri_format fmt, const pdt_point *pts, size_t n,
                          const pdt_tri *tris, size_t ntri, pdt_err *err)
{
    return write_tris(path, fmt, pts, n, tris, ntri, 0, NULL, err);
}

pdt_status pdt_write_tris_releasing(const char *path, pdt_tri_format fmt, const pdt_point *pts,
                                    size_t n, pdt_tri *tris, size_t ntri, pdt_err *err)
{
    return write_tris(path, fmt, pts, n, tris, ntri, 1, NULL, err);
}

pdt_status pdt_write_tris_deferred(const char *path, pdt_tri_format fmt, const pdt_point *pts,
                                   size_t n, pdt_tri *tris, size_t ntri, int release,
                                   pdt_pending_write *defer, pdt_err *err)
{
    defer->n = 0;
    return write_tris(path, fmt, pts, n, tris, ntri, release, defer, err);
}
