/* pdtview — the command line: the help, and options checked into an opts. */
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

static const char help_text[] =
    "usage: pdtview RUN [--size WxH] [--at N|--phase NAME|--end] [--hide R,R..]\n"
    "               [--panels code,stack,lifted,timeline,tree,notes|all|none]\n"
    "               [--bookmarks FILE]   (a lesson's moments: b / Shift+b, notes pane n)\n"
    "               [--beside RUN2]   (RUN2 beside RUN, following it phase by phase)\n"
    "               [--script KEYS] [--screenshot FILE.png] [--speed EV_PER_S]\n"
    "               [--record FILE.gif|.mp4|.webm] [--fps F] [--every K]\n"
    "               [--font-scale F] [--theme light|dark|contrast] [--fullscreen]\n"
    "               [--clean] [--circles] [--voronoi] [--mem BYTES] [--index on|off|auto]\n"
    "               [--layout-report F.json]   (the texts of the last frame, at exit)\n"
    "       pdtview --headless RUN (--at N | --phase NAME | --end) -o FILE.png|.svg|.pdf\n"
    "               [--size WxH] [--layout-report F.json]   (every text placed: box,\n"
    "               pixel size, panel)\n"
    "       pdtview --headless RUN --frames DIR --every K [--size WxH]\n"
    "       pdtview --headless RUN --gif OUT.gif | --video OUT.mp4|OUT.webm\n"
    "               [--phase P | --from N --to M] [--every K] [--fps F] [--hold S]\n"
    "               [--size WxH]   (an animation: all events, a phase, or N..M; the last\n"
    "               frame stays S seconds, a GIF's 2 by default: --hold 0 for none)\n"
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

/* The options' values as given, before they are checked into an opts. */
typedef struct raw {
    const char *size, *panels, *theme, *mem, *index;
    uint64_t at, every, from, to, ranks;
    double hold;
    const char *pos[1];
    int npos;
} raw;

/* Parse argv into *o and *w: 0 to go on, else pdt_cli_parse's answer (1
 * after --help, 2 after a usage error). */
static int parse_table(int argc, char **argv, opts *o, raw *w)
{
    const pdt_cli_opt table[] = {
        {"--headless", NULL, PDT_OPT_FLAG, &o->headless},
        {"--bench", NULL, PDT_OPT_FLAG, &o->bench},
        {"--counts", NULL, PDT_OPT_FLAG, &o->counts},
        {"--check", NULL, PDT_OPT_FLAG, &o->check},
        {"--describe", NULL, PDT_OPT_FLAG, &o->describe},
        {"--write-run", NULL, PDT_OPT_STR, &o->write_run},
        {"--end", NULL, PDT_OPT_FLAG, &o->end},
        {"--quiet", NULL, PDT_OPT_FLAG, &o->quiet},
        {"--at", NULL, PDT_OPT_U64, &w->at},
        {"--phase", NULL, PDT_OPT_STR, &o->phase},
        {"--output", "-o", PDT_OPT_STR, &o->out},
        {"--frames", NULL, PDT_OPT_STR, &o->frames},
        {"--every", NULL, PDT_OPT_U64, &w->every},
        {"--size", NULL, PDT_OPT_STR, &w->size},
        {"--script", NULL, PDT_OPT_STR, &o->script},
        {"--screenshot", NULL, PDT_OPT_STR, &o->screenshot},
        {"--hide", NULL, PDT_OPT_STR, &o->hide},
        {"--panels", NULL, PDT_OPT_STR, &w->panels},
        {"--speed", NULL, PDT_OPT_POSNUM, &o->speed},
        {"--gif", NULL, PDT_OPT_STR, &o->gif},
        {"--video", NULL, PDT_OPT_STR, &o->video},
        {"--record", NULL, PDT_OPT_STR, &o->record},
        {"--fps", NULL, PDT_OPT_POSNUM, &o->fps},
        {"--hold", NULL, PDT_OPT_NUM, &w->hold},
        {"--from", NULL, PDT_OPT_U64, &w->from},
        {"--to", NULL, PDT_OPT_U64, &w->to},
        {"--edit", NULL, PDT_OPT_STR, &o->edit},
        {"--hull", NULL, PDT_OPT_FLAG, &o->hull},
        {"--ranks", NULL, PDT_OPT_U64, &w->ranks},
        {"--bench-live", NULL, PDT_OPT_U64, &o->bench_live},
        {"--font-scale", NULL, PDT_OPT_POSNUM, &o->font_scale},
        {"--theme", NULL, PDT_OPT_STR, &w->theme},
        {"--fullscreen", NULL, PDT_OPT_FLAG, &o->fullscreen},
        {"--clean", NULL, PDT_OPT_FLAG, &o->clean},
        {"--circles", NULL, PDT_OPT_FLAG, &o->circles},
        {"--voronoi", NULL, PDT_OPT_FLAG, &o->voronoi},
        {"--bookmarks", NULL, PDT_OPT_STR, &o->bookmarks},
        {"--beside", NULL, PDT_OPT_STR, &o->beside},
        {"--mem", NULL, PDT_OPT_STR, &w->mem},
        {"--index", NULL, PDT_OPT_STR, &w->index},
        {"--layout-report", NULL, PDT_OPT_STR, &o->layout_report},
        {NULL, NULL, PDT_OPT_FLAG, NULL},
    };
    return pdt_cli_parse(PROG, help_text, argc, argv, table, w->pos, 1, &w->npos);
}

/* The mode (--bench-live, --edit, or a RUN) and its arguments: -1 to go
 * on, else the exit status (message printed); likewise below. */
