/* Unit tests of src/io: point and triangle parsers (every bad input with its
 * message), --scale rounding and collisions, writers, atomic output. */
#include <dirent.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../harness.h"
#include "pdt/io.h"

static char dir[64];

/* Full path of `name` in the test directory (static buffer, 4 slots). */
static const char *path(const char *name)
{
    static char buf[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

static void put(const char *name, const char *text)
{
    FILE *f = fopen(path(name), "wb");
    if (!f) return;
    fwrite(text, 1, strlen(text), f);
    fclose(f);
}

static char *slurp(const char *p)
{
    FILE *f = fopen(p, "rb");
    if (!f) return NULL;
    char *b = calloc(1, 1 << 16);
    if (b) fread(b, 1, (1 << 16) - 1, f);
    fclose(f);
    return b;
}

/* Number of entries (other than . and ..) in the test directory. */
static int entries(void)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
    if (d) closedir(d);
    return n;
}

static void clean(void)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) unlink(path(e->d_name));
    if (d) closedir(d);
}

/* Read `text` saved as `name`; returns the status, fills err. */
static pdt_status rd(const char *name, const char *text, double scale, pdt_point **p, size_t *n,
                     size_t *coll, pdt_err *err)
{
    put(name, text);
    pdt_err_clear(err);
    return pdt_read_points(path(name), scale, p, n, coll, err);
}

/* Expect reading `text` as `name` to fail with exactly "DIR/name:" + msg. */
static int bad(const char *name, const char *text, double scale, const char *msg)
{
    pdt_point *p = NULL;
    size_t n = 99;
    pdt_err err;
    pdt_status st = rd(name, text, scale, &p, &n, NULL, &err);
    char want[512];
    snprintf(want, sizeof want, "%s:%s", path(name), msg);
    int ok = st == PDT_ERR_PARSE && strcmp(err.msg, want) == 0 && p == NULL && n == 0;
    if (!ok) printf("#   want [%s]\n#   got  [%s] (status %d)\n", want, err.msg, (int)st);
    return ok;
}

TEST(text_basic)
{
    pdt_point *p;
    size_t n;
    pdt_err err;
    pdt_status st = rd("a.txt",
                       "\xEF\xBB\xBF# header comment\n"
                       "1 2\n"
                       "\n"
                       "   -3\t4   \r\n"
                       "5 6 # trailing comment\n"
                       "\t\r\n"
                       "-2147483648 2147483647\n"
                       "+7 0008", /* no final newline */
                       0, &p, &n, NULL, &err);
    CHECK_MSG(st == PDT_OK, "%s", err.msg);
    CHECK(n == 5);
    if (st == PDT_OK && n == 5) {
        CHECK(p[0].x == 1 && p[0].y == 2);
        CHECK(p[1].x == -3 && p[1].y == 4);
        CHECK(p[2].x == 5 && p[2].y == 6);
        CHECK(p[3].x == INT32_MIN && p[3].y == INT32_MAX);
        CHECK(p[4].x == 7 && p[4].y == 8);
    }
    free(p);
}

/* Spreadsheet exports: comma-, semicolon- or tab-separated, an optional
 * header line naming the columns, decimals under --scale. */
TEST(text_csv)
{
    const char *ok_texts[] = {
        "x,y\n1,2\n-3,4\n",
        "X;Y\r\n1;2\r\n-3;4\r\n",
        "x\ty\n1\t2\n-3\t4\n",
        "\"x\",\"y\"\n1 , 2\n-3,4\n",
        "# exported\n\nlon,lat\n1,2\n-3,4 # comment\n",
        "1,2\n-3 4\n",
    };
    for (size_t i = 0; i < sizeof ok_texts / sizeof *ok_texts; i++) {
        pdt_point *p = NULL;
        size_t n = 0;
        pdt_err err;
        pdt_status st = rd("c.txt", ok_texts[i], 0, &p, &n, NULL, &err);
        CHECK_MSG(st == PDT_OK && n == 2 && p[0].x == 1 && p[0].y == 2 && p[1].x == -3 &&
                      p[1].y == 4, "case %zu: %s", i, err.msg);
        free(p);
    }
    pdt_point *p = NULL;
    size_t n = 0;
    pdt_err err;
    pdt_status st = rd("d.txt", "x,y\n1.5,2.25\n", 100, &p, &n, NULL, &err);
    CHECK_MSG(st == PDT_OK && n == 1 && p[0].x == 150 && p[0].y == 225, "%s", err.msg);
    free(p);
    CHECK(bad("c.txt", "x,y\n1,,2\n", 0, "2: missing y coordinate"));
    CHECK(bad("c.txt", "x,y\n1,2,3\n", 0,
              "2: unexpected ',3' after the coordinates (one point 'x y' per line)"));
    CHECK(bad("c.txt", "x,y\n1,2,\n", 0,
              "2: unexpected ',' after the coordinates (one point 'x y' per line)"));
    CHECK(bad("c.txt", "x,y,z\n1,2,3\n", 0, "1: 'x' is not a number"));
    CHECK(bad("c.txt", "x,y\nx,y\n", 0, "2: 'x' is not a number"));  /* one header only */
    CHECK(bad("c.txt", "1,2\nx,y\n", 0, "2: 'x' is not a number"));  /* only on top */
    CHECK(bad("c.txt", ",1,2\n", 0, "1: missing x coordinate"));
    CHECK(bad("c.txt", "x,y\n1.5,2\n", 0,
              "2: coordinate 1.5 is not an integer (decimal coordinates need --scale K)"));
}

TEST(empty_file_is_zero_points)
{
    pdt_point *p = (pdt_point *)1;
    size_t n = 7;
    pdt_err err;
    CHECK(rd("e.txt", "", 0, &p, &n, NULL, &err) == PDT_OK && n == 0);
    free(p);
    CHECK(rd("e2.txt", "# only a comment\n\n  \n", 0, &p, &n, NULL, &err) == PDT_OK && n == 0);
    free(p);
    CHECK(rd("e.node", "", 0, &p, &n, NULL, &err) == PDT_OK && n == 0);
    free(p);
}

