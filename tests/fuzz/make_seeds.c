/* pdt — writes the binary seed inputs of the trace fuzz targets with the
 * real writer (tests/fuzz/corpus/{manifest,trace_rank,trace_run}/w-*).
 * Run by `make fuzz-seeds`; the text seeds are written by hand. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "pdt/hull.h"
#include "pdt/tracefile.h"

static void die(const char *what, const pdt_err *err)
{
    fprintf(stderr, "make_seeds: %s: %s\n", what, err ? err->msg : "");
    exit(1);
}

static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) die(path, NULL);
    fseek(fp, 0, SEEK_END);
    long n = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    unsigned char *b = malloc((size_t)n + 1);
    if (!b || fread(b, 1, (size_t)n, fp) != (size_t)n) die(path, NULL);
    fclose(fp);
    *len = (size_t)n;
    return b;
}

static void put(const char *path, const void *d, size_t n)
{
    FILE *fp = fopen(path, "wb");
    if (!fp || fwrite(d, 1, n, fp) != n || fclose(fp) != 0) die(path, NULL);
}

/* Record `nev` events of mixed kinds on `rank` into dir. */
static void record(const char *dir, int rank, int nranks, size_t nev, int close_it)
{
    pdt_trace_writer *w;
    pdt_err err = {0};
    if (pdt_tw_open(dir, rank, 2, &w, &err) != PDT_OK) die("pdt_tw_open", &err);
    pdt_trace *tr = pdt_tw_hook(w);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    for (size_t i = 0; i < nev; i++) {
        uint32_t p = (uint32_t)(i % 5);
        switch (i % 9) {
        case 0: PDT_TRACE(tr, 1, PDT_EV_PUSH, PDT_STACK_LOWER, p, i % 4 + 1, 0, 0); break;
        case 1: PDT_TRACE(tr, 1, PDT_EV_POP, PDT_STACK_LOWER, p, i % 4, UINT32_MAX, 0); break;
        case 2: PDT_TRACE(tr, 1, PDT_EV_LIFT, 0, p, 0, 0, (int64_t)p * p); break;
        case 3: PDT_TRACE(tr, 1, PDT_EV_TRI_NEW, 0, 0, 1, 2, 0); break;
        case 4: PDT_TRACE(tr, 2, PDT_EV_EDGE_ADD, 0, 1, 3, 0, 0); break;
        case 5: PDT_TRACE(tr, 1, PDT_EV_TRI_FINAL, 0, 1, 3, 2, 0); break;
        case 6:
            if (nranks > 1) PDT_TRACE(tr, 1, rank == 0 ? PDT_EV_SEND : PDT_EV_RECV, 3,
                                      rank == 0 ? 1 : 0, 64, 0, (int64_t)(i / 9));
            break;
        case 7: PDT_TRACE(tr, 1, PDT_EV_DISCARD, 0, 0, 1, 3, -1); break;
        default: PDT_TRACE(tr, 1, PDT_EV_HULL, 0, 4, 0, 0, 0); break;
        }
    }
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_RUN, 0, 0, 0, 0);
    if (close_it) {
        if (pdt_tw_close(w, &err) != PDT_OK) die("pdt_tw_close", &err);
    } else {
        pdt_tw_abort(w);
    }
}

/* The manifest and points.bin of a seed's run folder: command, its line,
 * pts[0..n), nranks ranks (off: their clock offsets), trace level. */
static void write_meta(const char *dir, const char *command, const char *line,
                       const pdt_point *pts, size_t n, int nranks, int level, int64_t *off)
{
    pdt_manifest m = {0};
    m.format_version = PDT_TRACE_FORMAT_MAJOR;
    snprintf(m.program_version, sizeof m.program_version, "%s", PDT_VERSION);
    snprintf(m.command, sizeof m.command, "%s", command);
    m.command_line = (char *)(uintptr_t)line;
    m.input_name = (char *)"in.txt";
    m.input_checksum = pdt_points_checksum(pts, n);
    m.n = n;
    m.nranks = nranks;
    m.level = level;
    m.clock_offset_ns = off;
    m.wall_start_ns = 1700000000000000000ull;
    pdt_err err = {0};
    if (pdt_run_write_meta(dir, &m, pts, n, &err) != PDT_OK) die("meta", &err);
}

static void meta(const char *dir, int nranks)
{
    pdt_point pts[5] = {{0, 0}, {10, 0}, {0, 10}, {7, 7}, {-3, 4}};
    int64_t off[4] = {0, 150, -20, 7};
    write_meta(dir, "triangulate", "pdt triangulate in.txt --trace run\\x", pts, 5, nranks, 2, off);
}

/* A hull run as `pdt hull --trace` records it: Graham's scan of pts[0..n). */
static void record_hull(const char *dir, const pdt_point *pts, size_t n)
{
    pdt_trace_writer *w;
    pdt_err err = {0};
    if (pdt_tw_open(dir, 0, 1, &w, &err) != PDT_OK) die("pdt_tw_open", &err);
    uint32_t out[16];
    size_t nout;
    if (n > 16 || pdt_hull_graham(pts, n, out, &nout, pdt_tw_hook(w)) != PDT_OK) die("hull", NULL);
    if (pdt_tw_close(w, &err) != PDT_OK) die("pdt_tw_close", &err);
    int64_t off = 0;
    write_meta(dir, "hull", "pdt hull in.txt -o in.hull --trace run", pts, n, 1, 1, &off);
}

