/* pdt — the reader library: open a run folder, validate, decode (the merged
 * order of the ranks' events: merge.c). */
#include "tf_internal.h"
#include "run_int.h"
#include "pdt/bigmem.h"
#include "pdt/io.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

void pdt_tf_warnf(pdt_run *run, const char *fmt, ...)
{
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    if (k < 0) return;
    size_t len = strlen(line);
    if (run->wlen + len + 2 > run->wcap) {
        size_t cap = 2 * (run->wcap + len + 2);
        char *w = realloc(run->warn, cap);
        if (!w) return;  /* a lost warning is better than a failed open */
        run->warn = w;
        run->wcap = cap;
    }
    memcpy(run->warn + run->wlen, line, len);
    run->wlen += len;
    run->warn[run->wlen++] = '\n';
    run->warn[run->wlen] = '\0';
}

static void rank_name(char *buf, size_t cap, int r)
{
    snprintf(buf, cap, "rank-%04d.trace", r);
}

/* Map a whole file read-only.  Returns 0, or errno (ENOENT if missing)
 * with the reason in why (pdt_open_input: a FIFO, a device, a folder are
 * refused, never waited on or read).  An empty file gives map = NULL,
 * size = 0. */
static int map_file(const char *path, uint8_t **map, size_t *size, char *why, size_t wcap)
{
    *map = NULL;
    *size = 0;
    int fd = pdt_open_input(path, why, wcap);
    if (fd < 0) return errno ? errno : EIO;
    struct stat st;
    if (fstat(fd, &st) != 0) {
        int e = errno;
        close(fd);
        snprintf(why, wcap, "%s", strerror(e));
        return e;
    }
    if (st.st_size > 0) {
        void *p = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE, fd, 0);
        if (p == MAP_FAILED) {
            int e = errno;
            close(fd);
            snprintf(why, wcap, "%s", strerror(e));
            return e;
        }
        *map = p;
        *size = (size_t)st.st_size;
    }
    close(fd);
    return 0;
}

/* Mapped trace pages already read are given back to the kernel in steps of
 * this many bytes, so that reading a file of any size keeps resident only
 * about this much of it (the pages are file-backed: reading them again just
 * faults them in from the page cache). */
#define RELEASE_STEP ((size_t)16 << 20)

/* Drop the resident pages of map[from, to) (whole pages inside it only).
 * Returns the new release mark: `to` rounded down to a page. */
static size_t release_pages(uint8_t *map, size_t from, size_t to)
{
    static size_t page;
    if (!page) page = (size_t)sysconf(_SC_PAGESIZE);
    size_t a = (from + page - 1) / page * page, b = to / page * page;
    if (map && b > a) madvise(map + a, b - a, MADV_DONTNEED);
    return b > from ? b : from;
}

/* points.bin's points read in place: pts into its mapping (the file's
 * layout, little-endian int32 pairs, is the host's), the header and both
 * checksums verified (as pdt_tf_points_parse does).  0 when they cannot be
 * (another byte order, or the file is not right: then pdt_tf_points_parse
 * copies them, or says what is wrong). */
static int points_in_place(const uint8_t *map, size_t size, pdt_point **pts, size_t *n)
{
    const uint16_t one = 1;
    if (*(const uint8_t *)&one != 1 || sizeof(pdt_point) != 8 || size < PTS_HEADER_SIZE ||
        memcmp(map, PTS_MAGIC, 8) != 0 || tf_get32(map + 20) != pdt_crc32c(0, map, 20))
        return 0;
    uint64_t cnt = tf_get64(map + 8);
    const uint8_t *d = map + PTS_HEADER_SIZE;
    if ((size - PTS_HEADER_SIZE) / 8 != cnt || (size - PTS_HEADER_SIZE) % 8 ||
        ((uintptr_t)d % _Alignof(pdt_point)))
        return 0;
    uint32_t crc = 0; /* (a step at a time, its pages given back: any number of points) */
    for (size_t o = 0, len = (size_t)cnt * 8; o < len; o += RELEASE_STEP) {
        size_t k = len - o < RELEASE_STEP ? len - o : RELEASE_STEP;
        crc = pdt_crc32c(crc, d + o, k);
        release_pages((uint8_t *)(uintptr_t)map, 0, PTS_HEADER_SIZE + o + k);
    }
    if (tf_get32(map + 16) != crc) return 0;
    *pts = (pdt_point *)(void *)(uintptr_t)d;
    *n = (size_t)cnt;
    return 1;
}

