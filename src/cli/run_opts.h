/* pdt — the options of the commands that compute on a point set
 * (`pdt triangulate`, `pdt hull`) and the run state they share.
 *
 * Kept small and separate so that the tracing and parallel parts can add
 * fields: tracing fills trace_dir / trace_level (parsed here, written by the
 * trace module through pdt_cli_trace_open), the MPI driver reuses the
 * read / compute / write steps of cmd_triangulate.c. */
#ifndef PDT_RUN_OPTS_H
#define PDT_RUN_OPTS_H

#include <stddef.h>

#include "pdt/common.h"
#include "pdt/delaunay.h"
#include "pdt/trace.h"

typedef struct pdt_run_opts {
    const char *command;     /* "triangulate" or "hull" */
    const char *input;       /* INPUT ("-" = standard input) */
    const char *output;      /* -o FILE; NULL = standard output */
    double scale;            /* --scale K; 0 = integer coordinates only */
    int stats;               /* --stats: JSON figures on stderr */
    const char *trace_dir;   /* --trace DIR; NULL = no trace */
    int trace_level;         /* --trace-level N (1 or 2; default 1) */
    int argc;                /* the whole command line, for trace manifests */
    char **argv;
} pdt_run_opts;

/* Parse the options shared by `pdt triangulate` and `pdt hull` (INPUT, -o,
 * --scale, --stats, --trace, --trace-level) for command `cmd` into o.
 * Returns -1 to go on, else the exit status to return (help printed, or a
 * usage error already reported). */
int pdt_cli_parse_run_opts(const char *cmd, const char *help, int argc, char **argv,
                           pdt_run_opts *o);

/* Tracing of one run (the run folder of docs/trace-format.md).  Opened
 * before the computation when o->trace_dir is set, closed after it. */
typedef struct pdt_cli_trace pdt_cli_trace;

/* Open the trace of a run of o->command on pts[0..n).  *t = NULL and PDT_OK
 * when o->trace_dir is NULL.  Returns an error if the folder cannot be made. */
pdt_status pdt_cli_trace_open(const pdt_run_opts *o, const pdt_point *pts, size_t n,
                              pdt_cli_trace **t, pdt_err *err);
/* The hook to pass to the algorithm (NULL when t is NULL). */
pdt_trace *pdt_cli_trace_hook(pdt_cli_trace *t);
/* Record the output triangles as final (TRI_FINAL); nothing if t is NULL. */
void pdt_cli_trace_finals(pdt_cli_trace *t, const pdt_tri *tris, size_t ntri);
/* Finish the run folder and free t (t may be NULL). */
pdt_status pdt_cli_trace_close(pdt_cli_trace *t, pdt_err *err);

/* The state of one `pdt triangulate` run, step by step. */
typedef struct pdt_tri_job {
    pdt_point *pts;          /* input points (malloc'd) */
    size_t n;
    size_t collisions;       /* points merged by --scale rounding */
    pdt_tri *tris;           /* canonical triangles (malloc'd) */
    size_t ntri;
    pdt_tri_stats st;        /* filled by the computation */
    double t_read, t_write;  /* seconds */
    double t_start;          /* pdt_cli_now() at the start */
    pdt_cli_trace *trace;    /* NULL = not traced */
} pdt_tri_job;

/* The three steps of `pdt triangulate`, reusable by a driver: read the input
 * named by o, compute T*, write it where o says.  Each returns PDT_OK or an
 * error described in err; pdt_tri_job_free releases what they allocated. */
pdt_status pdt_tri_job_read(const pdt_run_opts *o, pdt_tri_job *j, pdt_err *err);
pdt_status pdt_tri_job_compute(const pdt_run_opts *o, pdt_tri_job *j, pdt_err *err);
pdt_status pdt_tri_job_write(const pdt_run_opts *o, pdt_tri_job *j, pdt_err *err);
/* Messages about the input (duplicates, rounding collisions, why there are
 * no triangles) and, with --stats, the JSON figures: all on stderr. */
void pdt_tri_job_report(const pdt_run_opts *o, const pdt_tri_job *j);
void pdt_tri_job_free(pdt_tri_job *j);

#endif
