/* pdt_run_check: passes on real traces of every generator family, fails
 * naming the problem on traces altered on purpose (an event removed, a block
 * truncated, a checksum flipped, a triangle made final twice, a lift with the
 * wrong height, a message without its receive). */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../src/trace/tf_internal.h"
#include "../harness.h"
#include "pdt/delaunay.h"
#include "pdt/gen.h"
#include "pdt/hull.h"
#include "pdt/predicates.h"
#include "pdt/tracefile.h"
#include "pdt/par.h"

static char tmpdir[256];
/* memory budget of the checks (tiny_budget_spills makes it tiny) */
static uint64_t budget = PDT_TRACE_MEM_DEFAULT;
/* how the checks recompute T* (strips_tstar_same_verdicts: the cli's way) */
static pdt_tstar_fn tstar = NULL;

static void meta(const char *dir, const char *command, const pdt_point *pts, size_t n, int nranks)
{
    int64_t *off = calloc((size_t)nranks, sizeof *off);
    pdt_manifest m;
    memset(&m, 0, sizeof m);
    m.format_version = PDT_TRACE_FORMAT_MAJOR;
    snprintf(m.command, sizeof m.command, "%s", command);
    m.n = n;
    m.nranks = nranks;
    m.level = 1;
    m.clock_offset_ns = off;
    m.input_checksum = pdt_points_checksum(pts, n);
    pdt_err err = {0};
    CHECK_MSG(pdt_run_write_meta(dir, &m, pts, n, &err) == PDT_OK, "%s", err.msg);
    free(off);
}

/* A traced sequential triangulation, as `pdt triangulate --trace` records it. */
static void record_tri(const char *dir, const pdt_point *pts, size_t n, int level)
{
    pdt_trace_writer *w;
    pdt_err err = {0};
    CHECK(pdt_tw_open(dir, 0, level, &w, &err) == PDT_OK);
    meta(dir, "triangulate", pts, n, 1);
    pdt_trace *tr = pdt_tw_hook(w);
    pdt_tri *t;
    size_t nt;
    CHECK(pdt_triangulate(pts, n, &t, &nt, NULL, tr) == PDT_OK);
    for (size_t i = 0; i < nt; i++)
        PDT_TRACE(tr, 1, PDT_EV_TRI_FINAL, 0, t[i].v[0], t[i].v[1], t[i].v[2], 0);
    free(t);
    CHECK(pdt_tw_close(w, &err) == PDT_OK);
}

/* A traced Graham scan of pts, in a run folder whose points.bin holds
 * `as` instead (pts: a true run). */
static void record_hull_as(const char *dir, const pdt_point *pts, const pdt_point *as, size_t n)
{
    pdt_trace_writer *w;
    pdt_err err = {0};
    CHECK(pdt_tw_open(dir, 0, 1, &w, &err) == PDT_OK);
    meta(dir, "hull", as, n, 1);
    uint32_t *out = malloc((n ? n : 1) * sizeof *out);
    size_t nout;
    CHECK(pdt_hull_graham(pts, n, out, &nout, pdt_tw_hook(w)) == PDT_OK);
    free(out);
    CHECK(pdt_tw_close(w, &err) == PDT_OK);
}

static void record_hull(const char *dir, const pdt_point *pts, size_t n)
{
    record_hull_as(dir, pts, pts, n);
}

/* Run the check; returns its status, the message in msg. */
static pdt_status check_dir(const char *dir, char *msg, size_t cap)
{
    pdt_run *run;
    pdt_err err = {0};
    if (pdt_run_open(dir, &run, &err) != PDT_OK) {
        snprintf(msg, cap, "open: %s", err.msg);
        return err.code;
    }
    char summary[1024];
    pdt_status st = pdt_run_check_tstar(run, budget, tstar, summary, sizeof summary, &err);
    snprintf(msg, cap, "%s", st == PDT_OK ? summary : err.msg);
    pdt_run_close(run);
    return st;
}

/* Copy run `from` to `to`, dropping event `drop` of rank 0 (or none if
 * drop == UINT64_MAX) and applying `edit` to event `at` (if not NULL). */
static void copy_run(const char *from, const char *to, uint64_t drop, uint64_t at,
                     void (*edit)(pdt_event *))
{
    pdt_run *run;
    pdt_err err = {0};
    CHECK(pdt_run_open(from, &run, &err) == PDT_OK);
    if (!run) return;
    pdt_trace_writer *w;
    CHECK(pdt_tw_open(to, 0, 2, &w, &err) == PDT_OK);
    size_t np;
    const pdt_point *pts = pdt_run_points(run, &np);
    meta(to, pdt_run_manifest(run)->command, pts, np, 1);
    const pdt_event *ev;
    size_t n;
    CHECK(pdt_run_rank_events(run, 0, &ev, &n, &err) == PDT_OK);
    pdt_trace *tr = pdt_tw_hook(w);
    for (size_t i = 0; i < n; i++) {
        if (i == drop) continue;
        pdt_event e = ev[i];
        if (i == at && edit) edit(&e);
        tr->sink(tr, &e);
    }
    CHECK(pdt_tw_close(w, &err) == PDT_OK);
    pdt_run_close(run);
}

