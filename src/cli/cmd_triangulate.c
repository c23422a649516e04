/* pdt triangulate — read points, compute T*, write the canonical triangles.
 * The three steps are separate functions (run_opts.h) so that a driver (the
 * MPI one) can reuse them. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "pdt/delaunay.h"
#include "pdt/io.h"
#include "pdt/par.h"
#include "run_opts.h"

static const char help[] =
    "usage: pdt triangulate INPUT [-o OUT] [--scale K] [--stats]\n"
    "                             [--trace DIR] [--trace-level N]\n"
    "\n"
    "Compute T*, the Delaunay triangulation of the points in INPUT (exact; ties\n"
    "broken by the lexicographic rule, so the answer is unique).\n"
    "\n"
    "INPUT   one point 'x y' per line (32-bit integers; blank lines and '#' comments\n"
    "        allowed), or Triangle's .node format when the name ends in .node;\n"
    "        '-' reads standard input.\n"
    "-o OUT  write to OUT instead of standard output; the format follows the\n"
    "        extension: .tri canonical (default), .ele Triangle's format (with a\n"
    "        matching .node beside it), .off Geomview OFF.  OUT is replaced\n"
    "        atomically: on any error no file is left behind.\n"
    "--scale K       accept decimal coordinates: multiply by K, round to nearest\n"
    "                (halves away from zero); points that collide are reported.\n"
    "--stats         print one JSON object with counts, times and peak memory\n"
    "                to standard error.\n"
    "--trace DIR     record every step into the run folder DIR (for pdtview).\n"
    "--trace-level N 1 (default) or 2 (also every edge the kernel makes).\n"
    "\n"
    "Output (.tri): one triangle per line, 'i j k', 0-based input indices,\n"
    "counter-clockwise, rotated to start at the smallest index, lines sorted.\n"
    "Duplicate points are represented by their first occurrence.  Fewer than 3\n"
    "distinct points, or all collinear: no triangles, and a message says why.\n"
    "\n"
    "Exit status: 0 success, 2 usage or input error.\n";

pdt_status pdt_tri_job_read(const pdt_run_opts *o, pdt_tri_job *j, pdt_err *err)
{
    double t0 = pdt_cli_now();
    pdt_status st = pdt_read_points(o->input, o->scale, &j->pts, &j->n, &j->collisions, err);
    j->t_read = pdt_cli_now() - t0;
    return st;
}

pdt_status pdt_tri_job_compute(const pdt_run_opts *o, pdt_tri_job *j, pdt_err *err)
{
    pdt_status st = pdt_cli_trace_open(o, j->pts, j->n, &j->trace, err);
    if (st != PDT_OK) return st;
    st = pdt_triangulate(j->pts, j->n, &j->tris, &j->ntri, &j->st,
                         pdt_cli_trace_hook(j->trace));
    if (st != PDT_OK) pdt_err_set(err, st, "triangulation failed: %s", pdt_status_str(st));
    else pdt_cli_trace_finals(j->trace, j->tris, j->ntri);
    pdt_status cst = pdt_cli_trace_close(j->trace, err);
    j->trace = NULL;
    return st != PDT_OK ? st : cst;
}

pdt_status pdt_tri_job_write(const pdt_run_opts *o, pdt_tri_job *j, pdt_err *err)
{
    double t0 = pdt_cli_now();
    pdt_tri_format fmt = pdt_tri_format_of(o->output);
    if (fmt == PDT_FMT_ELE) {
        /* The .node written beside OUT.ele must not replace the input. */
        size_t len = strlen(o->output);
        char *node = malloc(len + 2);
        if (!node) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
        memcpy(node, o->output, len - 4);
        memcpy(node + len - 4, ".node", 6);
        int clash = strcmp(o->input, "-") != 0 && pdt_cli_same_file(node, o->input);
        pdt_status st = clash ? pdt_err_set(err, PDT_ERR_ARG, "%s: writing %s would replace "
                                            "the input %s; choose another -o name",
                                            o->output, node, o->input)
                              : PDT_OK;
        free(node);
        if (st != PDT_OK) return st;
    } else if (o->output && strcmp(o->input, "-") != 0 && pdt_cli_same_file(o->output, o->input)) {
        return pdt_err_set(err, PDT_ERR_ARG, "%s: output would replace the input; choose "
                           "another -o name", o->output);
    }
    pdt_status st = pdt_write_tris(o->output, fmt, j->pts, j->n, j->tris, j->ntri, err);
    j->t_write = pdt_cli_now() - t0;
    return st;
}