/* Files of 1 MiB or more are mapped, not read: one whose size is a
 * multiple of the page size (so no zero byte follows it in its last page)
 * ends with a point without a newline; another ends with a bad line, which
 * is still named by its number. */
TEST(large_file_mapped_exact_pages)
{
    size_t lines = (1u << 20) / 4; /* "1 2\n" is 4 bytes: the file is exactly 1 MiB */
    char *t = malloc(4 * lines + 1);
    CHECK(t != NULL);
    for (size_t i = 0; i < lines; i++) memcpy(t + 4 * i, "1 2\n", 4);
    memcpy(t + 4 * (lines - 1), "3 45", 4); /* last line, no newline */
    t[4 * lines] = '\0';
    pdt_point *p = NULL;
    size_t n = 0;
    pdt_err err;
    CHECK(rd("big.txt", t, 0, &p, &n, NULL, &err) == PDT_OK);
    CHECK(n == lines && p[0].x == 1 && p[0].y == 2 && p[n - 1].x == 3 && p[n - 1].y == 45);
    free(p);
    memcpy(t + 4 * (lines - 1), "3 4x", 4);
    p = NULL;
    CHECK(rd("big2.txt", t, 0, &p, &n, NULL, &err) == PDT_ERR_PARSE);
    char want[64];
    snprintf(want, sizeof want, "big2.txt:%zu:", lines);
    CHECK_MSG(strstr(err.msg, want) != NULL, "message: %s", err.msg);
    free(p);
    free(t);
}

TEST(text_bad_inputs)
{
    CHECK(bad("b.txt", "1 2\n3 4294967296\n", 0, "2: coordinate 4294967296 does not fit in 32 bits"));
    CHECK(bad("b.txt", "2147483648 0\n", 0, "1: coordinate 2147483648 does not fit in 32 bits"));
    CHECK(bad("b.txt", "0 -2147483649\n", 0, "1: coordinate -2147483649 does not fit in 32 bits"));
    CHECK(bad("b.txt", "1 99999999999999999999999\n", 0,
              "1: coordinate 99999999999999999999999 does not fit in 32 bits"));
    CHECK(bad("b.txt", "1 2\n\nabc 3\n", 0, "3: 'abc' is not a number"));
    CHECK(bad("b.txt", "1,2 3\n", 0,
              "1: unexpected '3' after the coordinates (one point 'x y' per line)"));
    CHECK(bad("b.txt", "1 2\n- 3\n", 0, "2: '-' is not a number"));
    CHECK(bad("b.txt", "1 0x10\n", 0, "1: '0x10' is not a number"));
    CHECK(bad("b.txt", "1 \x01\n", 0, "1: '\\x01' is not a number"));
    CHECK(bad("b.txt", "1.5 2\n", 0,
              "1: coordinate 1.5 is not an integer (decimal coordinates need --scale K)"));
    CHECK(bad("b.txt", "1 2e3\n", 0,
              "1: coordinate 2e3 is not an integer (decimal coordinates need --scale K)"));
    CHECK(bad("b.txt", "1 2\n7\n", 0, "2: missing y coordinate"));
    CHECK(bad("b.txt", "7 # 8\n", 0, "1: missing y coordinate"));
    CHECK(bad("b.txt", "1 2 3\n", 0,
              "1: unexpected '3' after the coordinates (one point 'x y' per line)"));
    CHECK(bad("b.txt", "1 2\r\n3 4 junk\r\n", 0,
              "2: unexpected 'junk' after the coordinates (one point 'x y' per line)"));
    CHECK(bad("b.txt", "1 abc\n", 1000, "1: 'abc' is not a number"));
    CHECK(bad("b.txt", "1 3000000\n", 1000,
              "1: coordinate 3000000 times scale 1000 does not fit in 32 bits"));
    CHECK(bad("b.txt", "1 1e999\n", 10, "1: coordinate 1e999 times scale 10 does not fit in 32 bits"));
}

TEST(file_errors)
{
    pdt_point *p;
    size_t n;
    pdt_err err;
    pdt_err_clear(&err);
    CHECK(pdt_read_points(dir, 0, &p, &n, NULL, &err) == PDT_ERR_IO);
    char want[256];
    snprintf(want, sizeof want, "%s: is a directory", dir);
    CHECK_MSG(strcmp(err.msg, want) == 0, "%s", err.msg);
    pdt_err_clear(&err);
    CHECK(pdt_read_points(path("missing.txt"), 0, &p, &n, NULL, &err) == PDT_ERR_IO);
    snprintf(want, sizeof want, "%s: cannot open: No such file or directory", path("missing.txt"));
    CHECK_MSG(strcmp(err.msg, want) == 0, "%s", err.msg);
    pdt_err_clear(&err);
    CHECK(pdt_read_points(path("x.txt"), -1, &p, &n, NULL, &err) == PDT_ERR_ARG);
    /* A file that opens but cannot be read: offset 0 of /proc/self/mem. */
    if (access("/proc/self/mem", R_OK) == 0) {
        pdt_err_clear(&err);
        CHECK(pdt_read_points("/proc/self/mem", 0, &p, &n, NULL, &err) == PDT_ERR_IO);
        CHECK_MSG(strcmp(err.msg, "/proc/self/mem: read error: Input/output error") == 0, "%s",
                  err.msg);
    }
    if (geteuid() != 0) { /* root reads everything */
        put("noread.txt", "1 2\n");
        chmod(path("noread.txt"), 0);
        pdt_err_clear(&err);
        CHECK(pdt_read_points(path("noread.txt"), 0, &p, &n, NULL, &err) == PDT_ERR_IO);
        CHECK(strstr(err.msg, "cannot open: Permission denied") != NULL);
    }
}

