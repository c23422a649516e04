/* Trace files: codec round trip, writer -> reader, damage reports, cursor
 * seek, merged order.  Synthetic events only (no algorithm code). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../src/trace/tf_internal.h"
#include "../harness.h"
#include "pdt/tracefile.h"

static char tmpdir[256];

static void make_tmp(void)
{
    snprintf(tmpdir, sizeof tmpdir, "%s/pdt-ttf.XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        exit(1);
    }
}

static void rm_rf(const char *dir)
{
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "cannot remove %s\n", dir);
}

static uint64_t rng = 0x9e3779b97f4a7c15u;
static uint64_t next_rand(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return rng;
}

static int ev_eq(const pdt_event *a, const pdt_event *b)
{
    return a->kind == b->kind && a->sub == b->sub && a->a == b->a && a->b == b->b &&
           a->c == b->c && a->v == b->v;
}

TEST(crc32c_check_value)
{
    CHECK(pdt_crc32c(0, "123456789", 9) == 0xE3069283u);
    CHECK(pdt_crc32c(pdt_crc32c(0, "1234", 4), "56789", 5) == 0xE3069283u);
    CHECK(pdt_crc32c(0, "", 0) == 0);
    /* longer than 8 bytes, odd length: the hardware and table paths must agree */
    uint8_t buf[1000];
    for (int i = 0; i < 1000; i++) buf[i] = (uint8_t)(i * 7 + 3);
    uint32_t whole = pdt_crc32c(0, buf, 1000), parts = 0;
    for (int i = 0; i < 1000; i += 37) parts = pdt_crc32c(parts, buf + i, i + 37 <= 1000 ? 37 : 1000 - (size_t)i);
    CHECK(whole == parts);
}

/* CRC-32C from its bitwise definition (reflected 0x82F63B78, all-ones
 * initial value and final xor), for comparing the fast paths with. */
static uint32_t crc32c_bitwise(const uint8_t *p, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++) c = c & 1 ? (c >> 1) ^ 0x82F63B78u : c >> 1;
    }
    return ~c;
}

/* Long buffers go through three interleaved lanes of 4096 bytes (three
 * times 4096 and more) whose registers are shifted and added: every length
 * around the lanes' bounds, at odd starts, and in pieces, against the
 * bitwise definition. */
TEST(crc32c_long_buffers_three_lanes)
{
    enum { N = 3 * 4096 * 3 + 100 };
    uint8_t *buf = malloc(N);
    CHECK(buf != NULL);
    if (!buf) return;
    uint32_t x = 12345;
    for (size_t i = 0; i < N; i++) buf[i] = (uint8_t)((x = x * 1103515245u + 12345u) >> 24);
    const size_t lens[] = {12287, 12288, 12289, 12295, 24576, 24583, 36863, 36864, N - 3};
    int bad = 0;
    for (size_t l = 0; l < sizeof lens / sizeof *lens; l++)
        for (size_t off = 0; off < 3; off++) {
            size_t n = lens[l];
            if (pdt_crc32c(0, buf + off, n) != crc32c_bitwise(buf + off, n)) bad++;
        }
    CHECK_MSG(bad == 0, "%d lengths differ from the bitwise CRC", bad);
    uint32_t parts = pdt_crc32c(0, buf, 20000);
    parts = pdt_crc32c(parts, buf + 20000, N - 20000);
    CHECK(parts == crc32c_bitwise(buf, N));
    free(buf);
}

TEST(crc64_check_value)
{
    CHECK(pdt_crc64(0, "123456789", 9) == 0x995DC9BBDF1939FAull);
    CHECK(pdt_crc64(pdt_crc64(0, "1234", 4), "56789", 5) == 0x995DC9BBDF1939FAull);
    CHECK(pdt_crc64(0, "", 0) == 0);
}

/* The CRC of a concatenation from the CRCs of its parts, at every split of
 * random data into up to 9 parts (empty parts included): what lets every
 * rank checksum its block of points.bin. */
/* CRC-64/XZ from its definition, a bit at a time (the reference for the
 * table-driven pdt_crc64). */
static uint64_t crc64_bitwise(const uint8_t *p, size_t n)
{
    uint64_t c = ~0ull;
    while (n--) {
        c ^= *p++;
        for (int k = 0; k < 8; k++) c = c & 1 ? (c >> 1) ^ 0xC96C5795D7870F42ull : c >> 1;
    }
    return ~c;
}

TEST(crc64_every_length_and_offset)
{
    enum { N = 4099 };
    uint8_t *buf = malloc(N + 8);
    CHECK(buf != NULL);
    if (!buf) return;
    for (size_t i = 0; i < N + 8; i++) buf[i] = (uint8_t)next_rand();
    size_t bad = 0;
    for (size_t off = 0; off < 8; off++)
        for (size_t len = 0; len <= 300; len++)
            bad += pdt_crc64(0, buf + off, len) != crc64_bitwise(buf + off, len);
    for (size_t off = 0; off < 8; off++) /* (a long one, and one continued after an odd start) */
        bad += pdt_crc64(pdt_crc64(0, buf + off, 77), buf + off + 77, N - 77) !=
               crc64_bitwise(buf + off, N);
    CHECK_MSG(bad == 0, "%zu checksums differ from the bitwise definition", bad);
    free(buf);
}