void pdt_run_release_points(const pdt_run *run)
{
    if (run->pts_map) release_pages(run->pts_map, 0, run->pts_map_size);
}

/* Validate the header and index the blocks of one rank file. */
/* Map rank r's file (rk->map) and check its header: PDT_OK with rk->present
 * set when its blocks can be read; PDT_OK without (a warning said why, or
 * the file is absent: rk->absent); an error for a format this pdt cannot
 * read. */
static pdt_status rank_header(pdt_run *run, int r, const char *name, pdt_err *err)
{
    tf_rank *rk = &run->rk[r];
    char *path = pdt_tf_path_join(run->dir, name);
    if (!path) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    char why[160];
    int e = map_file(path, &rk->map, &rk->size, why, sizeof why);
    free(path);
    if (e == ENOENT) {
        rk->absent = 1;
        return PDT_OK;
    }
    if (e) {
        pdt_tf_warnf(run, "%s: %s: no events for rank %d", name, why, r);
        return PDT_OK;
    }
    const uint8_t *p = rk->map;
    if (rk->size < TF_HEADER_SIZE || memcmp(p, TF_MAGIC, 8) != 0) {
        pdt_tf_warnf(run, "%s: not a pdt trace file (bad header): no events for rank %d", name, r);
        return PDT_OK;
    }
    if (tf_get32(p + 28) != pdt_crc32c(0, p, 28)) {
        pdt_tf_warnf(run, "%s: file header checksum mismatch: no events for rank %d", name, r);
        return PDT_OK;
    }
    unsigned maj = tf_get16(p + 8), min = tf_get16(p + 10);
    if (maj < PDT_TRACE_FORMAT_OLDEST || maj > PDT_TRACE_FORMAT_MAJOR)
        return pdt_err_set(err, PDT_ERR_FORMAT,
                           "%s/%s: trace format %u.%u; this pdt reads formats %d.x to %d.x",
                           run->dir, name, maj, min, PDT_TRACE_FORMAT_OLDEST,
                           PDT_TRACE_FORMAT_MAJOR);
    uint32_t hsize = tf_get32(p + 12);
    if (hsize < TF_HEADER_SIZE || hsize > rk->size) {
        pdt_tf_warnf(run, "%s: bad header size %u: no events for rank %d", name, hsize, r);
        return PDT_OK;
    }
    if (tf_get32(p + 16) != (uint32_t)r) pdt_tf_warnf(run, "%s: header says rank %u", name, tf_get32(p + 16));
    rk->level = (int)tf_get32(p + 20);
    rk->present = 1;
    return PDT_OK;
}

enum { BLK_NEXT, BLK_END, BLK_DAMAGED };

/* The end marker at byte off (its payload len bytes): whether its count
 * matches the blocks' (rk->complete), and what follows it. */
static void end_marker(pdt_run *run, tf_rank *rk, const char *name, uint64_t off, uint32_t len,
                       uint64_t expect)
{
    const uint8_t *h = rk->map + off;
    uint64_t total = len >= 8 ? tf_get64(h + TF_BLOCK_HEADER_SIZE) : UINT64_MAX;
    if (total != expect)
        pdt_tf_warnf(run, "%s: end marker at byte %" PRIu64 " counts %" PRIu64
                          " events, blocks hold %" PRIu64, name, off, total, expect);
    else
        rk->complete = 1;
    if (off + TF_BLOCK_HEADER_SIZE + len != rk->size)
        pdt_tf_warnf(run, "%s: %" PRIu64 " bytes after the end marker ignored", name,
                     rk->size - (off + TF_BLOCK_HEADER_SIZE + len));
}

/* ---- the costly checks of a window of blocks, made ahead on several threads ----
 *
 * A block's checksum and the check of its events (pdt_tf_validate) are most
 * of the cost of opening a run.  They are made ahead for the blocks of a window of the
 * file (found by their headers alone), on up to PRE_THREADS threads; the
 * scan then takes their answers, so that what it checks, in what order,
 * and what it says are the same as when it checks each block itself. */
#define PRE_THREADS 4
#define PRE_MIN_BYTES ((uint64_t)4 << 20) /* a window smaller than this: checked on one thread */
enum { PRE_SUM = 1, PRE_DATA = 2 };  /* a block's checks that passed */

