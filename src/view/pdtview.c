/* pdtview — replay a run folder step by step, in a window or headless.
 *
 *   pdtview RUN                                   the window
 *   pdtview --headless RUN (--at N | --phase NAME | --end) -o FILE.png|.svg|.pdf [--size WxH]
 *   pdtview --headless RUN --frames DIR --every K [--size WxH]
 *   pdtview --headless RUN --gif OUT.gif | --video OUT.mp4|OUT.webm
 *           [--phase P | --from N --to M] [--every K] [--fps F] [--hold S] [--size WxH]
 *   pdtview --edit FILE [--hull] [--ranks P]   the point editor
 *   pdtview --edit FILE [--hull] [--ranks P] --write-run DIR
 *                                           its live run as a run folder, no window
 *   pdtview --bench RUN [--size WxH]        open / seek / draw figures
 *   pdtview --write-run DIR RUN             copy a (synthetic) run to a run folder
 *
 * RUN is a run folder (pdt triangulate/hull --trace DIR), or a synthetic run
 * "synth:srm:COLS:ROWS:RANKS" / "synth:graham:N" (for tests and demos). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cairo.h>

#include "pdt/anim.h"
#include "pdt/safefile.h"
#include "pdt/describe.h"
#include "pdt/query.h"
#include "pdt/render.h"
#include "pdt/replay.h"
#include "pdt/tracefile.h"
#include "pdt/viewsynth.h"
#include "edit.h"
#include "shell.h"
#include "../cli/cli.h"

#define PROG "pdtview"

typedef struct opts {
    const char *run, *out, *frames, *phase, *script, *screenshot, *hide, *write_run;
    int headless, end, every, w, h, have_at, quiet, bench, counts, check, describe;
    size_t at;
    double speed;
    unsigned panels; /* PDT_PANEL_* bits (--panels) */
    /* animation export (--gif / --video) and the window's record key */
    const char *gif, *video, *record;
    double fps, hold;
    size_t from, to;
    int have_from, have_to;
    const char *edit;  /* --edit FILE: the point editor */
    int ranks, hull;
    uint64_t bench_live; /* --bench-live N: editor re-run figures on N points */
    double font_scale;
    int theme, fullscreen, clean, circles, voronoi;
    uint64_t mem;      /* --mem BYTES (or $PDTVIEW_MEM): the viewer's memory budget */
    int index;         /* --index on|off|auto: 1, 0, -1 */
} opts;

static const char help_text[] =
    "usage: pdtview RUN [--size WxH] [--at N|--phase NAME|--end] [--hide R,R..]\n"
    "               [--panels code,stack,lifted,timeline|all|none]\n"
    "               [--script KEYS] [--screenshot FILE.png] [--speed EV_PER_S]\n"
    "               [--record FILE.gif|.mp4|.webm] [--fps F] [--every K]\n"
    "               [--font-scale F] [--theme light|dark|contrast] [--fullscreen]\n"
    "               [--clean] [--circles] [--voronoi] [--mem BYTES] [--index on|off|auto]\n"
    "       pdtview --headless RUN (--at N | --phase NAME | --end) -o FILE.png|.svg|.pdf\n"
    "               [--size WxH]\n"
    "       pdtview --headless RUN --frames DIR --every K [--size WxH]\n"
    "       pdtview --headless RUN --gif OUT.gif | --video OUT.mp4|OUT.webm\n"
    "               [--phase P | --from N --to M] [--every K] [--fps F] [--hold S]\n"
    "               [--size WxH]   (an animation: all events, a phase, or N..M)\n"
    "       pdtview --edit FILE [--ranks P] [--hull] [--size WxH]   (click points in;\n"
    "               P simulated ranks run the parallel code; keys 1..8 and x switch)\n"
    "       pdtview --edit FILE [--ranks P] [--hull] --write-run DIR   (the live run as a\n"
    "               run folder, no window)\n"
    "       pdtview --bench RUN [--size WxH]\n"
    "       pdtview RUN [--at N|--phase NAME|--end] --counts   (triangles by status)\n"
    "       pdtview RUN --check     (seek equals stepping, both ways, at every cursor)\n"
    "       pdtview RUN [--at N|--phase NAME|--end] --describe\n"
    "               (what the window says: the start cursor, the pseudo-code, and for every\n"
    "                event K its event line and lit code line; tab-separated)\n"
    "       pdtview --write-run DIR RUN\n"
    "RUN: a run folder, or synth:srm:COLS:ROWS:RANKS, synth:graham:N\n"
    "--mem BYTES (or $PDTVIEW_MEM; e.g. 64M, default 1G): memory for the replay; a run\n"
    "  larger than a quarter of it is opened through a kept index (RUN/.pdtview-index, or\n"
    "  ~/.cache/pdt when RUN is read-only), built at the first opening; --index forces it.\n"
    "The cursor N counts events applied (0 = start, --end = all).\n"
    "Keys in the window: h or ? (help).  See docs/viewer.md.\n";