/* Index of the k-th (0-based) event of `kind` in rank 0 of dir. */
static uint64_t find_kind(const char *dir, int kind, int k)
{
    pdt_run *run;
    pdt_err err = {0};
    uint64_t found = UINT64_MAX;
    if (pdt_run_open(dir, &run, &err) != PDT_OK) return found;
    const pdt_event *ev;
    size_t n;
    pdt_run_rank_events(run, 0, &ev, &n, &err);
    for (size_t i = 0; i < n && found == UINT64_MAX; i++)
        if (ev[i].kind == kind && k-- == 0) found = i;
    pdt_run_close(run);
    return found;
}

static char *sub(const char *name)
{
    static char buf[4][400];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", tmpdir, name);
    return buf[k];
}

TEST(every_family_passes)
{
    const char *const *kinds = pdt_gen_kinds();
    for (int i = 0; kinds[i]; i++) {
        pdt_point *pts;
        size_t n = 300;
        pdt_err err = {0};
        CHECK(pdt_gen(kinds[i], n, 7, &pts, &err) == PDT_OK);
        char name[64], msg[1100];
        snprintf(name, sizeof name, "fam-%s", kinds[i]);
        record_tri(sub(name), pts, n, i % 2 ? 2 : 1);
        pdt_status st = check_dir(sub(name), msg, sizeof msg);
        CHECK_MSG(st == PDT_OK, "triangulate %s: %s", kinds[i], msg);
        snprintf(name, sizeof name, "hull-%s", kinds[i]);
        record_hull(sub(name), pts, n);
        st = check_dir(sub(name), msg, sizeof msg);
        CHECK_MSG(st == PDT_OK, "hull %s: %s", kinds[i], msg);
        free(pts);
    }
    /* tiny and empty inputs */
    pdt_point few[3] = {{0, 0}, {1, 0}, {0, 1}};
    char msg[1100];
    for (size_t n = 0; n <= 3; n++) {
        record_tri(sub("tiny"), few, n, 1);
        CHECK_MSG(check_dir(sub("tiny"), msg, sizeof msg) == PDT_OK, "n=%zu: %s", n, msg);
        record_hull(sub("tinyh"), few, n);
        CHECK_MSG(check_dir(sub("tinyh"), msg, sizeof msg) == PDT_OK, "hull n=%zu: %s", n, msg);
    }
}

static pdt_point *uniform(size_t n)
{
    pdt_point *pts;
    pdt_err err = {0};
    if (pdt_gen("uniform", n, 3, &pts, &err) != PDT_OK) return NULL;
    return pts;
}

static void expect_fail(const char *dir, const char *want)
{
    char msg[1100];
    pdt_status st = check_dir(dir, msg, sizeof msg);
    CHECK_MSG(st == PDT_ERR_CHECK, "%s: status %d: %s", dir, st, msg);
    CHECK_MSG(strstr(msg, want) != NULL, "%s: message '%s' lacks '%s'", dir, msg, want);
}

/* A copy of run `base` without its nth event of `kind` (edit NULL), or with
 * that event changed by edit, fails the check with `want` in the message. */
static void expect_fail_copy(const char *base, const char *name, int kind, int nth,
                             void (*edit)(pdt_event *), const char *want)
{
    uint64_t k = find_kind(sub(base), kind, nth);
    copy_run(sub(base), sub(name), edit ? UINT64_MAX : k, edit ? k : UINT64_MAX, edit);
    expect_fail(sub(name), want);
}

TEST(removed_events_are_named)
{
    pdt_point *pts = uniform(500);
    record_tri(sub("base"), pts, 500, 1);
    record_hull(sub("baseh"), pts, 500);
    char msg[1100];
    CHECK(check_dir(sub("base"), msg, sizeof msg) == PDT_OK);

    /* a copy with nothing removed still passes (the copy itself is sound) */
    copy_run(sub("base"), sub("same"), UINT64_MAX, UINT64_MAX, NULL);
    CHECK_MSG(check_dir(sub("same"), msg, sizeof msg) == PDT_OK, "%s", msg);

    expect_fail_copy("base", "nofinal", PDT_EV_TRI_FINAL, 10, NULL, "was never made final");

    expect_fail_copy("base", "nolift", PDT_EV_LIFT, 17, NULL, "was never lifted");

    expect_fail_copy("base", "nophaseend", PDT_EV_PHASE_END, 1, NULL, "phase lift begun at event #2 never ends");

    expect_fail_copy("baseh", "nopop", PDT_EV_POP, 3, NULL, "rank 0 event #");

    expect_fail_copy("baseh", "nopush", PDT_EV_PUSH, 5, NULL, "depth after push should be");

    /* level 2: the kernel's edges replay to exactly the triangles' edges */
    record_tri(sub("base-l2"), pts, 500, 2);
    CHECK_MSG(check_dir(sub("base-l2"), msg, sizeof msg) == PDT_OK, "%s", msg);
    CHECK_MSG(strstr(msg, "1 kernel runs with edges replayed") != NULL, "%s", msg);
    expect_fail_copy("base-l2", "noedgedel", PDT_EV_EDGE_DEL, 20, NULL, "rank 0 event #");
    expect_fail_copy("base-l2", "noedgeadd", PDT_EV_EDGE_ADD, 30, NULL, "rank 0 event #");

    uint64_t k = find_kind(sub("baseh"), PDT_EV_DELETE, 0);
    if (k != UINT64_MAX) {
        copy_run(sub("baseh"), sub("nodelete"), k, UINT64_MAX, NULL);
        expect_fail(sub("nodelete"), "neither deleted nor pushed");
    }
    free(pts);
}

