/* pdtview — --bench and --bench-live: open, seek, draw and live-edit figures. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cairo.h>

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

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, size_t n)
{
    qsort(v, n, sizeof *v, cmp_d);
    return n ? v[n / 2] : 0;
}

/* The process's peak and current memory (/proc/self/status): mapped index
 * pages count in RssFile, the replay's own memory in RssAnon. */
static void print_memory(const char *label)
{
    FILE *f = fopen("/proc/self/status", "r");
    if (!f) return;
    char line[256], out[256];
    snprintf(out, sizeof out, "%s:", label);
    while (fgets(line, sizeof line, f)) {
        static const char *const keys[] = {"VmHWM:", "VmRSS:", "RssAnon:", "RssFile:"};
        for (int i = 0; i < 4; i++) {
            unsigned long kb;
            if (!strncmp(line, keys[i], strlen(keys[i])) &&
                sscanf(line + strlen(keys[i]), "%lu", &kb) == 1) {
                size_t len = strlen(out);
                snprintf(out + len, sizeof out - len, " %.*s %.1f MiB", (int)strlen(keys[i]) - 1,
                         keys[i], (double)kb / 1024.0);
            }
        }
    }
    fclose(f);
    printf("%s (peak VmHWM; RssFile: pages of the mapped index and run)\n", out);
}

/* Figures for scripts/bench/40-view.sh: seek, step back, frames per second. */
int pdt_app_bench(const pdt_replay *r, pdt_rstate *s, const pdt_view *v, const opts *o)
{
    size_t m = pdt_replay_count(r), nt, ne;
    pdt_replay_tris(r, &nt);
    pdt_replay_edges(r, &ne);
    enum { NSEEK = 101 };
    double t[NSEEK], tc[NSEEK];
    uint64_t x = 88172645463325252ull;
    /* two rounds of random cursors: the first makes checkpoints on the way */
    for (int round = 0; round < 2; round++) {
        for (int i = 0; i < NSEEK; i++) {
            x ^= x << 13, x ^= x >> 7, x ^= x << 17;
            size_t k = m ? (size_t)(x % (m + 1)) : 0;
            double t0 = pdt_seconds(), c0 = cpu_s();
            pdt_replay_seek(r, s, k);
            t[i] = pdt_seconds() - t0;
            tc[i] = cpu_s() - c0;
        }
        double worst = 0, worst_c = 0;
        for (int i = 0; i < NSEEK; i++) {
            if (t[i] > worst) worst = t[i];
            if (tc[i] > worst_c) worst_c = tc[i];
        }
        printf("seek (random cursor, %s, median of %d): %.2f ms wall, %.2f ms CPU; worst %.2f ms "
               "wall, %.2f ms CPU\n", round ? "again" : "first round", NSEEK,
               1e3 * median(t, NSEEK), 1e3 * median(tc, NSEEK), 1e3 * worst, 1e3 * worst_c);
    }
    print_memory("memory after the seeks");
    size_t every, made, nck = pdt_replay_checkpoints(r, &every, &made);
    if (nck)
        printf("checkpoints: every %zu events, %zu of %zu made, %.1f MiB each\n", every, made, nck,
               (double)pdt_replay_state_bytes(r) / 1048576.0);
    else
        printf("checkpoints: none (the budget holds fewer than two states of %.1f MiB)\n",
               (double)pdt_replay_state_bytes(r) / 1048576.0);
    for (int i = 0; i < NSEEK; i++) {
        double t0 = pdt_seconds();
        for (int j = 0; j < 1000; j++) pdt_replay_step(r, s, -1);
        t[i] = (pdt_seconds() - t0) / 1000;
    }
    printf("step back (median): %.3f us\n", 1e6 * median(t, NSEEK));
    pdt_replay_seek(r, s, m);
    size_t drawn = 0;
    for (size_t i = 0; i < nt; i++)
        if (pdt_rstate_tri_status(r, s, i) != PDT_TS_NONE && pdt_rstate_tri_status(r, s, i) != PDT_TS_DISCARDED)
            drawn++;
    cairo_surface_t *sf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, o->w, o->h);
    int frames = 0;
    double t0 = pdt_seconds(), el = 0, c0 = cpu_s();
    pdt_err err = {0};
    while (frames < 3 || (el < 3.0 && frames < 200)) {
        cairo_t *cr = cairo_create(sf);
        if (pdt_render(cr, o->w, o->h, r, s, v, &err) != PDT_OK) {
            fprintf(stderr, "pdtview: %s\n", err.msg);
            cairo_destroy(cr);
            cairo_surface_destroy(sf);
            return PDT_EXIT_USAGE;
        }
        cairo_destroy(cr);
        frames++;
        el = pdt_seconds() - t0;
    }
    cairo_surface_destroy(sf);
    double cpu = cpu_s() - c0;
    printf("draw %zu triangles (%zu edges) at %dx%d: %.1f frames/s wall, %.1f ms CPU per frame "
           "(of all threads: the level of detail's pass runs on two from 2^20 triangles; "
           "%d frames)\n", drawn, 3 * drawn, o->w, o->h, frames / el, 1e3 * cpu / frames, frames);
    print_memory("memory");
    return 0;
}

