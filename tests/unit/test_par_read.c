/* Unit tests of pdt_par_read on regular files: every rank parses its own
 * part, and for every P (1..8, ranks as threads of the local backend) the
 * points, their order, the collision count and the failure (one message,
 * naming the first bad line, at one rank) are those of pdt_read_points on
 * the whole file.  Fixed cases (CSV header, TSV, CRLF, comments, byte-order
 * mark, files shorter than P lines, .node with attributes and markers and
 * every .node count/index error) and random files of good and bad lines. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../harness.h"
#include "pdt/io.h"
#include "pdt/par.h"

enum { MAXP = 8 };

/* What one rank got. */
typedef struct rank_out {
    pdt_status st;
    pdt_err err;
    pdt_par_input in;
} rank_out;

typedef struct job {
    const char *path;
    double scale;
    rank_out out[MAXP];
} job;

static pdt_status rank_read(pdt_comm *c, void *arg, pdt_err *err)
{
    job *j = arg;
    rank_out *o = &j->out[pdt_comm_rank(c)];
    pdt_err_clear(&o->err);
    o->st = pdt_par_read(c, j->path, j->scale, 0, &o->in, &o->err);
    (void)err;
    return PDT_OK; /* each rank's result is checked by the test */
}

static char file[64] = "";

static void put(const char *text, size_t len)
{
    FILE *f = fopen(file, "wb");
    if (!f) return;
    fwrite(text, 1, len, f);
    fclose(f);
}

/* Read `text` (saved under the name ending in ext) whole and with P = 1..8;
 * every P must give the plain result.  Returns the number of failed Ps. */
static int same_as_plain(const char *ext, const char *text, size_t len, double scale,
                         const char *label)
{
    static int k;
    snprintf(file, sizeof file, "/tmp/pdt-par-read-%ld-%d%s", (long)getpid(), k++, ext);
    put(text, len);
    pdt_point *pts = NULL;
    size_t n = 0, coll = 0;
    pdt_err perr;
    pdt_err_clear(&perr);
    pdt_status pst = pdt_read_points(file, scale, &pts, &n, &coll, &perr);
    int bad = 0;
    for (int P = 1; P <= MAXP; P++) {
        job *j = calloc(1, sizeof *j);
        j->path = file;
        j->scale = scale;
        pdt_err err;
        pdt_err_clear(&err);
        pdt_status s = pdt_comm_local_run(P, rank_read, j, &err);
        int ok = s == PDT_OK;
        uint64_t next = 0;
        int reporters = 0;
        for (int q = 0; q < P && ok; q++) {
            rank_out *o = &j->out[q];
            if (o->st != pst) ok = 0;
            if (pst != PDT_OK) {
                if (o->err.msg[0]) {
                    reporters++;
                    if (strcmp(o->err.msg, perr.msg) != 0) {
                        printf("#   %s P=%d rank %d: '%s', plain '%s'\n", label, P, q, o->err.msg,
                               perr.msg);
                        ok = 0;
                    }
                }
                continue;
            }
            if (o->in.first != next || o->in.n_total != n || o->in.collisions != coll) ok = 0;
            for (size_t i = 0; i < o->in.n && ok; i++)
                if (next + i >= n || o->in.pts[i].x != pts[next + i].x ||
                    o->in.pts[i].y != pts[next + i].y)
                    ok = 0;
            next += o->in.n;
        }
        if (ok && pst == PDT_OK && next != n) ok = 0;
        if (ok && pst != PDT_OK && reporters != 1) ok = 0;
        if (!ok) {
            bad++;
            printf("#   %s: P=%d differs from the plain read (%s; plain st %d '%s')\n", label, P,
                   err.msg, (int)pst, perr.msg);
        }
        for (int q = 0; q < P; q++) pdt_par_input_free(&j->out[q].in);
        free(j);
    }
    free(pts);
    unlink(file);
    return bad;
}