static void bad_z(pdt_event *e) { e->v += 1; }
static void cw(pdt_event *e)
{
    uint32_t t = e->b;
    e->b = e->c;
    e->c = t;
}

/* Replace a triangle's third point by another point of the run that keeps it
 * counter-clockwise (the first such one): a triangle T* does not have. */
static const pdt_point *edit_pts;
static size_t edit_n;
static void swap_point(pdt_event *e)
{
    for (uint32_t p = 0; p < edit_n; p++)
        if (p != e->a && p != e->b && p != e->c &&
            pdt_orient(edit_pts[e->a], edit_pts[e->b], edit_pts[p]) > 0) {
            e->c = p;
            return;
        }
}

TEST(edited_events_are_named)
{
    pdt_point *pts = uniform(200);
    record_tri(sub("base2"), pts, 200, 1);
    expect_fail_copy("base2", "badz", PDT_EV_LIFT, 3, bad_z, "z should be x*x + y*y");
    expect_fail_copy("base2", "cw", PDT_EV_TRI_FINAL, 4, cw, "not counter-clockwise");
    free(pts);
}

/* Bytes of a run's rank-0 file altered in place. */
static void alter(const char *dir, long truncate_to, long flip_at)
{
    char path[500];
    snprintf(path, sizeof path, "%s/rank-0000.trace", dir);
    if (truncate_to >= 0) CHECK(truncate(path, truncate_to) == 0);
    if (flip_at >= 0) {
        FILE *f = fopen(path, "r+b");
        CHECK(f != NULL);
        if (!f) return;
        fseek(f, flip_at, SEEK_SET);
        int c = fgetc(f);
        fseek(f, flip_at, SEEK_SET);
        fputc(c ^ 1, f);
        fclose(f);
    }
}

TEST(damaged_files_fail)
{
    pdt_point *pts = uniform(3000);  /* several blocks */
    record_tri(sub("dmg1"), pts, 3000, 1);
    alter(sub("dmg1"), 70000, -1);
    expect_fail(sub("dmg1"), "damaged run folder: rank-0000.trace: block 1 at byte");
    record_tri(sub("dmg2"), pts, 3000, 1);
    alter(sub("dmg2"), -1, 5000);
    expect_fail(sub("dmg2"), "rank-0000.trace: block 0 at byte 32: checksum mismatch");
    /* points.bin altered */
    record_tri(sub("dmg3"), pts, 3000, 1);
    char path[500];
    snprintf(path, sizeof path, "%s/points.bin", sub("dmg3"));
    FILE *f = fopen(path, "r+b");
    if (f) {
        fseek(f, 100, SEEK_SET);
        fputc(0x55, f);
        fclose(f);
    }
    expect_fail(sub("dmg3"), "points.bin: checksum mismatch");
    free(pts);
}