static int check_mode(opts *o, const raw *w)
{
    if (o->bench_live) {
        if (w->npos != 0 || o->edit)
            return pdt_cli_usage(PROG, "--bench-live N takes no RUN and no --edit");
        o->ranks = w->ranks < 1 ? 1 : (int)w->ranks;
    } else if (o->edit) {
        if (w->npos != 0 || o->headless)
            return pdt_cli_usage(PROG, "--edit FILE opens the editor window: no RUN, no --headless");
        if (w->ranks < 1 || w->ranks > 64)
            return pdt_cli_usage(PROG, "--ranks needs 1 .. 64, not '%llu'", (unsigned long long)w->ranks);
        o->ranks = (int)w->ranks;
    } else if (w->npos != 1) {
        return pdt_cli_usage(PROG, "needs one RUN (a run folder or synth:...)");
    }
    o->run = w->npos ? w->pos[0] : NULL;
    return -1;
}

/* Animations (--gif, --video, --record) and the range they cover. */
static int check_anim(opts *o, const raw *w)
{
    o->hold = w->hold;
    if (!o->fps) o->fps = 10;
    if (w->from != UINT64_MAX) o->from = (size_t)w->from, o->have_from = 1;
    if (w->to != UINT64_MAX) o->to = (size_t)w->to, o->have_to = 1;
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
    return -1;
}

/* The cursor and the picture: --at, --every, --size, --panels,
 * --font-scale, --theme. */
static int check_view(opts *o, raw *w)
{
    if (w->at != UINT64_MAX) {
        o->at = (size_t)w->at;
        o->have_at = 1;
    }
    if (w->every == UINT64_MAX) w->every = 1;
    else if (w->every == 0 || w->every > 1000000000)
        return pdt_cli_usage(PROG, "--every needs a whole number 1 .. 1000000000, not '%llu'",
                             (unsigned long long)w->every);
    o->every = (int)w->every;
    if (w->size && !parse_size(w->size, &o->w, &o->h))
        return pdt_cli_usage(PROG, "--size needs WxH, each 64 .. 16384, not '%s'", w->size);
    if (w->panels && pdt_panels_parse(w->panels, &o->panels) != 0)
        return pdt_cli_usage(PROG, "--panels needs a list of code, stack, lifted, timeline, "
                                   "tree, notes (or all, none), not '%s'", w->panels);
    o->panels_given = w->panels != NULL;
    if (o->font_scale < 0.4 || o->font_scale > 4)
        return pdt_cli_usage(PROG, "--font-scale needs a number 0.4 .. 4, not '%g'", o->font_scale);
    if (w->theme && pdt_theme_parse(w->theme, &o->theme) != 0)
        return pdt_cli_usage(PROG, "--theme needs light, dark or contrast, not '%s'", w->theme);
    return -1;
}

/* Memory and the kept index (--mem or $PDTVIEW_MEM, --index), --hide, and
 * what --headless writes. */
static int check_rest(opts *o, const raw *w)
{
    const char *env = getenv("PDTVIEW_MEM");
    o->mem = PDT_VIEW_MEM_DEFAULT;
    if (w->mem && pdt_cli_bytes(w->mem, &o->mem))
        return pdt_cli_usage(PROG, "--mem %s: not a byte count (e.g. 4096, 64M, 1G)", w->mem);
    if (!w->mem && env && *env && pdt_cli_bytes(env, &o->mem))
        return pdt_cli_usage(PROG, "PDTVIEW_MEM=%s: not a byte count (e.g. 4096, 64M, 1G)", env);
    o->index = -1;
    if (w->index && !strcmp(w->index, "on")) o->index = 1;
    else if (w->index && !strcmp(w->index, "off")) o->index = 0;
    else if (w->index && strcmp(w->index, "auto"))
        return pdt_cli_usage(PROG, "--index needs on, off or auto, not '%s'", w->index);
    if (o->hide && !valid_rank_list(o->hide))
        return pdt_cli_usage(PROG, "--hide needs rank numbers separated by commas, not '%s'", o->hide);
    if (o->headless && !o->out && !o->frames && !o->bench && !o->counts && !o->gif && !o->video)
        return pdt_cli_usage(PROG, "--headless needs -o FILE, --frames DIR, --gif FILE or --video FILE");
    if (o->layout_report && o->headless && !o->out)
        return pdt_cli_usage(PROG, "--layout-report F.json reports the picture of -o FILE: add -o");
    return -1;
}

/* Options into *o; returns -1 to go on, else the exit status (0 after
 * --help, 2 after a usage error, message printed). */
int pdt_app_parse_args(int argc, char **argv, opts *o)
{
    memset(o, 0, sizeof *o);
    o->w = 1600;
    o->h = 1000;
    o->speed = 20;
    o->panels = PDT_PANEL_ALL;
    o->font_scale = 1;
    raw w = {.at = UINT64_MAX, .every = UINT64_MAX, .from = UINT64_MAX, .to = UINT64_MAX, .ranks = 1,
             .hold = -1 /* not given: the animation's default (a GIF rests on its end) */};
    int rc = parse_table(argc, argv, o, &w);
    if (rc == 1) return PDT_EXIT_OK;
    if (rc) return PDT_EXIT_USAGE;
    if ((rc = check_mode(o, &w)) >= 0 || (rc = check_anim(o, &w)) >= 0 ||
        (rc = check_view(o, &w)) >= 0 || (rc = check_rest(o, &w)) >= 0)
        return rc;
    return -1;
}
