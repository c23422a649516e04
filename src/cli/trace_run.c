/* pdt — tracing of a command run (run_opts.h): the run folder of
 * docs/trace-format.md, one rank file per rank, written through the trace
 * writer; the manifest and points.bin by rank 0. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "pdt/par.h"
#include "pdt/tracefile.h"
#include "run_opts.h"

struct pdt_cli_trace {
    pdt_trace_writer *w;
    int64_t *offsets; /* clock offsets of the ranks (rank 0's matter) */
    int nranks;
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

/* Refuse what cannot be traced (no error: PDT_OK). */
static pdt_status traceable(const pdt_run_opts *o, pdt_err *err)
{
#ifdef PDT_NO_TRACE
    return pdt_err_set(err, PDT_ERR_ARG, "--trace %s: this pdt was built with TRACE=0 (tracing "
                       "compiled out); rebuild with make TRACE=1", o->trace_dir);
#endif
    if (o->trace_level < 1)
        return pdt_err_set(err, PDT_ERR_ARG, "--trace %s with --trace-level 0: nothing would "
                           "be recorded (use level 1 or 2)", o->trace_dir);
    return PDT_OK;
}

/* The manifest of a run of o->command on n points over p ranks (checksum
 * and points of the whole input: rank 0's job). */
static pdt_status write_manifest(const pdt_run_opts *o, int p, const int64_t *offsets,
                                 const pdt_point *pts, size_t n, pdt_err *err)
{
    pdt_manifest m;
    memset(&m, 0, sizeof m);
    m.format_version = PDT_TRACE_FORMAT_MAJOR;
    strncpy(m.program_version, PDT_VERSION, sizeof m.program_version - 1);
    strncpy(m.command, o->command, sizeof m.command - 1);
    m.command_line = join_args(o->argc, o->argv);
    m.input_name = (char *)(o->input ? o->input : "-");
    m.input_checksum = pdt_points_checksum(pts, n);
    m.n = n;
    m.nranks = p;
    m.level = o->trace_level;
    m.clock_offset_ns = (int64_t *)offsets;
    m.wall_start_ns = pdt_wall_ns();
    pdt_status st = m.command_line ? pdt_run_write_meta(o->trace_dir, &m, pts, n, err)
                                   : pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    free(m.command_line);
    return st;
}

