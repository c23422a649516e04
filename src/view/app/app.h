/* pdtview — the program's private header (src/view/app): its options, the
 * run it loaded, and the functions its files share. */
#ifndef PDT_VIEW_APP_H
#define PDT_VIEW_APP_H

#include <stddef.h>
#include <stdint.h>
#include <time.h>

#include "pdt/view/render.h"
#include "pdt/view/replay.h"
#include "pdt/tracefile.h"

#define PROG "pdtview"

typedef struct opts {
    const char *run, *out, *frames, *phase, *script, *screenshot, *hide, *write_run;
    int headless, end, every, w, h, have_at, quiet, bench, counts, check, describe;
    size_t at;
    double speed;
    unsigned panels; /* PDT_PANEL_* bits (--panels) */
    int panels_given; /* --panels was given (else a cluster run gets its own default) */
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
    const char *layout_report; /* --layout-report F.json: the texts of the frame drawn */
    const char *bookmarks; /* --bookmarks FILE: a lesson's key moments (lecture.h) */
    const char *beside;    /* --beside RUN2: a second run beside the first (beside.h) */
} opts;

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

static inline double cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- shared between the replay's files (each defined in the file named) ---- */

/* options.c */
int pdt_app_parse_args(int argc, char **argv, opts *o);

/* run.c */
pdt_status pdt_app_load(const char *name, loaded *L, pdt_err *err);
void pdt_app_unload(loaded *L);
pdt_status pdt_app_open_replay(const loaded *L, const opts *o, pdt_replay **r,
                              pdt_replay_open_info *info, pdt_err *err);
int pdt_app_write_run(const char *dir, const loaded *L, const char *command, int level,
                     pdt_err *err);

/* headless.c */
int pdt_app_headless(const pdt_replay *r, pdt_rstate *s, pdt_view *v, const opts *o, pdt_err *err);
int pdt_app_animate(const pdt_replay *r, pdt_rstate *s, const pdt_view *v, const opts *o,
                   pdt_err *err);
void pdt_app_counts(const pdt_replay *r, const pdt_rstate *s);
int pdt_app_describe(const pdt_replay *r, size_t start);
int pdt_app_check(const pdt_replay *r);

/* bench.c */
int pdt_app_bench(const pdt_replay *r, pdt_rstate *s, const pdt_view *v, const opts *o);
int pdt_app_bench_live(const opts *o);

/* pdtview.c */
int pdt_app_edit(const opts *o);

#endif