/* A FIFO, a device and a link to /dev/zero are refused by name, at once (a
 * regression would block in open() or read without end: the alarm turns
 * that into a failed run). */
TEST(not_regular_files_refused)
{
    pdt_point *p = NULL;
    size_t n;
    pdt_err err;
    pdt_points_head h;
    char want[512];
    alarm(30);
    CHECK(mkfifo(path("fifo.txt"), 0600) == 0);
    pdt_err_clear(&err);
    CHECK(pdt_read_points(path("fifo.txt"), 0, &p, &n, NULL, &err) == PDT_ERR_IO);
    snprintf(want, sizeof want, "%s: is a FIFO (named pipe), not a regular file", path("fifo.txt"));
    CHECK_MSG(strncmp(err.msg, want, strlen(want)) == 0, "%s", err.msg);
    pdt_err_clear(&err);
    CHECK(pdt_points_head_read(path("fifo.txt"), 0, &h, &err) == PDT_ERR_IO);
    CHECK_MSG(strncmp(err.msg, want, strlen(want)) == 0, "%s", err.msg);
    pdt_err_clear(&err);
    CHECK(pdt_read_points("/dev/zero", 0, &p, &n, NULL, &err) == PDT_ERR_IO);
    CHECK_MSG(strstr(err.msg, "/dev/zero: is a character device") == err.msg, "%s", err.msg);
    CHECK(symlink("/dev/zero", path("zero.txt")) == 0);
    pdt_err_clear(&err);
    CHECK(pdt_read_points(path("zero.txt"), 0, &p, &n, NULL, &err) == PDT_ERR_IO);
    CHECK_MSG(strstr(err.msg, "is a character device") != NULL, "%s", err.msg);
    char why[160];
    CHECK(pdt_open_input(path("fifo.txt"), why, sizeof why) < 0 && errno == EINVAL);
    int fd = pdt_open_input(path("missing"), why, sizeof why);
    CHECK(fd < 0 && errno == ENOENT && strcmp(why, "cannot open: No such file or directory") == 0);
    alarm(0);
}

/* A file whose first line never ends: the reader that finds where the
 * header ends stops after PDT_IO_LINE_SPAN bytes and names the line. */
TEST(head_read_endless_line_refused)
{
    size_t big = 3 * PDT_IO_LINE_SPAN;
    char *b = malloc(big + 1);
    if (!b) return;
    memcpy(b, "# points\n", 9);
    memset(b + 9, 'x', big - 9);
    b[big] = 0;
    put("endless.txt", b);
    free(b);
    pdt_points_head h;
    pdt_err err;
    pdt_err_clear(&err);
    CHECK(pdt_points_head_read(path("endless.txt"), 0, &h, &err) == PDT_ERR_PARSE);
    char want[512];
    snprintf(want, sizeof want, "%s:2: no end of line in %zu bytes", path("endless.txt"),
             PDT_IO_LINE_SPAN);
    CHECK_MSG(strncmp(err.msg, want, strlen(want)) == 0, "%s", err.msg);
}

TEST(node_format)
{
    pdt_point *p;
    size_t n;
    pdt_err err;
    /* Triangle's own style: 1-based, attributes, markers, comments. */
    pdt_status st = rd("a.node",
                       "# made by hand\n"
                       "3 2 1 1\n"
                       "1 10 20 0.5 0\n"
                       "2 -5 7 1e3 1  # comment\n"
                       "3 0 0 -2 1\n",
                       0, &p, &n, NULL, &err);
    CHECK_MSG(st == PDT_OK && n == 3, "%s", err.msg);
    if (st == PDT_OK && n == 3) CHECK(p[0].x == 10 && p[1].x == -5 && p[1].y == 7 && p[2].y == 0);
    free(p);
    /* 0-based, header with only count and dimension. */
    st = rd("b.node", "2 2\n0 1 1\n1 2 2\n", 0, &p, &n, NULL, &err);
    CHECK_MSG(st == PDT_OK && n == 2, "%s", err.msg);
    free(p);
    CHECK(bad("c.node", "3 3 0 0\n", 0, "1: .node header says dimension 3; only 2 is supported"));
    CHECK(bad("c.node", "x 2 0 0\n", 0, "1: bad point count in the .node header 'x'"));
    CHECK(bad("c.node", "-1 2 0 0\n", 0, "1: bad point count in the .node header '-1'"));
    CHECK(bad("c.node", "2 2 0 2\n", 0, "1: .node header says 2 boundary markers; must be 0 or 1"));
    CHECK(bad("c.node", "2 2 0 0 9\n", 0,
              "1: unexpected '9' after the .node header (count, 2, attributes, markers)"));
    CHECK(bad("c.node", "3 2 0 0\n0 1 1\n1 2 2\n", 0,
              "3: file ends after 2 of the 3 points the header announces"));
    CHECK(bad("c.node", "1 2 0 0\n0 1 1\n1 2 2\n", 0,
              "3: more points than the 1 the header announces"));
    CHECK(bad("c.node", "2 2 0 0\n0 1 1\n2 2 2\n", 0, "3: point index 2 out of order (expected 1)"));
    CHECK(bad("c.node", "2 2 0 0\n5 1 1\n", 0, "2: first point index is 5; must be 0 or 1"));
    CHECK(bad("c.node", "1 2 1 0\n0 1 1\n", 0, "2: missing attribute 1 of 1"));
    CHECK(bad("c.node", "1 2 1 0\n0 1 1 q\n", 0, "2: attribute 'q' is not a number"));
    CHECK(bad("c.node", "1 2 0 1\n0 1 1\n", 0, "2: missing boundary marker"));
    CHECK(bad("c.node", "1 2 0 1\n0 1 1 0.5\n", 0, "2: boundary marker '0.5' is not an integer"));
    CHECK(bad("c.node", "1 2 0 0\n0 1 1 4\n", 0,
              "2: unexpected '4' after the point (index x y, attributes, marker)"));
    CHECK(bad("c.node", "1 2 0 0\n0 1 4294967296\n", 0,
              "2: coordinate 4294967296 does not fit in 32 bits"));
}