/* Synthetic two-rank runs: messages and merge steps. */
static void two_ranks(const char *dir, int with_recv, int with_merge_end, int swap)
{
    /* lexicographic order, or (swap) points 1 and 2 exchanged */
    static const pdt_point lex[3] = {{0, 0}, {0, 4}, {4, 0}}, sw[3] = {{0, 0}, {4, 0}, {0, 4}};
    const pdt_point *pts = swap ? sw : lex;
    pdt_trace_writer *w0, *w1;
    pdt_err err = {0};
    CHECK(pdt_tw_open(dir, 0, 1, &w0, &err) == PDT_OK);
    CHECK(pdt_tw_open(dir, 1, 1, &w1, &err) == PDT_OK);
    pdt_trace *t0 = pdt_tw_hook(w0), *t1 = pdt_tw_hook(w1);
    PDT_TRACE(t0, 1, PDT_EV_LIFT, 0, 0, 0, 0, 0);
    PDT_TRACE(t0, 1, PDT_EV_LIFT, 0, 1, 0, 0, 16);
    PDT_TRACE(t1, 1, PDT_EV_LIFT, 0, 2, 0, 0, 16);
    PDT_TRACE(t0, 1, PDT_EV_SEND, 5, 1, 24, 0, 0);
    if (with_recv) PDT_TRACE(t1, 1, PDT_EV_RECV, 5, 0, 24, 0, 0);
    PDT_TRACE(t1, 1, PDT_EV_MERGE_BEGIN, 0, 0, 1, 2, 1);
    for (uint32_t i = 0; i < 3; i++) PDT_TRACE(t1, 1, PDT_EV_LIFT, 0, i, 0, 0, i ? 16 : 0);
    PDT_TRACE(t1, 1, PDT_EV_TRI_FINAL, 0, 0, swap ? 1 : 2, swap ? 2 : 1, 0);
    if (with_merge_end) PDT_TRACE(t1, 1, PDT_EV_MERGE_END, 0, 0, 3, 1, 0);
    CHECK(pdt_tw_close(w0, &err) == PDT_OK);
    CHECK(pdt_tw_close(w1, &err) == PDT_OK);
    meta(dir, "triangulate", pts, 3, 2);
}

TEST(messages_and_merges)
{
    char msg[1100];
    two_ranks(sub("msg-ok"), 1, 1, 0);
    CHECK_MSG(check_dir(sub("msg-ok"), msg, sizeof msg) == PDT_OK, "%s", msg);
    CHECK_MSG(strstr(msg, "1 merge steps, 1 messages") != NULL, "%s", msg);
    two_ranks(sub("msg-norecv"), 0, 1, 0);
    expect_fail(sub("msg-norecv"), "(send tag=5 to=1 bytes=24 seq=0): no matching recv on rank 1");
    two_ranks(sub("msg-noend"), 1, 0, 0);
    expect_fail(sub("msg-noend"), "never ends");
    /* strips must be consecutive lexicographic blocks: swap two points */
    two_ranks(sub("strips"), 1, 1, 1);
    expect_fail(sub("strips"), "the local lift-ups of rank 1 (1 points) are not a lexicographic "
                               "block after those of rank 0");
}

/* A monotone chain (lower stack 0 1 2, upper stack 2 ... 0) followed by its
 * HULL event: the count must be lower + upper - 2. */
static void chain_run(const char *dir, uint32_t hull_count)
{
    static const pdt_point pts[4] = {{0, 0}, {2, -1}, {4, 0}, {2, 3}};
    pdt_trace_writer *w;
    pdt_err err = {0};
    CHECK(pdt_tw_open(dir, 0, 1, &w, &err) == PDT_OK);
    pdt_trace *t = pdt_tw_hook(w);
    PDT_TRACE(t, 1, PDT_EV_PUSH, PDT_STACK_LOWER, 0, 1, 0, 0);
    PDT_TRACE(t, 1, PDT_EV_PUSH, PDT_STACK_LOWER, 1, 2, 0, 0);
    PDT_TRACE(t, 1, PDT_EV_PUSH, PDT_STACK_LOWER, 2, 3, 0, 0);
    PDT_TRACE(t, 1, PDT_EV_PUSH, PDT_STACK_UPPER, 2, 1, 0, 0);
    PDT_TRACE(t, 1, PDT_EV_PUSH, PDT_STACK_UPPER, 3, 2, 0, 0);
    PDT_TRACE(t, 1, PDT_EV_PUSH, PDT_STACK_UPPER, 0, 3, 0, 0);
    PDT_TRACE(t, 1, PDT_EV_HULL, 0, hull_count, 0, 0, 0);
    CHECK(pdt_tw_close(w, &err) == PDT_OK);
    meta(dir, "chain-test", pts, 4, 1);
}

TEST(chain_hull_counts)
{
    char msg[1100];
    chain_run(sub("chain-ok"), 4);
    CHECK_MSG(check_dir(sub("chain-ok"), msg, sizeof msg) == PDT_OK, "%s", msg);
    CHECK_MSG(strstr(msg, "1 chain hulls") != NULL, "%s", msg);
    chain_run(sub("chain-bad"), 5);
    expect_fail(sub("chain-bad"), "(hull vertices=5): the lower and upper stacks hold 4 hull vertices");
}

/* A traced triangulation of pts whose final triangles are tris[0..nt). */
static void record_tri_finals(const char *dir, const pdt_point *pts, size_t n, const pdt_tri *tris,
                              size_t nt)
{
    pdt_trace_writer *w;
    pdt_err err = {0};
    CHECK(pdt_tw_open(dir, 0, 1, &w, &err) == PDT_OK);
    meta(dir, "triangulate", pts, n, 1);
    pdt_trace *tr = pdt_tw_hook(w);
    pdt_tri *t;
    size_t k;
    CHECK(pdt_triangulate(pts, n, &t, &k, NULL, tr) == PDT_OK);
    free(t);
    for (size_t i = 0; i < nt; i++)
        PDT_TRACE(tr, 1, PDT_EV_TRI_FINAL, 0, tris[i].v[0], tris[i].v[1], tris[i].v[2], 0);
    CHECK(pdt_tw_close(w, &err) == PDT_OK);
}

