/* pdtview — what needs no window: pictures, frames, animations, and the
 * --counts, --describe and --check answers. */
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
#include "pdt/view/textlog.h"
#include "pdt/view/replay.h"
#include "pdt/tracefile.h"
#include "pdt/view/viewsynth.h"
#include "pdt/exit.h"
#include "pdt/opts.h"
#include "app.h"
#include "edit.h"
#include "shell.h"

int pdt_app_headless(const pdt_replay *r, pdt_rstate *s, pdt_view *v, const opts *o, pdt_err *err)
{
    size_t m = pdt_replay_count(r);
    if (o->out) {
        pdt_text_log *log = o->layout_report ? pdt_text_log_new() : NULL;
        if (o->layout_report && !log) {
            pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
            return PDT_EXIT_USAGE;
        }
        v->texts = log;
        pdt_status st = pdt_render_file(o->out, o->w, o->h, r, s, v, err);
        v->texts = NULL;
        if (st == PDT_OK && log) st = pdt_text_log_write(log, o->layout_report, err);
        pdt_text_log_free(log);
        if (st != PDT_OK) return PDT_EXIT_USAGE;
        if (!o->quiet) printf("pdtview: wrote %s (event %zu of %zu)\n", o->out, s->k, m);
    }
    if (o->frames) {
        if (mkdir(o->frames, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "pdtview: %s: %s\n", o->frames, strerror(errno));
            return PDT_EXIT_USAGE;
        }
        size_t count = 0;
        for (size_t k = 0;; k += (size_t)o->every) {
            if (k > m) k = m;
            pdt_replay_seek(r, s, k);
            char path[4096];
            snprintf(path, sizeof path, "%s/frame-%06zu.png", o->frames, count++);
            /* (a frame's name is ours: a link planted there is replaced, not followed) */
            if (pdt_render_file_ex(path, PDT_SAFE_NOFOLLOW, o->w, o->h, r, s, v, err) != PDT_OK)
                return PDT_EXIT_USAGE;
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
int pdt_app_animate(const pdt_replay *r, pdt_rstate *s, const pdt_view *v, const opts *o,
                   pdt_err *err)
{
    size_t m = pdt_replay_count(r);
    pdt_anim_opts ao = {o->w, o->h, o->fps, 0, m, o->every ? (size_t)o->every : 1, o->hold};
    if (o->phase && !phase_range(r, o->phase, &ao.from, &ao.to)) {
        pdt_err_set(err, PDT_ERR_ARG, "%s: no phase named \"%s\" in this run", o->run, o->phase);
        return PDT_EXIT_USAGE;
    }
    if (o->have_from) ao.from = o->from;
    if (o->have_to) ao.to = o->to;
    if (ao.to > m || ao.from > ao.to) {
        pdt_err_set(err, PDT_ERR_ARG, "--from %zu --to %zu: want from <= to <= %zu (the run's "
                    "events)", ao.from, ao.to, m);
        return PDT_EXIT_USAGE;
    }
    const char *outs[2] = {o->gif, o->video};
    for (int i = 0; i < 2; i++) {
        if (!outs[i]) continue;
        size_t frames = 0;
        if (pdt_anim_replay(outs[i], &ao, r, s, v, &frames, err) != PDT_OK) return PDT_EXIT_USAGE;
        if (!o->quiet)
            printf("pdtview: wrote %s (%zu frames of %dx%d at %g frames/s: events %zu to %zu, "
                   "every %zu)\n", outs[i], frames, o->w, o->h, o->fps, ao.from, ao.to, ao.every);
    }
    return 0;
}

/* Triangles by status at the cursor ("dropped": border-kernel candidates
 * that their merge neither kept nor shipped). */
void pdt_app_counts(const pdt_replay *r, const pdt_rstate *s)
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
/* The cursors PgDn visits from Home, each with its phase ("pgdn\tK\tNAME",
 * NAME:LEVEL for a merge level above 0), and where each rank's strip box is
 * first drawn ("box\tRANK\tK"), and from which cursor the legend's hull
 * swatch takes which rank's colour ("legend\thull\tK\tRANK"): what a
 * lesson's checks compare with its text. */
static void describe_stops(const pdt_replay *r)
{
    pdt_phase_stop st[128];
    size_t n = pdt_replay_phase_stops(r, st, 128), m = pdt_replay_count(r);
    for (size_t k = pdt_replay_find_phase_stop(r, 0, 1); k < m || (k == m && n && st[n - 1].k == m);
         k = pdt_replay_find_phase_stop(r, k, 1)) {
        const char *nm = "?";
        uint32_t sub = 0;
        for (size_t i = 0; i < n && i < 128; i++)
            if (st[i].k == k) nm = pdt_phase_name((int)st[i].phase), sub = st[i].sub;
        if (sub) printf("pgdn\t%zu\t%s:%u\n", k, nm ? nm : "?", sub);
        else printf("pgdn\t%zu\t%s\n", k, nm ? nm : "?");
        if (k == m) break;
    }
    for (int q = 0; q < pdt_replay_nranks(r); q++) {
        pdt_point lo, hi;
        if (pdt_replay_box(r, q, &lo, &hi)) printf("box\t%d\t%zu\n", q, pdt_replay_box_from(r, q));
    }
    /* the legend's hull swatch: from cursor K on, rank RANK's colour */
    size_t nh;
    const pdt_rhull *H = pdt_replay_hulls(r, &nh);
    int last = pdt_replay_hull_rank(r, 0);
    printf("legend\thull\t0\t%d\n", last);
    for (size_t i = 0; i < nh; i++) {
        int q = pdt_replay_hull_rank(r, (size_t)H[i].ev + 1);
        if (q != last) printf("legend\thull\t%zu\t%d\n", (size_t)H[i].ev + 1, q);
        last = q;
    }
}

int pdt_app_describe(const pdt_replay *r, size_t start)
{
    static const char *const names[PDT_CODE_COUNT] = {"graham", "srm"};
    printf("start\t%zu\n", start);
    describe_stops(r);
    for (int id = 0; id < PDT_CODE_COUNT; id++)
        for (size_t i = 0; i < pdt_code_count(id); i++)
            printf("listing\t%s\t%zu\t%s\n", names[id], i + 1, pdt_code_text(id, i));
    pdt_rstate *s = pdt_rstate_new(r);
    if (!s) {
        fprintf(stderr, "pdtview: out of memory\n");
        return PDT_EXIT_USAGE;
    }
    char line[512];
    for (size_t k = 0; k <= pdt_replay_count(r); k++) {
        if (k) pdt_replay_step(r, s, 1);
        int id = -1, cl = pdt_replay_code_line(r, s, &id);
        pdt_replay_describe_state(r, s, k, line, sizeof line);
        const char *nm = id >= 0 && id < PDT_CODE_COUNT ? names[id] : "-";
        if (cl >= 0) printf("event\t%zu\t%s\t%d\t%s\n", k, nm, cl + 1, line);
        else printf("event\t%zu\t%s\t-\t%s\n", k, nm, line);
    }
    pdt_rstate_free(s);
    return ferror(stdout) ? PDT_EXIT_USAGE : PDT_EXIT_OK;
}

/* Seek(k) == stepping forwards from 0 == stepping backwards from the end ==
 * the direct seek from the histories.  The seek starts from a pseudo-random
 * cursor each time, so that it goes through the checkpoints (made on the
 * way, within the --mem budget) as well as through stepping. */
int pdt_app_check(const pdt_replay *r)
{
    size_t m = pdt_replay_count(r), bad = 0, stride = m > 20000 ? m / 20000 : 1;
    pdt_rstate *a = pdt_rstate_new(r), *b = pdt_rstate_new(r), *c = pdt_rstate_new(r);
    if (!a || !b || !c) {
        pdt_rstate_free(a);
        pdt_rstate_free(b);
        pdt_rstate_free(c);
        fprintf(stderr, "pdtview: out of memory\n");
        return PDT_EXIT_USAGE;
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
    return bad ? PDT_EXIT_CHECK : PDT_EXIT_OK;
}