pdt_status pdt_cli_trace_open(const pdt_run_opts *o, const pdt_point *pts, size_t n,
                              pdt_cli_trace **t, pdt_err *err)
{
    *t = NULL;
    if (!o->trace_dir) return PDT_OK;
    pdt_status st = traceable(o, err);
    if (st != PDT_OK) return st;
    pdt_cli_trace *ct = calloc(1, sizeof *ct);
    if (!ct) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    st = pdt_tw_open(o->trace_dir, 0, o->trace_level, &ct->w, err);
    if (st != PDT_OK) {
        free(ct);
        return st;
    }
    /* the manifest first, so that a killed run still leaves a complete folder */
    int64_t offset0 = 0;
    st = write_manifest(o, 1, &offset0, pts, n, err);
    if (st != PDT_OK) {
        pdt_tw_abort(ct->w);
        free(ct);
        return st;
    }
    PDT_TRACE(pdt_tw_hook(ct->w), 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    *t = ct;
    return PDT_OK;
}

enum { TAG_CLOCK = 9, CLOCK_ROUNDS = 8 };

/* Clock offsets by ping-pong with rank 0 (the round with the smallest round
 * trip wins): off[q] is what to add to rank q's clock to get rank 0's.
 * off (size p) matters at rank 0 only. */
static pdt_status clock_offsets(pdt_comm *c, const pdt_trace_writer *w, int64_t *off,
                                pdt_err *err)
{
    int r = pdt_comm_rank(c), p = pdt_comm_size(c);
    pdt_status st = PDT_OK;
    off[0] = 0;
    for (int q = 1; q < p && st == PDT_OK; q++) {
        if (r != 0 && r != q) continue;
        int64_t best = INT64_MAX;
        for (int k = 0; k < CLOCK_ROUNDS && st == PDT_OK; k++) {
            void *buf = NULL;
            size_t len = 0;
            if (r == 0) {
                int64_t t0 = (int64_t)pdt_tw_now(w), tq;
                st = pdt_comm_send(c, q, TAG_CLOCK, &t0, sizeof t0, err);
                if (st == PDT_OK) st = pdt_comm_recv(c, q, TAG_CLOCK, &buf, &len, err);
                int64_t t1 = (int64_t)pdt_tw_now(w);
                if (st == PDT_OK && len == sizeof tq) {
                    memcpy(&tq, buf, sizeof tq);
                    if (t1 - t0 < best) {
                        best = t1 - t0;
                        off[q] = t0 + (t1 - t0) / 2 - tq;
                    }
                }
            } else {
                st = pdt_comm_recv(c, 0, TAG_CLOCK, &buf, &len, err);
                int64_t t = (int64_t)pdt_tw_now(w);
                if (st == PDT_OK) st = pdt_comm_send(c, 0, TAG_CLOCK, &t, sizeof t, err);
            }
            free(buf);
        }
    }
    return st;
}

pdt_status pdt_cli_trace_open_ranks(const pdt_run_opts *o, pdt_comm *c, pdt_cli_trace **t,
                                    pdt_err *err)
{
    *t = NULL;
    if (!o->trace_dir) return PDT_OK;
    int r = pdt_comm_rank(c), p = pdt_comm_size(c);
    pdt_cli_trace *ct = calloc(1, sizeof *ct);
    int64_t *off = calloc((size_t)p, sizeof *off);
    pdt_status st = ct && off ? traceable(o, err) : pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    /* rank 0 makes the folder first */
    if (st == PDT_OK && r == 0) st = pdt_tw_open(o->trace_dir, 0, o->trace_level, &ct->w, err);
    st = pdt_par_agree(c, st, NULL, err);
    if (st == PDT_OK && r != 0) st = pdt_tw_open(o->trace_dir, r, o->trace_level, &ct->w, err);
    st = pdt_par_agree(c, st, NULL, err);
    if (st == PDT_OK && p > 1) st = clock_offsets(c, ct->w, off, err);
    st = pdt_par_agree(c, st, NULL, err);
    if (st != PDT_OK) {
        if (ct && ct->w) pdt_tw_abort(ct->w);
        free(ct);
        free(off);
        return st;
    }
    ct->offsets = off;
    ct->nranks = p;
    PDT_TRACE(pdt_tw_hook(ct->w), 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    *t = ct;
    return PDT_OK;
}

pdt_status pdt_cli_trace_manifest(pdt_cli_trace *t, const pdt_run_opts *o, pdt_comm *c,
                                  const pdt_par_input *in, pdt_err *err)
{
    if (!t) return PDT_OK;
    /* the whole input at rank 0 (traced runs are small enough to be replayed) */
    int p = pdt_comm_size(c), r = pdt_comm_rank(c);
    pdt_point *all = r == 0 ? malloc((size_t)in->n_total * sizeof *all + 1) : NULL;
    size_t *cnt = malloc((size_t)p * sizeof *cnt);
    uint64_t *ks = malloc((size_t)p * sizeof *ks), k = in->n;
    pdt_status st = (r == 0 && !all) || !cnt || !ks
                        ? pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: trace: out of memory", r)
                        : PDT_OK;
    if (p > 1) {
        if (st == PDT_OK) st = pdt_comm_allgather(c, &k, sizeof k, ks, err);
        if (st == PDT_OK) {
            for (int q = 0; q < p; q++) cnt[q] = (size_t)ks[q] * sizeof(pdt_point);
            st = pdt_comm_gatherv(c, in->pts, in->n * sizeof(pdt_point), all, cnt, 0, err);
        }
    } else if (st == PDT_OK) {
        memcpy(all, in->pts, in->n * sizeof *all);
    }
    if (st == PDT_OK && r == 0)
        st = write_manifest(o, t->nranks, t->offsets, all, (size_t)in->n_total, err);
    free(all);
    free(cnt);
    free(ks);
    return pdt_par_agree(c, st, NULL, err);
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
    free(t->offsets);
    free(t);
    return st;
}