TEST(scale_rounding)
{
    pdt_point *p;
    size_t n, coll = 99;
    pdt_err err;
    pdt_status st = rd("s.txt",
                       "0.15 0.25\n"      /* 1.5 -> 2, 2.5 -> 3: halves away from zero */
                       "-0.15 -0.25\n"    /* -2, -3 */
                       "1e-3 2.5E2\n"     /* 0.01 -> 0, 2500 */
                       "0.0000000000000000000000001 -0\n" /* 0, 0 */
                       "214748364.7 -214748364.8\n", /* the int32 extremes */
                       10, &p, &n, &coll, &err);
    CHECK_MSG(st == PDT_OK && n == 5, "%s", err.msg);
    if (st == PDT_OK && n == 5) {
        CHECK_MSG(p[0].x == 2 && p[0].y == 3, "%d %d", p[0].x, p[0].y);
        CHECK(p[1].x == -2 && p[1].y == -3);
        CHECK(p[2].x == 0 && p[2].y == 2500);
        CHECK(p[3].x == 0 && p[3].y == 0);
        CHECK(p[4].x == INT32_MAX && p[4].y == INT32_MIN);
    }
    CHECK(coll == 0); /* no two rounded points are equal */
    free(p);
    /* Non-integer scale goes through double arithmetic. */
    st = rd("s2.txt", "1.5 2\n", 0.5, &p, &n, &coll, &err);
    CHECK(st == PDT_OK && n == 1 && p[0].x == 1 && p[0].y == 1);
    free(p);
}

TEST(scale_collisions)
{
    pdt_point *p;
    size_t n, coll = 99;
    pdt_err err;
    pdt_status st = rd("c.txt",
                       "1.04 2\n"
                       "1.0 2\n"   /* collides with 1.04 */
                       "1 2.00\n"  /* same value as 1.0 2: a duplicate, not a collision */
                       "0.96 2\n"  /* collides */
                       "5 5\n"
                       "5 5\n",    /* exact duplicate: not a collision */
                       10, &p, &n, &coll, &err);
    CHECK_MSG(st == PDT_OK && n == 6, "%s", err.msg);
    CHECK_MSG(coll == 2, "collisions %zu", coll);
    if (st == PDT_OK)
        CHECK(p[0].x == 10 && p[1].x == 10 && p[2].x == 10 && p[3].x == 10 && p[0].y == 20);
    free(p);
    /* Without scale nothing is counted. */
    st = rd("c2.txt", "1 2\n1 2\n", 0, &p, &n, &coll, &err);
    CHECK(st == PDT_OK && coll == 0);
    free(p);
}

TEST(points_write_roundtrip)
{
    clean();
    pdt_point pts[3] = { { 0, 0 }, { INT32_MIN, INT32_MAX }, { -7, 12 } };
    pdt_err err;
    pdt_err_clear(&err);
    CHECK(pdt_write_points(path("w.txt"), pts, 3, &err) == PDT_OK);
    char *t = slurp(path("w.txt"));
    CHECK(t && strcmp(t, "0 0\n-2147483648 2147483647\n-7 12\n") == 0);
    free(t);
    CHECK(pdt_write_points(path("w.node"), pts, 3, &err) == PDT_OK);
    pdt_point *p;
    size_t n;
    CHECK(pdt_read_points(path("w.node"), 0, &p, &n, NULL, &err) == PDT_OK && n == 3);
    CHECK(n == 3 && memcmp(p, pts, sizeof pts) == 0);
    free(p);
    CHECK(entries() == 2); /* no temporaries left */
}

/* The writers format numbers by hand: every digit count, both sides of every
 * power of ten, the int32 and uint32 extremes, compared with printf. */
TEST(numbers_every_digit_count)
{
    clean();
    enum { K = 64 };
    pdt_point pts[K];
    pdt_tri t[K];
    int64_t v[K];
    int nv = 0;
    v[nv++] = 0;
    for (int64_t p = 1; p <= INT64_C(1000000000); p *= 10) {
        v[nv++] = p - 1;
        v[nv++] = p;
        v[nv++] = p + 1;
    }
    v[nv++] = INT32_MAX;
    for (int i = 0; i < nv; i++) {
        pts[i].x = (int32_t)v[i];
        pts[i].y = (int32_t)-v[i];
        t[i].v[0] = (uint32_t)v[i];
        t[i].v[1] = (uint32_t)v[i] + 2147483648u;
        t[i].v[2] = UINT32_MAX - (uint32_t)i;
    }
    char *want = malloc(1 << 15), *want_t = malloc(1 << 15);
    size_t o = 0, ot = 0;
    for (int i = 0; i < nv; i++) {
        o += (size_t)snprintf(want + o, (1 << 15) - o, "%d %d\n", pts[i].x, pts[i].y);
        ot += (size_t)snprintf(want_t + ot, (1 << 15) - ot, "%u %u %u\n", t[i].v[0], t[i].v[1],
                               t[i].v[2]);
    }
    pdt_err err;
    pdt_err_clear(&err);
    CHECK(pdt_write_points(path("d.txt"), pts, (size_t)nv, &err) == PDT_OK);
    CHECK(pdt_write_tris(path("d.tri"), PDT_FMT_TRI, pts, (size_t)nv, t, (size_t)nv, &err) ==
          PDT_OK);
    char *got = slurp(path("d.txt")), *got_t = slurp(path("d.tri"));
    CHECK(got && strcmp(got, want) == 0);
    CHECK(got_t && strcmp(got_t, want_t) == 0);
    free(got);
    free(got_t);
    free(want);
    free(want_t);
}

