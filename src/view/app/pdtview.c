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
#include <langinfo.h>
#include <locale.h>
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
#include "pdt/view/ranktree.h"
#include "pdt/view/render.h"
#include "pdt/view/replay.h"
#include "pdt/tracefile.h"
#include "pdt/view/viewsynth.h"
#include "pdt/exit.h"
#include "pdt/opts.h"
#include "app.h"
#include "lecture.h"
#include "edit.h"
#include "shell.h"

/* --edit FILE: the editor's replay in the window, re-run after every change. */
int pdt_app_edit(const opts *o)
{
    pdt_live_opts lo = {o->hull, o->ranks ? o->ranks : 1, 1, 0};
    pdt_editor *ed;
    pdt_err err = {0};
    struct stat sb;
    if (!o->write_run && stat(o->edit, &sb) != 0 && !pdt_shell_video_init())
        return 1; /* (a missing file is made only for a window that opens) */
    if (pdt_editor_open(o->edit, &lo, &ed, &err) != PDT_OK) {
        fprintf(stderr, "pdtview: %s\n", err.msg);
        return PDT_EXIT_USAGE;
    }
    if (o->write_run) { /* the live run as a run folder (tests compare it with mpirun's) */
        loaded L = {0};
        const pdt_live_result *res = pdt_editor_run(ed);
        L.pts = pdt_editor_points(ed, &L.n);
        L.recs = res->recs;
        L.m = res->m;
        L.nranks = res->nranks;
        int rc = pdt_app_write_run(o->write_run, &L, lo.hull ? "hull" : "triangulate", lo.level, &err);
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
    v.help_more = pdt_editor_help(ed, &v.help_nmore);
    v.help_more_title = "Editor";
    char title[512];
    snprintf(title, sizeof title, "editing %s", o->edit);
    pdt_shell_opts so = {o->w, o->h, title, o->script, o->screenshot, o->speed,
                         o->record, o->fps, o->every, pdt_editor_hook(ed), o->fullscreen,
                         o->layout_report};
    int rc = pdt_shell_run(pdt_editor_replay(ed), pdt_editor_state(ed), &v, &so);
    pdt_editor_free(ed);
    return rc;
}

/* A kept index found damaged while it is read (pdt_replay_lazy_verify): say
 * so and stop (the replay cannot go on over a damaged table). */
static void index_damaged(const char *msg)
{
    fprintf(stderr, "pdtview: %s\n", msg);
    exit(PDT_EXIT_USAGE);
}

/* Kept indexes from this size on are verified chunk by chunk as they are
 * read ($PDTVIEW_VERIFY=lazy: all of them; =eager: none, whole at opening). */
#define LAZY_VERIFY_MIN ((uint64_t)64 << 20)

static void lazy_verify_setup(void)
{
    const char *verify = getenv("PDTVIEW_VERIFY");
    if (verify && !strcmp(verify, "eager")) return;
    pdt_replay_lazy_verify(index_damaged, verify && !strcmp(verify, "lazy") ? 0 : LAZY_VERIFY_MIN);
}

/* The replay of o's run: from its kept index, else loaded (into L) and
 * replayed; info says how.  With --write-run, the run is written instead
 * (*r stays NULL, *rc its status).  t0/c0: wall and CPU time at the start
 * (for --bench). */
static pdt_status open_run(const opts *o, loaded *L, pdt_replay **r, pdt_replay_open_info *info,
                           int *rc, pdt_err *err)
{
    double t0 = pdt_seconds(), c0 = cpu_s();
    /* a run folder with a valid kept index opens from the index alone */
    if (!o->write_run && o->index != 0 && strncmp(o->run, "synth:", 6) &&
        pdt_replay_open_kept(o->run, o->mem, r, info, err) != PDT_OK)
        return err->code;
    if (*r) {
        L->pts = pdt_replay_points(*r, &L->n);
        L->nranks = pdt_replay_nranks(*r);
        const char *w = pdt_replay_run_warnings(*r);
        if (*w) fprintf(stderr, "pdtview: %s: %s\n", o->run, w);
    } else if (pdt_app_load(o->run, L, err) != PDT_OK) {
        return err->code;
    }
    double t1 = pdt_seconds(), c1 = cpu_s();
    if (o->write_run) {
        if (L->run && pdt_run_merged(L->run, &L->recs, &L->m, err) != PDT_OK) return err->code;
        *rc = pdt_app_write_run(o->write_run, L, "triangulate", 2, err);
        if (!*rc && !o->quiet)
            printf("pdtview: wrote %zu events of %d ranks to %s\n", L->m, L->nranks, o->write_run);
        return PDT_OK;
    }
    if (!*r) {
        char why[sizeof info->why];
        snprintf(why, sizeof why, "%s", info->why);  /* why a kept index was not used */
        if (pdt_app_open_replay(L, o, r, info, err) != PDT_OK) return err->code;
        if (!*info->why) snprintf(info->why, sizeof info->why, "%s", why);
    }
    if (o->bench)
        printf("open %zu events, %zu points, %d ranks: %.3f s (read %.3f s + index %.3f s; "
               "cpu %.3f s + %.3f s)\n", pdt_replay_count(*r), L->n, L->nranks, pdt_seconds() - t0,
               t1 - t0, pdt_seconds() - t1, c1 - c0, cpu_s() - c1);
    return PDT_OK;
}

/* What the opening did: for --bench, the index's figures; otherwise why no
 * index could be kept or why one was rebuilt, and events the reader ignored. */
static void say_opening(const opts *o, const pdt_replay *r, const pdt_replay_open_info *info)
{
    if (o->bench) {
        if (info->indexed && info->built)
            printf("index build: working memory %.1f MiB (budget %.1f MiB; triangle events "
                   "grouped in %u buckets)\n", (double)info->build_bytes / 1048576.0,
                   (double)o->mem / 1048576.0, (unsigned)info->build_buckets);
        if (info->indexed)
            printf("kept index %s: %s%s%s\n", info->path,
                   info->built ? "built at this opening" : "mapped", *info->why ? "; " : "", info->why);
        else
            printf("in memory (no kept index)%s%s\n", *info->write_error ? ": " : "", info->write_error);
    } else if (!o->quiet && *info->write_error) { /* (neither beside the run nor in the cache) */
        if (*info->why && strcmp(info->why, "no index yet"))
            fprintf(stderr, "pdtview: %s: the index could not be used (%s)\n", o->run, info->why);
        fprintf(stderr, "pdtview: %s: no index kept (%s); the run is held in memory this time\n",
                o->run, info->write_error);
    } else if (!o->quiet && info->built && *info->why && strcmp(info->why, "no index yet")) {
        fprintf(stderr, "pdtview: %s: rebuilt the index (%s)\n", o->run, info->why);
    }
    if (pdt_replay_skipped(r) && !o->quiet)
        fprintf(stderr, "pdtview: %zu malformed events ignored\n", pdt_replay_skipped(r));
}

/* --hide R,R..: hidden[q] = 1 for each rank named. */
static pdt_status hide_ranks(const opts *o, const pdt_replay *r, uint8_t *hidden, pdt_err *err)
{
    for (const char *p = o->hide; p && *p;) {
        char *e;
        long q = strtol(p, &e, 10);
        if (e == p) break;
        if (q >= pdt_replay_nranks(r))
            return pdt_err_set(err, PDT_ERR_ARG, "--hide %ld: the run has %d ranks (0 .. %d)", q,
                               pdt_replay_nranks(r), pdt_replay_nranks(r) - 1);
        hidden[q] = 1;
        p = *e ? e + 1 : e;
    }
    return PDT_OK;
}

/* Where to start (--at, --end, --phase; the end headless and for --counts,
 * else 0): *k. */
static pdt_status start_cursor(const opts *o, const pdt_replay *r, size_t *k, pdt_err *err)
{
    *k = o->headless || o->counts ? pdt_replay_count(r) : 0;
    if (o->have_at) *k = o->at;
    if (o->end) *k = pdt_replay_count(r);
    if (o->phase) {
        *k = pdt_replay_phase_stop_named(r, o->phase);
        if (*k == (size_t)-1)
            return pdt_err_set(err, PDT_ERR_ARG, "%s: no phase named \"%s\" in this run", o->run,
                               o->phase);
    }
    if (*k > pdt_replay_count(r))
        return pdt_err_set(err, PDT_ERR_ARG, "--at %zu: the run has %zu events", *k,
                           pdt_replay_count(r));
    return PDT_OK;
}

/* The view the options ask for.  Without --panels, a cluster run (as many
 * ranks as make the timeline one of time) shows the timeline and the merge
 * tree, as lesson 12 does: the stacks, the lifted view and the code line of
 * hundreds of ranks at once say little, and the tree needs the room. */
static void view_of(const opts *o, int nranks, uint8_t *hidden, pdt_view *v)
{
    pdt_view_defaults(v);
    v->hidden = hidden;
    v->panels = o->panels;
    if (!o->panels_given && nranks >= PDT_RANKTREE_TIMED_RANKS)
        v->panels = PDT_PANEL_TIMELINE | PDT_PANEL_TREE;
    v->font_scale = o->font_scale;
    v->theme = o->theme;
    v->clean = o->clean;
    v->circles = o->circles;
    v->voronoi = o->voronoi;
}

/* The window with the lecturer's tools (lecture.h), and --beside's run. */
static int window(const opts *o, const pdt_replay *r, pdt_rstate *s, pdt_view *v, pdt_err *err)
{
    pdt_lecture *lec = NULL;
    loaded L2;
    memset(&L2, 0, sizeof L2);
    pdt_replay *r2 = NULL;
    pdt_rstate *s2 = NULL;
    pdt_replay_open_info info2;
    opts o2 = *o;
    o2.run = o->beside;
    int rc = PDT_EXIT_USAGE;
    if (pdt_lecture_new(r, s, o->bookmarks, &lec, err) != PDT_OK ||
        (o->beside && (pdt_app_load(o->beside, &L2, err) != PDT_OK ||
                       pdt_app_open_replay(&L2, &o2, &r2, &info2, err) != PDT_OK)))
        goto out;
    if (o->beside && (!(s2 = pdt_rstate_new(r2)) || pdt_lecture_beside(lec, r2, s2, err) != PDT_OK)) {
        if (!s2) pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
        goto out;
    }
    pdt_shell_opts so = {o->w, o->h, o->run, o->script, o->screenshot, o->speed,
                         o->record, o->fps, o->every, pdt_lecture_hook(lec), o->fullscreen,
                         o->layout_report};
    rc = pdt_shell_run(r, s, v, &so);
out:
    if (err->code != PDT_OK) fprintf(stderr, "pdtview: %s\n", err->msg);
    pdt_err_clear(err);
    pdt_lecture_free(lec);
    pdt_rstate_free(s2);
    pdt_replay_free(r2);
    pdt_app_unload(&L2);
    return rc;
}

/* Do what the options ask with the replay at cursor k: an exit status. */
static int act(const opts *o, const pdt_replay *r, pdt_rstate *s, pdt_view *v, size_t k,
               pdt_err *err)
{
    if (o->check) return pdt_app_check(r);
    if (o->describe) return pdt_app_describe(r, k);
    if (o->counts) {
        pdt_app_counts(r, s);
        return PDT_EXIT_OK;
    }
    if (!o->bench && !o->headless) return window(o, r, s, v, err);
    pdt_ranktree *tree = v->tree ? NULL : pdt_ranktree_new(r); /* one for every frame */
    if (tree) v->tree = tree;
    int rc;
    if (o->bench) rc = pdt_app_bench(r, s, v, o);
    else if (o->gif || o->video) {
        rc = PDT_EXIT_OK;
        if (pdt_app_animate(r, s, v, o, err)) {
            fprintf(stderr, "pdtview: %s\n", err->msg);
            pdt_err_clear(err);
            rc = PDT_EXIT_USAGE;
        }
    } else rc = pdt_app_headless(r, s, v, o, err);
    if (tree) v->tree = NULL;
    pdt_ranktree_free(tree);
    return rc;
}

/* SDL hands the window title (UTF-8) to X11 through the C library's
 * character type: under the "C" locale "pdtview — run" reaches the title
 * bar as "pdtview â".  Take the user's locale, else C.UTF-8. */
static void utf8_ctype(void)
{
    const char *cs = setlocale(LC_CTYPE, "") ? nl_langinfo(CODESET) : "";
    if (strcmp(cs, "UTF-8") && !setlocale(LC_CTYPE, "C.UTF-8")) setlocale(LC_CTYPE, "C");
}

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
            return PDT_EXIT_USAGE;
        }
    }
    if (o->write_run && in && pdt_safe_inside(in, o->write_run)) {
        fprintf(stderr, "pdtview: %s is inside the run folder %s that --write-run replaces; "
                "choose another folder; nothing written\n", in, o->write_run);
        return PDT_EXIT_USAGE;
    }
    return 0;
}

