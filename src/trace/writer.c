/* pdt — the trace writer: one per rank, one file per rank.
 *
 * The sink (called through the hook for every event) only stamps the time
 * and appends to an array of TF_BLOCK_EVENTS events; when the array is full
 * it is encoded and written as one checksummed block with write(2), so a
 * killed run leaves every completed block on disk. */
#include "tf_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

struct pdt_trace_writer {
    pdt_trace hook;
    int fd;
    char *path;
    uint64_t origin_ns;  /* the clock at open (CLOCK_MONOTONIC unless clock_ns) */
    uint64_t (*clock_ns)(void *user); /* pdt_tw_set_clock, or NULL */
    void *clock_user;
    uint64_t last_t;     /* latest clock reading (ns since origin) */
    pdt_event *buf;      /* TF_BLOCK_EVENTS */
    size_t nbuf;
    uint8_t *enc;        /* block header + encoded payload */
    uint64_t written;    /* events in blocks already written */
    pdt_err err;         /* first error */
};

static uint64_t mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

static uint64_t clock_of(const pdt_trace_writer *w)
{
    return w->clock_ns ? w->clock_ns(w->clock_user) : mono_ns();
}

uint64_t pdt_wall_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

/* Write all of buf; on failure record the error and stop recording. */
static void tw_write(pdt_trace_writer *w, const uint8_t *buf, size_t len)
{
    while (len > 0) {
        ssize_t k = write(w->fd, buf, len);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) {
            pdt_err_set(&w->err, PDT_ERR_IO, "%s: write failed: %s", w->path,
                        k < 0 ? strerror(errno) : "no progress");
            w->hook.level = 0;  /* stop recording: nothing more can be kept */
            return;
        }
        buf += k;
        len -= (size_t)k;
    }
}

static void tw_flush(pdt_trace_writer *w)
{
    if (w->nbuf == 0 || w->err.code != PDT_OK) {
        w->nbuf = 0;
        return;
    }
    uint64_t base = w->buf[0].t;
    uint8_t *payload = w->enc + TF_BLOCK_HEADER_SIZE;
    size_t len = pdt_tf_encode(w->buf, w->nbuf, base, payload);
    pdt_tf_block_header(w->enc, TF_BLOCK_MAGIC, payload, (uint32_t)len, w->written, base,
                        (uint32_t)w->nbuf);
    tw_write(w, w->enc, TF_BLOCK_HEADER_SIZE + len);
    w->written += w->nbuf;
    w->nbuf = 0;
}

/* Kinds whose time is always read from the clock (boundaries and messages);
 * the others (pushes, pops, lift-ups, triangles, edges ...) come in dense
 * bursts and reuse the latest reading unless TF_CLOCK_EVERY events passed. */
#define TF_CLOCK_KINDS                                                                     \
    ((1u << PDT_EV_PHASE_BEGIN) | (1u << PDT_EV_PHASE_END) | (1u << PDT_EV_MERGE_BEGIN) |   \
     (1u << PDT_EV_MERGE_END) | (1u << PDT_EV_SEND) | (1u << PDT_EV_RECV) |                \
     (1u << PDT_EV_HULL))
#define TF_CLOCK_EVERY 16u

static void tw_sink(pdt_trace *tr, const pdt_event *ev)
{
    pdt_trace_writer *w = tr->user;
    pdt_event *d = &w->buf[w->nbuf];
    *d = *ev;
    if ((ev->kind < 32 && (TF_CLOCK_KINDS >> ev->kind) & 1u) || w->nbuf % TF_CLOCK_EVERY == 0)
        w->last_t = clock_of(w) - w->origin_ns;
    d->t = w->last_t;
    if (++w->nbuf == TF_BLOCK_EVENTS) tw_flush(w);
}

static pdt_status make_dir(const char *dir, pdt_err *err)
{
    if (mkdir(dir, 0777) == 0 || errno == EEXIST) {
        struct stat st;
        if (stat(dir, &st) == 0 && S_ISDIR(st.st_mode)) return PDT_OK;
        return pdt_err_set(err, PDT_ERR_IO, "%s: exists and is not a folder", dir);
    }
    return pdt_err_set(err, PDT_ERR_IO, "%s: cannot create folder: %s", dir, strerror(errno));
}

/* Remove the folder's manifest and points.bin (rank 0, at the start of a
 * run).  0 when out of memory. */
static int remove_stale_meta(const char *dir)
{
    const char *stale[] = {"manifest", "points.bin"};
    for (int i = 0; i < 2; i++) {
        char *p = pdt_tf_path_join(dir, stale[i]);
        if (!p) return 0;
        unlink(p);
        free(p);
    }
    return 1;
}

