/* Graham's scan (Version B) through the trace writer and reader: the exact
 * sequence of sorts, deletions, pushes and pops on small fixed inputs.  The
 * expected sequences were derived by hand from the thesis' rules (see the
 * comments), not copied from a run. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../harness.h"
#include "pdt/hull.h"
#include "pdt/tracefile.h"

static char tmpdir[256];

/* Run Graham on pts with a trace writer in a fresh folder; return the
 * formatted events whose kind is in `kinds`, one per line. */
static char *graham_lines(const char *name, const pdt_point *pts, size_t n, const int *kinds,
                          int nkinds)
{
    char dir[400];
    snprintf(dir, sizeof dir, "%s/%s", tmpdir, name);
    pdt_trace_writer *w;
    pdt_err err = {0};
    CHECK(pdt_tw_open(dir, 0, 1, &w, &err) == PDT_OK);
    uint32_t *out = malloc(n * sizeof *out);
    size_t nout;
    CHECK(pdt_hull_graham(pts, n, out, &nout, pdt_tw_hook(w)) == PDT_OK);
    free(out);
    CHECK(pdt_tw_close(w, &err) == PDT_OK);
    int64_t off = 0;
    pdt_manifest m = {.format_version = 1, .n = n, .nranks = 1, .level = 1,
                      .clock_offset_ns = &off, .command = "hull"};
    m.input_checksum = pdt_points_checksum(pts, n);
    CHECK(pdt_run_write_meta(dir, &m, pts, n, &err) == PDT_OK);
    pdt_run *run;
    CHECK_MSG(pdt_run_open(dir, &run, &err) == PDT_OK, "%s", err.msg);
    size_t cap = 1 << 16, len = 0;
    char *s = calloc(cap, 1);
    const pdt_event *ev;
    size_t ne;
    CHECK(pdt_run_rank_events(run, 0, &ev, &ne, &err) == PDT_OK);
    for (size_t i = 0; i < ne; i++) {
        int want = 0;
        for (int k = 0; k < nkinds; k++) want |= ev[i].kind == kinds[k];
        if (!want) continue;
        char line[160];
        pdt_event_format(&ev[i], line, sizeof line);
        len += (size_t)snprintf(s + len, cap - len, "%s\n", line);
    }
    CHECK_MSG(*pdt_run_warnings(run) == '\0', "%s", pdt_run_warnings(run));
    pdt_run_close(run);
    return s;
}

static void expect_text(const char *got, const char *want)
{
    CHECK_MSG(strcmp(got, want) == 0, "\n--- got:\n%s--- want:\n%s", got, want);
}

/* The thesis' square with points sprinkled on its boundary (and one inside):
 * only the four corners are extreme.  p0 = (4,0) = pt 2.  Angles about p0:
 * 3 and 4 at 90 degrees (3 closer: deleted), 5, then 8 and 6 at 135 (8
 * closer: deleted), 7, then 1 and 0 at 180 (1 closer: deleted).  Scan over
 * 2 4 5 6 7 0: 5 is popped by 6 (collinear 4 5 6), 7 is popped by 0
 * (collinear 6 7 0). */
TEST(square_with_collinear_points)
{
    static const pdt_point sq[] = {{0, 0}, {2, 0}, {4, 0}, {4, 2}, {4, 4},
                                   {2, 4}, {0, 4}, {0, 2}, {2, 2}};
    int kinds[] = {PDT_EV_SORT, PDT_EV_DELETE, PDT_EV_PUSH, PDT_EV_POP};
    char *got = graham_lines("square", sq, 9, kinds, 4);
    expect_text(got,
                "sort pt=2 pos=0\n"
                "sort pt=3 pos=1\n"
                "sort pt=4 pos=2\n"
                "sort pt=5 pos=3\n"
                "sort pt=8 pos=4\n"
                "sort pt=6 pos=5\n"
                "sort pt=7 pos=6\n"
                "sort pt=1 pos=7\n"
                "sort pt=0 pos=8\n"
                "delete angular-tie pt=3 kept=4\n"
                "delete angular-tie pt=8 kept=6\n"
                "delete angular-tie pt=1 kept=0\n"
                "push graham pt=2 depth=1\n"
                "push graham pt=4 depth=2\n"
                "push graham pt=5 depth=3\n"
                "pop graham pt=5 depth=2 cause=6\n"
                "push graham pt=6 depth=3\n"
                "push graham pt=7 depth=4\n"
                "pop graham pt=7 depth=3 cause=0\n"
                "push graham pt=0 depth=4\n");
    free(got);
}

/* Angular ties and duplicates.  p0 = (5,0) = pt 1 (first index of the
 * rightmost lowest); pt 2 is a copy of it.  At 135 degrees about p0 lie 7, 6
 * and the copies 4 and 5 of (0,5): the farthest (the copy with the higher
 * index, 5) stays, 7 and 6 go as angular ties, 4 as a coincident copy.
 * Scan over 1 3 5 8 0: 8 is popped by 0 (right turn 5 8 0). */
TEST(angular_ties_and_duplicates)
{
    static const pdt_point p[] = {{0, 0}, {5, 0}, {5, 0}, {5, 5}, {0, 5},
                                  {0, 5}, {1, 4}, {3, 2}, {2, 1}};
    int kinds[] = {PDT_EV_DELETE, PDT_EV_PUSH, PDT_EV_POP};
    char *got = graham_lines("ties", p, 9, kinds, 3);
    expect_text(got,
                "delete coincident pt=2 kept=1\n"
                "delete angular-tie pt=7 kept=5\n"
                "delete angular-tie pt=6 kept=5\n"
                "delete coincident pt=4 kept=5\n"
                "push graham pt=1 depth=1\n"
                "push graham pt=3 depth=2\n"
                "push graham pt=5 depth=3\n"
                "push graham pt=8 depth=4\n"
                "pop graham pt=8 depth=3 cause=0\n"
                "push graham pt=0 depth=4\n");
    free(got);
}

/* Phases bracket the sort and the scan; nothing else is recorded. */
TEST(graham_phases)
{
    static const pdt_point p[] = {{0, 0}, {1, 0}, {0, 1}};
    int kinds[] = {PDT_EV_PHASE_BEGIN, PDT_EV_PHASE_END};
    char *got = graham_lines("phases", p, 3, kinds, 2);
    expect_text(got,
                "phase-begin graham-sort\n"
                "phase-end graham-sort\n"
                "phase-begin graham-scan\n"
                "phase-end graham-scan\n");
    free(got);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "%s/pdt-ttg.XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(tmpdir)) return 1;
    RUN(square_with_collinear_points);
    RUN(angular_ties_and_duplicates);
    RUN(graham_phases);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0) return 1;
    return test_summary();
}
