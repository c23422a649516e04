/* pdt — the options of the commands that compute on a point set
 * (`pdt triangulate`, `pdt hull`) and the run state they share.
 *
 * Kept small and separate so that the tracing and parallel parts can add
 * fields: tracing fills trace_dir / trace_level (parsed here, written by the
 * trace module through pdt_cli_trace_open). */
#ifndef PDT_RUN_OPTS_H
#define PDT_RUN_OPTS_H

#include <stddef.h>

#include "pdt/common.h"
#include "pdt/delaunay.h"
#include "pdt/par.h"
#include "pdt/trace.h"

typedef struct pdt_run_opts {
    const char *command;     /* "triangulate" or "hull" */
    const char *input;       /* INPUT ("-" = standard input) */
    const char *output;      /* -o FILE; NULL = standard output */
    double scale;            /* --scale K; 0 = integer coordinates only */
    int stats;               /* --stats: JSON figures on stderr */
    const char *trace_dir;   /* --trace DIR; NULL = no trace */
    int trace_level;         /* --trace-level N (1 or 2; default 1) */
    int partition;           /* --partition strips|bisect (triangulate only):
                              * pdt_par_partition, PDT_PART_DEFAULT if not given */
    int argc;                /* the whole command line, for trace manifests */
    char **argv;
} pdt_run_opts;

/* Parse the options shared by `pdt triangulate` and `pdt hull` (INPUT, -o,
 * --scale, --stats, --trace, --trace-level; --partition for triangulate)
 * for command `cmd` into o.
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
/* The run folder is written whole under a temporary name beside DIR (rank
 * 0 makes it; pdt/safefile.h) and put in place only when the run and its
 * output succeeded, with the output:
 *   pdt_cli_trace_end    every rank: its rank file complete (t stays);
 *   pdt_cli_trace_swap   rank 0: the new folder in DIR's place, the old one
 *                        kept aside until
 *   pdt_cli_trace_finish every rank: keep = 1 removes the old folder,
 *                        keep = 0 puts it back (or removes the temporary
 *                        folder); frees t.  t may be NULL in all three. */
pdt_status pdt_cli_trace_end(pdt_cli_trace *t, pdt_err *err);
pdt_status pdt_cli_trace_swap(pdt_cli_trace *t, pdt_err *err);
void pdt_cli_trace_finish(pdt_cli_trace *t, int keep);

/* The trace of a `pdt triangulate` run on every rank of c (collective; the
 * same status at every rank): rank 0 creates the folder, then every rank
 * opens its rank file and the clocks are compared.  *t = NULL and PDT_OK
 * when o->trace_dir is NULL.  Records the beginning of the run. */
pdt_status pdt_cli_trace_open_ranks(const pdt_run_opts *o, pdt_comm *c, pdt_cli_trace **t,
                                    pdt_err *err);
/* Collective: points.bin of the input read into `in` (every rank writes its
 * block at its offset; the blocks' checksums are combined at rank 0), then
 * the manifest (rank 0).  The same bytes whatever the number of ranks; on
 * failure neither file is left.  Nothing if t is NULL. */
pdt_status pdt_cli_trace_manifest(pdt_cli_trace *t, const pdt_run_opts *o, pdt_comm *c,
                                  const pdt_par_input *in, pdt_err *err);

#endif