/* trace_run's input for the one-rank run folder dir: manifest SEP points
 * SEP rank-0000.trace, to out/trace_run/name. */
static void put_run(const char *out, const char *name, const char *dir)
{
    char b[2100];
    const char *sep = "\n==PDT==\n", *parts[3] = {"manifest", "points.bin", "rank-0000.trace"};
    snprintf(b, sizeof b, "%s/trace_run/%s", out, name);
    FILE *fp = fopen(b, "wb");
    if (!fp) die(b, NULL);
    for (int i = 0; i < 3; i++) {
        size_t len;
        snprintf(b, sizeof b, "%s/%s", dir, parts[i]);
        unsigned char *d = slurp(b, &len);
        if ((i && fputs(sep, fp) == EOF) || fwrite(d, 1, len, fp) != len) die(b, NULL);
        free(d);
    }
    if (fclose(fp) != 0) die(name, NULL);
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: make_seeds TMPDIR CORPUSDIR\n");
        return 2;
    }
    const char *tmp = argv[1], *out = argv[2];
    char a[1024], b[1024];
    struct { const char *name; int nranks; size_t nev; int closed; } runs[] = {
        {"w-small", 1, 12, 1}, {"w-empty", 1, 0, 1}, {"w-killed", 1, 30, 0},
        {"w-twoblocks", 1, 5000, 1}, {"w-tworanks", 2, 40, 1},
    };
    for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
        snprintf(a, sizeof a, "%s/%s", tmp, runs[i].name);
        mkdir(a, 0777);
        for (int r = 0; r < runs[i].nranks; r++) record(a, r, runs[i].nranks, runs[i].nev, runs[i].closed);
        meta(a, runs[i].nranks);
        size_t ml, pl, rl;
        snprintf(b, sizeof b, "%s/manifest", a);
        unsigned char *man = slurp(b, &ml);
        snprintf(b, sizeof b, "%s/points.bin", a);
        unsigned char *pts = slurp(b, &pl);
        if (i == 0) {
            snprintf(b, sizeof b, "%s/manifest/w-manifest", out);
            put(b, man, ml);
        }
        /* trace_run: manifest SEP points SEP rank0 [SEP rank1] */
        const char *sep = "\n==PDT==\n";
        size_t cap = ml + pl + 64, n = 0;
        unsigned char *cat = malloc(cap);
        if (!cat) die("malloc", NULL);
        memcpy(cat, man, ml); n = ml;
        memcpy(cat + n, sep, strlen(sep)); n += strlen(sep);
        memcpy(cat + n, pts, pl); n += pl;
        for (int r = 0; r < runs[i].nranks; r++) {
            snprintf(b, sizeof b, "%s/rank-%04d.trace", a, r);
            unsigned char *rk = slurp(b, &rl);
            if (r == 0) {
                snprintf(b, sizeof b, "%s/trace_rank/%s", out, runs[i].name);
                put(b, rk, rl);
            }
            cat = realloc(cat, cap += rl + 16);
            if (!cat) die("realloc", NULL);
            memcpy(cat + n, sep, strlen(sep)); n += strlen(sep);
            memcpy(cat + n, rk, rl); n += rl;
            free(rk);
        }
        if (runs[i].nev < 1000) {  /* keep trace_run inputs small */
            snprintf(b, sizeof b, "%s/trace_run/%s", out, runs[i].name);
            put(b, cat, n);
        }
        free(cat);
        free(man);
        free(pts);
    }
    /* hull runs: Graham's scan of a square with points on its sides, copies of
     * corners and of the origin, a point inside; of points on a line; of
     * copies of one point (trace_run only) */
    static const pdt_point square[] = {{0, 4}, {2, 0}, {4, 4}, {2, 4}, {4, 0}, {2, 2},
                                       {4, 4}, {0, 0}, {4, 0}, {0, 2}, {1, 3}, {3, 1}};
    static const pdt_point line[] = {{3, 3}, {1, 1}, {2, 2}, {3, 3}, {1, 1}, {0, 0}};
    static const pdt_point one[] = {{7, -7}, {7, -7}, {7, -7}};
    struct { const char *name; const pdt_point *pts; size_t n; } hulls[] = {
        {"w-hull-square", square, sizeof square / sizeof *square},
        {"w-hull-line", line, sizeof line / sizeof *line},
        {"w-hull-one", one, sizeof one / sizeof *one},
    };
    for (size_t i = 0; i < sizeof hulls / sizeof hulls[0]; i++) {
        snprintf(a, sizeof a, "%s/%s", tmp, hulls[i].name);
        mkdir(a, 0777);
        record_hull(a, hulls[i].pts, hulls[i].n);
        put_run(out, hulls[i].name, a);
    }
    return 0;
}