typedef struct precheck {
    const uint8_t *map;
    uint64_t *off;          /* the window's blocks */
    uint8_t *ok;            /* per block: PRE_SUM | PRE_DATA when they passed */
    size_t n, cap, at;      /* at: the next block the scan asks about */
    _Atomic size_t next;    /* the next block to check */
} precheck;

static void *pre_worker(void *arg)
{
    precheck *P = arg;
    for (size_t k; (k = P->next++) < P->n;) {
        const uint8_t *h = P->map + P->off[k];
        uint32_t len = tf_get32(h + 4), count = tf_get32(h + 24);
        uint8_t ok = 0;
        if (pdt_crc32c(pdt_crc32c(0, h, 28), h + TF_BLOCK_HEADER_SIZE, len) == tf_get32(h + 28))
            ok |= PRE_SUM;
        if (count && pdt_tf_validate(h + TF_BLOCK_HEADER_SIZE, len, count) == 0)
            ok |= PRE_DATA;
        P->ok[k] = ok;
    }
    return NULL;
}

/* The event blocks of rk's file from byte off, by their headers, up to
 * RELEASE_STEP bytes (at least one block), checked ahead.  0 when out of
 * memory (then the scan checks every block itself). */
static int pre_window(precheck *P, const tf_rank *rk, uint64_t off)
{
    P->map = rk->map;
    P->n = P->at = 0;
    P->next = 0;
    uint64_t start = off;
    while (rk->size - off >= TF_BLOCK_HEADER_SIZE && (P->n == 0 || off - start < RELEASE_STEP)) {
        const uint8_t *h = rk->map + off;
        uint32_t len = tf_get32(h + 4);
        if (tf_get32(h) != TF_BLOCK_MAGIC || len > rk->size - off - TF_BLOCK_HEADER_SIZE) break;
        if (P->n == P->cap) {
            size_t nc = P->cap ? 2 * P->cap : 256;
            uint64_t *o = realloc(P->off, nc * sizeof *o);
            if (o) P->off = o;
            uint8_t *k = o ? realloc(P->ok, nc) : NULL;
            if (!k) return 0;
            P->ok = k;
            P->cap = nc;
        }
        P->off[P->n++] = off;
        off += TF_BLOCK_HEADER_SIZE + len;
    }
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    int threads = off - start < PRE_MIN_BYTES ? 1 : cpus < PRE_THREADS ? (int)cpus : PRE_THREADS;
    pthread_t th[PRE_THREADS];
    int started = 0;
    for (int t = 1; t < threads && (size_t)t < P->n; t++)
        if (pthread_create(&th[t], NULL, pre_worker, P) == 0) started |= 1 << t;
    pre_worker(P);
    for (int t = 1; t < PRE_THREADS; t++)
        if (started & (1 << t)) pthread_join(th[t], NULL);
    return 1;
}

/* What the window knows of the block at byte off: PRE_SUM | PRE_DATA as
 * they passed, or -1 when it was not checked ahead. */
static int pre_known(precheck *P, uint64_t off)
{
    if (!P || P->at >= P->n || P->off[P->at] != off) return -1;
    return P->ok[P->at++];
}

/* Block k at byte *off: checked (its header, checksum and events; known:
 * the checks made ahead, or -1), then noted in rk->blk and *off moved past
 * it (BLK_NEXT); the end marker (BLK_END); or damage, said in a warning
 * (BLK_DAMAGED).  -1 when out of memory. */
