/* pdt — tracing of a command run (run_opts.h).
 *
 * Placeholder until the trace writer lands: --trace DIR is parsed and passed
 * here, and reported as not available.  The trace module replaces this file
 * with one that creates the run folder through pdt_tw_open / pdt_tw_hook /
 * pdt_run_write_meta. */
#include "run_opts.h"

pdt_status pdt_cli_trace_open(const pdt_run_opts *o, const pdt_point *pts, size_t n,
                              pdt_cli_trace **t, pdt_err *err)
{
    (void)pts;
    (void)n;
    *t = NULL;
    if (!o->trace_dir) return PDT_OK;
    return pdt_err_set(err, PDT_ERR_ARG, "--trace %s: tracing is not available in this build "
                       "yet", o->trace_dir);
}

pdt_trace *pdt_cli_trace_hook(pdt_cli_trace *t)
{
    (void)t;
    return NULL;
}

pdt_status pdt_cli_trace_close(pdt_cli_trace *t, pdt_err *err)
{
    (void)t;
    (void)err;
    return PDT_OK;
}
