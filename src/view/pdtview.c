/* pdtview — replay a run folder step by step, in a window or headless.
 *
 *   pdtview RUN                                   the window
 *   pdtview --headless RUN (--at N | --phase NAME | --end) -o FILE.png|.svg|.pdf [--size WxH]
 *   pdtview --headless RUN --frames DIR --every K [--size WxH]
 *
 * RUN is a run folder (pdt triangulate/hull --trace DIR), or a synthetic run
 * "synth:srm:COLS:ROWS:RANKS" / "synth:graham:N" (for tests and demos). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "pdt/render.h"
#include "pdt/replay.h"
#include "pdt/tracefile.h"
#include "pdt/viewsynth.h"
#include "shell.h"

typedef struct opts {
    const char *run, *out, *frames, *phase, *script, *screenshot, *hide;
    int headless, end, every, w, h, have_at, quiet;
    size_t at;
    double speed;
} opts;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: pdtview RUN [--size WxH] [--at N|--phase NAME|--end] [--hide R,R..]\n"
            "               [--script KEYS] [--screenshot FILE.png] [--speed EV_PER_S]\n"
            "       pdtview --headless RUN (--at N | --phase NAME | --end) -o FILE.png|.svg|.pdf\n"
            "               [--size WxH]\n"
            "       pdtview --headless RUN --frames DIR --every K [--size WxH]\n"
            "RUN: a run folder, or synth:srm:COLS:ROWS:RANKS, synth:graham:N\n"
            "The cursor N counts events applied (0 = start, --end = all).\n"
            "Keys in the window: h or ? (help).  See docs/viewer.md.\n");
}

static int parse_size(const char *s, int *w, int *h)
{
    char *end;
    long a = strtol(s, &end, 10);
    if (*end != 'x' && *end != 'X') return 0;
    long b = strtol(end + 1, &end, 10);
    if (*end || a < 64 || b < 64 || a > 16384 || b > 16384) return 0;
    *w = (int)a;
    *h = (int)b;
    return 1;
}

static int parse_args(int argc, char **argv, opts *o)
{
    memset(o, 0, sizeof *o);
    o->w = 1600;
    o->h = 1000;
    o->speed = 20;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
#define NEED()                                                        \
    do {                                                              \
        if (!val) {                                                   \
            fprintf(stderr, "pdtview: %s needs a value\n", a);        \
            return 0;                                                 \
        }                                                             \
        i++;                                                          \
    } while (0)
        if (!strcmp(a, "--headless")) o->headless = 1;
        else if (!strcmp(a, "--end")) o->end = 1;
        else if (!strcmp(a, "--quiet")) o->quiet = 1;
        else if (!strcmp(a, "--at")) {
            NEED();
            char *e;
            o->at = strtoull(val, &e, 10);
            if (*e) {
                fprintf(stderr, "pdtview: --at %s: not a number\n", val);
                return 0;
            }
            o->have_at = 1;
        } else if (!strcmp(a, "--phase")) { NEED(); o->phase = val; }
        else if (!strcmp(a, "-o")) { NEED(); o->out = val; }
        else if (!strcmp(a, "--frames")) { NEED(); o->frames = val; }
        else if (!strcmp(a, "--every")) {
            NEED();
            o->every = atoi(val);
            if (o->every < 1) {
                fprintf(stderr, "pdtview: --every %s: need a positive number\n", val);
                return 0;
            }
        } else if (!strcmp(a, "--size")) {
            NEED();
            if (!parse_size(val, &o->w, &o->h)) {
                fprintf(stderr, "pdtview: --size %s: want WxH, 64..16384\n", val);
                return 0;
            }
        } else if (!strcmp(a, "--script")) { NEED(); o->script = val; }
        else if (!strcmp(a, "--screenshot")) { NEED(); o->screenshot = val; }
        else if (!strcmp(a, "--hide")) { NEED(); o->hide = val; }
        else if (!strcmp(a, "--speed")) {
            NEED();
            o->speed = atof(val);
            if (o->speed <= 0) o->speed = 20;
        } else if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            exit(0);
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "pdtview: unknown option %s\n", a);
            return 0;
        } else if (!o->run) o->run = a;
        else {
            fprintf(stderr, "pdtview: more than one run given (%s)\n", a);
            return 0;
        }
#undef NEED
    }
    if (!o->run) {
        fprintf(stderr, "pdtview: no run folder given\n");
        return 0;
    }
    if (o->headless && !o->out && !o->frames) {
        fprintf(stderr, "pdtview: --headless needs -o FILE or --frames DIR\n");
        return 0;
    }
    if (o->frames && !o->every) o->every = 1;
    return 1;
}

/* ---- the run ----------------------------------------------------------------- */