/* A traced triangulation whose final triangle `dup` is reported a second
 * time at the very end (far from the first: another sorted run). */
static void record_tri_dup(const char *dir, const pdt_point *pts, size_t n, size_t dup)
{
    pdt_tri *t;
    size_t nt;
    CHECK(pdt_triangulate(pts, n, &t, &nt, NULL, NULL) == PDT_OK);
    pdt_tri *with = malloc((nt + 1) * sizeof *with);
    memcpy(with, t, nt * sizeof *with);
    if (dup < nt) with[nt] = (pdt_tri){{t[dup].v[1], t[dup].v[2], t[dup].v[0]}};
    record_tri_finals(dir, pts, n, with, nt + (dup < nt));
    free(with);
    free(t);
}

/* With a budget of a few hundred bytes the final triangles go to disk in
 * sorted runs of 16 (more than 64 runs: merged into one on the way), and T*
 * is certified side by side on disk instead of recomputed: the verdicts are
 * the same as in memory, the reasons given are the certificate's. */
TEST(tiny_budget_spills)
{
    char msg[1100];
    pdt_point *pts = uniform(2000);
    budget = 256;
    edit_pts = pts;
    edit_n = 2000;
    record_tri(sub("tb"), pts, 2000, 1);
    CHECK_MSG(check_dir(sub("tb"), msg, sizeof msg) == PDT_OK, "%s", msg);
    CHECK_MSG(strstr(msg, "= T*") && strstr(msg, "sorted on disk in"), "%s", msg);
    CHECK_MSG(strstr(msg, "certified side by side on disk in"), "%s", msg);
    budget = PDT_TRACE_MEM_DEFAULT;
    CHECK_MSG(check_dir(sub("tb"), msg, sizeof msg) == PDT_OK && !strstr(msg, "on disk"), "%s",
              msg);
    budget = 256;
    /* a triangle missing: a hole, whose boundary turns right */
    expect_fail_copy("tb", "tb-nofinal", PDT_EV_TRI_FINAL, 1000, NULL, "turns right at point");
    record_tri_dup(sub("tb-dup"), pts, 2000, 7);
    expect_fail(sub("tb-dup"), "made final twice");
    expect_fail_copy("tb", "tb-cw", PDT_EV_TRI_FINAL, 3000, cw, "not counter-clockwise");
    /* a foreign triangle in place of a true one */
    expect_fail_copy("tb", "tb-wrong", PDT_EV_TRI_FINAL, 2500, swap_point, "the final triangles");
    budget = PDT_TRACE_MEM_DEFAULT;
    free(pts);
}

/* T* recomputed as the cli does (pdt_par_tstar), on 3 strips forced by
 * PDT_PLAIN_STRIPS (its own default is two strips from 2^21 points on): the
 * same verdicts as the whole kernel's, and the summary says so.  With
 * PDT_PLAIN_STRIPS=0 it runs the whole kernel and says nothing. */
TEST(strips_tstar_same_verdicts)
{
    char msg[1100];
    pdt_point *pts = uniform(2000);
    edit_pts = pts;
    edit_n = 2000;
    tstar = pdt_par_tstar;
    setenv("PDT_PLAIN_STRIPS", "3", 1);
    record_tri(sub("st"), pts, 2000, 1);
    CHECK_MSG(check_dir(sub("st"), msg, sizeof msg) == PDT_OK, "%s", msg);
    CHECK_MSG(strstr(msg, "= T*") && strstr(msg, "(T* recomputed on 3 strips)"), "%s", msg);
    expect_fail_copy("st", "st-nofinal", PDT_EV_TRI_FINAL, 1000, NULL, "was never made final");
    expect_fail_copy("st", "st-wrong", PDT_EV_TRI_FINAL, 2500, swap_point, "is not in T* of the run's points");
    record_tri_dup(sub("st-dup"), pts, 2000, 7);
    expect_fail(sub("st-dup"), "made final twice");
    /* every generator family: degenerate sets on strips too */
    static const char *fam[] = {"grid", "circle", "collinear", "duplicates", "parabola"};
    for (size_t f = 0; f < sizeof fam / sizeof *fam; f++) {
        pdt_point *q;
        pdt_err err = {0};
        if (pdt_gen(fam[f], 700, 5, &q, &err) != PDT_OK) continue;
        record_tri(sub("st-fam"), q, 700, 1);
        CHECK_MSG(check_dir(sub("st-fam"), msg, sizeof msg) == PDT_OK, "%s: %s", fam[f], msg);
        free(q);
    }
    setenv("PDT_PLAIN_STRIPS", "0", 1);
    CHECK_MSG(check_dir(sub("st"), msg, sizeof msg) == PDT_OK && !strstr(msg, "strips"), "%s", msg);
    unsetenv("PDT_PLAIN_STRIPS");
    tstar = NULL;
    free(pts);
}