TEST(tris_write_formats)
{
    clean();
    pdt_point pts[4] = { { 0, 0 }, { 10, 0 }, { 0, 10 }, { 10, 10 } };
    pdt_tri t[2] = { { { 0, 1, 3 } }, { { 0, 3, 2 } } };
    pdt_err err;
    pdt_err_clear(&err);
    CHECK(pdt_tri_format_of("x.tri") == PDT_FMT_TRI && pdt_tri_format_of(NULL) == PDT_FMT_TRI &&
          pdt_tri_format_of("x.ele") == PDT_FMT_ELE && pdt_tri_format_of("a/x.off") == PDT_FMT_OFF);
    CHECK(pdt_write_tris(path("t.tri"), PDT_FMT_TRI, pts, 4, t, 2, &err) == PDT_OK);
    char *s = slurp(path("t.tri"));
    CHECK(s && strcmp(s, "0 1 3\n0 3 2\n") == 0);
    free(s);
    CHECK(pdt_write_tris(path("t.off"), PDT_FMT_OFF, pts, 4, t, 2, &err) == PDT_OK);
    s = slurp(path("t.off"));
    CHECK(s && strcmp(s, "OFF\n4 2 0\n0 0 0\n10 0 0\n0 10 0\n10 10 0\n3 0 1 3\n3 0 3 2\n") == 0);
    free(s);
    CHECK(pdt_write_tris(path("t.ele"), PDT_FMT_ELE, pts, 4, t, 2, &err) == PDT_OK);
    s = slurp(path("t.ele"));
    CHECK(s && strstr(s, "2 3 0\n0 0 1 3\n1 0 3 2\n") != NULL);
    free(s);
    /* Both read back. */
    pdt_point *p;
    size_t n;
    CHECK(pdt_read_points(path("t.node"), 0, &p, &n, NULL, &err) == PDT_OK && n == 4 &&
          memcmp(p, pts, sizeof pts) == 0);
    free(p);
    pdt_tri *r;
    size_t nr;
    CHECK(pdt_read_tris(path("t.ele"), &r, &nr, &err) == PDT_OK && nr == 2 &&
          memcmp(r, t, sizeof t) == 0);
    free(r);
    CHECK(pdt_read_tris(path("t.tri"), &r, &nr, &err) == PDT_OK && nr == 2 &&
          memcmp(r, t, sizeof t) == 0);
    free(r);
    CHECK(entries() == 4); /* t.tri t.off t.ele t.node */
    pdt_err_clear(&err);
    CHECK(pdt_write_tris("-", PDT_FMT_ELE, pts, 4, t, 2, &err) == PDT_ERR_ARG);
}

/* The printer's eight-digits-at-once path (below 10^8) and the loop above
 * it, against printf: every value below 2*10^6 (every length up to 7
 * digits), each power of ten and its neighbours up to 2^32 - 1, and a
 * million pseudo-random values of every magnitude. */
TEST(format_lines_every_length)
{
    enum { K = 4096 };
    pdt_tri *t = malloc(K * sizeof *t);
    char *buf = malloc((size_t)K * PDT_LINE_MAX), *want = malloc((size_t)K * 40);
    CHECK(t && buf && want);
    if (!t || !buf || !want) return;
    uint64_t seed = 88172645463325252ull, bad = 0, done = 0;
    for (int phase = 0; phase < 3; phase++) {
        size_t rounds = phase == 0 ? 2000000 / (3 * K) + 1 : phase == 1 ? 1 : 1000000 / (3 * K) + 1;
        for (size_t r = 0; r < rounds; r++) {
            for (int i = 0; i < K; i++)
                for (int c = 0; c < 3; c++) {
                    uint32_t v;
                    if (phase == 0) {
                        v = (uint32_t)((r * K + (size_t)i) * 3 + (size_t)c);
                    } else if (phase == 1) {
                        uint64_t p10 = 1;
                        int k = (i * 3 + c) % 33; /* 10^0 .. 10^10, each with -1, +0, +1 */
                        for (int e = 0; e < k / 3; e++) p10 *= 10;
                        uint64_t w = p10 + (uint64_t)(k % 3) - 1;
                        v = w > UINT32_MAX ? UINT32_MAX - (uint32_t)(k % 3) : (uint32_t)w;
                    } else {
                        seed ^= seed << 13, seed ^= seed >> 7, seed ^= seed << 17;
                        v = (uint32_t)(seed >> (seed & 31)); /* every magnitude */
                    }
                    t[i].v[c] = v;
                }
            size_t n = pdt_format_lines(buf, PDT_LINES_TRI, t, K, 0), m = 0;
            for (int i = 0; i < K; i++)
                m += (size_t)sprintf(want + m, "%u %u %u\n", t[i].v[0], t[i].v[1], t[i].v[2]);
            bad += n != m || memcmp(buf, want, n) != 0;
            CHECK(pdt_lines_bytes(PDT_LINES_TRI, t, K, 0) == m);
            done++;
        }
    }
    CHECK_MSG(bad == 0, "%llu of %llu blocks printed wrong", (unsigned long long)bad,
              (unsigned long long)done);
    free(t);
    free(buf);
    free(want);
}

/* pdt_write_tris_releasing writes pdt_write_tris's bytes, with one thread
 * and several, chunks of every size, and .ele; and it does give the array's
 * memory back: whole 2 MiB pages inside it read as zeros afterwards, while
 * the bytes around them (a page the array shares with others) are kept. */