void pdt_tri_job_report(const pdt_run_opts *o, const pdt_tri_job *j)
{
    const pdt_tri_stats *s = &j->st;
    if (j->collisions)
        fprintf(stderr, "pdt: warning: %zu point%s became equal to a different point after "
                "rounding with --scale %g\n", j->collisions, j->collisions == 1 ? "" : "s",
                o->scale);
    if (s->n_dup)
        fprintf(stderr, "pdt: %zu duplicate point%s dropped (each copy is represented by its "
                "first occurrence)\n", s->n_dup, s->n_dup == 1 ? "" : "s");
    if (s->n_unique < 3)
        fprintf(stderr, "pdt: 0 triangles: only %zu distinct point%s (a triangle needs 3)\n",
                s->n_unique, s->n_unique == 1 ? "" : "s");
    else if (j->ntri == 0)
        fprintf(stderr, "pdt: 0 triangles: all %zu distinct points are collinear\n",
                s->n_unique);
    if (o->stats) {
        double total = pdt_cli_now() - j->t_start;
        fprintf(stderr,
                "{\"command\": \"triangulate\", \"n\": %zu, \"unique\": %zu, \"duplicates\": %zu, "
                "\"collisions\": %zu, \"triangles\": %zu, \"hull\": %zu, \"collinear\": %s, "
                "\"seconds\": {\"read\": %.6f, \"sort\": %.6f, \"kernel\": %.6f, "
                "\"canonical\": %.6f, \"write\": %.6f, \"total\": %.6f}, "
                "\"peak_rss_kib\": %ld}\n",
                j->n, s->n_unique, s->n_dup, j->collisions, j->ntri, s->n_hull,
                s->collinear ? "true" : "false", j->t_read, s->t_sort, s->t_kernel, s->t_canon,
                j->t_write, total, pdt_cli_peak_kib());
    }
}

void pdt_tri_job_free(pdt_tri_job *j)
{
    if (j->trace) pdt_cli_trace_close(j->trace, NULL);
    free(j->pts);
    free(j->tris);
    memset(j, 0, sizeof *j);
}

int pdt_cmd_triangulate(int argc, char **argv)
{
    pdt_run_opts o;
    int rc = pdt_cli_parse_run_opts("triangulate", help, argc, argv, &o);
    if (rc >= 0) return rc;
    if (pdt_comm_launched()) { /* under mpirun / srun: the parallel driver (src/par) */
        pdt_par_job pj = {o.input, o.output, o.scale, o.stats, o.trace_dir, o.trace_level,
                          o.argc, o.argv};
        return pdt_par_cmd_triangulate(NULL, NULL, &pj);
    }

    pdt_tri_job job = { .t_start = pdt_cli_now() };
    pdt_err err = { PDT_OK, "" };
    pdt_status st = pdt_tri_job_read(&o, &job, &err);
    if (st == PDT_OK) st = pdt_tri_job_compute(&o, &job, &err);
    if (st == PDT_OK) st = pdt_tri_job_write(&o, &job, &err);
    if (st == PDT_OK) pdt_tri_job_report(&o, &job);

    rc = st == PDT_OK ? PDT_EXIT_OK : pdt_cli_fail(&err);
    pdt_tri_job_free(&job);
    return rc;
}
