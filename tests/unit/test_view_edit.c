/* pdt — the point editor's model (src/view/app/edit.c) and live runs
 * (src/view/model/live.c): the file written after every change, undo/redo, the
 * replay re-built with the real algorithm, refusals, the tie report. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../harness.h"
#include "../../src/view/app/edit.h"
#include "pdt/delaunay.h"
#include "pdt/gen.h"
#include "pdt/io.h"

static char dir[] = "/tmp/pdt-edit-XXXXXX";

static char *path(const char *name)
{
    static char buf[256];
    snprintf(buf, sizeof buf, "%s/%s", dir, name);
    return buf;
}

/* The points in the saved file. */
static size_t saved(const char *p, pdt_point **pts)
{
    size_t n = 0;
    pdt_err err = {0};
    if (pdt_read_points(p, 0, pts, &n, NULL, &err) != PDT_OK) return (size_t)-1;
    return n;
}

static size_t finals_at_end(pdt_editor *ed)
{
    const pdt_replay *r = pdt_editor_replay(ed);
    pdt_rstate *s = pdt_editor_state(ed);
    size_t nt, c = 0;
    pdt_replay_tris(r, &nt);
    const pdt_rtri_hist *H = pdt_replay_tri_hist(r);
    /* as the window draws them: a final triangle a border kernel recomputed
     * and its merge dropped again stays final (pdt_rstate_tri_entry) */
    for (size_t t = 0; t < nt; t++) {
        uint32_t h = pdt_rstate_tri_entry(r, s, t);
        c += h != UINT32_MAX && H[h].status == PDT_TS_FINAL;
    }
    return c;
}

TEST(add_move_delete_saved_and_rerun)
{
    pdt_live_opts lo = {0, 1, 1, 0};
    pdt_editor *ed;
    pdt_err err = {0};
    char *f = strdup(path("a.txt"));
    CHECK(pdt_editor_open(f, &lo, &ed, &err) == PDT_OK);
    pdt_point *pts = NULL;
    CHECK(saved(f, &pts) == 0); /* created, empty */
    free(pts);
    CHECK(pdt_editor_add(ed, 0, 0, &err) == PDT_OK);
    CHECK(pdt_editor_add(ed, 10, 0, &err) == PDT_OK);
    CHECK(pdt_editor_add(ed, 0, 10, &err) == PDT_OK);
    CHECK(pdt_editor_add(ed, 10, 10, &err) == PDT_OK);
    CHECK(pdt_editor_add(ed, 3, 4, &err) == PDT_OK);
    CHECK(saved(f, &pts) == 5 && pts[4].x == 3 && pts[4].y == 4);
    free(pts);
    /* the replay is at its end: the 4 triangles of T* are final */
    CHECK(pdt_editor_state(ed)->k == pdt_replay_count(pdt_editor_replay(ed)));
    CHECK_MSG(finals_at_end(ed) == 4, "%zu final", finals_at_end(ed));
    CHECK(pdt_editor_run(ed)->ntri == 4);
    CHECK(pdt_editor_move(ed, 4, 5, 5, &err) == PDT_OK);
    CHECK(saved(f, &pts) == 5 && pts[4].x == 5 && pts[4].y == 5);
    free(pts);
    /* the square with its centre: no tie; the square alone: one tie */
    CHECK(pdt_editor_run(ed)->nties == 0);
    CHECK(pdt_editor_delete(ed, 4, &err) == PDT_OK);
    CHECK(saved(f, &pts) == 4);
    free(pts);
    CHECK_MSG(pdt_editor_run(ed)->nties == 1, "%zu ties", pdt_editor_run(ed)->nties);
    /* undo twice, redo once */
    CHECK(pdt_editor_undo(ed, &err) == PDT_OK && saved(f, &pts) == 5);
    free(pts);
    CHECK(pdt_editor_undo(ed, &err) == PDT_OK && saved(f, &pts) == 5 && pts[4].x == 3);
    free(pts);
    CHECK(pdt_editor_redo(ed, &err) == PDT_OK && saved(f, &pts) == 5 && pts[4].x == 5);
    free(pts);
    /* beyond int32: refused, nothing changes */
    pdt_err e2 = {0};
    CHECK(pdt_editor_add(ed, 4294967296LL, 0, &e2) == PDT_ERR_ARG && strstr(e2.msg, "32-bit"));
    size_t n;
    pdt_editor_points(ed, &n);
    CHECK(n == 5 && saved(f, &pts) == 5);
    free(pts);
    pdt_editor_free(ed);
    free(f);
}