typedef struct loaded {
    pdt_run *run;
    pdt_synth syn;
    const pdt_point *pts;
    size_t n;
    const pdt_rec *recs;
    size_t m;
    int nranks;
} loaded;

static pdt_status load(const char *name, loaded *L, pdt_err *err)
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
    st = pdt_run_merged(L->run, &L->recs, &L->m, err);
    if (st != PDT_OK) return st;
    L->nranks = pdt_run_manifest(L->run)->nranks;
    const char *w = pdt_run_warnings(L->run);
    if (w && *w) fprintf(stderr, "pdtview: %s: %s\n", name, w);
    return PDT_OK;
}

static void unload(loaded *L)
{
    if (L->run) pdt_run_close(L->run);
    pdt_synth_free(&L->syn);
}

static int headless(const pdt_replay *r, pdt_rstate *s, pdt_view *v, const opts *o, pdt_err *err)
{
    size_t m = pdt_replay_count(r);
    if (o->out) {
        if (pdt_render_file(o->out, o->w, o->h, r, s, v, err) != PDT_OK) return 1;
        if (!o->quiet) printf("pdtview: wrote %s (event %zu of %zu)\n", o->out, s->k, m);
    }
    if (o->frames) {
        if (mkdir(o->frames, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "pdtview: %s: %s\n", o->frames, strerror(errno));
            return 1;
        }
        size_t count = 0;
        for (size_t k = 0;; k += (size_t)o->every) {
            if (k > m) k = m;
            pdt_replay_seek(r, s, k);
            char path[4096];
            snprintf(path, sizeof path, "%s/frame-%06zu.png", o->frames, count++);
            if (pdt_render_file(path, o->w, o->h, r, s, v, err) != PDT_OK) return 1;
            if (k == m) break;
        }
        if (!o->quiet) printf("pdtview: wrote %zu frames to %s\n", count, o->frames);
    }
    return 0;
}

int main(int argc, char **argv)
{
    opts o;
    if (!parse_args(argc, argv, &o)) {
        usage(stderr);
        return 2;
    }
    pdt_err err = {0};
    loaded L;
    pdt_replay *r = NULL;
    pdt_rstate *s = NULL;
    uint8_t *hidden = NULL;
    int rc = 1;
    if (load(o.run, &L, &err) != PDT_OK) goto out;
    if (pdt_replay_new(L.pts, L.n, L.recs, L.m, L.nranks, &r, &err) != PDT_OK) goto out;
    if (pdt_replay_skipped(r) && !o.quiet)
        fprintf(stderr, "pdtview: %zu malformed events ignored\n", pdt_replay_skipped(r));
    s = pdt_rstate_new(r);
    hidden = calloc((size_t)pdt_replay_nranks(r) + 1, 1);
    if (!s || !hidden) {
        pdt_err_set(&err, PDT_ERR_NOMEM, "out of memory");
        goto out;
    }
    if (o.hide) {
        for (const char *p = o.hide; *p;) {
            char *e;
            long q = strtol(p, &e, 10);
            if (e == p) break;
            if (q >= 0 && q < pdt_replay_nranks(r)) hidden[q] = 1;
            p = *e ? e + 1 : e;
        }
    }
    /* where to start */
    size_t k = o.headless ? pdt_replay_count(r) : 0;
    if (o.have_at) k = o.at;
    if (o.end) k = pdt_replay_count(r);
    if (o.phase) {
        k = pdt_replay_find_phase_name(r, o.phase);
        if (k == (size_t)-1) {
            pdt_err_set(&err, PDT_ERR_ARG, "%s: no phase named \"%s\" in this run", o.run, o.phase);
            goto out;
        }
    }
    if (k > pdt_replay_count(r)) {
        pdt_err_set(&err, PDT_ERR_ARG, "--at %zu: the run has %zu events", k, pdt_replay_count(r));
        goto out;
    }
    pdt_replay_seek(r, s, k);
    pdt_view v;
    pdt_view_defaults(&v);
    v.hidden = hidden;
    if (o.headless) {
        rc = headless(r, s, &v, &o, &err);
    } else {
        pdt_shell_opts so = {o.w, o.h, o.run, o.script, o.screenshot, o.speed};
        rc = pdt_shell_run(r, s, &v, &so);
    }
out:
    if (err.code != PDT_OK) fprintf(stderr, "pdtview: %s\n", err.msg);
    free(hidden);
    pdt_rstate_free(s);
    pdt_replay_free(r);
    unload(&L);
    return err.code != PDT_OK ? 1 : rc;
}
