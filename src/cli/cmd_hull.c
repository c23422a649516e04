/* pdt hull — the convex hull by Graham's scan, Version B (thesis Chapter 2). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "pdt/safefile.h"
#include "pdt/hull.h"
#include "pdt/io.h"
#include "run_opts.h"

static const char help[] =
    "usage: pdt hull INPUT [-o OUT] [--scale K] [--stats] [--trace DIR] [--trace-level N]\n"
    "\n"
    "Convex hull of the points in INPUT by Graham's scan, Version B (the thesis'\n"
    "Chapter 2): the rightmost lowest point is the origin, the others are sorted\n"
    "by angle, only the farther of collinear points and one copy of coincident\n"
    "points are kept, and a point is pushed only on a strict left turn.\n"
    "\n"
    "Output: the indices (0-based, into INPUT) of the extreme points, one per\n"
    "line, counter-clockwise, starting at the origin.  Points in the middle of\n"
    "a hull edge are not extreme and are not listed.\n"
    "\n"
    "INPUT, -o, --scale, --stats, --trace, --trace-level: as for pdt triangulate.\n"
    "Exit status: 0 success, 2 usage or input error.\n";

/* Graham's scan on pts[0..n), traced when o asks for it. */
/* Graham's scan on pts[0..n), traced into *t when o asks for it (the run
 * folder complete, not yet in place: write_hull puts it there). */
static pdt_status compute(const pdt_run_opts *o, const pdt_point *pts, size_t n, uint32_t *out,
                          size_t *nout, pdt_cli_trace **t, pdt_err *err)
{
    pdt_status st = pdt_cli_trace_open(o, pts, n, t, err);
    if (st != PDT_OK) return st;
    st = pdt_hull_graham(pts, n, out, nout, pdt_cli_trace_hook(*t));
    if (st != PDT_OK) pdt_err_set(err, st, "hull failed: %s", pdt_status_str(st));
    pdt_status cst = pdt_cli_trace_end(*t, err);
    return st != PDT_OK ? st : cst;
}

/* One index per line, atomically; the output and the run folder t go in
 * place together. */
static pdt_status write_hull(const char *path, const uint32_t *h, size_t nh, pdt_cli_trace *t,
                             pdt_err *err)
{
    pdt_outfile f;
    pdt_pending_write pw;
    pdt_status st = pdt_out_open(&f, path, err);
    if (st != PDT_OK) return st;
    for (size_t i = 0; i < nh; i++) fprintf(f.fp, "%u\n", (unsigned)h[i]);
    st = pdt_out_finish_pair(&f, NULL, &pw, err);
    if (st == PDT_OK) st = pdt_cli_trace_swap(t, err);
    if (st == PDT_OK) return pdt_pending_commit(&pw, err);
    pdt_pending_drop(&pw);
    return st;
}

int pdt_cmd_hull(int argc, char **argv)
{
    pdt_run_opts o;
    int rc = pdt_cli_parse_run_opts("hull", help, argc, argv, &o);
    if (rc >= 0) return rc;

    double t0 = pdt_seconds(), t1 = t0, t2 = t0, t3 = t0;
    pdt_err err = { PDT_OK, "" };
    pdt_point *pts = NULL;
    uint32_t *hull = NULL;
    size_t n = 0, nh = 0, coll = 0;
    pdt_status st = pdt_read_points(o.input, o.scale, &pts, &n, &coll, &err);
    t1 = pdt_seconds();
    if (st == PDT_OK) {
        hull = malloc((n ? n : 1) * sizeof *hull);
        if (!hull) st = pdt_err_set(&err, PDT_ERR_NOMEM, "out of memory");
    }
    pdt_cli_trace *t = NULL;
    if (st == PDT_OK && pdt_safe_same_file(o.output, o.input))
        st = pdt_err_set(&err, PDT_ERR_ARG, "%s: output would replace the input; choose another "
                         "-o name", o.output);
    if (st == PDT_OK) st = compute(&o, pts, n, hull, &nh, &t, &err);
    t2 = pdt_seconds();
    if (st == PDT_OK) st = write_hull(o.output, hull, nh, t, &err);
    pdt_cli_trace_finish(t, st == PDT_OK);
    t3 = pdt_seconds();

    if (st == PDT_OK) {
        if (coll)
            fprintf(stderr, "pdt: warning: %zu point%s became equal to a different point after "
                    "rounding with --scale %g\n", coll, coll == 1 ? "" : "s", o.scale);
        if (o.stats)
            fprintf(stderr, "{\"command\": \"hull\", \"n\": %zu, \"collisions\": %zu, "
                    "\"hull\": %zu, \"seconds\": {\"read\": %.6f, \"hull\": %.6f, "
                    "\"write\": %.6f, \"total\": %.6f}, \"peak_rss_kib\": %ld}\n",
                    n, coll, nh, t1 - t0, t2 - t1, t3 - t2, t3 - t0, pdt_cli_peak_kib());
    }
    rc = st == PDT_OK ? PDT_EXIT_OK : pdt_cli_fail(&err);
    free(pts);
    free(hull);
    return rc;
}