TEST(hull_mode_and_presets)
{
    pdt_live_opts lo = {1, 1, 1, 0};
    pdt_editor *ed;
    pdt_err err = {0};
    char *f = strdup(path("b.txt"));
    CHECK(pdt_editor_open(f, &lo, &ed, &err) == PDT_OK);
    CHECK(pdt_editor_preset(ed, PDT_PRESET_CIRCLE, &err) == PDT_OK);
    size_t n;
    pdt_editor_points(ed, &n);
    CHECK(n == 20);
    CHECK(pdt_editor_run(ed)->nhull == 20 && pdt_editor_run(ed)->ntri == 0);
    CHECK(pdt_replay_kind_count(pdt_editor_replay(ed), PDT_EV_PUSH) > 0);
    CHECK(pdt_editor_set_mode(ed, 0, 1, &err) == PDT_OK);
    /* 20 cocircular points: 18 triangles, every interior edge a tie (17) */
    CHECK_MSG(pdt_editor_run(ed)->ntri == 18, "%zu", pdt_editor_run(ed)->ntri);
    CHECK_MSG(pdt_editor_run(ed)->nties == 17, "%zu", pdt_editor_run(ed)->nties);
    CHECK(pdt_editor_preset(ed, PDT_PRESET_DUPLICATES, &err) == PDT_OK);
    CHECK(pdt_editor_run(ed)->ntri > 0);
    CHECK(pdt_editor_preset(ed, PDT_PRESET_COLLINEAR, &err) == PDT_OK);
    CHECK(pdt_editor_random(ed, 50, 0, 0, 100, 100, &err) == PDT_OK);
    pdt_editor_points(ed, &n);
    CHECK(n == 61);
    pdt_point *pts = NULL;
    CHECK(saved(f, &pts) == 61);
    free(pts);
    /* 4 simulated ranks; Graham only runs on one whatever the ranks say */
    CHECK(pdt_editor_set_mode(ed, 0, 4, &err) == PDT_OK);
    CHECK(pdt_editor_run(ed)->nranks == 4 && pdt_replay_nranks(pdt_editor_replay(ed)) == 4);
    CHECK_MSG(finals_at_end(ed) == pdt_editor_run(ed)->ntri, "%zu final of %zu",
              finals_at_end(ed), pdt_editor_run(ed)->ntri);
    CHECK(pdt_editor_add(ed, 33, 77, &err) == PDT_OK && pdt_editor_run(ed)->nranks == 4);
    CHECK(pdt_editor_set_mode(ed, 1, 4, &err) == PDT_OK && pdt_editor_run(ed)->nranks == 1);
    /* more ranks than a live run takes: refused */
    pdt_err e2 = {0};
    CHECK(pdt_editor_set_mode(ed, 0, PDT_LIVE_MAX_RANKS + 1, &e2) != PDT_OK &&
          strstr(e2.msg, "simulated ranks"));
    pdt_editor_free(ed);
    free(f);
}

/* The row of key k in the help table of ed's mode, or NULL. */
static const char *help_row(pdt_editor *ed, const char *k)
{
    int n;
    const char *const(*rows)[2] = pdt_editor_help(ed, &n);
    for (int i = 0; i < n; i++)
        if (!strcmp(rows[i][0], k)) return rows[i][1];
    return NULL;
}