static int scan_block(pdt_run *run, tf_rank *rk, const char *name, size_t k, uint64_t *off,
                      size_t *cap, int known)
{
    uint64_t left = rk->size - *off, at = *off, expect = rk->nev;
    if (left < TF_BLOCK_HEADER_SIZE) {
        pdt_tf_warnf(run, "%s: block %zu at byte %" PRIu64 ": truncated block header (%" PRIu64
                          " of %u bytes)", name, k, at, left, TF_BLOCK_HEADER_SIZE);
        return BLK_DAMAGED;
    }
    const uint8_t *h = rk->map + at;
    uint32_t magic = tf_get32(h), len = tf_get32(h + 4), count = tf_get32(h + 24);
    uint64_t first = tf_get64(h + 8), base = tf_get64(h + 16);
    if (magic != TF_BLOCK_MAGIC && magic != TF_END_MAGIC) {
        pdt_tf_warnf(run, "%s: block %zu at byte %" PRIu64 ": bad block magic 0x%08x", name, k, at,
                     magic);
        return BLK_DAMAGED;
    }
    if (len > left - TF_BLOCK_HEADER_SIZE) {
        pdt_tf_warnf(run, "%s: block %zu at byte %" PRIu64 ": truncated (payload of %u bytes, %" PRIu64
                          " left)", name, k, at, len, left - TF_BLOCK_HEADER_SIZE);
        return BLK_DAMAGED;
    }
    if (known >= 0 ? !(known & PRE_SUM)
                   : pdt_crc32c(pdt_crc32c(0, h, 28), h + TF_BLOCK_HEADER_SIZE, len) != tf_get32(h + 28)) {
        pdt_tf_warnf(run, "%s: block %zu at byte %" PRIu64 ": checksum mismatch", name, k, at);
        return BLK_DAMAGED;
    }
    if (magic == TF_END_MAGIC) {
        end_marker(run, rk, name, at, len, expect);
        return BLK_END;
    }
    if (first != expect) {
        pdt_tf_warnf(run, "%s: block %zu at byte %" PRIu64 ": starts at event %" PRIu64
                          ", expected %" PRIu64, name, k, at, first, expect);
        return BLK_DAMAGED;
    }
    if (count == 0 || (known >= 0 ? !(known & PRE_DATA)
                                  : pdt_tf_validate(h + TF_BLOCK_HEADER_SIZE, len, count) != 0)) {
        pdt_tf_warnf(run, "%s: block %zu at byte %" PRIu64 ": malformed event data", name, k, at);
        return BLK_DAMAGED;
    }
    if (rk->nblk == *cap) {
        size_t nc = *cap ? 2 * *cap : 64;
        tf_block *b = realloc(rk->blk, nc * sizeof *b);
        if (!b) return -1;
        rk->blk = b;
        *cap = nc;
    }
    rk->blk[rk->nblk++] = (tf_block){at, first, base, len, count};
    rk->nev += count;
    *off += TF_BLOCK_HEADER_SIZE + len;
    return BLK_NEXT;
}

/* Rank r's file: its header, then every block up to the end marker or the
 * first damage (the blocks before it are kept); warnings say what is wrong. */
static pdt_status scan_rank(pdt_run *run, int r, pdt_err *err)
{
    tf_rank *rk = &run->rk[r];
    char name[32];
    rank_name(name, sizeof name, r);
    pdt_status st = rank_header(run, r, name, err);
    if (st != PDT_OK || !rk->present) return st;
    size_t cap = 0, released = 0;
    uint64_t off = tf_get32(rk->map + 12);
    int how = BLK_NEXT;
    rk->nev = 0;
    precheck pre = {0}, *P = &pre;
    for (size_t k = 0; how == BLK_NEXT && off < rk->size; k++) {
        if (off - released >= RELEASE_STEP) released = release_pages(rk->map, released, off);
        if (P && P->at == P->n && !pre_window(P, rk, off)) P = NULL;
        how = scan_block(run, rk, name, k, &off, &cap, pre_known(P, off));
        if (how < 0) break;
    }
    free(pre.off);
    free(pre.ok);
    if (how < 0) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    release_pages(rk->map, released, rk->size);
    if (how == BLK_DAMAGED)
        pdt_tf_warnf(run, "%s: read %" PRIu64 " events in %zu intact blocks before the damage", name,
                     rk->nev, rk->nblk);
    else if (!rk->complete)
        pdt_tf_warnf(run, "%s: no end marker (run killed?): read %" PRIu64 " events in %zu blocks",
                     name, rk->nev, rk->nblk);
    return PDT_OK;
}

static char *read_text(const char *path, int *errnum, char *why, size_t wcap)
{
    uint8_t *map;
    size_t size;
    *errnum = map_file(path, &map, &size, why, wcap);
    if (*errnum) return NULL;
    char *s = malloc(size + 1);
    if (!s) {
        *errnum = ENOMEM;
    } else {
        if (size) memcpy(s, map, size);
        s[size] = '\0';
    }
    if (map) munmap(map, size);
    return s;
}

/* No manifest: describe the rank files found (a run killed before rank 0
 * wrote the manifest). */
