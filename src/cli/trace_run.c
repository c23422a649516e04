/* pdt — tracing of a sequential command run (run_opts.h): the run folder of
 * docs/trace-format.md for one rank, written through the trace writer. */
#include <stdlib.h>
#include <string.h>

#include "pdt/tracefile.h"
#include "run_opts.h"

struct pdt_cli_trace {
    pdt_trace_writer *w;
};

/* The command line as one string, arguments separated by spaces. */
static char *join_args(int argc, char **argv)
{
    size_t len = 1;
    for (int i = 0; i < argc; i++) len += strlen(argv[i]) + 1;
    char *s = malloc(len), *p = s;
    if (!s) return NULL;
    for (int i = 0; i < argc; i++) {
        size_t k = strlen(argv[i]);
        if (i) *p++ = ' ';
        memcpy(p, argv[i], k);
        p += k;
    }
    *p = '\0';
    return s;
}

pdt_status pdt_cli_trace_open(const pdt_run_opts *o, const pdt_point *pts, size_t n,
                              pdt_cli_trace **t, pdt_err *err)
{
    *t = NULL;
    if (!o->trace_dir) return PDT_OK;
#ifdef PDT_NO_TRACE
    return pdt_err_set(err, PDT_ERR_ARG, "--trace %s: this pdt was built with TRACE=0 (tracing "
                       "compiled out); rebuild with make TRACE=1", o->trace_dir);
#endif
    if (o->trace_level < 1)
        return pdt_err_set(err, PDT_ERR_ARG, "--trace %s with --trace-level 0: nothing would "
                           "be recorded (use level 1 or 2)", o->trace_dir);
    pdt_cli_trace *ct = calloc(1, sizeof *ct);
    if (!ct) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    pdt_status st = pdt_tw_open(o->trace_dir, 0, o->trace_level, &ct->w, err);
    if (st != PDT_OK) {
        free(ct);
        return st;
    }
    /* the manifest first, so that a killed run still leaves a complete folder */
    int64_t offset0 = 0;
    pdt_manifest m;
    memset(&m, 0, sizeof m);
    m.format_version = PDT_TRACE_FORMAT_MAJOR;
    strncpy(m.program_version, PDT_VERSION, sizeof m.program_version - 1);
    strncpy(m.command, o->command, sizeof m.command - 1);
    m.command_line = join_args(o->argc, o->argv);
    m.input_name = (char *)(o->input ? o->input : "-");
    m.input_checksum = pdt_points_checksum(pts, n);
    m.n = n;
    m.nranks = 1;
    m.level = o->trace_level;
    m.clock_offset_ns = &offset0;
    m.wall_start_ns = pdt_wall_ns();
    if (!m.command_line) st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    else st = pdt_run_write_meta(o->trace_dir, &m, pts, n, err);
    free(m.command_line);
    if (st != PDT_OK) {
        pdt_tw_abort(ct->w);
        free(ct);
        return st;
    }
    PDT_TRACE(pdt_tw_hook(ct->w), 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    *t = ct;
    return PDT_OK;
}

pdt_trace *pdt_cli_trace_hook(pdt_cli_trace *t)
{
    return t ? pdt_tw_hook(t->w) : NULL;
}

void pdt_cli_trace_finals(pdt_cli_trace *t, const pdt_tri *tris, size_t ntri)
{
    if (!t) return;
    pdt_trace *tr = pdt_tw_hook(t->w);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_OUTPUT, 0, 0, 0, 0);
    for (size_t i = 0; i < ntri; i++)
        PDT_TRACE(tr, 1, PDT_EV_TRI_FINAL, 0, tris[i].v[0], tris[i].v[1], tris[i].v[2], 0);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_OUTPUT, 0, 0, 0, 0);
}

pdt_status pdt_cli_trace_close(pdt_cli_trace *t, pdt_err *err)
{
    if (!t) return PDT_OK;
    PDT_TRACE(pdt_tw_hook(t->w), 1, PDT_EV_PHASE_END, PDT_PH_RUN, 0, 0, 0, 0);
    pdt_status st = pdt_tw_close(t->w, err);
    free(t);
    return st;
}
