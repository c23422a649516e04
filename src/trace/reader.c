/* pdt — the reader library: open a run folder, validate, decode, merge. */
#include "tf_internal.h"
#include "pdt/io.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

typedef pdt_block_ref tf_block;  /* off: of the block header; first: its first event */
_Static_assert(PDT_BLOCK_HEADER_BYTES == TF_BLOCK_HEADER_SIZE, "tracefile.h says the header size");

typedef struct tf_rank {
    int present, complete, level;
    int absent;       /* the file does not exist (reported in ranges by pdt_run_open) */
    uint8_t *map;
    size_t size;
    tf_block *blk;
    size_t nblk;
    uint64_t nev;
    int64_t shift;    /* added to every time: offset - min(0, min offsets) */
    pdt_event *ev;    /* all events, decoded on demand */
} tf_rank;

struct pdt_run {
    char *dir;
    pdt_manifest m;
    pdt_point *pts;
    size_t npts;
    uint8_t *pts_map;  /* points.bin, when pts points into it (no copy) */
    size_t pts_map_size;
    int nranks;
    tf_rank *rk;
    char *warn;
    size_t wlen, wcap;
    pdt_rec *merged;
    size_t nmerged;
    int merged_done;
};

static void warnf(pdt_run *run, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void warnf(pdt_run *run, const char *fmt, ...)
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
static pdt_status scan_rank(pdt_run *run, int r, pdt_err *err)
{
    tf_rank *rk = &run->rk[r];
    char name[32];
    rank_name(name, sizeof name, r);
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
        warnf(run, "%s: %s: no events for rank %d", name, why, r);
        return PDT_OK;
    }
    const uint8_t *p = rk->map;
    if (rk->size < TF_HEADER_SIZE || memcmp(p, TF_MAGIC, 8) != 0) {
        warnf(run, "%s: not a pdt trace file (bad header): no events for rank %d", name, r);
        return PDT_OK;
    }
    if (tf_get32(p + 28) != pdt_crc32c(0, p, 28)) {
        warnf(run, "%s: file header checksum mismatch: no events for rank %d", name, r);
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
        warnf(run, "%s: bad header size %u: no events for rank %d", name, hsize, r);
        return PDT_OK;
    }
    if (tf_get32(p + 16) != (uint32_t)r)
        warnf(run, "%s: header says rank %u", name, tf_get32(p + 16));
    rk->level = (int)tf_get32(p + 20);
    rk->present = 1;

    size_t cap = 0, released = 0;
    uint64_t off = hsize, expect = 0;
    int damaged = 0;
    for (size_t k = 0; off < rk->size; k++) {
        if (off - released >= RELEASE_STEP) released = release_pages(rk->map, released, off);
        uint64_t left = rk->size - off;
        if (left < TF_BLOCK_HEADER_SIZE) {
            warnf(run, "%s: block %zu at byte %" PRIu64 ": truncated block header (%" PRIu64
                       " of %u bytes)", name, k, off, left, TF_BLOCK_HEADER_SIZE);
            damaged = 1;
            break;
        }
        const uint8_t *h = p + off;
        uint32_t magic = tf_get32(h), len = tf_get32(h + 4), count = tf_get32(h + 24);
        uint64_t first = tf_get64(h + 8), base = tf_get64(h + 16);
        if (magic != TF_BLOCK_MAGIC && magic != TF_END_MAGIC) {
            warnf(run, "%s: block %zu at byte %" PRIu64 ": bad block magic 0x%08x", name, k, off,
                  magic);
            damaged = 1;
            break;
        }
        if (len > left - TF_BLOCK_HEADER_SIZE) {
            warnf(run, "%s: block %zu at byte %" PRIu64 ": truncated (payload of %u bytes, %" PRIu64
                       " left)", name, k, off, len, left - TF_BLOCK_HEADER_SIZE);
            damaged = 1;
            break;
        }
        uint32_t crc = pdt_crc32c(pdt_crc32c(0, h, 28), h + TF_BLOCK_HEADER_SIZE, len);
        if (crc != tf_get32(h + 28)) {
            warnf(run, "%s: block %zu at byte %" PRIu64 ": checksum mismatch", name, k, off);
            damaged = 1;
            break;
        }
        if (magic == TF_END_MAGIC) {
            uint64_t total = len >= 8 ? tf_get64(h + TF_BLOCK_HEADER_SIZE) : UINT64_MAX;
            if (total != expect)
                warnf(run, "%s: end marker at byte %" PRIu64 " counts %" PRIu64
                           " events, blocks hold %" PRIu64, name, off, total, expect);
            else
                rk->complete = 1;
            if (off + TF_BLOCK_HEADER_SIZE + len != rk->size)
                warnf(run, "%s: %" PRIu64 " bytes after the end marker ignored", name,
                      rk->size - (off + TF_BLOCK_HEADER_SIZE + len));
            break;
        }
        if (first != expect) {
            warnf(run, "%s: block %zu at byte %" PRIu64 ": starts at event %" PRIu64
                       ", expected %" PRIu64, name, k, off, first, expect);
            damaged = 1;
            break;
        }
        if (count == 0 ||
            pdt_tf_decode(h + TF_BLOCK_HEADER_SIZE, len, count, base, NULL) != 0) {
            warnf(run, "%s: block %zu at byte %" PRIu64 ": malformed event data", name, k, off);
            damaged = 1;
            break;
        }
        if (rk->nblk == cap) {
            size_t nc = cap ? 2 * cap : 64;
            tf_block *b = realloc(rk->blk, nc * sizeof *b);
            if (!b) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
            rk->blk = b;
            cap = nc;
        }
        rk->blk[rk->nblk++] = (tf_block){off, first, base, len, count};
        expect += count;
        off += TF_BLOCK_HEADER_SIZE + len;
    }
    release_pages(rk->map, released, rk->size);
    rk->nev = expect;
    if (damaged)
        warnf(run, "%s: read %" PRIu64 " events in %zu intact blocks before the damage", name,
              expect, rk->nblk);
    else if (!rk->complete)
        warnf(run, "%s: no end marker (run killed?): read %" PRIu64 " events in %zu blocks",
              name, expect, rk->nblk);
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
    warnf(run, "manifest: missing (run killed before it was written?); found %d rank file%s, "
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
            warnf(run, "manifest: clock_offset_ns of rank %d is %" PRId64 " ns, beyond +-%" PRId64
                       " ns: clocks not aligned", r, off[r], CLOCK_OFFSET_MAX);
            memset(off, 0, (size_t)run->nranks * sizeof *off);
            return 0;
        }
        if (off[r] < minoff) minoff = off[r];
    }
    return minoff;
}