static pdt_status guess_manifest(pdt_run *run, pdt_err *err)
{
    int n = 0;
    for (;; n++) {
        char name[32];
        rank_name(name, sizeof name, n);
        char *p = pdt_tf_path_join(run->dir, name);
        if (!p) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
        int ok = access(p, F_OK) == 0;
        free(p);
        if (!ok) break;
    }
    if (n == 0)
        return pdt_err_set(err, PDT_ERR_IO, "%s/manifest: missing, and no rank-0000.trace: not a "
                                            "pdt run folder", run->dir);
    memset(&run->m, 0, sizeof run->m);
    run->m.format_version = PDT_TRACE_FORMAT_MAJOR;
    run->m.nranks = n;
    run->m.clock_offset_ns = calloc((size_t)n, sizeof *run->m.clock_offset_ns);
    if (!run->m.clock_offset_ns)
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    pdt_tf_warnf(run, "manifest: missing (run killed before it was written?); found %d rank file%s, "
               "clocks not aligned, no points", n, n == 1 ? "" : "s");
    return PDT_OK;
}

/* The checksum of the points by the algorithm the manifest names (format 1
 * runs: FNV-1a 64; format 2: CRC-64/XZ). */
static uint64_t points_sum(const pdt_manifest *m, const pdt_point *pts, size_t n)
{
    return m->input_checksum_kind == PDT_CHECKSUM_FNV1A64 ? pdt_points_fnv1a64(pts, n)
                                                          : pdt_points_checksum(pts, n);
}

/* ---- the points' checksum, made beside the rank files' scan ----------------------- */

static void *sum_worker(void *arg)
{
    pdt_run *run = arg;
    run->sum.value = points_sum(&run->m, run->pts, run->npts);
    return NULL;
}

/* The points' checksum started on a thread of its own (made here when
 * none can be started), its warning's place among the warnings noted. */
static void sum_start(pdt_run *run)
{
    run->sum.warn_at = run->wlen;
    if (pthread_create(&run->sum.th, NULL, sum_worker, run) == 0) {
        run->sum.started = 1;
        return;
    }
    sum_worker(run);
    run->sum.done = 1;
}

/* The checksum done: compared with the manifest's, a mismatch said where
 * read_points would have said it; the points' pages given back. */
static void sum_finish(pdt_run *run)
{
    if (run->sum.started) {
        pthread_join(run->sum.th, NULL);
        run->sum.started = 0;
        run->sum.done = 1;
        if (run->pts_map) release_pages(run->pts_map, 0, run->pts_map_size);
    }
    if (!run->sum.done) return;
    run->sum.done = 0;
    if (run->sum.value == run->m.input_checksum) return;
    size_t tail = run->wlen - run->sum.warn_at;
    char *after = malloc(tail + 1);
    if (!after) return;  /* (a lost warning is better than a failed open) */
    if (tail) memcpy(after, run->warn + run->sum.warn_at, tail);
    run->wlen = run->sum.warn_at;
    pdt_tf_warnf(run, "points.bin: points do not match the manifest's input_checksum");
    for (size_t at = 0; at < tail;) { /* the later warnings again, one line at a time */
        const char *nl = memchr(after + at, '\n', tail - at);
        size_t len = nl ? (size_t)(nl - (after + at)) : tail - at;
        pdt_tf_warnf(run, "%.*s", (int)len, after + at);
        at += len + 1;
    }
    free(after);
}

/* The largest clock offset taken as one (10^18 ns, about 31 years): the
 * differences of offsets in this range, and times shifted by them, are
 * computed without overflow. */
#define CLOCK_OFFSET_MAX INT64_C(1000000000000000000)

/* The smallest of 0 and the manifest's clock offsets (each rank's shift is
 * its offset minus this).  An offset beyond +-CLOCK_OFFSET_MAX is no clock
 * offset (a damaged or hostile manifest): then the ranks' clocks are left
 * unaligned (every offset 0), with a warning naming it. */
static int64_t clock_base(pdt_run *run)
{
    int64_t *off = run->m.clock_offset_ns, minoff = 0;
    for (int r = 0; r < run->nranks; r++) {
        if (off[r] < -CLOCK_OFFSET_MAX || off[r] > CLOCK_OFFSET_MAX) {
            pdt_tf_warnf(run, "manifest: clock_offset_ns of rank %d is %" PRId64 " ns, beyond +-%" PRId64
                       " ns: clocks not aligned", r, off[r], CLOCK_OFFSET_MAX);
            memset(off, 0, (size_t)run->nranks * sizeof *off);
            return 0;
        }
        if (off[r] < minoff) minoff = off[r];
    }
    return minoff;
}

/* The manifest (run->m), or one guessed from the rank files when there is
 * none. */