/* Flip the first side shared by two triangles of t whose quadrilateral is
 * convex: both new triangles counter-clockwise, the side no longer
 * Delaunay.  1 if one was flipped. */
static int flip_one(const pdt_point *p, pdt_tri *t, size_t nt)
{
    for (size_t i = 0; i < nt; i++)
        for (size_t j = i + 1; j < nt; j++)
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++) {
                    uint32_t u = t[i].v[a], w = t[i].v[(a + 1) % 3], c = t[i].v[(a + 2) % 3];
                    if (t[j].v[b] != w || t[j].v[(b + 1) % 3] != u) continue;
                    uint32_t d = t[j].v[(b + 2) % 3];
                    if (pdt_orient(p[u], p[d], p[c]) <= 0 || pdt_orient(p[d], p[w], p[c]) <= 0)
                        continue;
                    t[i] = (pdt_tri){{u, d, c}};
                    t[j] = (pdt_tri){{d, w, c}};
                    return 1;
                }
    return 0;
}

/* T* certified side by side on disk (a budget too small to recompute it):
 * every family passes, degenerate ones included, and each kind of wrong
 * set of final triangles is named by the condition it breaks. */
TEST(certified_tstar)
{
    char msg[1100];
    budget = 256;
    const char *const *kinds = pdt_gen_kinds();
    for (int i = 0; kinds[i]; i++) {
        pdt_point *q;
        pdt_err err = {0};
        CHECK(pdt_gen(kinds[i], 700, 11, &q, &err) == PDT_OK);
        record_tri(sub("ct-fam"), q, 700, 1);
        CHECK_MSG(check_dir(sub("ct-fam"), msg, sizeof msg) == PDT_OK, "%s: %s", kinds[i], msg);
        /* collinear points have no triangles: nothing to certify */
        CHECK_MSG(strstr(msg, "certified") || strstr(msg, " 0 final triangles"), "%s: %s",
                  kinds[i], msg);
        free(q);
    }
    pdt_point few[4] = {{0, 0}, {4, 0}, {0, 4}, {1, 1}};
    for (size_t n = 0; n <= 4; n++) {
        record_tri(sub("ct-tiny"), few, n, 1);
        CHECK_MSG(check_dir(sub("ct-tiny"), msg, sizeof msg) == PDT_OK, "n=%zu: %s", n, msg);
    }

    size_t n = 400;
    pdt_point *pts = uniform(n);
    pdt_tri *t;
    size_t nt;
    CHECK(pdt_triangulate(pts, n, &t, &nt, NULL, NULL) == PDT_OK);
    record_tri_finals(sub("ct-ok"), pts, n, t, nt);
    CHECK_MSG(check_dir(sub("ct-ok"), msg, sizeof msg) == PDT_OK, "%s", msg);

    /* a side flipped: a triangulation, but not Delaunay */
    pdt_tri *f = malloc(nt * sizeof *f);
    memcpy(f, t, nt * sizeof *f);
    CHECK(flip_one(pts, f, nt));
    record_tri_finals(sub("ct-flip"), pts, n, f, nt);
    expect_fail(sub("ct-flip"), "is not locally Delaunay");

    /* a triangle on top of another: a third triangle on the side a-b of
     * t[0], left of it as t[0] is (three on a side, or two on one side of it) */
    pdt_tri *g3 = malloc((nt + 1) * sizeof *g3);
    memcpy(g3, t, nt * sizeof *g3);
    uint32_t a0 = t[0].v[0], b0 = t[0].v[1], d0 = UINT32_MAX;
    for (uint32_t p = 0; p < n && d0 == UINT32_MAX; p++)
        if (p != t[0].v[2] && pdt_orient(pts[a0], pts[b0], pts[p]) > 0) d0 = p;
    CHECK(d0 != UINT32_MAX);
    g3[nt] = (pdt_tri){{a0, b0, d0}};
    record_tri_finals(sub("ct-over"), pts, n, g3, nt + 1);
    expect_fail(sub("ct-over"), "final triangles");
    free(g3);

    /* no triangle at all, though the points are not on one line */
    record_tri_finals(sub("ct-none"), pts, n, t, 0);
    expect_fail(sub("ct-none"), "no triangle was made final");

    /* T* of the points but one inside: a convex triangulation, locally
     * Delaunay, with a point too few (Euler's formula) */
    uint32_t inner = UINT32_MAX;  /* a point near the middle of the square: inside */
    for (uint32_t p = 0; p < n && inner == UINT32_MAX; p++)
        if (labs(pts[p].x - (1 << 19)) < (1 << 17) && labs(pts[p].y - (1 << 19)) < (1 << 17))
            inner = p;
    CHECK(inner != UINT32_MAX);
    pdt_point *rest = malloc(n * sizeof *rest);
    uint32_t *orig = malloc(n * sizeof *orig);
    size_t m = 0;
    for (uint32_t p = 0; p < n; p++)
        if (p != inner) {
            orig[m] = p;
            rest[m++] = pts[p];
        }
    pdt_tri *u;
    size_t nu;
    CHECK(pdt_triangulate(rest, m, &u, &nu, NULL, NULL) == PDT_OK);
    for (size_t i = 0; i < nu; i++)
        for (int k = 0; k < 3; k++) u[i].v[k] = orig[u[i].v[k]];
    record_tri_finals(sub("ct-euler"), pts, n, u, nu);
    expect_fail(sub("ct-euler"), "by Euler's formula");

    /* a copy of a point as a corner */
    pdt_point *dup = malloc((n + 1) * sizeof *dup);
    memcpy(dup, pts, n * sizeof *dup);
    dup[n] = pts[t[0].v[0]];
    pdt_tri *g = malloc(nt * sizeof *g);
    memcpy(g, t, nt * sizeof *g);
    for (size_t i = 0; i < nt; i++)
        for (int k = 0; k < 3; k++)
            if (g[i].v[k] == t[0].v[0]) g[i].v[k] = (uint32_t)n;
    record_tri_finals(sub("ct-copy"), dup, n + 1, g, nt);
    expect_fail(sub("ct-copy"), "is a copy of an earlier input point");

    budget = PDT_TRACE_MEM_DEFAULT;
    free(g);
    free(dup);
    free(u);
    free(rest);
    free(orig);
    free(f);
    free(t);
    free(pts);
}

