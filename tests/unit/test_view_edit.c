/* pdt — the point editor's model (src/view/edit.c) and live runs
 * (src/view/live.c): the file written after every change, undo/redo, the
 * replay re-built with the real algorithm, refusals, the tie report. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../harness.h"
#include "../../src/view/edit.h"
#include "pdt/delaunay.h"
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
    for (size_t t = 0; t < nt; t++) c += pdt_rstate_tri_status(r, s, t) == PDT_TS_FINAL;
    return c;
}

TEST(add_move_delete_saved_and_rerun)
{
    pdt_live_opts lo = {0, 1, 1};
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
    pdt_live_opts lo = {1, 1, 1};
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
    /* more ranks than the live runner has: refused, the mode stays */
    pdt_err e2 = {0};
    CHECK(pdt_editor_set_mode(ed, 0, 4, &e2) != PDT_OK || pdt_editor_run(ed)->nranks == 4);
    CHECK(pdt_replay_nranks(pdt_editor_replay(ed)) >= 1);
    pdt_editor_free(ed);
    free(f);
}

TEST(unparsable_file_is_never_written)
{
    char *f = strdup(path("bad.txt"));
    FILE *fp = fopen(f, "w");
    fputs("0 0\n1 2\n3 4294967296\n", fp);
    fclose(fp);
    pdt_live_opts lo = {0, 1, 1};
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

int main(void)
{
    if (!mkdtemp(dir)) return 1;
    RUN(add_move_delete_saved_and_rerun);
    RUN(hull_mode_and_presets);
    RUN(unparsable_file_is_never_written);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0) return 1;
    return test_summary();
}
