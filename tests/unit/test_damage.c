/* Damaged run folders: a real traced run (the sequential pipeline,
 * pdt_triangulate, traced at level 2 through the trace writer) is
 *   (a) truncated at every byte offset of its rank file,
 *   (b) given a one-bit flip in every byte of its rank file,
 *   (c) missing a rank file (a two-rank folder), or its manifest,
 *   (d) given a manifest (or rank file header) of another format version.
 * pdt_run_open must never crash or hang (an alarm turns a hang into a
 * failure; the sanitizer build runs this too), must name the file and the
 * damaged block's byte offset in its warnings, and must still give the
 * intact prefix: the events read equal the events of the complete blocks
 * before the damage, so they grow monotonically with the truncation offset.
 * The block layout is found here by walking the intact file's block headers
 * (magic, length, count: docs/trace-format.md), independently of the reader. */
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

#include "../harness.h"
#include "pdt/delaunay.h"
#include "pdt/gen.h"
#include "pdt/tracefile.h"

static char tmpdir[256];

static void rm_rf(const char *dir)
{
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "cannot remove %s\n", dir);
}

static uint32_t get32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint8_t *slurp(const char *path, size_t *len)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) return NULL;
    fseek(fp, 0, SEEK_END);
    long n = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    uint8_t *b = malloc((size_t)n + 1);
    if (b && fread(b, 1, (size_t)n, fp) != (size_t)n) {
        free(b);
        b = NULL;
    }
    fclose(fp);
    *len = (size_t)n;
    return b;
}

static int put_file(const char *path, const void *d, size_t n)
{
    FILE *fp = fopen(path, "wb");
    if (!fp) return -1;
    int ok = fwrite(d, 1, n, fp) == n;
    return fclose(fp) == 0 && ok ? 0 : -1;
}

/* ---- the run under test --------------------------------------------------- */

/* Points of the traced run: enough for 3 event blocks (4096 events each) at
 * trace level 2; setup() doubles it while the run has fewer blocks (the
 * number of events per point depends on what the pipeline traces). */
static size_t n_points = 1100;

/* Trace the sequential pipeline on `rank` of an nranks-folder dir (rank 0
 * also writes the manifest and points.bin).  Returns events recorded. */
static uint64_t traced_run(const char *dir, int rank, int nranks)
{
    pdt_point *pts = NULL;
    pdt_err err = {0};
    if (pdt_gen("uniform", n_points, 7, &pts, &err) != PDT_OK) return 0;
    pdt_trace_writer *w;
    if (pdt_tw_open(dir, rank, 2, &w, &err) != PDT_OK) return 0;
    if (rank == 0) {
        int64_t off[2] = {0, 0};
        pdt_manifest m = {0};
        m.format_version = PDT_TRACE_FORMAT_MAJOR;
        snprintf(m.program_version, sizeof m.program_version, "%s", PDT_VERSION);
        snprintf(m.command, sizeof m.command, "triangulate");
        m.command_line = (char *)"test_damage";
        m.input_name = (char *)"uniform";
        m.input_checksum = pdt_points_checksum(pts, n_points);
        m.n = n_points;
        m.nranks = nranks;
        m.level = 2;
        m.clock_offset_ns = off;
        m.wall_start_ns = pdt_wall_ns();
        if (pdt_run_write_meta(dir, &m, pts, n_points, &err) != PDT_OK) return 0;
    }
    pdt_tri *t = NULL;
    size_t nt = 0;
    pdt_triangulate(pts, n_points, &t, &nt, NULL, pdt_tw_hook(w));
    uint64_t nev = pdt_tw_events(w);
    if (pdt_tw_close(w, &err) != PDT_OK) nev = 0;
    free(t);
    free(pts);
    return nev;
}

/* Block layout of an intact rank file. */
typedef struct layout {
    size_t nblk;          /* event blocks */
    size_t off[64];       /* byte offset of block k's header; off[nblk] = end marker */
    uint64_t before[64];  /* events in blocks 0..k-1 */
    size_t end_off, size;
} layout;

static int walk(const uint8_t *p, size_t size, layout *L)
{
    memset(L, 0, sizeof *L);
    L->size = size;
    size_t off = get32(p + 12);
    uint64_t ev = 0;
    while (off + 32 <= size) {
        uint32_t magic = get32(p + off), len = get32(p + off + 4), cnt = get32(p + off + 24);
        if (L->nblk >= 63) return -1;
        L->off[L->nblk] = off;
        L->before[L->nblk] = ev;
        if (magic == 0x45544450u) {  /* "PDTE" */
            L->end_off = off;
            return off + 32 + len == size ? 0 : -1;
        }
        ev += cnt;
        L->nblk++;
        off += 32 + len;
    }
    return -1;
}