#define SAME(ext, text, scale) CHECK(same_as_plain(ext, text, strlen(text), scale, #text) == 0)

TEST(text_files)
{
    SAME(".txt", "0 0\n10 0\n0 10\n10 10\n5 5\n3 7\n", 0);
    SAME(".txt", "x,y\n0,0\n10,0\n0,10\n10,10\n5,5\n", 0);
    SAME(".csv", "\"x\";\"y\"\r\n0;0\r\n10;0\r\n0;10\r\n", 0);
    SAME(".tsv", "x\ty\n0\t0\n10\t0\n0\t10\n", 0);
    SAME(".txt", "\xEF\xBB\xBFx y\n1 2\n3 4\n", 0);
    SAME(".txt", "\xEF\xBB\xBF" "1 2\n3 4\n", 0);
    SAME(".txt", "# only comments\n\n   \n# and blanks\n", 0);
    SAME(".txt", "# a comment first\n\nx,y\n1,2\n", 0);
    SAME(".txt", "1 2", 0);                       /* one line, no '\n' */
    SAME(".txt", "1 2\n3 4", 0);                  /* fewer lines than ranks */
    SAME(".txt", "1 2\n1 2\n1 2\n1 2\n1 2\n3 4\n1 2\n", 0); /* duplicates everywhere */
    SAME(".txt", "1 2 # one\n  3   4  \n\n#\n5 6\n", 0);
    SAME(".txt", "1.5 2\n1.50 2\n1.49 2\n3 4e0\n", 2); /* --scale collisions across parts */
    SAME(".txt", "0.1 0.2\n0.10 0.20\n0.1 0.2\n1 1\n0.100 0.2\n", 10);
}

TEST(text_errors)
{
    SAME(".txt", "1 2\n3 4\n5 x\n7 8\n9 10\n11 12\n", 0);
    SAME(".txt", "1 2\n3 4\n5 6\n7 8\n9 10\n11\n", 0);    /* bad last line */
    SAME(".txt", "1 2\n3 4\n5 6\n7 8\n9 10\n11", 0);      /* ... without '\n' */
    SAME(".txt", "1 2\n3 4 5\n5 6\n7 8\n9 y\nz 12\n", 0); /* several: the first wins */
    SAME(".txt", "x,y\n1,2\nx,y\n", 0);                    /* a second header is bad */
    SAME(".txt", "1 2\n1.5 2\n", 0);
    SAME(".txt", "1 2\n3 99999999999\n", 0);
    SAME(".txt", "1 2\n3 4\n5 6\n7 8\n9 1e999999\n", 1);
    SAME(".txt", "x,y,z\n1,2\n", 0);
}

TEST(node_files)
{
    SAME(".node", "4 2 0 0\n0 0 0\n1 10 0\n2 0 10\n3 10 10\n", 0);
    SAME(".node", "# c\n\n4 2 1 1\n1 0 0 0.5 1\n2 10 0 0.5 0\n3 0 10 1 1\n4 10 10 2 0\n", 0);
    SAME(".node", "3 2\n0 0 0\n1 1 0\n2 0 1\n# end\n\n", 0);
    SAME(".node", "0 2 0 0\n", 0);
    SAME(".node", "# nothing\n", 0);
}