static pdt_status read_manifest(pdt_run *run, const char *dir, pdt_err *err)
{
    char *mpath = pdt_tf_path_join(dir, "manifest");
    if (!mpath) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    int e;
    char why[160];
    pdt_status st;
    char *text = read_text(mpath, &e, why, sizeof why);
    if (text) {
        st = pdt_tf_manifest_parse(mpath, text, &run->m, err);
        free(text);
    } else if (e == ENOENT) {
        st = guess_manifest(run, err);
    } else if (e == ENOMEM) {
        st = pdt_err_set(err, PDT_ERR_NOMEM, "%s: out of memory", mpath);
    } else {
        st = pdt_err_set(err, PDT_ERR_IO, "%s: %s", mpath, why);
    }
    free(mpath);
    return st;
}

/* points.bin's points (run->pts: in place in its mapping, or a copy), checked
 * against the manifest; what is wrong is a warning (the run then cannot be
 * replayed or checked), only running out of memory an error. */
static pdt_status read_points(pdt_run *run, const char *dir, pdt_err *err)
{
    char *ppath = pdt_tf_path_join(dir, "points.bin");
    if (!ppath) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    uint8_t *map = NULL;
    size_t size = 0;
    char why[160];
    pdt_status st = PDT_OK;
    if (map_file(ppath, &map, &size, why, sizeof why) != 0) {
        pdt_tf_warnf(run, "points.bin: %s: the run cannot be replayed or checked", why);
    } else {
        pdt_err perr = {0};
        if (points_in_place(map, size, &run->pts, &run->npts)) {
            run->pts_map = map; /* (kept: the points are read from it) */
            run->pts_map_size = size;
        }
        if (!run->pts_map &&
            pdt_tf_points_parse("points.bin", map, size, &run->pts, &run->npts, &perr) != PDT_OK) {
            if (perr.code == PDT_ERR_NOMEM) st = pdt_err_set(err, perr.code, "%s", perr.msg);
            else pdt_tf_warnf(run, "%s", perr.msg);
        } else if (run->npts != run->m.n) {
            pdt_tf_warnf(run, "points.bin: %zu points, manifest says %" PRIu64, run->npts, run->m.n);
        } else {
            sum_start(run);  /* (its warning, if any, goes here: sum_finish) */
        }
    }
    if (run->pts_map) { /* (the checks read every page; the sum gives them back) */
        if (!run->sum.started) release_pages(map, 0, size);
    } else if (map) {
        munmap(map, size);
    }
    free(ppath);
    return st;
}

/* Ranks from .. to-1 have no file: one warning for them all. */
static void report_absent(pdt_run *run, int from, int to)
{
    char a[32], b[32];
    rank_name(a, sizeof a, from);
    rank_name(b, sizeof b, to - 1);
    if (from == to - 1)
        pdt_tf_warnf(run, "%s: missing: no events for rank %d", a, from);
    else
        pdt_tf_warnf(run, "%s to %s: missing (%d files): no events for ranks %d to %d", a, b,
                     to - from, from, to - 1);
}

/* Every rank's file, its clock shifted by its offset.  Missing rank files
 * are reported as ranges: a damaged manifest may announce up to 2^20
 * ranks, and one line per absent file would bury the other warnings. */
static pdt_status scan_ranks(pdt_run *run, pdt_err *err)
{
    run->rk = calloc((size_t)run->nranks, sizeof *run->rk);
    if (!run->rk) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    int64_t minoff = clock_base(run);
    int absent_from = -1;
    pdt_status st = PDT_OK;
    for (int r = 0; r <= run->nranks && st == PDT_OK; r++) {
        if (r < run->nranks) {
            run->rk[r].shift = run->m.clock_offset_ns[r] - minoff;
            st = scan_rank(run, r, err);
            if (run->rk[r].absent) {
                if (absent_from < 0) absent_from = r;
                continue;
            }
        }
        if (absent_from >= 0) report_absent(run, absent_from, r);
        absent_from = -1;
    }
    return st;
}