TEST(crc_combine_any_split)
{
    enum { LEN = 3000 };
    uint8_t buf[LEN];
    for (int i = 0; i < LEN; i++) buf[i] = (uint8_t)next_rand();
    uint32_t whole32 = pdt_crc32c(0, buf, LEN);
    uint64_t whole64 = pdt_crc64(0, buf, LEN);
    for (int trial = 0; trial < 200; trial++) {
        int parts = 1 + (int)(next_rand() % 9);
        size_t cut[10];
        cut[0] = 0;
        cut[parts] = LEN;
        for (int k = 1; k < parts; k++) cut[k] = (size_t)(next_rand() % (LEN + 1));
        for (int a = 1; a < parts; a++) /* sort the cuts */
            for (int b = a; b > 1 && cut[b] < cut[b - 1]; b--) {
                size_t t = cut[b];
                cut[b] = cut[b - 1];
                cut[b - 1] = t;
            }
        uint32_t c32 = 0;
        uint64_t c64 = 0;
        for (int k = 0; k < parts; k++) {
            size_t len = cut[k + 1] - cut[k];
            c32 = pdt_crc32c_combine(c32, pdt_crc32c(0, buf + cut[k], len), len);
            c64 = pdt_crc64_combine(c64, pdt_crc64(0, buf + cut[k], len), len);
        }
        CHECK_MSG(c32 == whole32 && c64 == whole64, "trial %d, %d parts", trial, parts);
    }
    /* lengths beyond 32 bits: combining with an empty B of a huge length is
     * multiplication by x^(8 len); three steps of 2^31 bytes equal one of 3 * 2^31 */
    uint64_t big = 3ull << 31, a = pdt_crc64(0, buf, 64);
    uint64_t step = pdt_crc64_combine(pdt_crc64_combine(pdt_crc64_combine(a, 0, 1ull << 31), 0,
                                                        1ull << 31), 0, 1ull << 31);
    CHECK(pdt_crc64_combine(a, 0, big) == step);
}

/* The manifest's checksum is the CRC-64 of points.bin's data bytes. */
TEST(points_checksum_is_crc64_of_the_bytes)
{
    pdt_point pts[3] = {{1, -2}, {-2147483647 - 1, 2147483647}, {0, 7}};
    uint8_t b[24];
    pdt_points_encode(b, pts, 3);
    CHECK(b[4] == 0xfe && b[7] == 0xff && b[11] == 0x80 && b[15] == 0x7f);
    CHECK(pdt_points_checksum(pts, 3) == pdt_crc64(0, b, 24));
    CHECK(pdt_points_checksum(pts, 0) == 0);
}

/* The validator that opening a run uses accepts exactly the payloads the
 * decoder accepts: encoded blocks of extreme events, each cut short, with
 * one byte changed (every place, several values), grown by a byte, with
 * one event more or less counted, and random bytes. */
TEST(validate_agrees_with_decode)
{
    enum { N = 300 };
    pdt_event ev[N];
    const uint32_t u[] = {0, 1, 127, 128, 16383, 16384, 0x0fffffff, 0x10000000, UINT32_MAX};
    const int64_t v[] = {0, -1, 63, -64, INT64_MAX, INT64_MIN};
    for (int i = 0; i < N; i++) {
        memset(&ev[i], 0, sizeof ev[i]);
        ev[i].kind = (uint8_t)(i % 40);
        ev[i].sub = (uint8_t)(i % 3 ? 0 : i);
        ev[i].a = u[i % 9];
        ev[i].b = i % 2 ? u[(i / 2) % 9] : 0;
        ev[i].c = i % 5 ? 0 : u[(i / 5) % 9];
        ev[i].v = i % 7 ? 0 : v[(i / 7) % 6];
        ev[i].t = (uint64_t)i * (i % 4 ? 1000003u : UINT64_C(0x123456789abcd));
    }
    uint8_t *buf = malloc(N * TF_MAX_EVENT_BYTES + 16), *mut = malloc(N * TF_MAX_EVENT_BYTES + 16);
    size_t len = pdt_tf_encode(ev, N, 5, buf), cases = 0, differ = 0;
#define SAME(P, L, C)                                                                         \
    do {                                                                                      \
        cases++;                                                                              \
        if ((pdt_tf_validate(P, L, C) == 0) != (pdt_tf_decode(P, L, C, 5, NULL) == 0)) differ++; \
    } while (0)
    SAME(buf, len, N);
    SAME(buf, len, N - 1);
    SAME(buf, len, N + 1);
    for (size_t k = 0; k < len; k++) SAME(buf, k, N);
    memcpy(mut, buf, len);
    mut[len] = 0;
    SAME(mut, len + 1, N);
    const uint8_t vals[] = {0x00, 0x0f, 0x10, 0x7f, 0x80, 0xff, 0x1f, 0x20};
    for (size_t k = 0; k < len; k++)
        for (size_t j = 0; j < sizeof vals; j++) {
            memcpy(mut, buf, len);
            mut[k] = vals[j];
            SAME(mut, len, N);
        }
    for (int r = 0; r < 20000; r++) {
        size_t l = (size_t)(next_rand() % 64);
        uint32_t c = (uint32_t)(next_rand() % 8);
        for (size_t k = 0; k < l; k++) {
            uint64_t x = next_rand();  /* (mostly small bytes: events that parse) */
            mut[k] = (uint8_t)(x % 4 == 0 ? x >> 8 : (x >> 8) % 24);
        }
        SAME(mut, l, c);
    }
#undef SAME
    CHECK_MSG(differ == 0, "%zu of %zu payloads judged differently", differ, cases);
    CHECK(pdt_tf_validate(buf, len, N) == 0);
    free(buf);
    free(mut);
}

