/* pdt — the comments of the editor's point file (editnotes.c): read once
 * when the editor opens the file, written back with the points after every
 * change, each comment with the point it was written beside. */
#ifndef PDT_VIEW_EDITNOTES_H
#define PDT_VIEW_EDITNOTES_H

#include "pdt/common.h"
#include "pdt/io.h"

typedef struct pdt_edit_notes pdt_edit_notes;

/* The comments of the point file `path` (x y lines): *out NULL when it has
 * none or does not exist (then writing is pdt_write_points).  Fails only
 * when out of memory. */
pdt_status pdt_edit_notes_read(const char *path, pdt_edit_notes **out, pdt_err *err);
void pdt_edit_notes_free(pdt_edit_notes *N);
/* The point at `from` moved to `to`: its comments go with it. */
void pdt_edit_notes_moved(pdt_edit_notes *N, pdt_point from, pdt_point to);
/* Write the points to `path` atomically, each with its comments. */
pdt_status pdt_edit_notes_write(const pdt_edit_notes *N, const char *path, const pdt_point *pts,
                                size_t n, pdt_err *err);

#endif