TEST(tris_write_releasing)
{
    clean();
    const size_t nt = 1000003; /* 12 MB: several 2 MiB pages, not a whole number of them */
    pdt_tri *ref = malloc(nt * sizeof *ref);
    pdt_point pts[3] = { { 0, 0 }, { 1, 0 }, { 0, 1 } };
    CHECK(ref != NULL);
    if (!ref) return;
    for (size_t i = 0; i < nt; i++)
        ref[i] = (pdt_tri){ { (uint32_t)i, (uint32_t)(i * 7 + 1), (uint32_t)(nt - i) } };
    pdt_err err;
    pdt_err_clear(&err);
    CHECK(pdt_write_tris(path("ref.tri"), PDT_FMT_TRI, pts, 3, ref, nt, &err) == PDT_OK);
    CHECK(pdt_write_tris(path("ref.ele"), PDT_FMT_ELE, pts, 3, ref, nt, &err) == PDT_OK);
    char *want = slurp(path("ref.tri")), *want_ele = slurp(path("ref.ele"));
    static const char *threads[] = { "1", "2", "3" }, *chunks[] = { "", "1000", "77777" };
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            setenv("PDT_WRITE_THREADS", threads[a], 1);
            setenv("PDT_TEST_WRITE_CHUNK", chunks[b], 1);
            for (int ele = 0; ele < 2; ele++) {
                /* the array inside a larger block: the bytes just before and
                 * after it must survive */
                unsigned char *blk = malloc(nt * sizeof(pdt_tri) + 2 * 4096);
                CHECK(blk != NULL);
                if (!blk) continue;
                memset(blk, 0xA5, 4096);
                memset(blk + 4096 + nt * sizeof(pdt_tri), 0x5A, 4096);
                pdt_tri *t = (pdt_tri *)(void *)(blk + 4096);
                memcpy(t, ref, nt * sizeof *t);
                const char *name = ele ? "rel.ele" : "rel.tri";
                CHECK(pdt_write_tris_releasing(path(name), ele ? PDT_FMT_ELE : PDT_FMT_TRI, pts, 3,
                                               t, nt, &err) == PDT_OK);
                char *got = slurp(path(name));
                CHECK_MSG(got && strcmp(got, ele ? want_ele : want) == 0,
                          "threads %s, chunks '%s', %s: bytes differ", threads[a], chunks[b], name);
                free(got);
                size_t zero = 0;
                for (size_t i = 0; i < nt; i++)
                    zero += t[i].v[0] == 0 && t[i].v[1] == 0 && t[i].v[2] == 0;
                CHECK_MSG(zero >= nt / 2, "threads %s: only %zu of %zu triangles given back",
                          threads[a], zero, nt);
                size_t kept = 0;
                for (int i = 0; i < 4096; i++)
                    kept += blk[i] == 0xA5 && blk[4096 + nt * sizeof(pdt_tri) + (size_t)i] == 0x5A;
                CHECK(kept == 4096);
                free(blk);
            }
        }
    unsetenv("PDT_WRITE_THREADS");
    unsetenv("PDT_TEST_WRITE_CHUNK");
    free(want);
    free(want_ele);
    free(ref);
}

/* Expect reading triangles `text` as `name` (with npts points) to fail with msg. */
static int badtri(const char *name, const char *text, size_t npts, const char *msg)
{
    put(name, text);
    pdt_tri *t = NULL;
    size_t n = 5;
    pdt_err err;
    pdt_err_clear(&err);
    pdt_status st = pdt_read_tris_n(path(name), npts, &t, &n, &err);
    char want[512];
    snprintf(want, sizeof want, "%s:%s", path(name), msg);
    int ok = st == PDT_ERR_PARSE && strcmp(err.msg, want) == 0 && !t && n == 0;
    if (!ok) printf("#   want [%s]\n#   got  [%s]\n", want, err.msg);
    return ok;
}

TEST(tris_read_bad_inputs)
{
    CHECK(badtri("b.tri", "0 1 2\n0 1\n", 10, "2: missing point index"));
    CHECK(badtri("b.tri", "0 1 x\n", 10, "1: point index 'x' is not a whole number"));
    CHECK(badtri("b.tri", "0 1 -2\n", 10, "1: point index -2 is out of range"));
    CHECK(badtri("b.tri", "0 1 2 3\n", 10,
                 "1: unexpected '3' after the three point indices (one triangle 'i j k' per line)"));
    CHECK(badtri("b.tri", "# c\n0 1 2\n0 1 12\n", 10, "3: point index 12 out of range (10 points)"));
    CHECK(badtri("b.ele", "1 6 0\n", 10, "1: .ele header says 6 points per triangle; only 3 is supported"));
    CHECK(badtri("b.ele", "2 3 0\n1 1 2 3\n", 10,
                 "2: file ends after 1 of the 2 triangles the header announces"));
    CHECK(badtri("b.ele", "1 3 0\n1 0 2 3\n", 10, "2: point index 0 is below the first index 1"));
    CHECK(badtri("b.ele", "1 3 0\n0 0 1 2\n1 0 1 2\n", 10,
                 "3: more triangles than the 1 the header announces"));
    /* 1-based .ele: indices shift down by one. */
    put("g.ele", "1 3 1\n1 1 2 3 0.5\n");
    pdt_tri *t;
    size_t n;
    pdt_err err;
    pdt_err_clear(&err);
    CHECK(pdt_read_tris_n(path("g.ele"), 3, &t, &n, &err) == PDT_OK && n == 1 && t[0].v[0] == 0 &&
          t[0].v[2] == 2);
    free(t);
}