int main(int argc, char **argv)
{
    opts o;
    utf8_ctype();
    int prc = pdt_app_parse_args(argc, argv, &o);
    if (prc >= 0) return prc;
    if ((prc = check_outputs(&o))) return prc;
    if (o.bench_live) return pdt_app_bench_live(&o);
    if (o.edit) return pdt_app_edit(&o);
    lazy_verify_setup();
    pdt_err err = {0};
    loaded L;
    memset(&L, 0, sizeof L);
    pdt_replay *r = NULL;
    pdt_rstate *s = NULL;
    uint8_t *hidden = NULL;
    int rc = PDT_EXIT_USAGE;
    pdt_replay_open_info info;
    size_t k;
    if (open_run(&o, &L, &r, &info, &rc, &err) != PDT_OK || !r) goto out;
    say_opening(&o, r, &info);
    s = pdt_rstate_new(r);
    hidden = calloc((size_t)pdt_replay_nranks(r) + 1, 1);
    if (!s || !hidden) {
        pdt_err_set(&err, PDT_ERR_NOMEM, "out of memory");
        goto out;
    }
    if (hide_ranks(&o, r, hidden, &err) != PDT_OK || start_cursor(&o, r, &k, &err) != PDT_OK)
        goto out;
    pdt_replay_seek(r, s, k);
    pdt_view v;
    view_of(&o, pdt_replay_nranks(r), hidden, &v);
    rc = act(&o, r, s, &v, k, &err);
out:
    if (err.code != PDT_OK) { /* unreadable run, bad argument: 2, as for pdt */
        fprintf(stderr, "pdtview: %s\n", err.msg);
        rc = err.code == PDT_ERR_CHECK ? PDT_EXIT_CHECK : PDT_EXIT_USAGE;
    }
    free(hidden);
    pdt_rstate_free(s);
    pdt_replay_free(r);
    pdt_app_unload(&L);
    return rc;
}