/* "WxH", each 64 .. 16384. */
static int parse_size(const char *s, int *w, int *h)
{
    char *end;
    long a = strtol(s, &end, 10);
    if (end == s || (*end != 'x' && *end != 'X')) return 0;
    const char *b0 = end + 1;
    long b = strtol(b0, &end, 10);
    if (end == b0 || *end || a < 64 || b < 64 || a > 16384 || b > 16384) return 0;
    *w = (int)a;
    *h = (int)b;
    return 1;
}


/* "R,R,..": rank numbers separated by commas. */
static int valid_rank_list(const char *s)
{
    if (!*s) return 0;
    for (const char *p = s; *p;) {
        if (*p < '0' || *p > '9') return 0;
        while (*p >= '0' && *p <= '9') p++;
        if (*p == ',' && p[1]) p++;
        else if (*p) return 0;
    }
    return 1;
}

/* Options into *o; returns -1 to go on, else the exit status (0 after
 * --help, 2 after a usage error, message printed). */
static int parse_args(int argc, char **argv, opts *o)
{
    memset(o, 0, sizeof *o);
    o->w = 1600;
    o->h = 1000;
    o->speed = 20;
    o->panels = PDT_PANEL_ALL;
    const char *size = NULL, *panels = NULL, *theme = NULL, *mem = NULL, *index = NULL;
    o->font_scale = 1;
    uint64_t at = UINT64_MAX, every = UINT64_MAX, from = UINT64_MAX, to = UINT64_MAX,
             ranks = 1;
    double hold = 0;
    const pdt_cli_opt table[] = {
        {"--headless", NULL, PDT_OPT_FLAG, &o->headless},
        {"--bench", NULL, PDT_OPT_FLAG, &o->bench},
        {"--counts", NULL, PDT_OPT_FLAG, &o->counts},
        {"--check", NULL, PDT_OPT_FLAG, &o->check},
        {"--describe", NULL, PDT_OPT_FLAG, &o->describe},
        {"--write-run", NULL, PDT_OPT_STR, &o->write_run},
        {"--end", NULL, PDT_OPT_FLAG, &o->end},
        {"--quiet", NULL, PDT_OPT_FLAG, &o->quiet},
        {"--at", NULL, PDT_OPT_U64, &at},
        {"--phase", NULL, PDT_OPT_STR, &o->phase},
        {"--output", "-o", PDT_OPT_STR, &o->out},
        {"--frames", NULL, PDT_OPT_STR, &o->frames},
        {"--every", NULL, PDT_OPT_U64, &every},
        {"--size", NULL, PDT_OPT_STR, &size},
        {"--script", NULL, PDT_OPT_STR, &o->script},
        {"--screenshot", NULL, PDT_OPT_STR, &o->screenshot},
        {"--hide", NULL, PDT_OPT_STR, &o->hide},
        {"--panels", NULL, PDT_OPT_STR, &panels},
        {"--speed", NULL, PDT_OPT_POSNUM, &o->speed},
        {"--gif", NULL, PDT_OPT_STR, &o->gif},
        {"--video", NULL, PDT_OPT_STR, &o->video},
        {"--record", NULL, PDT_OPT_STR, &o->record},
        {"--fps", NULL, PDT_OPT_POSNUM, &o->fps},
        {"--hold", NULL, PDT_OPT_POSNUM, &hold},
        {"--from", NULL, PDT_OPT_U64, &from},
        {"--to", NULL, PDT_OPT_U64, &to},
        {"--edit", NULL, PDT_OPT_STR, &o->edit},
        {"--hull", NULL, PDT_OPT_FLAG, &o->hull},
        {"--ranks", NULL, PDT_OPT_U64, &ranks},
        {"--bench-live", NULL, PDT_OPT_U64, &o->bench_live},
        {"--font-scale", NULL, PDT_OPT_POSNUM, &o->font_scale},
        {"--theme", NULL, PDT_OPT_STR, &theme},
        {"--fullscreen", NULL, PDT_OPT_FLAG, &o->fullscreen},
        {"--clean", NULL, PDT_OPT_FLAG, &o->clean},
        {"--circles", NULL, PDT_OPT_FLAG, &o->circles},
        {"--voronoi", NULL, PDT_OPT_FLAG, &o->voronoi},
        {"--mem", NULL, PDT_OPT_STR, &mem},
        {"--index", NULL, PDT_OPT_STR, &index},
        {NULL, NULL, PDT_OPT_FLAG, NULL},
    };
    const char *pos[1];
    int npos;
    int rc = pdt_cli_parse(PROG, help_text, argc, argv, table, pos, 1, &npos);
    if (rc == 1) return PDT_EXIT_OK;
    if (rc) return PDT_EXIT_USAGE;
    if (o->bench_live) {
        if (npos != 0 || o->edit)
            return pdt_cli_usage(PROG, "--bench-live N takes no RUN and no --edit");
        o->ranks = ranks < 1 ? 1 : (int)ranks;
    } else if (o->edit) {
        if (npos != 0 || o->headless)
            return pdt_cli_usage(PROG, "--edit FILE opens the editor window: no RUN, no --headless");
        if (ranks < 1 || ranks > 64)
            return pdt_cli_usage(PROG, "--ranks needs 1 .. 64, not '%llu'", (unsigned long long)ranks);
        o->ranks = (int)ranks;
    } else if (npos != 1) {
        return pdt_cli_usage(PROG, "needs one RUN (a run folder or synth:...)");
    }
    o->run = npos ? pos[0] : NULL;
    o->hold = hold;
    if (!o->fps) o->fps = 10;
    if (from != UINT64_MAX) o->from = (size_t)from, o->have_from = 1;
    if (to != UINT64_MAX) o->to = (size_t)to, o->have_to = 1;
    if (o->video && pdt_anim_format_of(o->video) != PDT_ANIM_MP4 &&
        pdt_anim_format_of(o->video) != PDT_ANIM_WEBM)
        return pdt_cli_usage(PROG, "--video %s: want a name ending in .mp4 or .webm", o->video);
    if (o->gif && pdt_anim_format_of(o->gif) != PDT_ANIM_GIF)
        return pdt_cli_usage(PROG, "--gif %s: want a name ending in .gif", o->gif);
    if (o->record && pdt_anim_format_of(o->record) < 0)
        return pdt_cli_usage(PROG, "--record %s: want a name ending in .gif, .mp4 or .webm", o->record);
    if ((o->gif || o->video) && !o->headless)
        return pdt_cli_usage(PROG, "--gif and --video write files headless: add --headless");
    if ((o->have_from || o->have_to) && o->phase)
        return pdt_cli_usage(PROG, "give --phase or --from/--to, not both");
    if (at != UINT64_MAX) {
        o->at = (size_t)at;
        o->have_at = 1;
    }
    if (every == UINT64_MAX) every = 1;
    else if (every == 0 || every > 1000000000)
        return pdt_cli_usage(PROG, "--every needs a whole number 1 .. 1000000000, not '%llu'",
                             (unsigned long long)every);
    o->every = (int)every;
    if (size && !parse_size(size, &o->w, &o->h))
        return pdt_cli_usage(PROG, "--size needs WxH, each 64 .. 16384, not '%s'", size);
    if (panels && pdt_panels_parse(panels, &o->panels) != 0)
        return pdt_cli_usage(PROG, "--panels needs a list of code, stack, lifted, timeline (or all, "
                                   "none), not '%s'", panels);
    if (o->font_scale < 0.4 || o->font_scale > 4)
        return pdt_cli_usage(PROG, "--font-scale needs a number 0.4 .. 4, not '%g'", o->font_scale);
    if (theme && pdt_theme_parse(theme, &o->theme) != 0)
        return pdt_cli_usage(PROG, "--theme needs light, dark or contrast, not '%s'", theme);
    const char *env = getenv("PDTVIEW_MEM");
    o->mem = PDT_VIEW_MEM_DEFAULT;
    if (mem && pdt_cli_bytes(mem, &o->mem))
        return pdt_cli_usage(PROG, "--mem %s: not a byte count (e.g. 4096, 64M, 1G)", mem);
    if (!mem && env && *env && pdt_cli_bytes(env, &o->mem))
        return pdt_cli_usage(PROG, "PDTVIEW_MEM=%s: not a byte count (e.g. 4096, 64M, 1G)", env);
    o->index = -1;
    if (index && !strcmp(index, "on")) o->index = 1;
    else if (index && !strcmp(index, "off")) o->index = 0;
    else if (index && strcmp(index, "auto"))
        return pdt_cli_usage(PROG, "--index needs on, off or auto, not '%s'", index);
    if (o->hide && !valid_rank_list(o->hide))
        return pdt_cli_usage(PROG, "--hide needs rank numbers separated by commas, not '%s'", o->hide);
    if (o->headless && !o->out && !o->frames && !o->bench && !o->counts && !o->gif && !o->video)
        return pdt_cli_usage(PROG, "--headless needs -o FILE, --frames DIR, --gif FILE or --video FILE");
    return -1;
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

/* The replay of the loaded run: a run folder through pdt_replay_open_run
 * (kept index or memory, by the budget), a synthetic run in memory. */
static pdt_status open_replay(const loaded *L, const opts *o, pdt_replay **r,
                              pdt_replay_open_info *info, pdt_err *err)
{
    memset(info, 0, sizeof *info);
    if (L->run) return pdt_replay_open_run(L->run, o->run, o->mem, o->index, r, info, err);
    pdt_status st = pdt_replay_new(L->pts, L->n, L->recs, L->m, L->nranks, r, err);
    if (st == PDT_OK) pdt_replay_set_mem(*r, o->mem);
    return st;
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
            /* (a frame's name is ours: a link planted there is replaced, not followed) */
            if (pdt_render_file_ex(path, PDT_SAFE_NOFOLLOW, o->w, o->h, r, s, v, err) != PDT_OK)
                return 1;
            if (k == m) break;
        }
        if (!o->quiet) printf("pdtview: wrote %zu frames to %s\n", count, o->frames);
    }
    return 0;
}