/* The check of a hull run in memory and in a budget of 1 byte (the hull
 * certified unless the run is empty, the stacks in files): the same
 * verdict; the summary the same but for what says it was certified.  When
 * it fails, each names why. */
static void hull_both(const char *name, const char *want_mem, const char *want_cert)
{
    char mem[1100], tiny[1100];
    pdt_status a = check_dir(sub(name), mem, sizeof mem);
    budget = 1;
    pdt_status b = check_dir(sub(name), tiny, sizeof tiny);
    budget = PDT_TRACE_MEM_DEFAULT;
    CHECK_MSG(a == b, "%s: %d '%s' in memory, %d '%s' certified", name, a, mem, b, tiny);
    if (!want_mem) {
        const char *said = " (the hull certified point by point: recomputing it would not fit the "
                           "memory budget)";
        size_t len = strlen(mem);
        CHECK_MSG(a == PDT_OK && !strstr(mem, "certified"), "%s: %s", name, mem);
        if (strstr(mem, " 0 events")) said = "";  /* no points: nothing to certify */
        CHECK_MSG(strncmp(tiny, mem, len) == 0 && strcmp(tiny + len, said) == 0, "%s: '%s' / '%s'",
                  name, mem, tiny);
        return;
    }
    CHECK_MSG(a == PDT_ERR_CHECK && strstr(mem, want_mem), "%s: '%s' lacks '%s'", name, mem, want_mem);
    CHECK_MSG(strstr(tiny, want_cert), "%s: '%s' lacks '%s'", name, tiny, want_cert);
}