TEST(help_lists_the_keys_of_the_mode)
{
    pdt_live_opts lo = {0, 1, 1, 0};
    pdt_editor *ed;
    pdt_err err = {0};
    char *f = strdup(path("help.txt"));
    CHECK(pdt_editor_open(f, &lo, &ed, &err) == PDT_OK);
    CHECK(pdt_editor_set_mode(ed, 0, 4, &err) == PDT_OK);
    CHECK(help_row(ed, "0") && help_row(ed, "g") && strstr(help_row(ed, "x"), "Graham"));
    CHECK(!help_row(ed, "g N Enter"));
    CHECK(pdt_editor_set_mode(ed, 1, 4, &err) == PDT_OK);
    CHECK(!help_row(ed, "0") && !help_row(ed, "9")); /* one rank: nothing to show or hide */
    CHECK(strstr(help_row(ed, "x"), "back to the triangulation"));
    CHECK(help_row(ed, "g") && !strcmp(help_row(ed, "g"), "grid snap on / off"));
    pdt_editor_free(ed);
    free(f);
}

TEST(unparsable_file_is_never_written)
{
    char *f = strdup(path("bad.txt"));
    FILE *fp = fopen(f, "w");
    fputs("0 0\n1 2\n3 4294967296\n", fp);
    fclose(fp);
    pdt_live_opts lo = {0, 1, 1, 0};
    pdt_editor *ed = NULL;
    pdt_err err = {0};
    CHECK(pdt_editor_open(f, &lo, &ed, &err) != PDT_OK && ed == NULL);
    CHECK_MSG(strstr(err.msg, "bad.txt:3") != NULL, "%s", err.msg);
    fp = fopen(f, "r");
    char buf[64] = "";
    size_t got = fread(buf, 1, sizeof buf - 1, fp);
    fclose(fp);
    CHECK(got == 21 && !strcmp(buf, "0 0\n1 2\n3 4294967296\n"));
    free(f);
}

/* The whole text of a file (static buffer). */
static const char *slurp(const char *p)
{
    static char buf[4096];
    FILE *fp = fopen(p, "r");
    size_t got = fp ? fread(buf, 1, sizeof buf - 1, fp) : 0;
    if (fp) fclose(fp);
    buf[got] = 0;
    return buf;
}

TEST(comments_kept_after_edits)
{
    char *f = strdup(path("notes.txt"));
    FILE *fp = fopen(f, "w");
    fputs("# lesson points\n0 0\n10 0\n# the witness:\n5 9  # inside\n0 10\n# end\n", fp);
    fclose(fp);
    pdt_live_opts lo = {0, 1, 1, 0};
    pdt_editor *ed = NULL;
    pdt_err err = {0};
    CHECK(pdt_editor_open(f, &lo, &ed, &err) == PDT_OK);
    CHECK(pdt_editor_delete(ed, 1, &err) == PDT_OK);   /* 10 0 */
    CHECK(pdt_editor_add(ed, 20, 20, &err) == PDT_OK);
    CHECK(pdt_editor_move(ed, 1, 6, 8, &err) == PDT_OK); /* the witness moves: its notes too */
    CHECK_MSG(!strcmp(slurp(f), "# lesson points\n0 0\n# the witness:\n6 8  # inside\n0 10\n"
                                "20 20\n# end\n"), "%s", slurp(f));
    CHECK(pdt_editor_undo(ed, &err) == PDT_OK && pdt_editor_undo(ed, &err) == PDT_OK);
    CHECK_MSG(strstr(slurp(f), "# the witness:\n") && strstr(slurp(f), "# lesson points\n0 0\n"),
              "%s", slurp(f));
    pdt_editor_free(ed);
    free(f);
}

/* Rank q's events in a merged list: q's own order, its seq 0, 1, 2, ...; the
 * frame `mpirun -np P pdt triangulate --trace` records around the library
 * (run, read ... write, run); every RECV after its SEND. */
static int rank_frame_ok(const pdt_live_result *res, int q)
{
    uint32_t want = 0;
    const pdt_event *first[3] = {NULL, NULL, NULL}, *last = NULL;
    for (size_t k = 0; k < res->m; k++) {
        if (res->recs[k].rank != (uint32_t)q) continue;
        if (res->recs[k].seq != want) return 0;
        if (want < 3) first[want] = &res->recs[k].ev;
        last = &res->recs[k].ev;
        want++;
    }
    return want > 4 && first[0]->kind == PDT_EV_PHASE_BEGIN && first[0]->sub == PDT_PH_RUN &&
           first[1]->kind == PDT_EV_PHASE_BEGIN && first[1]->sub == PDT_PH_READ &&
           first[2]->kind == PDT_EV_PHASE_END && first[2]->sub == PDT_PH_READ &&
           last->kind == PDT_EV_PHASE_END && last->sub == PDT_PH_RUN;
}