/* One frame of the editor's replay drawn into sf. */
static pdt_status draw_once(cairo_surface_t *sf, const opts *o, pdt_editor *ed, const pdt_view *v,
                            pdt_err *err)
{
    cairo_t *cr = cairo_create(sf);
    pdt_status st = pdt_render(cr, o->w, o->h, pdt_editor_replay(ed), pdt_editor_state(ed), v, err);
    cairo_destroy(cr);
    cairo_surface_flush(sf);
    return st;
}

/* --bench-live N: what a click costs in the editor on N points: the change
 * (save + re-run + replay index + seek) and one frame drawn at --size;
 * 101 changes (adds and deletes alternating), median and worst. */
int pdt_app_bench_live(const opts *o)
{
    char dir[] = "/tmp/pdtview-bench-XXXXXX", path[64];
    if (!mkdtemp(dir)) {
        perror("pdtview: mkdtemp");
        return PDT_EXIT_USAGE;
    }
    snprintf(path, sizeof path, "%s/points.txt", dir);
    pdt_live_opts lo = {o->hull, o->ranks, 1, 0};
    pdt_editor *ed = NULL;
    pdt_err err = {0};
    enum { NCLICK = 101 };
    double t[NCLICK], tc[NCLICK], tr[NCLICK];
    int rc = PDT_EXIT_USAGE;
    cairo_surface_t *sf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, o->w, o->h);
    pdt_view v;
    pdt_view_defaults(&v);
    v.panels = o->panels;
    if (pdt_editor_open(path, &lo, &ed, &err) != PDT_OK ||
        pdt_editor_random(ed, (size_t)o->bench_live, 0, 0, 10000, 10000, &err) != PDT_OK)
        goto out;
    /* the opening frame: the window draws it when the editor opens, before
     * any click can come (fonts and cairo's caches warm up here) */
    double o0 = pdt_seconds(), oc0 = cpu_s();
    if (draw_once(sf, o, ed, &v, &err) != PDT_OK) goto out;
    double open_wall = pdt_seconds() - o0, open_cpu = cpu_s() - oc0;
    uint64_t x = 88172645463325252ull;
    for (int i = 0; i < NCLICK; i++) {
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        double t0 = pdt_seconds(), c0 = cpu_s();
        size_t n;
        pdt_editor_points(ed, &n);
        pdt_status st = i % 2 ? pdt_editor_delete(ed, n - 1, &err)
                              : pdt_editor_add(ed, (int64_t)(x % 10001), (int64_t)(x / 10001 % 10001), &err);
        if (st != PDT_OK) goto out;
        tr[i] = pdt_editor_last_run_s(ed);
        if (draw_once(sf, o, ed, &v, &err) != PDT_OK) goto out;
        t[i] = pdt_seconds() - t0;
        tc[i] = cpu_s() - c0;
    }
    double worst = 0, worst_cpu = 0;
    for (int i = 0; i < NCLICK; i++) {
        worst = t[i] > worst ? t[i] : worst;
        worst_cpu = tc[i] > worst_cpu ? tc[i] : worst_cpu;
    }
    double load = -1;
    FILE *la = fopen("/proc/loadavg", "r");
    if (la) {
        if (fscanf(la, "%lf", &load) != 1) load = -1;
        fclose(la);
    }
    printf("live edit, %llu points, %s, %d rank%s, frame %dx%d: click to redrawn frame median %.2f ms "
           "wall (%.2f ms CPU), worst %.2f ms wall (%.2f ms CPU); of which save + re-run + index + seek "
           "median %.2f ms (%d changes; load %.1f); the opening frame before them %.1f ms wall (%.1f ms CPU)\n",
           (unsigned long long)o->bench_live, o->hull ? "hull" : "triangulate", o->ranks,
           o->ranks > 1 ? "s" : "", o->w, o->h, 1e3 * median(t, NCLICK), 1e3 * median(tc, NCLICK),
           1e3 * worst, 1e3 * worst_cpu, 1e3 * median(tr, NCLICK), NCLICK, load, 1e3 * open_wall,
           1e3 * open_cpu);
    rc = PDT_EXIT_OK;
out:
    if (rc) fprintf(stderr, "pdtview: %s\n", err.msg);
    cairo_surface_destroy(sf);
    pdt_editor_free(ed);
    unlink(path);
    rmdir(dir);
    return rc;
}
