/* pdt — the viewer's point editor (pdtview --edit FILE): points in, the
 * real algorithm re-run in the viewer's process after every change
 * (include/pdt/view/live.h), the replay reloaded at the same place.
 *
 * The model (open, add, move, delete, undo, redo, random points, presets,
 * modes) knows nothing of SDL; pdt_editor_hook() connects it to the shell
 * (left click adds, drag moves, right click deletes, keys).  FILE is written
 * atomically after every change, in the normal point format; a FILE that
 * does not parse is never written (pdt_editor_open fails with its file:line
 * message). */
#ifndef PDT_VIEW_EDIT_H
#define PDT_VIEW_EDIT_H

#include "pdt/view/live.h"
#include "pdt/view/render.h"
#include "shell.h"

typedef struct pdt_editor pdt_editor;

/* Presets (replace the points; undoable). */
typedef enum pdt_preset {
    PDT_PRESET_CIRCLE = 0, /* the 20 integer points of x^2 + y^2 = 25^2, shifted: all cocircular */
    PDT_PRESET_GRID,       /* 6 x 6 grid, spacing 10: every cell cocircular */
    PDT_PRESET_COLLINEAR,  /* 8 points on one line, and 3 off it */
    PDT_PRESET_DUPLICATES, /* 6 points, three of them given twice */
    PDT_PRESET_COUNT
} pdt_preset;

/* Open the editor on `path`: read its points (a missing file is created
 * empty), run the algorithm.  Fails, writing nothing, when the file does not
 * parse (err names file:line) or cannot be created.  o->ranks is the number
 * of simulated ranks.  The caller owns *ed (pdt_editor_free). */
pdt_status pdt_editor_open(const char *path, const pdt_live_opts *o, pdt_editor **ed,
                           pdt_err *err);
void pdt_editor_free(pdt_editor *ed);

/* Changes.  Each one pushes an undo step, saves the file and re-runs; each
 * returns PDT_OK, or an error (the change is refused and nothing changes:
 * out of range, no such point, ...; or the save failed, in which case the
 * change stays in memory and the message says so). */
pdt_status pdt_editor_add(pdt_editor *ed, int64_t x, int64_t y, pdt_err *err);
pdt_status pdt_editor_move(pdt_editor *ed, size_t i, int64_t x, int64_t y, pdt_err *err);
pdt_status pdt_editor_delete(pdt_editor *ed, size_t i, pdt_err *err);
/* k pseudo-random points inside [x0,x1] x [y0,y1] (clamped to int32). */
pdt_status pdt_editor_random(pdt_editor *ed, size_t k, int64_t x0, int64_t y0, int64_t x1,
                             int64_t y1, pdt_err *err);
pdt_status pdt_editor_preset(pdt_editor *ed, pdt_preset p, pdt_err *err);
/* Undo / redo one change (PDT_ERR_ARG when there is none). */
pdt_status pdt_editor_undo(pdt_editor *ed, pdt_err *err);
pdt_status pdt_editor_redo(pdt_editor *ed, pdt_err *err);
/* Switch mode: Graham's hull only, or the triangulation on `ranks` ranks. */
pdt_status pdt_editor_set_mode(pdt_editor *ed, int hull, int ranks, pdt_err *err);

/* The points (owned by ed, valid until the next change). */
const pdt_point *pdt_editor_points(const pdt_editor *ed, size_t *n);
/* The current run, its replay and the state shown (owned by ed). */
const pdt_live_result *pdt_editor_run(const pdt_editor *ed);
const pdt_replay *pdt_editor_replay(const pdt_editor *ed);
pdt_rstate *pdt_editor_state(pdt_editor *ed);
/* Seconds the last re-run took (algorithm + replay index + seek). */
double pdt_editor_last_run_s(const pdt_editor *ed);

/* The keys of ed's current mode (Graham's scan only, or the triangulation)
 * for the help overlay (pdt_view.help_more): {keys, what they do}, *n rows,
 * held by ed until its mode changes or it is freed. */
const char *const (*pdt_editor_help(pdt_editor *ed, int *n))[2];

/* The shell hook (input, current replay, overlay) for ed; valid while ed is. */
const pdt_shell_hook *pdt_editor_hook(pdt_editor *ed);

#endif