/* A rank file's header (TF_HEADER_SIZE bytes at h). */
static void file_header(uint8_t *h, int rank, int level)
{
    memset(h, 0, TF_HEADER_SIZE);
    memcpy(h, TF_MAGIC, 8);
    h[8] = PDT_TRACE_FORMAT_MAJOR;
    h[10] = PDT_TRACE_FORMAT_MINOR;
    tf_put32(h + 12, TF_HEADER_SIZE);
    tf_put32(h + 16, (uint32_t)rank);
    tf_put32(h + 20, (uint32_t)level);
    tf_put32(h + 28, pdt_crc32c(0, h, 28));
}

pdt_status pdt_tw_open(const char *dir, int rank, int level, pdt_trace_writer **out,
                       pdt_err *err)
{
    *out = NULL;
    if (rank < 0 || level < 1 || level > 2)
        return pdt_err_set(err, PDT_ERR_ARG, "trace writer: bad rank %d or level %d", rank, level);
    pdt_status st = make_dir(dir, err);
    if (st != PDT_OK) return st;
    pdt_trace_writer *w = calloc(1, sizeof *w);
    if (!w) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    w->fd = -1;
    char name[32];
    snprintf(name, sizeof name, "rank-%04d.trace", rank);
    w->path = pdt_tf_path_join(dir, name);
    w->buf = malloc(TF_BLOCK_EVENTS * sizeof *w->buf);
    w->enc = malloc(TF_BLOCK_HEADER_SIZE + TF_BLOCK_EVENTS * TF_MAX_EVENT_BYTES);
    if (!w->path || !w->buf || !w->enc) {
        pdt_tw_abort(w);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    if (rank == 0 && !remove_stale_meta(dir)) {  /* a stale manifest must not describe the new traces */
        pdt_tw_abort(w);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    /* a fresh file: never through a link or into another name's inode
     * planted at this name (a traced run writes into a folder it created
     * itself: pdt/safefile.h) */
    (void)unlink(w->path);
    w->fd = open(w->path, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (w->fd < 0) {
        st = pdt_err_set(err, PDT_ERR_IO, "%s: cannot create: %s", w->path, strerror(errno));
        pdt_tw_abort(w);
        return st;
    }
    uint8_t h[TF_HEADER_SIZE];
    file_header(h, rank, level);
    tw_write(w, h, sizeof h);
    if (w->err.code != PDT_OK) {
        st = pdt_err_set(err, w->err.code, "%s", w->err.msg);
        pdt_tw_abort(w);
        return st;
    }
    w->hook.level = level;
    w->hook.rank = rank;
    w->hook.gid = NULL;
    w->hook.sink = tw_sink;
    w->hook.user = w;
    w->origin_ns = mono_ns();
    *out = w;
    return PDT_OK;
}

pdt_trace *pdt_tw_hook(pdt_trace_writer *w)
{
    return &w->hook;
}

uint64_t pdt_tw_now(const pdt_trace_writer *w)
{
    return clock_of(w) - w->origin_ns;
}

void pdt_tw_set_clock(pdt_trace_writer *w, uint64_t (*clock_ns)(void *user), void *user)
{
    w->clock_ns = clock_ns;
    w->clock_user = user;
    w->origin_ns = clock_of(w);
    w->last_t = 0;
}

uint64_t pdt_tw_events(const pdt_trace_writer *w)
{
    return w->written + w->nbuf;
}

void pdt_tw_abort(pdt_trace_writer *w)
{
    if (!w) return;
    if (w->fd >= 0) close(w->fd);
    free(w->path);
    free(w->buf);
    free(w->enc);
    free(w);
}

pdt_status pdt_tw_close(pdt_trace_writer *w, pdt_err *err)
{
    if (!w) return PDT_OK;
    tw_flush(w);
    if (w->err.code == PDT_OK) {
        uint8_t *payload = w->enc + TF_BLOCK_HEADER_SIZE;
        tf_put64(payload, w->written);
        tf_put64(payload + 8, 0);
        pdt_tf_block_header(w->enc, TF_END_MAGIC, payload, TF_END_PAYLOAD, w->written,
                            pdt_tw_now(w), 0);
        tw_write(w, w->enc, TF_BLOCK_HEADER_SIZE + TF_END_PAYLOAD);
    }
    if (close(w->fd) != 0 && w->err.code == PDT_OK)
        pdt_err_set(&w->err, PDT_ERR_IO, "%s: close failed: %s", w->path, strerror(errno));
    w->fd = -1;
    pdt_status st = w->err.code;
    if (st != PDT_OK) pdt_err_set(err, st, "%s", w->err.msg);
    pdt_tw_abort(w);
    return st;
}

char *pdt_tf_path_join(const char *dir, const char *name)
{
    size_t a = strlen(dir), b = strlen(name);
    char *p = malloc(a + b + 2);
    if (!p) return NULL;
    memcpy(p, dir, a);
    p[a] = '/';
    memcpy(p + a + 1, name, b + 1);
    return p;
}