TEST(codec_extremes)
{
    /* every kind, extreme field values, times going backwards too */
    size_t n = 0;
    pdt_event ev[400];
    uint32_t u[] = {0, 1, 2, 127, 128, 0x7fffffff, 0x80000000u, UINT32_MAX - 1, UINT32_MAX};
    int64_t v[] = {0, 1, -1, INT64_MAX, INT64_MIN, 1LL << 62, -(1LL << 40)};
    uint64_t t[] = {0, 1, UINT64_MAX, 5, 1ull << 63, 12345678901ull};
    for (int k = 0; k < PDT_EV_KIND_COUNT + 3 && n < 400; k++)
        for (int j = 0; j < 12 && n < 400; j++) {
            pdt_event *e = &ev[n++];
            memset(e, 0, sizeof *e);
            e->kind = (uint8_t)(k < PDT_EV_KIND_COUNT ? k : 200 + k);
            e->sub = (uint8_t)(j * 23);
            e->a = u[(k + j) % 9];
            e->b = u[(k * 3 + j) % 9];
            e->c = u[(k * 5 + 2 * j) % 9];
            e->v = v[(k + 2 * j) % 7];
            e->t = t[(k + j) % 6];
        }
    uint8_t *buf = malloc(n * TF_MAX_EVENT_BYTES);
    pdt_event *back = malloc(n * sizeof *back);
    size_t len = pdt_tf_encode(ev, n, 777, buf);
    CHECK(len <= n * TF_MAX_EVENT_BYTES);
    CHECK(pdt_tf_decode(buf, len, (uint32_t)n, 777, back) == 0);
    size_t bad = 0;
    for (size_t i = 0; i < n; i++)
        if (!ev_eq(&ev[i], &back[i]) || ev[i].t != back[i].t) bad++;
    CHECK_MSG(bad == 0, "%zu events differ", bad);
    /* one event at a time (some skipped): the same events, then the end */
    pdt_block_cursor c;
    pdt_block_cursor_start(&c, buf, (uint32_t)len, (uint32_t)n, 777);
    size_t cbad = 0, got = 0;
    for (size_t i = 0; i < n; i++) {
        pdt_event e;
        int skip = i % 5 == 3;
        if (pdt_block_cursor_next(&c, skip ? NULL : &e) != 1) break;
        got++;
        if (!skip && (!ev_eq(&ev[i], &e) || ev[i].t != e.t)) cbad++;
    }
    CHECK(got == n);
    CHECK_MSG(cbad == 0, "%zu events differ one at a time", cbad);
    CHECK(pdt_block_cursor_next(&c, NULL) == 0);
    /* malformed: one byte short, one event too many, garbage mask */
    CHECK(pdt_tf_decode(buf, len - 1, (uint32_t)n, 777, back) != 0);
    CHECK(pdt_tf_decode(buf, len, (uint32_t)n + 1, 777, back) != 0);
    pdt_block_cursor_start(&c, buf, (uint32_t)len - 1, (uint32_t)n, 777);
    int rc = 1;
    for (size_t i = 0; i < n && rc == 1; i++) rc = pdt_block_cursor_next(&c, NULL);
    CHECK(rc == -1);  /* the last event runs past the payload */
    pdt_block_cursor_start(&c, buf, (uint32_t)len, (uint32_t)n - 1, 777);
    rc = 1;
    for (size_t i = 0; i < n && rc == 1; i++) rc = pdt_block_cursor_next(&c, NULL);
    CHECK(rc == -1);  /* bytes left after the count */
    buf[1] = 0xff;
    CHECK(pdt_tf_decode(buf, len, (uint32_t)n, 777, NULL) != 0);
    free(buf);
    free(back);
}

/* Write `n` pseudo-random events of every kind through the writer hook. */
static void emit_random(pdt_trace *tr, size_t n, pdt_event *keep)
{
    for (size_t i = 0; i < n; i++) {
        int kind = 1 + (int)(next_rand() % (PDT_EV_KIND_COUNT - 1));
        uint32_t a = (uint32_t)next_rand(), b = (uint32_t)(next_rand() % 1000),
                 c = i % 7 ? UINT32_MAX : (uint32_t)next_rand();
        int64_t v = i % 3 ? (int64_t)next_rand() : -(int64_t)(i % 5);
        int sub = (int)(next_rand() % 6);
        PDT_TRACE(tr, 1, kind, sub, a, b, c, v);
        if (keep) {
            keep[i].kind = (uint8_t)kind;
            keep[i].sub = (uint8_t)sub;
            keep[i].a = a;
            keep[i].b = b;
            keep[i].c = c;
            keep[i].v = v;
        }
    }
}