TEST(hull_certified_in_bounded_memory)
{
    const char *const *kinds = pdt_gen_kinds();
    for (int i = 0; kinds[i]; i++) {
        pdt_point *q;
        pdt_err err = {0};
        CHECK(pdt_gen(kinds[i], 900, 13, &q, &err) == PDT_OK);
        record_hull(sub("hb-fam"), q, 900);
        hull_both("hb-fam", NULL, NULL);
        free(q);
    }
    /* n = 0..3, all at one point, all on a line (copies included) */
    pdt_point few[3] = {{5, 5}, {-1, 7}, {9, 8}};
    for (size_t n = 0; n <= 3; n++) {
        record_hull(sub("hb-few"), few, n);
        hull_both("hb-few", NULL, NULL);
    }
    pdt_point one[500], line[500];
    for (int i = 0; i < 500; i++) {
        one[i] = (pdt_point){-7, 3};
        line[i] = (pdt_point){3 * (i % 97) - 100, -2 * (i % 97) + 40};
    }
    record_hull(sub("hb-one"), one, 500);
    hull_both("hb-one", NULL, NULL);
    record_hull(sub("hb-line"), line, 500);
    hull_both("hb-line", NULL, NULL);

    /* the points of the run are not the points scanned: the final stack
     * is not their hull */
    size_t n = 2000;
    pdt_point *pts = uniform(n), *as = malloc(n * sizeof *as);
    uint32_t *h = malloc(n * sizeof *h);
    size_t nh;
    CHECK(pdt_hull_graham(pts, n, h, &nh, NULL) == PDT_OK && nh >= 3);
    uint32_t in = UINT32_MAX, hi = 0;  /* a point inside (the last), a corner before it */
    for (uint32_t p = 0; p < n; p++) {
        int corner = 0;
        for (size_t k = 0; k < nh; k++) corner |= h[k] == p;
        if (!corner) in = p;
    }
    for (size_t k = 1; k < nh; k++)
        if (h[k] < in && h[k] > hi) hi = h[k];
    CHECK(in != UINT32_MAX && hi > 0);
    memcpy(as, pts, n * sizeof *as);
    as[in] = (pdt_point){-5, -(1 << 30)};  /* far below */
    record_hull_as(sub("hb-below"), pts, as, n);
    hull_both("hb-below", "is not the hull of the run's points (", "is not the rightmost lowest point: pt");
    memcpy(as, pts, n * sizeof *as);
    as[in] = (pdt_point){pts[h[1]].x + 1, pts[h[1]].y};  /* beside a corner, outside */
    record_hull_as(sub("hb-out"), pts, as, n);
    char want[200];
    snprintf(want, sizeof want, "pt %" PRIu32 " (%" PRId32 ", %" PRId32 ") lies outside it", in,
             as[in].x, as[in].y);
    hull_both("hb-out", "first difference at position", want);
    memcpy(as, pts, n * sizeof *as);
    as[in] = pts[hi];  /* a later copy of a corner */
    record_hull_as(sub("hb-copy"), pts, as, n);
    snprintf(want, sizeof want, "pt %" PRIu32 " is a later copy of its point pt %" PRIu32, in, hi);
    hull_both("hb-copy", "first difference at position", want);
    memcpy(as, pts, n * sizeof *as);
    /* a corner moved inside the triangle of the origin and its neighbours */
    as[h[2]] = (pdt_point){(int32_t)(((int64_t)pts[h[0]].x + pts[h[1]].x + pts[h[3 % nh]].x) / 3),
                           (int32_t)(((int64_t)pts[h[0]].y + pts[h[1]].y + pts[h[3 % nh]].y) / 3)};
    record_hull_as(sub("hb-dent"), pts, as, n);
    snprintf(want, sizeof want, "no strict left turn at position 2 (pts %" PRIu32 " %" PRIu32
             " %" PRIu32 ")", h[1], h[2], h[3 % nh]);
    hull_both("hb-dent", "first difference at position", want);
    free(h);
    free(as);
    free(pts);
}

static void del_to_add(pdt_event *e) { e->kind = PDT_EV_EDGE_ADD; }

/* A level-2 kernel run whose edges outgrow a quarter of the budget is
 * replayed on disk: the same verdicts, each wrong edge event named by its
 * rank and event. */
TEST(level2_edges_on_disk)
{
    char msg[1100];
    pdt_point *pts = uniform(600);
    record_tri(sub("l2"), pts, 600, 2);
    budget = 4096;
    CHECK_MSG(check_dir(sub("l2"), msg, sizeof msg) == PDT_OK, "%s", msg);
    CHECK_MSG(strstr(msg, "1 kernel runs with edges replayed (1 of them replayed on disk"), "%s", msg);
    /* an edge never deleted: alive at the end though no triangle has it */
    expect_fail_copy("l2", "l2-nodel", PDT_EV_EDGE_DEL, 20, NULL, "edges alive at the end of the kernel run");
    /* an edge never added: a triangle's side missing (here; or deleted while absent) */
    expect_fail_copy("l2", "l2-noadd", PDT_EV_EDGE_ADD, 30, NULL, "was never added or was deleted");
    /* a deletion made an addition: the edge is added while it exists */
    expect_fail_copy("l2", "l2-twice", PDT_EV_EDGE_DEL, 20, del_to_add, "the edge already exists");
    /* the last edge added missing: a triangle's side never added */
    uint64_t last = UINT64_MAX;
    for (int k = 0; find_kind(sub("l2"), PDT_EV_EDGE_ADD, k) != UINT64_MAX; k += 64) last = (uint64_t)k;
    expect_fail_copy("l2", "l2-nolast", PDT_EV_EDGE_ADD, (int)last, NULL, "rank 0, the kernel run begun at event #");
    budget = PDT_TRACE_MEM_DEFAULT;
    CHECK_MSG(check_dir(sub("l2"), msg, sizeof msg) == PDT_OK && !strstr(msg, "on disk"), "%s", msg);
    free(pts);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "%s/pdt-ttc.XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(tmpdir)) return 1;
    RUN(every_family_passes);
    RUN(removed_events_are_named);
    RUN(strips_tstar_same_verdicts);
    RUN(edited_events_are_named);
    RUN(damaged_files_fail);
    RUN(messages_and_merges);
    RUN(chain_hull_counts);
    RUN(tiny_budget_spills);
    RUN(certified_tstar);
    RUN(level2_edges_on_disk);
    RUN(hull_certified_in_bounded_memory);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0) return 1;
    return test_summary();
}