/* The cursors of phase `name` ("merge", "merge:1", ...): from its first
 * PHASE_BEGIN to after the last PHASE_END of that phase on any rank.
 * Returns 0 when the run has no such phase. */
static int phase_range(const pdt_replay *r, const char *name, size_t *from, size_t *to)
{
    size_t k = pdt_replay_find_phase_name(r, name);
    if (k == (size_t)-1) return 0;
    size_t np, m = pdt_replay_count(r), len = strcspn(name, ":");
    const pdt_rphase *P = pdt_replay_phases(r, &np);
    int id = -1;
    for (int q = 0; q < PDT_PH_COUNT; q++)
        if (pdt_phase_name(q) && strlen(pdt_phase_name(q)) == len &&
            !strncmp(pdt_phase_name(q), name, len))
            id = q;
    long sub = name[len] ? strtol(name + len + 1, NULL, 10) : -1;
    *from = k ? k - 1 : 0;
    *to = *from;
    for (size_t i = 0; i < np; i++) {
        if ((int)P[i].phase != id || (sub >= 0 && P[i].sub != (uint32_t)sub)) continue;
        size_t end = P[i].end_ev == UINT32_MAX ? m : (size_t)P[i].end_ev + 1;
        if (end > *to) *to = end;
    }
    return 1;
}