static void write_meta(const char *dir, int nranks, const int64_t *offsets)
{
    pdt_point pts[5] = {{0, 0}, {10, 0}, {0, 10}, {-2147483647 - 1, 2147483647}, {3, 4}};
    pdt_manifest m;
    memset(&m, 0, sizeof m);
    m.format_version = PDT_TRACE_FORMAT_MAJOR;
    snprintf(m.program_version, sizeof m.program_version, "%s", PDT_VERSION);
    m.command_line = "pdt triangulate --trace x \"a b\"\nsecond line\\";
    m.input_name = "in put.txt";
    m.input_checksum = pdt_points_checksum(pts, 5);
    m.n = 5;
    m.nranks = nranks;
    m.level = 1;
    snprintf(m.command, sizeof m.command, "triangulate");
    m.clock_offset_ns = (int64_t *)offsets;
    m.wall_start_ns = 1700000000123456789ull;
    pdt_err err = {0};
    CHECK_MSG(pdt_run_write_meta(dir, &m, pts, 5, &err) == PDT_OK, "%s", err.msg);
}

static char run_dir[300];

TEST(writer_reader_round_trip)
{
    snprintf(run_dir, sizeof run_dir, "%s/rt", tmpdir);
    pdt_trace_writer *w;
    pdt_err err = {0};
    CHECK(pdt_tw_open(run_dir, 0, 1, &w, &err) == PDT_OK);
    size_t n = 3 * TF_BLOCK_EVENTS + 17;  /* several blocks and a partial one */
    pdt_event *keep = calloc(n, sizeof *keep);
    emit_random(pdt_tw_hook(w), n, keep);
    PDT_TRACE(pdt_tw_hook(w), 2, PDT_EV_EDGE_ADD, 0, 1, 2, 0, 0); /* level 2: not recorded */
    CHECK(pdt_tw_events(w) == n);
    CHECK_MSG(pdt_tw_close(w, &err) == PDT_OK, "%s", err.msg);
    int64_t off[1] = {0};
    write_meta(run_dir, 1, off);

    pdt_run *run;
    CHECK_MSG(pdt_run_open(run_dir, &run, &err) == PDT_OK, "%s", err.msg);
    if (!run) return;
    CHECK_MSG(strcmp(pdt_run_warnings(run), "") == 0, "%s", pdt_run_warnings(run));
    const pdt_manifest *m = pdt_run_manifest(run);
    CHECK(m->nranks == 1 && m->n == 5 && m->level == 1);
    CHECK(!strcmp(m->command, "triangulate"));
    CHECK(!strcmp(m->command_line, "pdt triangulate --trace x \"a b\"\nsecond line\\"));
    CHECK(!strcmp(m->input_name, "in put.txt"));
    CHECK(m->wall_start_ns == 1700000000123456789ull);
    size_t np;
    const pdt_point *pts = pdt_run_points(run, &np);
    CHECK(np == 5 && pts[3].x == -2147483647 - 1 && pts[3].y == 2147483647);
    pdt_rank_info info;
    pdt_run_rank_info(run, 0, &info);
    CHECK(info.events == n && info.complete && info.present && info.blocks == 4);
    const pdt_event *ev;
    size_t ne;
    CHECK(pdt_run_rank_events(run, 0, &ev, &ne, &err) == PDT_OK);
    CHECK(ne == n);
    size_t bad = 0, backwards = 0;
    for (size_t i = 0; i < ne && i < n; i++) {
        if (!ev_eq(&ev[i], &keep[i])) bad++;
        if (i && ev[i].t < ev[i - 1].t) backwards++;
    }
    CHECK_MSG(bad == 0, "%zu events differ", bad);
    CHECK(backwards == 0);
    /* bytes per event for random 32-bit fields stays near the 16-byte goal */
    double bpe = (double)info.bytes / (double)n;
    CHECK_MSG(bpe < 24, "%.1f bytes/event", bpe);

    /* cursor: seek to every block boundary and a few random places */
    pdt_cursor *c;
    CHECK(pdt_cursor_open(run, 0, &c, &err) == PDT_OK);
    uint64_t probe[] = {0, 1, TF_BLOCK_EVENTS - 1, TF_BLOCK_EVENTS, 2 * TF_BLOCK_EVENTS + 5, n - 1,
                        7, n - 17};
    for (size_t i = 0; i < sizeof probe / sizeof *probe; i++) {
        pdt_event e;
        uint64_t seq;
        CHECK(pdt_cursor_seek(c, probe[i], &err) == PDT_OK);
        CHECK(pdt_cursor_next(c, &e, &seq) == 1);
        CHECK(seq == probe[i] && ev_eq(&e, &ev[probe[i]]) && e.t == ev[probe[i]].t);
    }
    CHECK(pdt_cursor_seek(c, n, &err) == PDT_OK);
    pdt_event e;
    CHECK(pdt_cursor_next(c, &e, NULL) == 0);
    CHECK(pdt_cursor_seek(c, n + 1, &err) == PDT_ERR_ARG);
    /* a full walk equals the decoded array */
    CHECK(pdt_cursor_seek(c, 0, NULL) == PDT_OK);
    size_t k = 0;
    bad = 0;
    while (pdt_cursor_next(c, &e, NULL))
        if (!ev_eq(&e, &ev[k++])) bad++;
    CHECK(k == n && bad == 0);
    pdt_cursor_close(c);
    pdt_run_close(run);
    free(keep);
}