pdt_status pdt_run_open(const char *dir, pdt_run **out, pdt_err *err)
{
    *out = NULL;
    pdt_run *run = calloc(1, sizeof *run);
    if (!run) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    pdt_status st = PDT_OK;
    run->dir = pdt_tf_path_join(dir, "");
    char *mpath = pdt_tf_path_join(dir, "manifest");
    if (!run->dir || !mpath) {
        free(mpath);
        pdt_run_close(run);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    run->dir[strlen(dir)] = '\0';  /* join added a '/' */
    int e;
    char why[160];
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
    if (st != PDT_OK) {
        pdt_run_close(run);
        return st;
    }
    run->nranks = run->m.nranks;

    /* points.bin */
    if (run->m.command[0]) {
        char *ppath = pdt_tf_path_join(dir, "points.bin");
        uint8_t *map = NULL;
        size_t size = 0;
        if (!ppath) st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
        else if ((e = map_file(ppath, &map, &size, why, sizeof why)) != 0)
            warnf(run, "points.bin: %s: the run cannot be replayed or checked", why);
        else {
            pdt_err perr = {0};
            if (points_in_place(map, size, &run->pts, &run->npts)) {
                run->pts_map = map; /* (kept: the points are read from it) */
                run->pts_map_size = size;
            }
            if (!run->pts_map &&
                pdt_tf_points_parse("points.bin", map, size, &run->pts, &run->npts, &perr) != PDT_OK) {
                if (perr.code == PDT_ERR_NOMEM) st = pdt_err_set(err, perr.code, "%s", perr.msg);
                else warnf(run, "%s", perr.msg);
            } else if (run->npts != run->m.n) {
                warnf(run, "points.bin: %zu points, manifest says %" PRIu64, run->npts,
                      run->m.n);
            } else if (points_sum(&run->m, run->pts, run->npts) != run->m.input_checksum) {
                warnf(run, "points.bin: points do not match the manifest's input_checksum");
            }
        }
        if (run->pts_map) release_pages(map, 0, size); /* (the checksums read every page) */
        else if (map) munmap(map, size);
        free(ppath);
        if (st != PDT_OK) {
            pdt_run_close(run);
            return st;
        }
    }

    run->rk = calloc((size_t)run->nranks, sizeof *run->rk);
    if (!run->rk) {
        pdt_run_close(run);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    int64_t minoff = clock_base(run);
    /* Missing rank files are reported as ranges: a damaged manifest may
     * announce up to 2^20 ranks, and one line per absent file would bury the
     * other warnings. */
    int absent_from = -1;
    for (int r = 0; r <= run->nranks && st == PDT_OK; r++) {
        if (r < run->nranks) {
            run->rk[r].shift = run->m.clock_offset_ns[r] - minoff;
            st = scan_rank(run, r, err);
            if (run->rk[r].absent) {
                if (absent_from < 0) absent_from = r;
                continue;
            }
        }
        if (absent_from >= 0) {
            char a[32], b[32];
            rank_name(a, sizeof a, absent_from);
            rank_name(b, sizeof b, r - 1);
            if (absent_from == r - 1)
                warnf(run, "%s: missing: no events for rank %d", a, absent_from);
            else
                warnf(run, "%s to %s: missing (%d files): no events for ranks %d to %d", a, b,
                      r - absent_from, absent_from, r - 1);
            absent_from = -1;
        }
    }
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
 * for 10^7 events): they ask for transparent huge pages, which cuts the page
 * faults of filling them.  NULL when out of memory; free with free(). */
static void *big_alloc(size_t bytes)
{
    const size_t huge = (size_t)2 << 20;
    if (bytes < 2 * huge) return malloc(bytes ? bytes : 1);
    if (bytes > SIZE_MAX - huge) return NULL;
    size_t round = (bytes + huge - 1) / huge * huge;
    void *p = aligned_alloc(huge, round);
    if (p) madvise(p, round, MADV_HUGEPAGE);
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
        rk->ev = big_alloc((size_t)rk->nev * sizeof *rk->ev);
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

int pdt_cursor_next(pdt_cursor *c, pdt_event *ev, uint64_t *seq)
{
    tf_rank *rk = c->rk;
    if (c->pos >= rk->nev) return 0;
    const tf_block *bk = c->blk != SIZE_MAX ? &rk->blk[c->blk] : NULL;
    if (!bk || c->pos < bk->first || c->pos >= bk->first + bk->count) {
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
        if (cursor_load(c, b) != 0) return 0;
        bk = &rk->blk[b];
    }
    *ev = c->buf[c->pos - bk->first];
    if (seq) *seq = c->pos;
    c->pos++;
    return 1;
}

void pdt_cursor_close(pdt_cursor *c)
{
    if (!c) return;
    free(c->buf);
    free(c);
}

/* ---- merged order ----------------------------------------------------------- */

typedef struct msg_key {
    uint32_t src, dst, tag;
    int64_t seq;
} msg_key;

typedef struct msg_slot {
    msg_key k;
    uint32_t count;  /* sends not yet received */
    int used;
} msg_slot;

typedef struct msg_set {
    msg_slot *s;
    size_t cap, n;
} msg_set;

static uint64_t key_hash(const msg_key *k)
{
    uint64_t h = k->src * 0x9e3779b97f4a7c15u ^ k->dst * 0xc2b2ae3d27d4eb4fu ^
                 k->tag * 0x165667b19e3779f9u ^ (uint64_t)k->seq * 0xff51afd7ed558ccdu;
    return h ^ (h >> 29);
}

static int key_eq(const msg_key *a, const msg_key *b)
{
    return a->src == b->src && a->dst == b->dst && a->tag == b->tag && a->seq == b->seq;
}

/* Slot of k (inserting if `add`); NULL if absent or out of memory. */
static msg_slot *msg_find(msg_set *m, const msg_key *k, int add)
{
    if (add && 2 * (m->n + 1) > m->cap) {
        size_t cap = m->cap ? 2 * m->cap : 64;
        msg_slot *s = calloc(cap, sizeof *s);
        if (!s) return NULL;
        for (size_t i = 0; i < m->cap; i++) {
            if (!m->s[i].used) continue;
            size_t j = key_hash(&m->s[i].k) & (cap - 1);
            while (s[j].used) j = (j + 1) & (cap - 1);
            s[j] = m->s[i];
        }
        free(m->s);
        m->s = s;
        m->cap = cap;
    }
    if (!m->cap) return NULL;
    size_t j = key_hash(k) & (m->cap - 1);
    while (m->s[j].used) {
        if (key_eq(&m->s[j].k, k)) return &m->s[j];
        j = (j + 1) & (m->cap - 1);
    }
    if (!add) return NULL;
    m->s[j].used = 1;
    m->s[j].k = *k;
    m->s[j].count = 0;
    m->n++;
    return &m->s[j];
}

static msg_key ev_key(const pdt_event *e, uint32_t rank)
{
    msg_key k;
    k.tag = e->sub;
    k.seq = e->v;
    if (e->kind == PDT_EV_SEND) {
        k.src = rank;
        k.dst = e->a;
    } else {
        k.src = e->a;
        k.dst = rank;
    }
    return k;
}

/* ---- the streaming merge ------------------------------------------------------
 *
 * One cursor per rank; a heap of the ranks whose next event (head) may go
 * next, ordered by (aligned time, rank); a rank whose head is a RECV whose
 * SEND is still to come waits ("blocked") until that SEND has gone out.
 * Memory: one decoded block per rank plus the message sets — independent of
 * the number of events. */

struct pdt_merge {
    pdt_run *run;
    uint32_t R;
    pdt_cursor **cur;    /* per rank */
    pdt_event *head;     /* per rank: its next event, valid while has[r] */
    uint64_t *pos;       /* per rank: index of head in the rank */
    uint8_t *has;
    uint32_t *heap;      /* ranks whose head may go next */
    size_t nheap;
    uint8_t *blocked;    /* ranks whose head is a RECV waiting for its SEND */
    size_t nblocked;
    msg_set sent;        /* sends placed and not yet received */
    msg_set unsent;      /* sends not yet placed (all SENDs of the run at the start) */
    uint32_t next;       /* a rank known to go next without asking the heap, or UINT32_MAX */
    uint64_t left;       /* events not yet delivered */
};

static int head_less(const pdt_merge *m, uint32_t a, uint32_t b)
{
    uint64_t ta = m->head[a].t, tb = m->head[b].t;
    return ta != tb ? ta < tb : a < b;
}

static void heap_push(pdt_merge *m, uint32_t r)
{
    size_t i = m->nheap++;
    m->heap[i] = r;
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (!head_less(m, m->heap[i], m->heap[p])) break;
        uint32_t t = m->heap[i];
        m->heap[i] = m->heap[p];
        m->heap[p] = t;
        i = p;
    }
}

static uint32_t heap_pop(pdt_merge *m)
{
    uint32_t top = m->heap[0];
    m->heap[0] = m->heap[--m->nheap];
    size_t i = 0;
    for (;;) {
        size_t l = 2 * i + 1, k = i;
        if (l < m->nheap && head_less(m, m->heap[l], m->heap[k])) k = l;
        if (l + 1 < m->nheap && head_less(m, m->heap[l + 1], m->heap[k])) k = l + 1;
        if (k == i) break;
        uint32_t t = m->heap[i];
        m->heap[i] = m->heap[k];
        m->heap[k] = t;
        i = k;
    }
    return top;
}

/* Load rank r's next event into head[r]. */
static void advance(pdt_merge *m, uint32_t r)
{
    m->has[r] = (uint8_t)pdt_cursor_next(m->cur[r], &m->head[r], &m->pos[r]);
}

/* Put rank r's head event into the heap, or mark it blocked.  A RECV waits
 * only for a SEND that is still to come: one whose SEND is in no file (a
 * lost or damaged rank file) is placed by its time at once, so it cannot
 * hold up, or be forced ahead of, messages that are all there. */
static void schedule(pdt_merge *m, uint32_t r)
{
    if (!m->has[r]) return;
    const pdt_event *e = &m->head[r];
    if (e->kind == PDT_EV_RECV) {
        msg_key key = ev_key(e, r);
        msg_slot *s = msg_find(&m->sent, &key, 0);
        msg_slot *u = msg_find(&m->unsent, &key, 0);
        if ((!s || s->count == 0) && u && u->count > 0) {
            m->blocked[r] = 1;
            m->nblocked++;
            return;
        }
    }
    heap_push(m, r);
}

/* Every SEND of the run into m->unsent (one pass over the events). */
static pdt_status count_sends(pdt_merge *m, pdt_err *err)
{
    for (uint32_t r = 0; r < m->R; r++) {
        pdt_cursor *c;
        pdt_status st = pdt_cursor_open(m->run, (int)r, &c, err);
        if (st != PDT_OK) return st;
        pdt_event e;
        while (pdt_cursor_next(c, &e, NULL)) {
            if (e.kind != PDT_EV_SEND) continue;
            msg_key key = ev_key(&e, r);
            msg_slot *u = msg_find(&m->unsent, &key, 1);
            if (!u) {
                pdt_cursor_close(c);
                return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory (message index)");
            }
            u->count++;
        }
        pdt_cursor_close(c);
    }
    return PDT_OK;
}

pdt_status pdt_merge_open(pdt_run *run, pdt_merge **out, pdt_err *err)
{
    *out = NULL;
    pdt_merge *m = calloc(1, sizeof *m);
    if (!m) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    size_t R = (size_t)run->nranks;
    m->run = run;
    m->R = (uint32_t)R;
    m->next = UINT32_MAX;
    m->cur = calloc(R ? R : 1, sizeof *m->cur);
    m->head = calloc(R ? R : 1, sizeof *m->head);
    m->pos = calloc(R ? R : 1, sizeof *m->pos);
    m->has = calloc(R ? R : 1, 1);
    m->heap = calloc(R ? R : 1, sizeof *m->heap);
    m->blocked = calloc(R ? R : 1, 1);
    pdt_status st = PDT_OK;
    if (!m->cur || !m->head || !m->pos || !m->has || !m->heap || !m->blocked)
        st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    /* one rank: the order is its file order whatever the messages say */
    if (st == PDT_OK && R > 1) st = count_sends(m, err);
    for (uint32_t r = 0; st == PDT_OK && r < R; r++) {
        st = pdt_cursor_open(run, (int)r, &m->cur[r], err);
        m->left += run->rk[r].nev;
    }
    if (st != PDT_OK) {
        pdt_merge_close(m);
        return st;
    }
    for (uint32_t r = 0; r < R; r++) {
        advance(m, r);
        schedule(m, r);
    }
    *out = m;
    return PDT_OK;
}

/* Bookkeeping of the messages when event e of rank r is placed. */
static int place_message(pdt_merge *m, const pdt_event *e, uint32_t r, uint64_t seq)
{
    msg_key key = ev_key(e, r);
    if (e->kind == PDT_EV_SEND) {
        msg_slot *s = msg_find(&m->sent, &key, 1);
        if (!s) return -1;
        s->count++;
        msg_slot *u = msg_find(&m->unsent, &key, 0);
        if (u && u->count) u->count--;
        uint32_t d = key.dst;  /* wake the receiver waiting for this message */
        if (m->nblocked && d < m->R && m->blocked[d]) {
            msg_key wk = ev_key(&m->head[d], d);
            if (key_eq(&wk, &key)) {
                m->blocked[d] = 0;
                m->nblocked--;
                heap_push(m, d);
            }
        }
    } else {
        msg_slot *s = msg_find(&m->sent, &key, 0);
        if (s && s->count) s->count--;
        else  /* its SEND is in no file, or a cycle forced it */
            warnf(m->run, "rank %u event #%" PRIu64 ": recv from rank %u (tag %u, seq %" PRId64
                          ") has no matching send", r, seq, e->a, e->sub, e->v);
    }
    return 0;
}

int pdt_merge_next(pdt_merge *m, pdt_rec *rec, pdt_err *err)
{
    if (m->left == 0) return 0;
    uint32_t r = UINT32_MAX;
    if (m->next != UINT32_MAX) {
        r = m->next;
        m->next = UINT32_MAX;
    } else if (m->nheap > 0) {
        r = heap_pop(m);
    } else {  /* every remaining head is a RECV whose SEND is missing: force one */
        for (uint32_t q = 0; q < m->R; q++)
            if (m->blocked[q] && (r == UINT32_MAX || head_less(m, q, r))) r = q;
        if (r == UINT32_MAX) {  /* a cursor stopped early: it could not get memory */
            pdt_err_set(err, PDT_ERR_NOMEM, "out of memory decoding a trace block");
            return -1;
        }
        m->blocked[r] = 0;
        m->nblocked--;
    }
    rec->ev = m->head[r];
    rec->rank = r;
    rec->seq = (uint32_t)m->pos[r];
    m->left--;
    advance(m, r);
    if ((rec->ev.kind == PDT_EV_SEND || rec->ev.kind == PDT_EV_RECV) &&
        place_message(m, &rec->ev, r, m->pos[r] - 1) != 0) {
        pdt_err_set(err, PDT_ERR_NOMEM, "out of memory (message index)");
        return -1;
    }
    /* Fast path: if r's next event is no RECV and comes before every head in
     * the heap, pushing r and popping the heap would give r again (the order
     * (t, rank) is total), so skip both. */
    if (m->has[r] && m->head[r].kind != PDT_EV_RECV &&
        (m->nheap == 0 || head_less(m, r, m->heap[0])))
        m->next = r;
    else
        schedule(m, r);
    return 1;
}

void pdt_merge_close(pdt_merge *m)
{
    if (!m) return;
    for (uint32_t r = 0; m->cur && r < m->R; r++) pdt_cursor_close(m->cur[r]);
    free(m->cur);
    free(m->head);
    free(m->pos);
    free(m->has);
    free(m->heap);
    free(m->blocked);
    free(m->sent.s);
    free(m->unsent.s);
    free(m);
}

pdt_status pdt_run_merged(pdt_run *run, const pdt_rec **recs, size_t *n, pdt_err *err)
{
    *recs = NULL;
    *n = 0;
    if (run->merged_done) {
        *recs = run->merged;
        *n = run->nmerged;
        return PDT_OK;
    }
    uint64_t total = 0;
    for (int r = 0; r < run->nranks; r++) total += run->rk[r].nev;
    if (total > SIZE_MAX / sizeof(pdt_rec))
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory (%" PRIu64 " events)", total);
    pdt_merge *m;
    pdt_status st = pdt_merge_open(run, &m, err);
    if (st != PDT_OK) return st;
    pdt_rec *out = big_alloc((size_t)total * sizeof *out);
    if (!out) {
        pdt_merge_close(m);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory (%" PRIu64 " events)", total);
    }
    size_t k = 0;
    int got;
    while (k < total && (got = pdt_merge_next(m, &out[k], err)) == 1) k++;
    pdt_merge_close(m);
    if (k < total) {
        free(out);
        return err->code ? err->code : pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    run->merged = out;
    run->nmerged = (size_t)total;
    run->merged_done = 1;
    *recs = run->merged;
    *n = run->nmerged;
    return PDT_OK;
}
