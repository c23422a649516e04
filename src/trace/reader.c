/* pdt — the reader library: open a run folder, validate, decode, merge. */
#include "tf_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct tf_block {
    uint64_t off;     /* of the block header */
    uint64_t first;   /* index of the first event */
    uint64_t base_t;
    uint32_t len, count;
} tf_block;

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

/* Map a whole file read-only.  Returns 0, or errno (ENOENT if missing).
 * An empty file gives map = NULL, size = 0. */
static int map_file(const char *path, uint8_t **map, size_t *size)
{
    *map = NULL;
    *size = 0;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return errno;
    struct stat st;
    if (fstat(fd, &st) != 0) {
        int e = errno;
        close(fd);
        return e;
    }
    if (st.st_size > 0) {
        void *p = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE, fd, 0);
        if (p == MAP_FAILED) {
            int e = errno;
            close(fd);
            return e;
        }
        *map = p;
        *size = (size_t)st.st_size;
    }
    close(fd);
    return 0;
}

/* Validate the header and index the blocks of one rank file. */
static pdt_status scan_rank(pdt_run *run, int r, pdt_err *err)
{
    tf_rank *rk = &run->rk[r];
    char name[32];
    rank_name(name, sizeof name, r);
    char *path = pdt_tf_path_join(run->dir, name);
    if (!path) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    int e = map_file(path, &rk->map, &rk->size);
    free(path);
    if (e == ENOENT) {
        rk->absent = 1;
        return PDT_OK;
    }
    if (e) {
        warnf(run, "%s: %s: no events for rank %d", name, strerror(e), r);
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
    if (maj != PDT_TRACE_FORMAT_MAJOR)
        return pdt_err_set(err, PDT_ERR_FORMAT, "%s/%s: trace format %u.%u; this pdt reads %d.x",
                           run->dir, name, maj, min, PDT_TRACE_FORMAT_MAJOR);
    uint32_t hsize = tf_get32(p + 12);
    if (hsize < TF_HEADER_SIZE || hsize > rk->size) {
        warnf(run, "%s: bad header size %u: no events for rank %d", name, hsize, r);
        return PDT_OK;
    }
    if (tf_get32(p + 16) != (uint32_t)r)
        warnf(run, "%s: header says rank %u", name, tf_get32(p + 16));
    rk->level = (int)tf_get32(p + 20);
    rk->present = 1;

    size_t cap = 0;
    uint64_t off = hsize, expect = 0;
    int damaged = 0;
    for (size_t k = 0; off < rk->size; k++) {
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
    rk->nev = expect;
    if (damaged)
        warnf(run, "%s: read %" PRIu64 " events in %zu intact blocks before the damage", name,
              expect, rk->nblk);
    else if (!rk->complete)
        warnf(run, "%s: no end marker (run killed?): read %" PRIu64 " events in %zu blocks",
              name, expect, rk->nblk);
    return PDT_OK;
}

static char *read_text(const char *path, int *errnum)
{
    uint8_t *map;
    size_t size;
    *errnum = map_file(path, &map, &size);
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
    char *text = read_text(mpath, &e);
    if (text) {
        st = pdt_tf_manifest_parse(mpath, text, &run->m, err);
        free(text);
    } else if (e == ENOENT) {
        st = guess_manifest(run, err);
    } else {
        st = pdt_err_set(err, PDT_ERR_IO, "%s: cannot read: %s", mpath, strerror(e));
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
        else if ((e = map_file(ppath, &map, &size)) != 0)
            warnf(run, "points.bin: %s: the run cannot be replayed or checked", strerror(e));
        else {
            pdt_err perr = {0};
            if (pdt_tf_points_parse("points.bin", map, size, &run->pts, &run->npts, &perr) !=
                PDT_OK) {
                if (perr.code == PDT_ERR_NOMEM) st = pdt_err_set(err, perr.code, "%s", perr.msg);
                else warnf(run, "%s", perr.msg);
            } else if (run->npts != run->m.n) {
                warnf(run, "points.bin: %zu points, manifest says %" PRIu64, run->npts,
                      run->m.n);
            } else if (pdt_points_checksum(run->pts, run->npts) != run->m.input_checksum) {
                warnf(run, "points.bin: points do not match the manifest's input_checksum");
            }
        }
        if (map) munmap(map, size);
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
    int64_t minoff = 0;
    for (int r = 0; r < run->nranks; r++)
        if (run->m.clock_offset_ns[r] < minoff) minoff = run->m.clock_offset_ns[r];
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
    free(run->pts);
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

typedef struct heap {
    uint32_t *r;     /* ranks */
    size_t n;
} heap;

static int head_less(pdt_run *run, const size_t *pos, uint32_t a, uint32_t b)
{
    uint64_t ta = run->rk[a].ev[pos[a]].t, tb = run->rk[b].ev[pos[b]].t;
    return ta != tb ? ta < tb : a < b;
}

static void heap_push(heap *h, pdt_run *run, const size_t *pos, uint32_t r)
{
    size_t i = h->n++;
    h->r[i] = r;
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (!head_less(run, pos, h->r[i], h->r[p])) break;
        uint32_t t = h->r[i];
        h->r[i] = h->r[p];
        h->r[p] = t;
        i = p;
    }
}

static uint32_t heap_pop(heap *h, pdt_run *run, const size_t *pos)
{
    uint32_t top = h->r[0];
    h->r[0] = h->r[--h->n];
    size_t i = 0;
    for (;;) {
        size_t l = 2 * i + 1, m = i;
        if (l < h->n && head_less(run, pos, h->r[l], h->r[m])) m = l;
        if (l + 1 < h->n && head_less(run, pos, h->r[l + 1], h->r[m])) m = l + 1;
        if (m == i) break;
        uint32_t t = h->r[i];
        h->r[i] = h->r[m];
        h->r[m] = t;
        i = m;
    }
    return top;
}

typedef struct merge_ctx {
    pdt_run *run;
    const size_t *pos;   /* next event of each rank */
    heap *h;             /* ranks whose head may go next */
    uint8_t *blocked;    /* ranks whose head is a RECV waiting for its SEND */
    size_t nblocked;
    msg_set *sent;       /* sends not yet received */
    msg_set *unsent;     /* sends not yet placed (all SENDs of the run at the start) */
} merge_ctx;

/* Put rank r's head event into the heap, or mark it blocked.  A RECV waits
 * only for a SEND that is still to come: one whose SEND is in no file (a
 * lost or damaged rank file) is placed by its time at once, so it cannot
 * hold up, or be forced ahead of, messages that are all there. */
static void schedule(merge_ctx *mc, uint32_t r)
{
    if (mc->pos[r] >= mc->run->rk[r].nev) return;
    const pdt_event *e = &mc->run->rk[r].ev[mc->pos[r]];
    if (e->kind == PDT_EV_RECV) {
        msg_key key = ev_key(e, r);
        msg_slot *s = msg_find(mc->sent, &key, 0);
        msg_slot *u = msg_find(mc->unsent, &key, 0);
        if ((!s || s->count == 0) && u && u->count > 0) {
            mc->blocked[r] = 1;
            mc->nblocked++;
            return;
        }
    }
    heap_push(mc->h, mc->run, mc->pos, r);
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
    size_t total = 0;
    for (int r = 0; r < run->nranks; r++) {
        const pdt_event *ev;
        size_t k;
        pdt_status st = pdt_run_rank_events(run, r, &ev, &k, err);
        if (st != PDT_OK) return st;
        total += k;
    }
    size_t R = (size_t)run->nranks;
    pdt_rec *out = big_alloc(total * sizeof *out);
    size_t *pos = calloc(R, sizeof *pos);
    heap h = {malloc(R * sizeof(uint32_t)), 0};
    uint8_t *blocked = calloc(R, 1);
    msg_set sent = {0}, unsent = {0};
    pdt_status st = PDT_OK;
    if (!out || !pos || !h.r || !blocked) {
        st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (uint32_t r = 0; r < R; r++)
        for (size_t i = 0; i < run->rk[r].nev; i++) {
            const pdt_event *e = &run->rk[r].ev[i];
            if (e->kind != PDT_EV_SEND) continue;
            msg_key key = ev_key(e, r);
            msg_slot *u = msg_find(&unsent, &key, 1);
            if (!u) {
                st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
                goto done;
            }
            u->count++;
        }
    merge_ctx mc = {run, pos, &h, blocked, 0, &sent, &unsent};
    size_t k = 0;
    for (uint32_t r = 0; r < R; r++) schedule(&mc, r);
    /* `next`: a rank known to go next without asking the heap (see the end
     * of the loop), or UINT32_MAX. */
    uint32_t next = UINT32_MAX;
    while (k < total) {
        uint32_t r;
        if (next != UINT32_MAX) {
            r = next;
            next = UINT32_MAX;
        } else if (h.n > 0) {
            r = heap_pop(&h, run, pos);
        } else {  /* every remaining head is a RECV whose SEND is missing: force one */
            r = UINT32_MAX;
            for (uint32_t q = 0; q < R; q++)
                if (blocked[q] && (r == UINT32_MAX || head_less(run, pos, q, r))) r = q;
            blocked[r] = 0;
            mc.nblocked--;
        }
        const pdt_event *e = &run->rk[r].ev[pos[r]];
        out[k].ev = *e;
        out[k].rank = r;
        out[k].seq = (uint32_t)pos[r];
        k++;
        pos[r]++;
        msg_key key = ev_key(e, r);
        if (e->kind == PDT_EV_SEND) {
            msg_slot *s = msg_find(&sent, &key, 1);
            if (!s) {
                st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
                goto done;
            }
            s->count++;
            msg_slot *u = msg_find(&unsent, &key, 0);
            if (u && u->count) u->count--;
            if (mc.nblocked) {  /* wake the receiver waiting for this message */
                uint32_t d = key.dst;
                if (d < R && blocked[d]) {
                    const pdt_event *w = &run->rk[d].ev[pos[d]];
                    msg_key wk = ev_key(w, d);
                    if (key_eq(&wk, &key)) {
                        blocked[d] = 0;
                        mc.nblocked--;
                        heap_push(&h, run, pos, d);
                    }
                }
            }
        } else if (e->kind == PDT_EV_RECV) {
            msg_slot *s = msg_find(&sent, &key, 0);
            if (s && s->count) s->count--;
            else  /* its SEND is in no file, or a cycle forced it */
                warnf(run, "rank %u event #%zu: recv from rank %u (tag %u, seq %" PRId64
                           ") has no matching send", r, pos[r] - 1, e->a, e->sub, e->v);
        }
        /* Fast path: if r's next event is no RECV and comes before every
         * head in the heap, pushing r and popping the heap would give r
         * again (the order (t, rank) is total), so skip both. */
        if (pos[r] < run->rk[r].nev && run->rk[r].ev[pos[r]].kind != PDT_EV_RECV &&
            (h.n == 0 || head_less(run, pos, r, h.r[0])))
            next = r;
        else
            schedule(&mc, r);
    }
    run->merged = out;
    run->nmerged = total;
    run->merged_done = 1;
    out = NULL;
    *recs = run->merged;
    *n = run->nmerged;
done:
    free(out);
    free(pos);
    free(h.r);
    free(blocked);
    free(sent.s);
    free(unsent.s);
    return st;
}