/* Which block holds byte b (nblk = the end marker); -1 for the file header. */
static long block_of(const layout *L, size_t b)
{
    if (b < L->off[0]) return -1;
    for (size_t k = 0; k < L->nblk; k++)
        if (b < L->off[k + 1]) return (long)k;
    return (long)L->nblk;
}

static char dir1[300], rank0[400];
static layout L;
static uint64_t total_ev;
static uint8_t *orig;

typedef struct opened {
    pdt_status st;
    uint64_t events;
    int complete, present;
    char warn[4096];
    char err[1024];
} opened;

/* Open dir, note what the reader says; if `check`, also decode the merged
 * order (it must hold every event counted) and run the checker on it. */
static void open_run(const char *dir, opened *o, int check)
{
    memset(o, 0, sizeof *o);
    pdt_run *run = NULL;
    pdt_err err = {0};
    o->st = pdt_run_open(dir, &run, &err);
    snprintf(o->err, sizeof o->err, "%s", err.msg);
    if (o->st != PDT_OK) return;
    pdt_rank_info info;
    pdt_run_rank_info(run, 0, &info);
    o->events = info.events;
    o->complete = info.complete;
    o->present = info.present;
    if (check) {  /* decode everything (costly: only on some of the damaged files) */
        const pdt_rec *rec;
        size_t n = 0;
        if (pdt_run_merged(run, &rec, &n, &err) != PDT_OK) o->events = UINT64_MAX;
        uint64_t total = 0;
        for (int r = 0; r < pdt_run_nranks(run); r++) {
            pdt_run_rank_info(run, r, &info);
            total += info.events;
        }
        if (n != total) o->events = UINT64_MAX - 1;
        char sum[256];
        pdt_err cerr = {0};
        pdt_run_check(run, sum, sizeof sum, &cerr);
    }
    snprintf(o->warn, sizeof o->warn, "%s", pdt_run_warnings(run));
    pdt_run_close(run);
}

static int setup(void)
{
    size_t size;
    for (int tries = 0;; tries++) {
        snprintf(dir1, sizeof dir1, "%s/one-%zu", tmpdir, n_points);
        total_ev = traced_run(dir1, 0, 1);
        snprintf(rank0, sizeof rank0, "%s/rank-0000.trace", dir1);
        orig = slurp(rank0, &size);
        if (!orig || total_ev == 0 || walk(orig, size, &L) != 0) return -1;
        if (L.nblk >= 3 || tries == 4) break;
        free(orig);
        n_points *= 2;
    }
    printf("# run: %zu points, %llu events, %zu bytes, %zu event blocks\n", n_points,
           (unsigned long long)total_ev, size, L.nblk);
    return 0;
}

TEST(damage_intact_run)
{
    opened o;
    open_run(dir1, &o, 1);
    CHECK(o.st == PDT_OK);
    CHECK(o.events == total_ev && o.complete == 1);
    CHECK_MSG(o.warn[0] == '\0', "warnings: %s", o.warn);
    CHECK_MSG(L.nblk >= 3, "the test needs several blocks, got %zu", L.nblk);
}

TEST(damage_truncate_every_byte)
{
    int fd = open(rank0, O_WRONLY);
    CHECK(fd >= 0);
    if (fd < 0) return;
    uint64_t prev = UINT64_MAX;
    size_t bad_count = 0, bad_where = 0, bad_mono = 0, bad_open = 0;
    for (size_t t = L.size; t-- > 0;) {  /* shrinking: one ftruncate per step */
        if (ftruncate(fd, (off_t)t) != 0) {
            CHECK_MSG(0, "ftruncate %zu", t);
            break;
        }
        opened o;
        open_run(dir1, &o, t % 509 == 0);
        if (o.st != PDT_OK) {
            if (bad_open++ < 3) CHECK_MSG(0, "t=%zu: open failed: %s", t, o.err);
            continue;
        }
        /* expected: every block whose bytes all lie below t */
        uint64_t want = 0;
        long k = block_of(&L, t);  /* the block cut by t (or starting at t) */
        if (k >= 0) want = L.before[k];
        if (o.events != want || o.complete) {
            if (bad_count++ < 3)
                CHECK_MSG(0, "t=%zu: %llu events (complete %d), want %llu", t,
                          (unsigned long long)o.events, o.complete, (unsigned long long)want);
        }
        if (prev != UINT64_MAX && o.events > prev && bad_mono++ < 3)
            CHECK_MSG(0, "t=%zu: events %llu > %llu at t+1", t, (unsigned long long)o.events,
                      (unsigned long long)prev);
        prev = o.events;
        /* where: the file, and the cut block's byte offset (or the header) */
        char need[96];
        if (k < 0) snprintf(need, sizeof need, "rank-0000.trace: not a pdt trace file");
        else if (t == L.off[k]) snprintf(need, sizeof need, "rank-0000.trace: no end marker");
        else snprintf(need, sizeof need, "block %ld at byte %zu", k, L.off[k]);
        if (!strstr(o.warn, need) && bad_where++ < 3)
            CHECK_MSG(0, "t=%zu: warnings lack '%s': %s", t, need, o.warn);
    }
    close(fd);
    CHECK(put_file(rank0, orig, L.size) == 0);
    printf("# truncated at all %zu offsets\n", L.size);
}