pdt_status pdt_run_open(const char *dir, pdt_run **out, pdt_err *err)
{
    *out = NULL;
    pdt_run *run = calloc(1, sizeof *run);
    if (!run) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    run->dir = pdt_tf_path_join(dir, "");
    if (!run->dir) {
        pdt_run_close(run);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    run->dir[strlen(dir)] = '\0';  /* join added a '/' */
    pdt_status st = read_manifest(run, dir, err);
    if (st == PDT_OK) run->nranks = run->m.nranks;
    if (st == PDT_OK && run->m.command[0]) st = read_points(run, dir, err);
    if (st == PDT_OK) st = scan_ranks(run, err);
    sum_finish(run);
    if (st != PDT_OK) {
        pdt_run_close(run);
        return st;
    }
    *out = run;
    return PDT_OK;
}

void pdt_run_close(pdt_run *run)
{
    if (!run) return;
    if (run->sum.started) pthread_join(run->sum.th, NULL);
    for (int r = 0; run->rk && r < run->nranks; r++) {
        tf_rank *rk = &run->rk[r];
        if (rk->map) munmap(rk->map, rk->size);
        free(rk->blk);
        free(rk->ev);
    }
    free(run->rk);
    pdt_manifest_free(&run->m);
    if (run->pts_map) munmap(run->pts_map, run->pts_map_size);
    else free(run->pts);
    free(run->warn);
    free(run->merged);
    free(run->dir);
    free(run);
}

const pdt_manifest *pdt_run_manifest(const pdt_run *run)
{
    return &run->m;
}

const pdt_point *pdt_run_points(const pdt_run *run, size_t *n)
{
    *n = run->npts;
    return run->pts;
}

const char *pdt_run_warnings(const pdt_run *run)
{
    return run->warn ? run->warn : "";
}

int pdt_run_nranks(const pdt_run *run)
{
    return run->nranks;
}

void pdt_run_rank_info(const pdt_run *run, int rank, pdt_rank_info *info)
{
    memset(info, 0, sizeof *info);
    if (rank < 0 || rank >= run->nranks) return;
    const tf_rank *rk = &run->rk[rank];
    info->events = rk->nev;
    info->bytes = rk->size;
    info->blocks = rk->nblk;
    info->complete = rk->complete;
    info->present = rk->present;
    info->level = rk->level;
}

size_t pdt_run_rank_blocks(const pdt_run *run, int rank, const pdt_block_ref **blk,
                           const uint8_t **file, int64_t *shift)
{
    *blk = NULL;
    *file = NULL;
    *shift = 0;
    if (rank < 0 || rank >= run->nranks) return 0;
    const tf_rank *rk = &run->rk[rank];
    *blk = rk->blk;
    *file = rk->map;
    *shift = rk->shift;
    return rk->nblk;
}

int pdt_block_decode(const uint8_t *payload, uint32_t len, uint32_t count, uint64_t base_t,
                     pdt_event *out)
{
    return pdt_tf_decode(payload, len, count, base_t, out);
}

/* malloc() for the big arrays of decoded and merged events (hundreds of MB
 * for 10^7 events), 2 MiB-aligned for huge pages if asked for
 * (pdt_big_advise).  NULL when out of memory; free with free(). */
void *pdt_tf_big_alloc(size_t bytes)
{
    const size_t huge = (size_t)2 << 20;
    if (bytes < 2 * huge) return malloc(bytes ? bytes : 1);
    if (bytes > SIZE_MAX - huge) return NULL;
    size_t round = (bytes + huge - 1) / huge * huge;
    void *p = aligned_alloc(huge, round);
    if (p) pdt_big_advise(p, round);
    return p;
}

static void shift_times(pdt_event *ev, size_t n, int64_t shift)
{
    for (size_t i = 0; i < n; i++) ev[i].t += (uint64_t)shift;
}

pdt_status pdt_run_rank_events(pdt_run *run, int rank, const pdt_event **ev, size_t *n,
                               pdt_err *err)
{
    *ev = NULL;
    *n = 0;
    if (rank < 0 || rank >= run->nranks)
        return pdt_err_set(err, PDT_ERR_ARG, "rank %d: the run has ranks 0..%d", rank,
                           run->nranks - 1);
    tf_rank *rk = &run->rk[rank];
    if (!rk->ev && rk->nev) {
        if (rk->nev > SIZE_MAX / sizeof *rk->ev)
            return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
        rk->ev = pdt_tf_big_alloc((size_t)rk->nev * sizeof *rk->ev);
        if (!rk->ev)
            return pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: out of memory (%" PRIu64 " events)",
                               rank, rk->nev);
        for (size_t b = 0; b < rk->nblk; b++) {
            const tf_block *bk = &rk->blk[b];
            /* validated at open: cannot fail */
            pdt_tf_decode(rk->map + bk->off + TF_BLOCK_HEADER_SIZE, bk->len, bk->count,
                          bk->base_t, rk->ev + bk->first);
        }
        shift_times(rk->ev, (size_t)rk->nev, rk->shift);
    }
    *ev = rk->ev;
    *n = (size_t)rk->nev;
    return PDT_OK;
}