/* --gif / --video: the events of the run, of a phase, or --from..--to. */
static int animate(const pdt_replay *r, pdt_rstate *s, const pdt_view *v, const opts *o,
                   pdt_err *err)
{
    size_t m = pdt_replay_count(r);
    pdt_anim_opts ao = {o->w, o->h, o->fps, 0, m, o->every ? (size_t)o->every : 1, o->hold};
    if (o->phase && !phase_range(r, o->phase, &ao.from, &ao.to)) {
        pdt_err_set(err, PDT_ERR_ARG, "%s: no phase named \"%s\" in this run", o->run, o->phase);
        return 1;
    }
    if (o->have_from) ao.from = o->from;
    if (o->have_to) ao.to = o->to;
    if (ao.to > m || ao.from > ao.to) {
        pdt_err_set(err, PDT_ERR_ARG, "--from %zu --to %zu: want from <= to <= %zu (the run's "
                    "events)", ao.from, ao.to, m);
        return 1;
    }
    const char *outs[2] = {o->gif, o->video};
    for (int i = 0; i < 2; i++) {
        if (!outs[i]) continue;
        size_t frames = 0;
        if (pdt_anim_replay(outs[i], &ao, r, s, v, &frames, err) != PDT_OK) return 2;
        if (!o->quiet)
            printf("pdtview: wrote %s (%zu frames of %dx%d at %g frames/s: events %zu to %zu, "
                   "every %zu)\n", outs[i], frames, o->w, o->h, o->fps, ao.from, ao.to, ao.every);
    }
    return 0;
}