static void copy_file(const char *from, const char *to, long truncate_to, long flip_at)
{
    FILE *f = fopen(from, "rb"), *g = fopen(to, "wb");
    if (!f || !g) {
        CHECK_MSG(0, "cannot copy %s", from);
        if (f) fclose(f);
        if (g) fclose(g);
        return;
    }
    int ch;
    long i = 0;
    while ((ch = fgetc(f)) != EOF && (truncate_to < 0 || i < truncate_to)) {
        if (i == flip_at) ch ^= 0x10;
        fputc(ch, g);
        i++;
    }
    fclose(f);
    fclose(g);
}

/* A copy of run_dir with rank-0000.trace altered; returns the warnings. */
static const char *damaged_warnings(const char *name, long truncate_to, long flip_at,
                                    uint64_t *events, pdt_run **keep)
{
    char dir[400], from[400], to[500];
    snprintf(dir, sizeof dir, "%s/%s", tmpdir, name);
    mkdir(dir, 0777);
    const char *files[] = {"manifest", "points.bin"};
    for (int i = 0; i < 2; i++) {
        snprintf(from, sizeof from, "%s/%s", run_dir, files[i]);
        snprintf(to, sizeof to, "%s/%s", dir, files[i]);
        copy_file(from, to, -1, -1);
    }
    snprintf(from, sizeof from, "%s/rank-0000.trace", run_dir);
    snprintf(to, sizeof to, "%s/rank-0000.trace", dir);
    copy_file(from, to, truncate_to, flip_at);
    pdt_err err = {0};
    pdt_run *run = NULL;
    CHECK_MSG(pdt_run_open(dir, &run, &err) == PDT_OK, "%s", err.msg);
    *keep = run;
    if (!run) return "";
    pdt_rank_info info;
    pdt_run_rank_info(run, 0, &info);
    *events = info.events;
    return pdt_run_warnings(run);
}

/* Offset of block k (k = 0 first) in run_dir's rank 0 file. */
static long block_offset(int k)
{
    char path[400];
    snprintf(path, sizeof path, "%s/rank-0000.trace", run_dir);
    FILE *f = fopen(path, "rb");
    long off = TF_HEADER_SIZE;
    for (int i = 0; f && i < k; i++) {
        uint8_t h[TF_BLOCK_HEADER_SIZE];
        fseek(f, off, SEEK_SET);
        if (fread(h, 1, sizeof h, f) != sizeof h) break;
        off += TF_BLOCK_HEADER_SIZE + (long)tf_get32(h + 4);
    }
    if (f) fclose(f);
    return off;
}

TEST(damage_is_reported_with_offsets)
{
    uint64_t nev;
    pdt_run *run;
    long b2 = block_offset(2);
    char want[200];

    /* a flipped payload byte in block 2 */
    const char *w = damaged_warnings("flip", -1, b2 + 40, &nev, &run);
    snprintf(want, sizeof want, "rank-0000.trace: block 2 at byte %ld: checksum mismatch", b2);
    CHECK_MSG(strstr(w, want) != NULL, "warnings: %s", w);
    CHECK(nev == 2 * TF_BLOCK_EVENTS);
    pdt_run_close(run);

    /* truncated in the middle of block 2 */
    w = damaged_warnings("trunc", b2 + 100, -1, &nev, &run);
    snprintf(want, sizeof want, "block 2 at byte %ld: truncated", b2);
    CHECK_MSG(strstr(w, want) != NULL, "warnings: %s", w);
    CHECK(nev == 2 * TF_BLOCK_EVENTS);
    pdt_run_close(run);

    /* killed before the end marker: the last complete block is kept */
    long end = block_offset(4);
    w = damaged_warnings("killed", end, -1, &nev, &run);
    CHECK_MSG(strstr(w, "no end marker") != NULL, "warnings: %s", w);
    CHECK(nev == 3 * TF_BLOCK_EVENTS + 17);
    pdt_run_close(run);

    /* a flipped byte in the file header */
    w = damaged_warnings("header", -1, 17, &nev, &run);
    CHECK_MSG(strstr(w, "file header checksum mismatch") != NULL, "warnings: %s", w);
    CHECK(nev == 0);
    pdt_run_close(run);
}

