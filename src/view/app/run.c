/* pdtview — loading a run (a run folder or a synthetic run) and writing one
 * as a run folder. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cairo.h>

#include "pdt/safefile.h"
#include "pdt/view/anim.h"
#include "pdt/view/describe.h"
#include "pdt/view/query.h"
#include "pdt/view/render.h"
#include "pdt/view/replay.h"
#include "pdt/tracefile.h"
#include "pdt/view/viewsynth.h"
#include "pdt/exit.h"
#include "pdt/opts.h"
#include "app.h"
#include "edit.h"
#include "shell.h"

pdt_status pdt_app_load(const char *name, loaded *L, pdt_err *err)
{
    memset(L, 0, sizeof *L);
    if (!strncmp(name, "synth:", 6)) {
        int a = 0, b = 0, c = 0;
        pdt_status st;
        if (sscanf(name, "synth:srm:%d:%d:%d", &a, &b, &c) == 3)
            st = pdt_synth_srm(a, b, c, 2, &L->syn, err);
        else if (sscanf(name, "synth:graham:%d", &a) == 1 && a > 0)
            st = pdt_synth_graham((size_t)a, 1, &L->syn, err);
        else
            return pdt_err_set(err, PDT_ERR_ARG, "%s: want synth:srm:COLS:ROWS:RANKS or synth:graham:N", name);
        if (st != PDT_OK) return st;
        L->pts = L->syn.pts;
        L->n = L->syn.n;
        L->recs = L->syn.recs;
        L->m = L->syn.m;
        L->nranks = L->syn.nranks;
        return PDT_OK;
    }
    pdt_status st = pdt_run_open(name, &L->run, err);
    if (st != PDT_OK) return st;
    L->pts = pdt_run_points(L->run, &L->n);
    L->nranks = pdt_run_manifest(L->run)->nranks;
    const char *w = pdt_run_warnings(L->run);
    if (w && *w) fprintf(stderr, "pdtview: %s: %s\n", name, w);
    return PDT_OK;
}

void pdt_app_unload(loaded *L)
{
    if (L->run) pdt_run_close(L->run);
    pdt_synth_free(&L->syn);
}

/* The replay of the loaded run: a run folder through pdt_replay_open_run
 * (kept index or memory, by the budget), a synthetic run in memory. */
pdt_status pdt_app_open_replay(const loaded *L, const opts *o, pdt_replay **r,
                              pdt_replay_open_info *info, pdt_err *err)
{
    memset(info, 0, sizeof *info);
    if (L->run) return pdt_replay_open_run(L->run, o->run, o->mem, o->index, r, info, err);
    pdt_status st = pdt_replay_new(L->pts, L->n, L->recs, L->m, L->nranks, r, err);
    if (st == PDT_OK) pdt_replay_set_mem(*r, o->mem);
    return st;
}

/* Write the loaded events to a run folder through the trace writer, in
 * their merged order (so the reader's causal merge finds the same order). */
int pdt_app_write_run(const char *dir, const loaded *L, const char *command, int level,
                     pdt_err *err)
{
    int p = L->nranks;
    pdt_trace_writer **w = calloc((size_t)p, sizeof *w);
    int64_t *off = calloc((size_t)p, sizeof *off);
    pdt_status st = PDT_OK;
    pdt_safe_dir sd = {0};  /* written whole beside DIR, swapped in at the end */
    if (!w || !off) st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    if (st == PDT_OK) st = pdt_safe_dir_open(&sd, dir, err);
    const char *into = sd.tmp;
    for (int q = 0; q < p && st == PDT_OK; q++) st = pdt_tw_open(into, q, level, &w[q], err);
    /* every writer's clock starts at its open: align them on rank 0's */
    if (st == PDT_OK) {
        uint64_t t0 = pdt_tw_now(w[0]);
        for (int q = 0; q < p; q++) off[q] = (int64_t)(t0 - pdt_tw_now(w[q]));
    }
    for (size_t i = 0; i < L->m && st == PDT_OK; i++) {
        pdt_trace *tr = pdt_tw_hook(w[L->recs[i].rank]);
        tr->sink(tr, &L->recs[i].ev);
    }
    for (int q = 0; q < p && w; q++) {
        pdt_status s2 = w[q] ? pdt_tw_close(w[q], err) : PDT_OK;
        if (st == PDT_OK) st = s2;
    }
    if (st == PDT_OK) {
        pdt_manifest mf;
        memset(&mf, 0, sizeof mf);
        mf.format_version = PDT_TRACE_FORMAT_MAJOR;
        snprintf(mf.program_version, sizeof mf.program_version, "%s", PDT_VERSION);
        mf.command_line = (char *)"pdtview --write-run";
        mf.input_name = (char *)"synthetic";
        mf.input_checksum = pdt_points_checksum(L->pts, L->n);
        mf.n = L->n;
        mf.nranks = p;
        mf.level = level;
        snprintf(mf.command, sizeof mf.command, "%s", command);
        mf.clock_offset_ns = off;
        mf.wall_start_ns = pdt_wall_ns();
        st = pdt_run_write_meta(into, &mf, L->pts, L->n, err);
    }
    if (st == PDT_OK) st = pdt_safe_dir_commit(&sd, err);
    else pdt_safe_dir_abort(&sd);
    free(w);
    free(off);
    return st == PDT_OK ? 0 : 1;
}