static double cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

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
static int bench(const pdt_replay *r, pdt_rstate *s, const pdt_view *v, const opts *o)
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
            return 1;
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

/* Triangles by status at the cursor ("dropped": border-kernel candidates
 * that their merge neither kept nor shipped). */
static void counts(const pdt_replay *r, const pdt_rstate *s)
{
    size_t nt, c[PDT_TS_COUNT] = {0}, dropped = 0;
    pdt_replay_tris(r, &nt);
    const pdt_rtri_hist *H = pdt_replay_tri_hist(r);
    for (size_t t = 0; t < nt; t++) {
        uint32_t h = pdt_rstate_tri_entry(r, s, t);
        if (h != UINT32_MAX) c[H[h].status]++;
        else if (pdt_rstate_tri_status(r, s, t) != PDT_TS_NONE) dropped++;
    }
    printf("cursor %zu of %zu: candidate %zu final %zu deferred %zu shipped %zu discarded %zu dropped %zu\n",
           s->k, pdt_replay_count(r), c[PDT_TS_CANDIDATE], c[PDT_TS_FINAL], c[PDT_TS_DEFERRED],
           c[PDT_TS_SHIPPED], c[PDT_TS_DISCARDED], dropped);
}

/* What the window would show, for the lesson checks (scripts/lesson-check.py),
 * from the window's own functions: "start K" (the cursor the options give),
 * "listing NAME I TEXT" (the code panel's lines), and per event K
 * "event K LISTING LINE TEXT" (the listing the panel shows, the lit line,
 * 1-based, or "-" for none; the event line).  Tab-separated, one record per line. */
static int describe(const pdt_replay *r, size_t start)
{
    static const char *const names[PDT_CODE_COUNT] = {"graham", "srm"};
    printf("start\t%zu\n", start);
    for (int id = 0; id < PDT_CODE_COUNT; id++)
        for (size_t i = 0; i < pdt_code_count(id); i++)
            printf("listing\t%s\t%zu\t%s\n", names[id], i + 1, pdt_code_text(id, i));
    pdt_rstate *s = pdt_rstate_new(r);
    if (!s) {
        fprintf(stderr, "pdtview: out of memory\n");
        return 1;
    }
    char line[512];
    for (size_t k = 1; k <= pdt_replay_count(r); k++) {
        pdt_replay_step(r, s, 1);
        int id = -1, cl = pdt_replay_code_line(r, s, &id);
        pdt_replay_describe_state(r, s, k, line, sizeof line);
        const char *nm = id >= 0 && id < PDT_CODE_COUNT ? names[id] : "-";
        if (cl >= 0) printf("event\t%zu\t%s\t%d\t%s\n", k, nm, cl + 1, line);
        else printf("event\t%zu\t%s\t-\t%s\n", k, nm, line);
    }
    pdt_rstate_free(s);
    return ferror(stdout) ? 1 : 0;
}

