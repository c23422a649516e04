/* pdt — the layout report: every text a frame placed, with its box, its
 * pixel size and the panel it belongs to (pdtview --layout-report).
 *
 * A log is attached to a frame through pdt_view.texts; pdt_render() empties
 * it and records each text the renderer draws, in device pixels.  Drawing
 * code outside the renderer (a hook's overlay) records its texts with
 * pdt_text_log_note() on the same cairo context. */
#ifndef PDT_VIEW_TEXTLOG_H
#define PDT_VIEW_TEXTLOG_H

#include <cairo.h>
#include <stddef.h>

#include "pdt/common.h"

typedef struct pdt_text_log pdt_text_log;

/* One text placed: its ink box (device pixels), font size in pixels, the
 * panel ("picture", "event", "status", "code", "legend", "stack", "lifted",
 * "timeline", "tree", "notes", "help") and whether a clip cut part of it. */
typedef struct pdt_text_rec {
    const char *text;
    double x, y, w, h, px;
    const char *panel;
    int clipped;
} pdt_text_rec;

/* A new, empty log (NULL when out of memory); free with pdt_text_log_free. */
pdt_text_log *pdt_text_log_new(void);
void pdt_text_log_free(pdt_text_log *log);

/* Empty the log for a new w x h frame. */
void pdt_text_log_clear(pdt_text_log *log, double w, double h);

/* The texts recorded (valid until the next clear or note). */
const pdt_text_rec *pdt_text_log_texts(const pdt_text_log *log, size_t *n);

/* Texts drawn on cr from now on are recorded in log (NULL: no longer). */
void pdt_text_log_attach(cairo_t *cr, pdt_text_log *log);

/* The panel of the texts drawn next on cr (a static string); NULL: found
 * from where each text lies.  Does nothing when no log is attached. */
void pdt_text_log_panel(cairo_t *cr, const char *panel);

/* Record text s about to be shown at (x, y) (user space, baseline) with
 * cr's current font and `size` (user units).  Does nothing when no log is
 * attached to cr, or when the text falls wholly outside the clip. */
void pdt_text_log_note(cairo_t *cr, double size, double x, double y, const char *s);

/* Write the log as JSON: {"width", "height", "texts": [{"text", "x", "y",
 * "w", "h", "px", "panel", "clipped"}, ...]}. */
pdt_status pdt_text_log_write(const pdt_text_log *log, const char *path, pdt_err *err);

#endif