TEST(damage_bitflip_every_byte)
{
    int fd = open(rank0, O_WRONLY);
    CHECK(fd >= 0);
    if (fd < 0) return;
    size_t bad_count = 0, bad_where = 0, bad_open = 0;
    for (size_t i = 0; i < L.size; i++) {
        uint8_t b = (uint8_t)(orig[i] ^ (1u << (i % 8)));
        if (pwrite(fd, &b, 1, (off_t)i) != 1) {
            CHECK_MSG(0, "pwrite %zu", i);
            break;
        }
        opened o;
        open_run(dir1, &o, i % 503 == 0);
        if (pwrite(fd, &orig[i], 1, (off_t)i) != 1) {
            CHECK_MSG(0, "pwrite %zu", i);
            break;
        }
        if (o.st != PDT_OK) {
            if (bad_open++ < 3) CHECK_MSG(0, "flip at %zu: open failed: %s", i, o.err);
            continue;
        }
        long k = block_of(&L, i);
        uint64_t want = k < 0 ? 0 : L.before[k];
        if (k == (long)L.nblk) want = total_ev;  /* end marker: all events, not complete */
        if ((o.events != want || o.complete) && bad_count++ < 3)
            CHECK_MSG(0, "flip at %zu (block %ld): %llu events (complete %d), want %llu", i, k,
                      (unsigned long long)o.events, o.complete, (unsigned long long)want);
        char need[96];
        if (k < 0) snprintf(need, sizeof need, "rank-0000.trace: ");
        else if (k == (long)L.nblk) snprintf(need, sizeof need, "rank-0000.trace: ");
        else snprintf(need, sizeof need, "rank-0000.trace: block %ld at byte %zu", k, L.off[k]);
        if ((!strstr(o.warn, need) || (k < 0 && !strstr(o.warn, "no events for rank 0"))) &&
            bad_where++ < 3)
            CHECK_MSG(0, "flip at %zu: warnings lack '%s': %s", i, need, o.warn);
    }
    close(fd);
    printf("# flipped one bit in each of %zu bytes\n", L.size);
}