/* Seek(k) == stepping forwards from 0 == stepping backwards from the end ==
 * the direct seek from the histories.  The seek starts from a pseudo-random
 * cursor each time, so that it goes through the checkpoints (made on the
 * way, within the --mem budget) as well as through stepping. */
static int check(const pdt_replay *r)
{
    size_t m = pdt_replay_count(r), bad = 0, stride = m > 20000 ? m / 20000 : 1;
    pdt_rstate *a = pdt_rstate_new(r), *b = pdt_rstate_new(r), *c = pdt_rstate_new(r);
    if (!a || !b || !c) {
        pdt_rstate_free(a);
        pdt_rstate_free(b);
        pdt_rstate_free(c);
        fprintf(stderr, "pdtview: out of memory\n");
        return 1;
    }
    uint64_t x = 0x9E3779B97F4A7C15ull;
    for (int pass = 0; pass < 2; pass++) {
        for (size_t i = 0; i <= m; i++) {
            size_t k = pass == 0 ? i : m - i;
            if (k % stride == 0 || k == m) {
                x ^= x << 13, x ^= x >> 7, x ^= x << 17;
                pdt_replay_seek(r, b, (size_t)(x % (m + 1)));
                pdt_replay_seek(r, b, k);
                pdt_replay_seek_direct(r, c, k);
                bad += !pdt_rstate_equal(r, a, b) || !pdt_rstate_equal(r, a, c);
            }
            if (i < m) pdt_replay_step(r, a, pass == 0 ? 1 : -1);
        }
    }
    size_t every, made, nck = pdt_replay_checkpoints(r, &every, &made);
    printf("check: %zu events, %zu cursors compared both ways, %zu differ", m,
           2 * (m / stride + 1), bad);
    if (nck) printf(" (checkpoints every %zu events: %zu of %zu made)", every, made, nck);
    if (a->paged[1]) printf(" (states paged: over a quarter of --mem)");
    printf("\n");
    pdt_rstate_free(a);
    pdt_rstate_free(b);
    pdt_rstate_free(c);
    return bad != 0;
}

/* Write the loaded events to a run folder through the trace writer, in
 * their merged order (so the reader's causal merge finds the same order). */