TEST(atomic_write_leaves_nothing)
{
    clean();
    pdt_err err;
    pdt_outfile o;
    /* Abort: neither the target nor a temporary remains. */
    pdt_err_clear(&err);
    CHECK(pdt_out_open(&o, path("x.tri"), &err) == PDT_OK);
    fputs("0 1 2\n", o.fp);
    CHECK(entries() == 1); /* the temporary */
    pdt_out_abort(&o);
    CHECK(entries() == 0);
    /* An existing file is untouched by an aborted write and replaced by a committed one. */
    put("keep.tri", "old\n");
    CHECK(pdt_out_open(&o, path("keep.tri"), &err) == PDT_OK);
    fputs("new\n", o.fp);
    char *s = slurp(path("keep.tri"));
    CHECK(s && strcmp(s, "old\n") == 0);
    free(s);
    pdt_out_abort(&o);
    s = slurp(path("keep.tri"));
    CHECK(s && strcmp(s, "old\n") == 0);
    free(s);
    CHECK(pdt_out_open(&o, path("keep.tri"), &err) == PDT_OK);
    fputs("new\n", o.fp);
    CHECK(pdt_out_commit(&o, &err) == PDT_OK);
    s = slurp(path("keep.tri"));
    CHECK(s && strcmp(s, "new\n") == 0);
    free(s);
    CHECK(entries() == 1);
    /* A target in a missing directory, or a directory: an error, nothing made. */
    pdt_err_clear(&err);
    CHECK(pdt_out_open(&o, path("nodir/x.tri"), &err) == PDT_ERR_IO);
    CHECK_MSG(strstr(err.msg, "nodir/x.tri: cannot create: No such file or directory") != NULL,
              "%s", err.msg);
    pdt_err_clear(&err);
    CHECK(pdt_out_open(&o, dir, &err) == PDT_ERR_IO && strstr(err.msg, "is a directory"));
    CHECK(entries() == 1);
    /* A write error (the device is full) at commit: an error. */
    if (access("/dev/full", W_OK) == 0) {
        pdt_err_clear(&err);
        CHECK(pdt_out_open(&o, "/dev/full", &err) == PDT_OK);
        if (o.fp) {
            fputs("0 1 2\n", o.fp);
            CHECK(pdt_out_commit(&o, &err) == PDT_ERR_IO);
            CHECK_MSG(strstr(err.msg, "/dev/full: write error") != NULL, "%s", err.msg);
        }
    }
}

/* pdt_replace_file: the new bytes under the target's name, the temporary's
 * name gone, an existing target replaced (by an exchange), a missing one
 * created, and a symbolic link replaced itself, as rename(2) does. */
static void put_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static int file_is(const char *path, const char *text)
{
    char got[64] = "";
    FILE *f = fopen(path, "rb");
    size_t n = f ? fread(got, 1, sizeof got - 1, f) : 0;
    if (f) fclose(f);
    return f && n == strlen(text) && memcmp(got, text, n) == 0;
}

TEST(replace_file_exchanges_names)
{
    char rdir[] = "/tmp/pdt-replace-XXXXXX";
    CHECK(mkdtemp(rdir) != NULL);
    char tmp[128], dst[128], other[128];
    snprintf(tmp, sizeof tmp, "%s/.out.tmp", rdir);
    snprintf(dst, sizeof dst, "%s/out.tri", rdir);
    snprintf(other, sizeof other, "%s/other", rdir);
    put_text(tmp, "first\n");
    CHECK(pdt_replace_file(tmp, dst) == 0); /* no target yet */
    CHECK(file_is(dst, "first\n") && access(tmp, F_OK) != 0);
    put_text(tmp, "second, longer\n");
    CHECK(pdt_replace_file(tmp, dst) == 0); /* over an existing file */
    CHECK(file_is(dst, "second, longer\n"));
    CHECK_MSG(access(tmp, F_OK) != 0, "the old file is left under the temporary's name");
    put_text(other, "kept\n");
    unlink(dst);
    CHECK(symlink(other, dst) == 0);
    put_text(tmp, "third\n");
    CHECK(pdt_replace_file(tmp, dst) == 0); /* the link itself is replaced */
    struct stat sb;
    CHECK(lstat(dst, &sb) == 0 && S_ISREG(sb.st_mode));
    CHECK(file_is(dst, "third\n") && file_is(other, "kept\n"));
    CHECK(pdt_replace_file(tmp, dst) != 0); /* no temporary: an error, target kept */
    CHECK(file_is(dst, "third\n"));
    unlink(dst);
    unlink(other);
    rmdir(rdir);
}

TEST(devices_are_written_not_replaced)
{
    pdt_err err;
    pdt_point pts[1] = { { 1, 2 } };
    pdt_err_clear(&err);
    CHECK(pdt_write_points("/dev/null", pts, 1, &err) == PDT_OK);
    struct stat sb;
    CHECK(stat("/dev/null", &sb) == 0 && S_ISCHR(sb.st_mode));
}

/* The text reader's one-pass path for plain "x y" lines and its general
 * tokenizer agree: every line read as it is (the one-pass path when it
 * applies) and with a trailing comment (always the general path) gives the
 * same point or the same message. */
TEST(text_fast_path_same_as_general)
{
    static const char *num[] = {"0", "-0", "+5", "12", "007", "2147483647", "2147483648",
                                "-2147483648", "-2147483649", "0000000001", "00000000001",
                                "99999999999", "1.5", "-", "+", "x", "12x", ""};
    static const char *sep[] = {" ", ",", ";", "\t", " , ", ",,", "", " ;\t"};
    int n_num = (int)(sizeof num / sizeof *num), n_sep = (int)(sizeof sep / sizeof *sep);
    int bad = 0;
    for (int a = 0; a < n_num; a++)
        for (int b = 0; b < n_num; b++)
            for (int k = 0; k < n_sep; k++) {
                char t1[128], t2[128];
                snprintf(t1, sizeof t1, "1 1\n%s%s%s\n2 2", num[a], sep[k], num[b]);
                snprintf(t2, sizeof t2, "1 1\n%s%s%s #\n2 2", num[a], sep[k], num[b]);
                pdt_point *p1 = NULL, *p2 = NULL;
                size_t n1 = 0, n2 = 0;
                pdt_err e1, e2;
                pdt_status s1 = rd("f1.txt", t1, 0, &p1, &n1, NULL, &e1);
                pdt_status s2 = rd("f1.txt", t2, 0, &p2, &n2, NULL, &e2);
                int same = s1 == s2 && n1 == n2 && strcmp(e1.msg, e2.msg) == 0;
                for (size_t i = 0; same && i < n1; i++)
                    same = p1[i].x == p2[i].x && p1[i].y == p2[i].y;
                if (!same && bad++ < 5)
                    printf("#   '%s': status %d '%s' vs %d '%s'\n", t1, (int)s1, e1.msg, (int)s2,
                           e2.msg);
                free(p1);
                free(p2);
            }
    CHECK(bad == 0);
}