TEST(damage_missing_rank_file)
{
    char dir2[300], p[400];
    snprintf(dir2, sizeof dir2, "%s/two", tmpdir);
    uint64_t e0 = traced_run(dir2, 0, 2), e1 = traced_run(dir2, 1, 2);
    CHECK(e0 > 0 && e1 > 0);
    opened o;
    open_run(dir2, &o, 0);
    CHECK(o.st == PDT_OK && o.events == e0);
    snprintf(p, sizeof p, "%s/rank-0001.trace", dir2);
    CHECK(unlink(p) == 0);
    open_run(dir2, &o, 1);
    CHECK_MSG(o.st == PDT_OK, "%s", o.err);
    CHECK(o.events == e0 && o.complete);
    CHECK_MSG(strstr(o.warn, "rank-0001.trace: missing"), "warnings: %s", o.warn);
    /* rank 0 gone as well: the folder still opens, with nothing to show */
    snprintf(p, sizeof p, "%s/rank-0000.trace", dir2);
    CHECK(unlink(p) == 0);
    open_run(dir2, &o, 1);
    CHECK_MSG(o.st == PDT_OK, "%s", o.err);
    CHECK(o.events == 0 && !o.present);
    CHECK_MSG(strstr(o.warn, "rank-0000.trace to rank-0001.trace: missing (2 files)"), "%s",
              o.warn);
    /* a damaged manifest announcing a million ranks: one line, not a million */
    snprintf(p, sizeof p, "%s/manifest", dir2);
    CHECK(put_file(p, "format = 1.0\nranks = 1000000\n", 28) == 0);
    open_run(dir2, &o, 0);
    CHECK_MSG(o.st == PDT_OK, "%s", o.err);
    CHECK_MSG(strstr(o.warn, "rank-0000.trace to rank-999999.trace: missing (1000000 files)") &&
                  strlen(o.warn) < 200, "%.300s", o.warn);
    /* no manifest: the rank files alone still open, with a notice */
    char dir3[300];
    snprintf(dir3, sizeof dir3, "%s/nomanifest", tmpdir);
    uint64_t e = traced_run(dir3, 0, 1);
    snprintf(p, sizeof p, "%s/manifest", dir3);
    CHECK(unlink(p) == 0);
    open_run(dir3, &o, 1);
    CHECK_MSG(o.st == PDT_OK, "%s", o.err);
    CHECK(o.events == e);
    CHECK_MSG(strstr(o.warn, "manifest: missing"), "warnings: %s", o.warn);
    /* no points.bin: the events are still there */
    snprintf(p, sizeof p, "%s/points.bin", dir1);
    char q[400];
    snprintf(q, sizeof q, "%s/points.bin.away", dir1);
    CHECK(rename(p, q) == 0);
    open_run(dir1, &o, 1);
    CHECK(o.st == PDT_OK && o.events == total_ev);
    CHECK_MSG(strstr(o.warn, "points.bin"), "warnings: %s", o.warn);
    CHECK(rename(q, p) == 0);
    /* an empty folder is not a run */
    char dir4[300];
    snprintf(dir4, sizeof dir4, "%s/empty", tmpdir);
    mkdir(dir4, 0700);
    open_run(dir4, &o, 0);
    CHECK(o.st != PDT_OK && strstr(o.err, "not a pdt run folder"));
}

/* Replace the manifest's "format = ..." line. */
static void set_format(const char *dir, const char *line)
{
    char p[400];
    snprintf(p, sizeof p, "%s/manifest", dir);
    size_t n;
    uint8_t *m = slurp(p, &n);
    if (!m) return;
    m[n] = 0;
    char *f = strstr((char *)m, "\nformat = ");
    char *e = f ? strchr(f + 1, '\n') : NULL;
    if (!f || !e) {
        free(m);
        return;
    }
    FILE *fp = fopen(p, "wb");
    if (fp) {
        fwrite(m, 1, (size_t)(f + 1 - (char *)m), fp);
        fputs(line, fp);
        fputs(e, fp);
        fclose(fp);
    }
    free(m);
}

TEST(damage_manifest_version)
{
    char d[300];
    snprintf(d, sizeof d, "%s/ver", tmpdir);
    uint64_t e = traced_run(d, 0, 1);
    opened o;
    set_format(d, "format = 3.0");
    open_run(d, &o, 0);
    CHECK(o.st == PDT_ERR_FORMAT);
    CHECK_MSG(strstr(o.err, "manifest:2:") && strstr(o.err, "format 3.0") &&
              strstr(o.err, "reads formats 1.x to 2.x"), "%s", o.err);
    set_format(d, "format = 0.9");
    open_run(d, &o, 0);
    CHECK_MSG(o.st == PDT_ERR_FORMAT && strstr(o.err, "format 0.9"), "%s", o.err);
    set_format(d, "format = one");
    open_run(d, &o, 0);
    CHECK_MSG(o.st == PDT_ERR_FORMAT && strstr(o.err, "bad format version 'one'"), "%s", o.err);
    set_format(d, "format = 2.42");  /* a newer minor version is read */
    open_run(d, &o, 1);
    CHECK_MSG(o.st == PDT_OK && o.events == e, "%s", o.err);
    set_format(d, "format = 2.0");
    /* the rank file's own header says major version 3 (checksum made valid) */
    char p[400];
    snprintf(p, sizeof p, "%s/rank-0000.trace", d);
    size_t n;
    uint8_t *r = slurp(p, &n);
    CHECK(r != NULL);
    if (!r) return;
    r[8] = 3;
    uint32_t crc = pdt_crc32c(0, r, 28);
    for (int i = 0; i < 4; i++) r[28 + i] = (uint8_t)(crc >> (8 * i));
    CHECK(put_file(p, r, n) == 0);
    free(r);
    open_run(d, &o, 0);
    CHECK(o.st == PDT_ERR_FORMAT);
    CHECK_MSG(strstr(o.err, "rank-0000.trace") && strstr(o.err, "trace format 3.0"), "%s", o.err);
}