static int write_run(const char *dir, const loaded *L, const char *command, int level,
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

/* --edit FILE: the editor's replay in the window, re-run after every change. */
static int edit(const opts *o)
{
    pdt_live_opts lo = {o->hull, o->ranks ? o->ranks : 1, 1, 0};
    pdt_editor *ed;
    pdt_err err = {0};
    if (pdt_editor_open(o->edit, &lo, &ed, &err) != PDT_OK) {
        fprintf(stderr, "pdtview: %s\n", err.msg);
        return 2;
    }
    if (o->write_run) { /* the live run as a run folder (tests compare it with mpirun's) */
        loaded L = {0};
        const pdt_live_result *res = pdt_editor_run(ed);
        L.pts = pdt_editor_points(ed, &L.n);
        L.recs = res->recs;
        L.m = res->m;
        L.nranks = res->nranks;
        int rc = write_run(o->write_run, &L, lo.hull ? "hull" : "triangulate", lo.level, &err);
        if (rc) fprintf(stderr, "pdtview: %s\n", err.msg);
        else if (!o->quiet)
            printf("pdtview: wrote the live run of %s (%zu events, %d rank%s) to %s\n", o->edit,
                   L.m, L.nranks, L.nranks > 1 ? "s" : "", o->write_run);
        pdt_editor_free(ed);
        return rc ? 2 : 0;
    }
    pdt_view v;
    pdt_view_defaults(&v);
    v.panels = o->panels;
    v.font_scale = o->font_scale;
    v.theme = o->theme;
    v.clean = o->clean;
    v.circles = o->circles;
    v.voronoi = o->voronoi;
    v.help_more = pdt_editor_keys;
    v.help_nmore = pdt_editor_nkeys;
    v.help_more_title = "Editor";
    char title[512];
    snprintf(title, sizeof title, "editing %s", o->edit);
    pdt_shell_opts so = {o->w, o->h, title, o->script, o->screenshot, o->speed,
                         o->record, o->fps, o->every, pdt_editor_hook(ed), o->fullscreen};
    int rc = pdt_shell_run(pdt_editor_replay(ed), pdt_editor_state(ed), &v, &so);
    pdt_editor_free(ed);
    return rc;
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
static int bench_live(const opts *o)
{
    char dir[] = "/tmp/pdtview-bench-XXXXXX", path[64];
    if (!mkdtemp(dir)) {
        perror("pdtview: mkdtemp");
        return 1;
    }
    snprintf(path, sizeof path, "%s/points.txt", dir);
    pdt_live_opts lo = {o->hull, o->ranks, 1, 0};
    pdt_editor *ed = NULL;
    pdt_err err = {0};
    enum { NCLICK = 101 };
    double t[NCLICK], tc[NCLICK], tr[NCLICK];
    int rc = 1;
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
    rc = 0;
out:
    if (rc) fprintf(stderr, "pdtview: %s\n", err.msg);
    cairo_surface_destroy(sf);
    pdt_editor_free(ed);
    unlink(path);
    rmdir(dir);
    return rc;
}

/* A kept index found damaged while it is read (pdt_replay_lazy_verify): say
 * so and stop.  Called from a signal handler: write and _exit only. */
static void index_damaged(const char *msg)
{
    static const char pre[] = "pdtview: ";
    if (write(2, pre, sizeof pre - 1) < 0 || write(2, msg, strlen(msg)) < 0 || write(2, "\n", 1) < 0)
        _exit(1);
    _exit(1);
}

/* Kept indexes from this size on are verified chunk by chunk as they are
 * read ($PDTVIEW_VERIFY=lazy: all of them; =eager: none, whole at opening). */
#define LAZY_VERIFY_MIN ((uint64_t)64 << 20)

/* An input is never an output: the run folder or the edited file read must
 * not be replaced by -o, --gif, --video or --write-run (checked before
 * anything is written).  0, or the exit status after a message. */
static int check_outputs(const opts *o)
{
    const char *in = o->edit ? o->edit : o->run && strncmp(o->run, "synth:", 6) ? o->run : NULL;
    const char *outs[3] = {o->out, o->gif, o->video};
    for (int k = 0; k < 3 && in; k++) {
        if (!outs[k]) continue;
        if (o->edit ? pdt_safe_same_file(outs[k], in) : pdt_safe_touches_run(outs[k], in)) {
            fprintf(stderr, "pdtview: %s would replace %s%s, which is read; choose another "
                    "name; nothing written\n", outs[k], o->edit ? "" : "a file of the run folder ",
                    in);
            return 2;
        }
    }
    if (o->write_run && in && pdt_safe_inside(in, o->write_run)) {
        fprintf(stderr, "pdtview: %s is inside the run folder %s that --write-run replaces; "
                "choose another folder; nothing written\n", in, o->write_run);
        return 2;
    }
    return 0;
}

int main(int argc, char **argv)
{
    opts o;
    int prc = parse_args(argc, argv, &o);
    if (prc >= 0) return prc;
    if ((prc = check_outputs(&o))) return prc;
    if (o.bench_live) return bench_live(&o);
    if (o.edit) return edit(&o);
    const char *verify = getenv("PDTVIEW_VERIFY");
    if (!verify || strcmp(verify, "eager"))
        pdt_replay_lazy_verify(index_damaged, verify && !strcmp(verify, "lazy") ? 0 : LAZY_VERIFY_MIN);
    pdt_err err = {0};
    loaded L;
    pdt_replay *r = NULL;
    pdt_rstate *s = NULL;
    uint8_t *hidden = NULL;
    int rc = 1;
    double t0 = pdt_seconds(), c0 = cpu_s();
    pdt_replay_open_info info;
    memset(&L, 0, sizeof L);
    /* a run folder with a valid kept index opens from the index alone */
    if (!o.write_run && o.index != 0 && strncmp(o.run, "synth:", 6) &&
        pdt_replay_open_kept(o.run, o.mem, &r, &info, &err) != PDT_OK)
        goto out;
    if (r) {
        L.pts = pdt_replay_points(r, &L.n);
        L.nranks = pdt_replay_nranks(r);
        const char *w = pdt_replay_run_warnings(r);
        if (*w) fprintf(stderr, "pdtview: %s: %s\n", o.run, w);
    } else if (load(o.run, &L, &err) != PDT_OK) {
        goto out;
    }
    double t1 = pdt_seconds(), c1 = cpu_s();
    if (o.write_run) {
        if (L.run && pdt_run_merged(L.run, &L.recs, &L.m, &err) != PDT_OK) goto out;
        rc = write_run(o.write_run, &L, "triangulate", 2, &err);
        if (!rc && !o.quiet) printf("pdtview: wrote %zu events of %d ranks to %s\n", L.m, L.nranks, o.write_run);
        goto out;
    }
    if (!r) {
        char why[sizeof info.why];
        snprintf(why, sizeof why, "%s", info.why);  /* why a kept index was not used */
        if (open_replay(&L, &o, &r, &info, &err) != PDT_OK) goto out;
        if (!*info.why) snprintf(info.why, sizeof info.why, "%s", why);
    }
    if (o.bench) {
        printf("open %zu events, %zu points, %d ranks: %.3f s (read %.3f s + index %.3f s; "
               "cpu %.3f s + %.3f s)\n", pdt_replay_count(r), L.n, L.nranks, pdt_seconds() - t0,
               t1 - t0, pdt_seconds() - t1, c1 - c0, cpu_s() - c1);
        if (info.indexed && info.built)
            printf("index build: working memory %.1f MiB (budget %.1f MiB; triangle events "
                   "grouped in %u buckets)\n", (double)info.build_bytes / 1048576.0,
                   (double)o.mem / 1048576.0, (unsigned)info.build_buckets);
        if (info.indexed)
            printf("kept index %s: %s%s%s\n", info.path,
                   info.built ? "built at this opening" : "mapped", *info.why ? "; " : "", info.why);
        else
            printf("in memory (no kept index)%s%s\n", *info.write_error ? ": " : "", info.write_error);
    } else if (!o.quiet && info.built && *info.why && strcmp(info.why, "no index yet")) {
        fprintf(stderr, "pdtview: %s: rebuilt the index (%s)\n", o.run, info.why);
    }
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
            if (q >= pdt_replay_nranks(r)) {
                pdt_err_set(&err, PDT_ERR_ARG, "--hide %ld: the run has %d ranks (0 .. %d)", q,
                            pdt_replay_nranks(r), pdt_replay_nranks(r) - 1);
                goto out;
            }
            hidden[q] = 1;
            p = *e ? e + 1 : e;
        }
    }
    /* where to start */
    size_t k = o.headless || o.counts ? pdt_replay_count(r) : 0;
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
    v.panels = o.panels;
    v.font_scale = o.font_scale;
    v.theme = o.theme;
    v.clean = o.clean;
    v.circles = o.circles;
    v.voronoi = o.voronoi;
    if (o.check) {
        rc = check(r);
    } else if (o.describe) {
        rc = describe(r, k);
    } else if (o.counts) {
        counts(r, s);
        rc = 0;
    } else if (o.bench) {
        rc = bench(r, s, &v, &o);
    } else if (o.headless && (o.gif || o.video)) {
        rc = animate(r, s, &v, &o, &err);
        if (rc) {
            fprintf(stderr, "pdtview: %s\n", err.msg);
            pdt_err_clear(&err);
            rc = 2;
        }
    } else if (o.headless) {
        rc = headless(r, s, &v, &o, &err);
    } else {
        pdt_shell_opts so = {o.w, o.h, o.run, o.script, o.screenshot, o.speed,
                             o.record, o.fps, o.every, NULL, o.fullscreen};
        rc = pdt_shell_run(r, s, &v, &so);
    }
out:
    if (err.code != PDT_OK) { /* unreadable run, bad argument: 2, as for pdt */
        fprintf(stderr, "pdtview: %s\n", err.msg);
        rc = err.code == PDT_ERR_CHECK ? 1 : 2;
    }
    free(hidden);
    pdt_rstate_free(s);
    pdt_replay_free(r);
    unload(&L);
    return rc;
}