TEST(missing_rank_and_bad_version)
{
    char dir[400], path[500];
    snprintf(dir, sizeof dir, "%s/two", tmpdir);
    pdt_trace_writer *w;
    pdt_err err = {0};
    CHECK(pdt_tw_open(dir, 0, 1, &w, &err) == PDT_OK);
    PDT_TRACE(pdt_tw_hook(w), 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    CHECK(pdt_tw_close(w, &err) == PDT_OK);
    int64_t off[2] = {0, 0};
    write_meta(dir, 2, off);  /* says 2 ranks; rank 1 never wrote */
    pdt_run *run;
    CHECK_MSG(pdt_run_open(dir, &run, &err) == PDT_OK, "%s", err.msg);
    if (run) {
        CHECK_MSG(strstr(pdt_run_warnings(run), "rank-0001.trace: missing") != NULL, "%s",
                  pdt_run_warnings(run));
        pdt_run_close(run);
    }
    /* a manifest of another major version is an error naming both versions */
    snprintf(path, sizeof path, "%s/manifest", dir);
    FILE *f = fopen(path, "w");
    fprintf(f, "format = 3.3\nranks = 1\n");
    fclose(f);
    pdt_err_clear(&err);
    CHECK(pdt_run_open(dir, &run, &err) == PDT_ERR_FORMAT);
    CHECK_MSG(strstr(err.msg, "format 3.3") && strstr(err.msg, "reads formats 1.x to 2.x"), "%s", err.msg);
    /* no manifest at all: the rank files are still readable */
    remove(path);
    pdt_err_clear(&err);
    CHECK(pdt_run_open(dir, &run, &err) == PDT_OK);
    if (run) {
        CHECK(pdt_run_nranks(run) == 1);
        CHECK(strstr(pdt_run_warnings(run), "manifest: missing") != NULL);
        pdt_run_close(run);
    }
}

/* Three ranks exchange messages; rank clocks are skewed by the manifest's
 * offsets so that, by time alone, receives would come before their sends. */
/* Replace line `key = ...` of dir/manifest by `line`. */
static void set_manifest_line(const char *dir, const char *key, const char *line)
{
    char path[400], text[4096], out[4096];
    snprintf(path, sizeof path, "%s/manifest", dir);
    FILE *f = fopen(path, "rb");
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    if (f) fclose(f);
    text[n] = 0;
    size_t o = 0, kl = strlen(key);
    for (char *s = text, *e; *s; s = e) {
        e = strchr(s, '\n');
        e = e ? e + 1 : s + strlen(s);
        if (!strncmp(s, key, kl) && s[kl] == ' ') o += (size_t)snprintf(out + o, sizeof out - o, "%s\n", line);
        else o += (size_t)snprintf(out + o, sizeof out - o, "%.*s", (int)(e - s), s);
    }
    f = fopen(path, "wb");
    if (f) {
        fwrite(out, 1, o, f);
        fclose(f);
    }
}

/* A run folder of format 1 (FNV-1a 64 input checksum, rank files of major
 * version 1), as pdt wrote them before points.bin was written in parallel,
 * is read as it was; a wrong FNV is reported; an unknown checksum name is
 * refused naming the manifest's line. */
TEST(format_1_runs_are_still_read)
{
    char dir[300], path[400];
    snprintf(dir, sizeof dir, "%s/old", tmpdir);
    pdt_trace_writer *w;
    pdt_err err = {0};
    CHECK(pdt_tw_open(dir, 0, 1, &w, &err) == PDT_OK);
    PDT_TRACE(pdt_tw_hook(w), 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    PDT_TRACE(pdt_tw_hook(w), 1, PDT_EV_PHASE_END, PDT_PH_RUN, 0, 0, 0, 0);
    CHECK(pdt_tw_close(w, &err) == PDT_OK);
    int64_t off0 = 0;
    write_meta(dir, 1, &off0);
    pdt_point pts[5] = {{0, 0}, {10, 0}, {0, 10}, {-2147483647 - 1, 2147483647}, {3, 4}};
    char line[128];
    set_manifest_line(dir, "format", "format = 1.0");
    snprintf(line, sizeof line, "input_checksum = fnv1a64:%016llx",
             (unsigned long long)pdt_points_fnv1a64(pts, 5));
    set_manifest_line(dir, "input_checksum", line);
    snprintf(path, sizeof path, "%s/rank-0000.trace", dir); /* header: major version 1 */
    FILE *f = fopen(path, "r+b");
    uint8_t h[32];
    CHECK(f && fread(h, 1, 32, f) == 32);
    h[8] = 1;
    uint32_t crc = pdt_crc32c(0, h, 28);
    for (int i = 0; i < 4; i++) h[28 + i] = (uint8_t)(crc >> (8 * i));
    if (f) {
        fseek(f, 0, SEEK_SET);
        fwrite(h, 1, 32, f);
        fclose(f);
    }
    pdt_run *run = NULL;
    CHECK_MSG(pdt_run_open(dir, &run, &err) == PDT_OK, "%s", err.msg);
    if (run) {
        const pdt_manifest *m = pdt_run_manifest(run);
        size_t n;
        CHECK(m->format_version == 1 && m->input_checksum_kind == PDT_CHECKSUM_FNV1A64);
        CHECK(pdt_run_points(run, &n) && n == 5);
        CHECK_MSG(!*pdt_run_warnings(run), "%s", pdt_run_warnings(run));
        pdt_run_close(run);
    }
    /* format 1's checksum, wrong: the same warning as ever */
    set_manifest_line(dir, "input_checksum", "input_checksum = fnv1a64:0000000000000001");
    CHECK(pdt_run_open(dir, &run, &err) == PDT_OK);
    if (run) {
        CHECK_MSG(strstr(pdt_run_warnings(run), "input_checksum"), "%s", pdt_run_warnings(run));
        pdt_run_close(run);
    }
    /* no name: format 1's FNV-1a 64 (its readers accepted bare hex) */
    snprintf(line, sizeof line, "input_checksum = %016llx",
             (unsigned long long)pdt_points_fnv1a64(pts, 5));
    set_manifest_line(dir, "input_checksum", line);
    CHECK(pdt_run_open(dir, &run, &err) == PDT_OK);
    if (run) {
        CHECK_MSG(!*pdt_run_warnings(run), "%s", pdt_run_warnings(run));
        pdt_run_close(run);
    }
    set_manifest_line(dir, "input_checksum", "input_checksum = sha1:0123456789abcdef");
    pdt_err_clear(&err);
    CHECK(pdt_run_open(dir, &run, &err) == PDT_ERR_FORMAT);
    CHECK_MSG(strstr(err.msg, "manifest:") && strstr(err.msg, "sha1:0123"), "%s", err.msg);
}

TEST(merged_order_is_causal)
{
    char dir[400];
    snprintf(dir, sizeof dir, "%s/merged", tmpdir);
    pdt_trace_writer *w[3];
    pdt_err err = {0};
    for (int r = 0; r < 3; r++) CHECK(pdt_tw_open(dir, r, 1, &w[r], &err) == PDT_OK);
    pdt_trace *t0 = pdt_tw_hook(w[0]), *t1 = pdt_tw_hook(w[1]), *t2 = pdt_tw_hook(w[2]);
    /* interleaved as a real run would be (real time order) */
    PDT_TRACE(t1, 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    PDT_TRACE(t2, 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    PDT_TRACE(t0, 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    for (int s = 0; s < 50; s++) {
        PDT_TRACE(t0, 1, PDT_EV_SEND, 3, 1, 100 + s, 0, s);  /* 0 -> 1 */
        PDT_TRACE(t1, 1, PDT_EV_RECV, 3, 0, 100 + s, 0, s);
        PDT_TRACE(t1, 1, PDT_EV_SEND, 4, 2, 8, 0, s);        /* 1 -> 2 */
        PDT_TRACE(t2, 1, PDT_EV_RECV, 4, 1, 8, 0, s);
        PDT_TRACE(t2, 1, PDT_EV_LIFT, 0, (uint32_t)s, 0, 0, s * s);
    }
    for (int r = 0; r < 3; r++) CHECK(pdt_tw_close(w[r], &err) == PDT_OK);
    int64_t off[3] = {0, -1000000000, -2000000000}; /* receivers look 1 s and 2 s earlier */
    write_meta(dir, 3, off);
    pdt_run *run;
    CHECK_MSG(pdt_run_open(dir, &run, &err) == PDT_OK, "%s", err.msg);
    if (!run) return;
    const pdt_rec *rec;
    size_t n;
    CHECK(pdt_run_merged(run, &rec, &n, &err) == PDT_OK);
    CHECK(n == 3 + 50 * 5);
    /* property: each rank's order kept; every recv after its send */
    uint32_t last_seq[3] = {0, 0, 0};
    int seen[3] = {0, 0, 0}, order_ok = 1, causal_ok = 1;
    int sent01[50] = {0}, sent12[50] = {0};
    for (size_t i = 0; i < n; i++) {
        const pdt_rec *r = &rec[i];
        if (seen[r->rank] && r->seq != last_seq[r->rank] + 1) order_ok = 0;
        if (!seen[r->rank] && r->seq != 0) order_ok = 0;
        seen[r->rank] = 1;
        last_seq[r->rank] = r->seq;
        if (r->ev.kind == PDT_EV_SEND) (r->rank == 0 ? sent01 : sent12)[r->ev.v] = 1;
        if (r->ev.kind == PDT_EV_RECV && !(r->rank == 1 ? sent01 : sent12)[r->ev.v]) causal_ok = 0;
    }
    CHECK(order_ok);
    CHECK(causal_ok);
    /* with the skew, rank 2's first event (aligned earliest) comes first */
    CHECK(rec[0].rank == 2 && rec[0].ev.kind == PDT_EV_PHASE_BEGIN);
    CHECK_MSG(strcmp(pdt_run_warnings(run), "") == 0, "%s", pdt_run_warnings(run));
    pdt_run_close(run);
}

/* The merged order of `dir`'s run by pdt_merge_fill, `max` records a call,
 * is pdt_merge_next's record for record (a run of one rank is copied from
 * its decoded blocks: a call ends at a block's end).  The number of records
 * compared, or -1 when they differ. */
static long fill_same_as_next(const char *dir, size_t max)
{
    pdt_run *run;
    pdt_err err = {0};
    if (pdt_run_open(dir, &run, &err) != PDT_OK) return -1;
    pdt_merge *a, *b;
    long n = 0;
    if (pdt_merge_open(run, &a, &err) == PDT_OK) {
        if (pdt_merge_open(run, &b, &err) == PDT_OK) {
            pdt_rec *buf = calloc(max, sizeof *buf), one;
            int got;
            while (buf && n >= 0 && (got = pdt_merge_fill(a, buf, max, &err)) > 0)
                for (int i = 0; i < got && n >= 0; i++, n++)
                    if (pdt_merge_next(b, &one, &err) != 1 || one.rank != buf[i].rank ||
                        one.seq != buf[i].seq || !ev_eq(&one.ev, &buf[i].ev))
                        n = -1;
            if (n >= 0 && (!buf || pdt_merge_next(b, &one, &err) != 0)) n = -1;
            free(buf);
            pdt_merge_close(b);
        }
        pdt_merge_close(a);
    }
    pdt_run_close(run);
    return n;
}

TEST(merge_fill_is_merge_next_order)
{
    char rt[400], merged[400];
    snprintf(rt, sizeof rt, "%s/rt", tmpdir);          /* one rank, four blocks */
    snprintf(merged, sizeof merged, "%s/merged", tmpdir); /* three ranks, messages */
    size_t maxes[] = {1, 5, TF_BLOCK_EVENTS - 1, 100000};
    for (size_t k = 0; k < sizeof maxes / sizeof *maxes; k++) {
        long a = fill_same_as_next(rt, maxes[k]), b = fill_same_as_next(merged, maxes[k]);
        CHECK_MSG(a == 3 * TF_BLOCK_EVENTS + 17, "one rank, %zu a call: %ld", maxes[k], a);
        CHECK_MSG(b == 3 + 50 * 5, "three ranks, %zu a call: %ld", maxes[k], b);
    }
}

TEST(event_text)
{
    char buf[160];
    pdt_event e = {.kind = PDT_EV_POP, .sub = PDT_STACK_GRAHAM, .a = 17, .b = 3, .c = 12};
    CHECK(!strcmp(pdt_event_format(&e, buf, sizeof buf), "pop graham pt=17 depth=3 cause=12"));
    e.c = UINT32_MAX;
    CHECK(!strcmp(pdt_event_format(&e, buf, sizeof buf), "pop graham pt=17 depth=3 cause=-"));
    pdt_event l = {.kind = PDT_EV_LIFT, .a = 4, .v = 25};
    CHECK(!strcmp(pdt_event_format(&l, buf, sizeof buf), "lift pt=4 z=25"));
    /* a message of 5 GiB + 7 bytes: the count's high half is in c */
    uint64_t big = ((uint64_t)5 << 30) + 7;
    pdt_event snd = {.kind = PDT_EV_SEND, .sub = 3, .a = 1, .b = (uint32_t)big,
                     .c = (uint32_t)(big >> 32), .v = 2};
    CHECK(pdt_event_bytes(&snd) == big);
    CHECK(!strcmp(pdt_event_format(&snd, buf, sizeof buf), "send tag=3 to=1 bytes=5368709127 seq=2"));
    snd.kind = PDT_EV_RECV;
    CHECK(!strcmp(pdt_event_format(&snd, buf, sizeof buf),
                  "recv tag=3 from=1 bytes=5368709127 seq=2"));
    snd.c = 0; /* as every trace written before: the low half alone */
    CHECK(pdt_event_bytes(&snd) == 1073741831u);
    CHECK(pdt_event_kind_by_name("tri-final") == PDT_EV_TRI_FINAL);
    CHECK(pdt_event_kind_by_name("nope") == -1);
    for (int k = 0; k < PDT_EV_KIND_COUNT + 2; k++) {
        pdt_event x = {.kind = (uint8_t)k, .a = 1, .b = 2, .c = 3, .v = 4};
        pdt_event_format(&x, buf, sizeof buf);
        CHECK(strlen(buf) > 3);
    }
}

int main(void)
{
    make_tmp();
    RUN(crc32c_check_value);
    RUN(crc32c_long_buffers_three_lanes);
    RUN(crc64_check_value);
    RUN(crc64_every_length_and_offset);
    RUN(crc_combine_any_split);
    RUN(points_checksum_is_crc64_of_the_bytes);
    RUN(codec_extremes);
    RUN(validate_agrees_with_decode);
    RUN(writer_reader_round_trip);
    RUN(damage_is_reported_with_offsets);
    RUN(missing_rank_and_bad_version);
    RUN(format_1_runs_are_still_read);
    RUN(merged_order_is_causal);
    RUN(merge_fill_is_merge_next_order);
    RUN(event_text);
    rm_rf(tmpdir);
    return test_summary();
}