static int causal(const pdt_live_result *res)
{
    int p = res->nranks;
    uint64_t *sent = calloc((size_t)(p * p), sizeof *sent);
    int ok = sent != NULL;
    for (size_t k = 0; ok && k < res->m; k++) {
        const pdt_event *e = &res->recs[k].ev;
        uint32_t r = res->recs[k].rank;
        if (e->kind == PDT_EV_SEND) sent[r * (uint32_t)p + e->a]++;
        if (e->kind == PDT_EV_RECV) ok = sent[e->a * (uint32_t)p + r] > (uint64_t)e->v;
    }
    free(sent);
    return ok;
}

/* P simulated ranks run the parallel code: T* is the sequential pipeline's,
 * triangle for triangle in the canonical order, for P = 2 .. 8 and for
 * inputs with duplicates and collinear runs; every rank's events are framed
 * as the command frames them, and the merge is causal. */
TEST(simulated_ranks_give_the_same_triangles)
{
    static const char *const kinds[] = {"uniform", "clusters", "duplicates", "collinear", "grid"};
    for (size_t i = 0; i < sizeof kinds / sizeof *kinds; i++) {
        pdt_point *pts = NULL;
        pdt_err err = {0};
        size_t n = 150;
        CHECK(pdt_gen(kinds[i], n, 7, &pts, &err) == PDT_OK);
        pdt_live_opts one = {0, 1, 1, 0};
        pdt_live_result r1;
        CHECK(pdt_live_run(pts, n, &one, &r1, &err) == PDT_OK);
        for (int p = 2; p <= 8; p++) {
            pdt_live_opts lo = {0, p, 1, 0};
            pdt_live_result rp;
            pdt_status st = pdt_live_run(pts, n, &lo, &rp, &err);
            CHECK_MSG(st == PDT_OK, "%s on %d ranks: %s", kinds[i], p, err.msg);
            if (st != PDT_OK) continue;
            CHECK_MSG(rp.ntri == r1.ntri && !memcmp(rp.tris, r1.tris, r1.ntri * sizeof *r1.tris),
                      "%s on %d ranks: %zu triangles, sequential %zu", kinds[i], p, rp.ntri,
                      r1.ntri);
            CHECK(rp.nranks == p && rp.nties == r1.nties);
            size_t finals = 0;
            for (size_t k = 0; k < rp.m; k++) finals += rp.recs[k].ev.kind == PDT_EV_TRI_FINAL;
            CHECK_MSG(finals == rp.ntri, "%s, %d ranks: %zu TRI_FINAL", kinds[i], p, finals);
            for (int q = 0; q < p; q++) CHECK_MSG(rank_frame_ok(&rp, q), "%s rank %d", kinds[i], q);
            CHECK(causal(&rp));
            pdt_live_free(&rp);
        }
        pdt_live_free(&r1);
        free(pts);
    }
    /* fewer points than ranks, and none at all */
    pdt_point few[3] = {{0, 0}, {5, 0}, {0, 5}};
    for (size_t n = 0; n <= 3; n++) {
        pdt_live_opts lo = {0, 6, 1, 0};
        pdt_live_result rp;
        pdt_err err = {0};
        CHECK_MSG(pdt_live_run(few, n, &lo, &rp, &err) == PDT_OK, "%zu points: %s", n, err.msg);
        CHECK(rp.ntri == (n == 3));
        pdt_live_free(&rp);
    }
}

int main(void)
{
    if (!mkdtemp(dir)) return 1;
    RUN(add_move_delete_saved_and_rerun);
    RUN(hull_mode_and_presets);
    RUN(help_lists_the_keys_of_the_mode);
    RUN(unparsable_file_is_never_written);
    RUN(comments_kept_after_edits);
    RUN(simulated_ranks_give_the_same_triangles);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0) return 1;
    return test_summary();
}