TEST(node_errors)
{
    SAME(".node", "5 2 0 0\n0 0 0\n1 10 0\n2 0 10\n3 10 10\n", 0);      /* file ends */
    SAME(".node", "5 2 0 0\n0 0 0\n1 10 0\n2 0 10\n3 10 10\n# x\n", 0);
    SAME(".node", "3 2 0 0\n0 0 0\n1 10 0\n2 0 10\n3 10 10\n4 4 4\n", 0); /* more points */
    SAME(".node", "3 2 0 0\n0 0 0\n1 10 0\n2 0 10\nfoo\n4 4 4\n", 0);   /* more, garbage */
    SAME(".node", "2 2 0 0\n0 0 0\n1 10 0\nbar\n", 0);
    SAME(".node", "0 2 0 0\nbaz\n", 0);
    SAME(".node", "4 2 0 0\n2 0 0\n3 10 0\n4 0 10\n5 10 10\n", 0);    /* first index */
    SAME(".node", "4 2 0 0\n2 0 x\n3 10 0\n4 0 10\n5 10 10\n", 0);
    SAME(".node", "4 2 0 0\n0 0 0\n1 10 0\n3 0 10\n4 10 10\n", 0);    /* order, mid */
    SAME(".node", "4 2 0 0\n0 0 0\n1 10 0\n2 0 10\n4 10 10\n", 0);    /* order, last */
    SAME(".node", "4 2 0 0\n0 0 0\n1 10 0\n2 0 10\n3 10\n", 0);
    SAME(".node", "4 3 0 0\n0 0 0\n", 0);
    SAME(".node", "4 2 1 2\n0 0 0\n", 0);
    SAME(".node", "4 2 1 0\n0 0 0 a\n", 0);
}

static uint64_t seed = 0x9e3779b97f4a7c15ull;
static unsigned rnd(unsigned n)
{
    seed ^= seed << 13;
    seed ^= seed >> 7;
    seed ^= seed << 17;
    return (unsigned)(seed % n);
}

static size_t good_line(char *b, unsigned k, int x, int y)
{
    switch (k) {
    case 0: return (size_t)sprintf(b, "%d %d\n", x, y);
    case 1: return (size_t)sprintf(b, "%d,%d\n", x, y);
    case 2: return (size_t)sprintf(b, " %d ; %d # c\n", x, y);
    case 3: return (size_t)sprintf(b, "%d\t%d\r\n", x, y);
    default: return (size_t)sprintf(b, "%d  ,  %d\n", x, y);
    }
}

static size_t bad_line(char *b, unsigned k, int x, int y)
{
    switch (k) {
    case 0: return (size_t)sprintf(b, "%d\n", x);
    case 1: return (size_t)sprintf(b, "%d %d %d\n", x, y, x);
    case 2: return (size_t)sprintf(b, "a %d\n", x);
    case 3: return (size_t)sprintf(b, "%d,,%d\n", x, y);
    default: return (size_t)sprintf(b, "%d.5 %d\n", x, y);
    }
}

/* Parts of 1 MiB or more are mapped, not read: the parts' bytes and their
 * closing zero byte (over the next part's first byte, in a copied page),
 * a file whose size is a multiple of the page size ending without '\n',
 * and a bad line deep in a mapped part, all as the plain read sees them. */
TEST(large_parts_mapped)
{
    size_t cap = (size_t)6 << 20, len = 0;
    char *buf = malloc(cap + 64);
    for (int v = 0; len < cap - 64; v++)
        len += (size_t)sprintf(buf + len, "%d %d\n", v % 100003 - 50000, (int)(((long)v * 7919) % 65521));
    size_t pg = (size_t)sysconf(_SC_PAGESIZE);
    size_t whole = len / pg * pg; /* cut at a page boundary, last line without '\n' */
    while (buf[whole - 1] == '\n' || buf[whole - 1] == ' ') whole--, buf[whole] = '7';
    buf[whole] = '\0';
    while (whole % pg) buf[whole++] = '1';
    buf[whole] = '\0';
    CHECK(same_as_plain(".txt", buf, whole, 0, "large, page multiple") == 0);
    /* the mapped path is the one taken: a part of at least 1 MiB */
    snprintf(file, sizeof file, "/tmp/pdt-par-read-%ld-map.txt", (long)getpid());
    put(buf, whole);
    pdt_points_head h;
    pdt_err err;
    pdt_err_clear(&err);
    CHECK(pdt_points_head_read(file, 0, &h, &err) == PDT_OK);
    for (int q = 0; q < 3; q++) {
        pdt_points_part pt;
        CHECK(pdt_points_part_load(file, &h, q, 3, &pt, &err) == PDT_OK);
        CHECK_MSG(pt.maplen > 0, "part %d of 3 not mapped", q);
        CHECK(pt.buf[pt.hi - pt.lo] == '\0');
        CHECK(memcmp(pt.buf, buf + pt.lo, (size_t)(pt.hi - pt.lo)) == 0);
        pdt_points_part_free(&pt);
    }
    unlink(file);
    memcpy(buf + whole / 2 + 40, "\n12 x3\n", 8); /* a bad line in the middle */
    CHECK(same_as_plain(".txt", buf, whole, 0, "large, bad line") == 0);
    free(buf);
}