/* Numbers of every length from 1 to 10 digits (leading zeros too), signed
 * or not, with every separator, each line read as strtoll reads it: the
 * branch-free digit reader (8 bytes at a time, up to 7 digits) and the
 * byte loop (longer numbers, and the text's last bytes) agree with it
 * wherever a number starts and ends. */
TEST(text_numbers_every_length)
{
    enum { LINES = 4000 };
    static const char *sep[] = {" ", ",", ";", "\t", " , ", "  "};
    char *text = malloc(LINES * 40 + 1);
    int32_t (*want)[2] = malloc(LINES * sizeof *want);
    uint64_t s = 12345;
    size_t o = 0;
    for (int i = 0; i < LINES; i++) {
        char num[2][24];
        for (int k = 0; k < 2; k++) {
            s = s * 6364136223846793005u + 1442695040888963407u;
            int digits = 1 + (int)((s >> 33) % 10), sign = (int)((s >> 45) % 3);
            char *q = num[k];
            if (sign == 1) *q++ = '-';
            if (sign == 2) *q++ = '+';
            uint64_t t = s;
            for (int d = 0; d < digits; d++) {
                t = t * 6364136223846793005u + 1442695040888963407u;
                *q++ = (char)('0' + (t >> 40) % 10);
            }
            *q = 0;
            long long v = strtoll(num[k], NULL, 10);
            if (v > INT32_MAX || v < INT32_MIN) { /* keep it in range: drop the first digit */
                memmove(num[k] + (sign != 0), num[k] + (sign != 0) + 1, strlen(num[k]));
                v = strtoll(num[k], NULL, 10);
            }
            want[i][k] = (int32_t)v;
        }
        o += (size_t)sprintf(text + o, "%s%s%s\n", num[0], sep[i % 6], num[1]);
    }
    text[o - 1] = 0; /* the last line without its newline */
    pdt_point *p = NULL;
    size_t n = 0;
    pdt_err e;
    CHECK(rd("len.txt", text, 0, &p, &n, NULL, &e) == PDT_OK);
    CHECK_MSG(n == LINES, "%zu points: %s", n, e.msg);
    int bad = 0;
    for (size_t i = 0; i < n && i < LINES; i++)
        if (p[i].x != want[i][0] || p[i].y != want[i][1]) {
            if (bad++ < 5)
                printf("#   line %zu: read %d %d, want %d %d\n", i + 1, p[i].x, p[i].y, want[i][0],
                       want[i][1]);
        }
    CHECK(bad == 0);
    free(p);
    free(want);
    free(text);
}

/* A thread faulting the point array in ahead of the parser
 * (PDT_READ_PREFAULT; arrays of 8 MiB or more, so 1.1 M points here) gives
 * the same points, the same count and the same message for a bad last line. */
TEST(read_prefault_same_points)
{
    enum { N = 1100000 };
    char *text = malloc((size_t)N * 16 + 32);
    size_t o = 0;
    uint64_t s = 99;
    for (int i = 0; i < N; i++) {
        s = s * 6364136223846793005u + 1442695040888963407u;
        o += (size_t)sprintf(text + o, "%u %d\n", (unsigned)(s >> 44), -(int)((s >> 20) & 0xfffff));
    }
    text[o] = 0;
    pdt_point *a = NULL, *b = NULL;
    size_t na = 0, nb = 0;
    pdt_err ea, eb;
    CHECK(rd("pf.txt", text, 0, &a, &na, NULL, &ea) == PDT_OK);
    pdt_err_clear(&eb);
    CHECK(pdt_read_points_ex(path("pf.txt"), 0, PDT_READ_PREFAULT, &b, &nb, NULL, &eb) == PDT_OK);
    CHECK(na == N && nb == N && a && b && memcmp(a, b, (size_t)N * sizeof *a) == 0);
    free(a);
    free(b);
    strcpy(text + o, "1 x\n");
    a = b = NULL;
    pdt_status sa = rd("pf.txt", text, 0, &a, &na, NULL, &ea);
    pdt_err_clear(&eb);
    pdt_status sb = pdt_read_points_ex(path("pf.txt"), 0, PDT_READ_PREFAULT, &b, &nb, NULL, &eb);
    CHECK_MSG(sa == PDT_ERR_PARSE && sb == sa && strcmp(ea.msg, eb.msg) == 0, "'%s' / '%s'",
              ea.msg, eb.msg);
    CHECK(strstr(eb.msg, ":1100001:") != NULL);
    free(a);
    free(b);
    free(text);
}

int main(void)
{
    snprintf(dir, sizeof dir, "%s/pdt-io.XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    RUN(text_basic);
    RUN(empty_file_is_zero_points);
    RUN(text_bad_inputs);
    RUN(text_csv);
    RUN(file_errors);
    RUN(not_regular_files_refused);
    RUN(head_read_endless_line_refused);
    RUN(node_format);
    RUN(scale_rounding);
    RUN(scale_collisions);
    RUN(points_write_roundtrip);
    RUN(numbers_every_digit_count);
    RUN(text_fast_path_same_as_general);
    RUN(text_numbers_every_length);
    RUN(read_prefault_same_points);
    RUN(tris_write_formats);
    RUN(tris_write_releasing);
    RUN(format_lines_every_length);
    RUN(tris_read_bad_inputs);
    RUN(atomic_write_leaves_nothing);
    RUN(large_file_mapped_exact_pages);
    RUN(devices_are_written_not_replaced);
    RUN(replace_file_exchanges_names);
    clean();
    rmdir(dir);
    return test_summary();
}