/* ---- cursor ------------------------------------------------------------------- */

struct pdt_cursor {
    pdt_run *run;
    tf_rank *rk;
    size_t blk;        /* block in buf (SIZE_MAX: none) */
    pdt_event *buf;
    size_t cap;
    uint64_t pos;      /* index of the next event */
    size_t released;   /* mapped bytes before this were given back (release_pages) */
};

pdt_status pdt_cursor_open(pdt_run *run, int rank, pdt_cursor **out, pdt_err *err)
{
    *out = NULL;
    if (rank < 0 || rank >= run->nranks)
        return pdt_err_set(err, PDT_ERR_ARG, "rank %d: the run has ranks 0..%d", rank,
                           run->nranks - 1);
    pdt_cursor *c = calloc(1, sizeof *c);
    if (!c) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    c->run = run;
    c->rk = &run->rk[rank];
    c->blk = SIZE_MAX;
    *out = c;
    return PDT_OK;
}

pdt_status pdt_cursor_seek(pdt_cursor *c, uint64_t k, pdt_err *err)
{
    if (k > c->rk->nev)
        return pdt_err_set(err, PDT_ERR_ARG, "event %" PRIu64 ": the rank has %" PRIu64 " events",
                           k, c->rk->nev);
    c->pos = k;
    return PDT_OK;
}

/* Decode block b into c->buf; 0 or -1 (no memory). */
static int cursor_load(pdt_cursor *c, size_t b)
{
    const tf_block *bk = &c->rk->blk[b];
    if (bk->count > c->cap) {
        pdt_event *n = realloc(c->buf, bk->count * sizeof *n);
        if (!n) return -1;
        c->buf = n;
        c->cap = bk->count;
    }
    pdt_tf_decode(c->rk->map + bk->off + TF_BLOCK_HEADER_SIZE, bk->len, bk->count, bk->base_t,
                  c->buf);
    shift_times(c->buf, bk->count, c->rk->shift);
    c->blk = b;
    if (bk->off > c->released + RELEASE_STEP)  /* reading forwards: drop what is behind */
        c->released = release_pages(c->rk->map, c->released, (size_t)bk->off);
    else if (bk->off < c->released)            /* a seek backwards */
        c->released = (size_t)bk->off;
    return 0;
}

/* The block of c's position decoded (the next one, as a pass forwards
 * goes, or found by a binary search): 1, or 0 at the end or when it could
 * not be decoded. */
static int cursor_at(pdt_cursor *c)
{
    tf_rank *rk = c->rk;
    if (c->pos >= rk->nev) return 0;
    const tf_block *bk = c->blk != SIZE_MAX ? &rk->blk[c->blk] : NULL;
    if (bk && c->pos >= bk->first && c->pos < bk->first + bk->count) return 1;
    size_t b;
    if (bk && c->blk + 1 < rk->nblk && rk->blk[c->blk + 1].first == c->pos) {
        b = c->blk + 1;  /* the common case: the next block */
    } else {             /* binary search: last block with first <= pos */
        size_t lo = 0, hi = rk->nblk;
        while (hi - lo > 1) {
            size_t mid = lo + (hi - lo) / 2;
            if (rk->blk[mid].first <= c->pos) lo = mid;
            else hi = mid;
        }
        b = lo;
    }
    return cursor_load(c, b) == 0;
}

int pdt_cursor_next(pdt_cursor *c, pdt_event *ev, uint64_t *seq)
{
    if (!cursor_at(c)) return 0;
    *ev = c->buf[c->pos - c->rk->blk[c->blk].first];
    if (seq) *seq = c->pos;
    c->pos++;
    return 1;
}

size_t pdt_cursor_span(pdt_cursor *c, const pdt_event **evs, size_t max, uint64_t *seq)
{
    if (!max || !cursor_at(c)) return 0;
    const tf_block *bk = &c->rk->blk[c->blk];
    size_t at = (size_t)(c->pos - bk->first), n = bk->count - at < max ? bk->count - at : max;
    *evs = c->buf + at;
    *seq = c->pos;
    c->pos += n;
    return n;
}

void pdt_cursor_close(pdt_cursor *c)
{
    if (!c) return;
    free(c->buf);
    free(c);
}