/* Random text files: mostly good lines in every spelling, some bad ones. */
TEST(random_text_files)
{
    static const char *other[] = {"# comment\n", "\n", "   \n", "\r\n", "#\n"};
    char *buf = malloc(1 << 16);
    int fails = 0;
    for (int t = 0; t < 60 && fails == 0; t++) {
        size_t len = 0;
        int lines = 1 + (int)rnd(40), with_bad = rnd(3) == 0;
        if (rnd(4) == 0) len += (size_t)sprintf(buf + len, "x,y\n");
        for (int i = 0; i < lines; i++) {
            unsigned k = rnd(10);
            int x = (int)rnd(7), y = (int)rnd(7);
            if (with_bad && rnd(12) == 0)
                len += bad_line(buf + len, rnd(5), x, y);
            else if (k < 3)
                len += (size_t)sprintf(buf + len, "%s", other[rnd(5)]);
            else
                len += good_line(buf + len, rnd(5), x, y);
        }
        if (rnd(3) == 0 && len && buf[len - 1] == '\n') len--;
        buf[len] = '\0';
        char label[32];
        snprintf(label, sizeof label, "random text %d", t);
        fails += same_as_plain(".txt", buf, len, 0, label);
    }
    CHECK(fails == 0);
    free(buf);
}

/* Random .node files: counts a little off now and then, a bad line. */
TEST(random_node_files)
{
    char *buf = malloc(1 << 16);
    int fails = 0;
    for (int t = 0; t < 60 && fails == 0; t++) {
        int pts = (int)rnd(30), nattr = (int)rnd(2), nmark = (int)rnd(2), base = (int)rnd(2);
        int count = pts + (rnd(4) == 0 ? (int)rnd(3) - 1 : 0);
        if (count < 0) count = 0;
        size_t len = (size_t)sprintf(buf, "%s%d 2 %d %d\n", rnd(3) ? "" : "# head\n\n", count,
                                     nattr, nmark);
        for (int i = 0; i < pts; i++) {
            if (rnd(6) == 0) len += (size_t)sprintf(buf + len, rnd(2) ? "# c\n" : "\n");
            int idx = base + i + (rnd(40) == 0 ? 1 : 0);
            len += (size_t)sprintf(buf + len, "%d %d %d", idx, (int)rnd(9), (int)rnd(9));
            for (int a = 0; a < nattr; a++) len += (size_t)sprintf(buf + len, " 0.5");
            if (nmark) len += (size_t)sprintf(buf + len, rnd(40) == 0 ? " m" : " 1");
            len += (size_t)sprintf(buf + len, "\n");
        }
        if (rnd(3) == 0 && len && buf[len - 1] == '\n') len--;
        buf[len] = '\0';
        char label[32];
        snprintf(label, sizeof label, "random node %d", t);
        fails += same_as_plain(".node", buf, len, 0, label);
    }
    CHECK(fails == 0);
    free(buf);
}

int main(void)
{
    RUN(text_files);
    RUN(text_errors);
    RUN(node_files);
    RUN(node_errors);
    RUN(large_parts_mapped);
    RUN(random_text_files);
    RUN(random_node_files);
    return test_summary();
}