/* Regression: with a rank file lost, the causal merge blamed (and moved
 * ahead of its SEND) a RECV whose SEND was present.  Rank 1's file is
 * missing; rank 0 receives from rank 1 (that SEND is lost) and then sends to
 * rank 2, whose RECV has the earliest time of all.  The merge must place
 * rank 0's orphaned RECV, then its SEND, then rank 2's RECV, and warn only
 * about rank 0's RECV. */
TEST(damage_merge_missing_sender_rank)
{
    char d[300];
    snprintf(d, sizeof d, "%s/lostsender", tmpdir);
    pdt_trace_writer *w0, *w2;
    pdt_err err = {0};
    CHECK(pdt_tw_open(d, 0, 1, &w0, &err) == PDT_OK);
    CHECK(pdt_tw_open(d, 2, 1, &w2, &err) == PDT_OK);
    if (err.code) return;
    PDT_TRACE(pdt_tw_hook(w2), 1, PDT_EV_RECV, 7, 0, 16, 0, 0);  /* earliest time */
    struct timespec ts = {0, 2000000};
    nanosleep(&ts, NULL);
    PDT_TRACE(pdt_tw_hook(w0), 1, PDT_EV_RECV, 7, 1, 16, 0, 0);  /* from the lost rank */
    PDT_TRACE(pdt_tw_hook(w0), 1, PDT_EV_SEND, 7, 2, 16, 0, 0);
    CHECK(pdt_tw_close(w0, &err) == PDT_OK && pdt_tw_close(w2, &err) == PDT_OK);
    int64_t off[3] = {0, 0, 0};
    pdt_manifest m = {0};
    m.format_version = PDT_TRACE_FORMAT_MAJOR;
    m.nranks = 3;
    m.level = 1;
    m.clock_offset_ns = off;
    CHECK(pdt_run_write_meta(d, &m, NULL, 0, &err) == PDT_OK);
    pdt_run *run = NULL;
    CHECK(pdt_run_open(d, &run, &err) == PDT_OK);
    if (!run) return;
    const pdt_rec *rec;
    size_t n = 0;
    CHECK(pdt_run_merged(run, &rec, &n, &err) == PDT_OK);
    CHECK(n == 3);
    if (n == 3) {
        CHECK_MSG(rec[0].rank == 0 && rec[0].ev.kind == PDT_EV_RECV, "first: rank %u kind %u",
                  rec[0].rank, rec[0].ev.kind);
        CHECK(rec[1].rank == 0 && rec[1].ev.kind == PDT_EV_SEND);
        CHECK_MSG(rec[2].rank == 2 && rec[2].ev.kind == PDT_EV_RECV, "last: rank %u", rec[2].rank);
    }
    const char *wn = pdt_run_warnings(run);
    CHECK_MSG(strstr(wn, "rank-0001.trace: missing"), "%s", wn);
    CHECK_MSG(strstr(wn, "rank 0 event #0: recv from rank 1"), "%s", wn);
    CHECK_MSG(!strstr(wn, "rank 2 event"), "%s", wn);
    pdt_run_close(run);
}

/* A hang is an endless loop in the reader: it burns CPU.  So the watchdog
 * counts this process's CPU time (240 s, SIGPROF), not wall time, which a
 * loaded machine stretches many times over; a wall-clock backstop (30 min)
 * catches a process that blocks. */
static void on_alarm(int sig)
{
    static const char cpu[] = "not ok - damage tests hung (240 s of CPU time)\n";
    static const char wall[] = "not ok - damage tests hung (30 min of wall time)\n";
    const char *msg = sig == SIGPROF ? cpu : wall;
    size_t len = sig == SIGPROF ? sizeof cpu - 1 : sizeof wall - 1;
    if (write(1, msg, len) < 0) _exit(3);
    _exit(2);
}

int main(void)
{
    signal(SIGALRM, on_alarm);
    signal(SIGPROF, on_alarm);
    struct itimerval cpu_limit = {.it_value = {.tv_sec = 240}};
    setitimer(ITIMER_PROF, &cpu_limit, NULL);
    alarm(1800);
    snprintf(tmpdir, sizeof tmpdir, "%s/pdt-damage.XXXXXX",
             getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 1;
    }
    if (setup() != 0) {
        printf("not ok - damage_setup (could not make the traced run)\n");
        rm_rf(tmpdir);
        return 1;
    }
    RUN(damage_intact_run);
    RUN(damage_truncate_every_byte);
    RUN(damage_bitflip_every_byte);
    RUN(damage_missing_rank_file);
    RUN(damage_manifest_version);
    RUN(damage_merge_missing_sender_rank);
    free(orig);
    rm_rf(tmpdir);
    return test_summary();
}
