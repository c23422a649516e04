/* pdt — input and output: point files, triangle files, atomic writes.
 *
 * Readers report every problem as "FILE:LINE: what is wrong" through pdt_err
 * and return PDT_ERR_PARSE (or PDT_ERR_IO).  Writers never leave a
 * half-written file: they write to a temporary file next to the target and
 * rename it into place only when everything succeeded. */
#ifndef PDT_IO_H
#define PDT_IO_H

#include <stdio.h>

#include "pdt/common.h"

/* ---- atomic output ---------------------------------------------------- */

typedef struct pdt_outfile {
    FILE *fp;        /* write here */
    char *path;      /* final name (NULL for standard output) */
    char *tmp;       /* temporary name (NULL: writing directly) */
} pdt_outfile;

/* Open `path` for atomic writing ("-" or NULL = standard output).  A path
 * that names an existing device or pipe (/dev/null, a fifo) is written
 * directly, never replaced. */
pdt_status pdt_out_open(pdt_outfile *o, const char *path, pdt_err *err);
/* Flush, close and rename into place.  On any write error the temporary is
 * removed and an error returned. */
pdt_status pdt_out_commit(pdt_outfile *o, pdt_err *err);
/* Close and remove the temporary (nothing is left behind). */
void pdt_out_abort(pdt_outfile *o);

/* ---- points ------------------------------------------------------------ */

/* Read points.  Format by extension: ".node" is Triangle's node format,
 * anything else is text, one point "x y" per line, blank lines and '#'
 * comments allowed.  With scale == 0 coordinates must be integers that fit
 * in int32; with scale > 0 decimal coordinates are multiplied by scale and
 * rounded to the nearest integer (then *collisions, if not NULL, counts the
 * points that became equal to an earlier distinct-looking point).
 * *pts is malloc'd (caller frees). */
pdt_status pdt_read_points(const char *path, double scale, pdt_point **pts, size_t *n,
                           size_t *collisions, pdt_err *err);

/* Write points as text ("x y" per line) or, for a ".node" path, Triangle's
 * node format.  Atomic. */
pdt_status pdt_write_points(const char *path, const pdt_point *pts, size_t n, pdt_err *err);

/* ---- triangles ---------------------------------------------------------- */

typedef enum pdt_tri_format {
    PDT_FMT_TRI = 0, /* canonical: "i j k" per line, 0-based */
    PDT_FMT_ELE,     /* Triangle's .ele (+ matching .node beside it) */
    PDT_FMT_OFF      /* Geomview OFF */
} pdt_tri_format;

/* Format chosen by the extension of path (.tri, .ele, .off); NULL/"-" = tri. */
pdt_tri_format pdt_tri_format_of(const char *path);

/* Write triangles (input indices) in the given format; atomic.  `pts` is
 * needed for .ele (writes the .node) and .off. */
pdt_status pdt_write_tris(const char *path, pdt_tri_format fmt, const pdt_point *pts, size_t n,
                          const pdt_tri *tris, size_t ntri, pdt_err *err);

/* ---- formatting, for writers that place the bytes themselves ----------------
 * (the parallel write: every rank formats its block of lines and writes it
 * at its offset; the plain writer above formats with the same functions). */

/* What a block of lines holds. */
typedef enum pdt_lines {
    PDT_LINES_TRI,       /* triangles "a b c" (.tri) */
    PDT_LINES_ELE,       /* triangles "i a b c", i = first + k (.ele) */
    PDT_LINES_OFF_TRI,   /* triangles "3 a b c" (.off faces) */
    PDT_LINES_NODE,      /* points "i x y", i = first + k (.node) */
    PDT_LINES_OFF_POINT, /* points "x y 0" (.off vertices) */
    PDT_LINES_XY         /* points "x y" (text) */
} pdt_lines;

/* The most bytes one line of any kind takes. */
enum { PDT_LINE_MAX = 64 };

/* Write items[0..n) (pdt_tri for the triangle kinds, pdt_point for the
 * point kinds) as lines of `kind` at buf, the k-th numbered first + k where
 * the kind numbers its lines.  Requires room for n * PDT_LINE_MAX bytes.
 * Returns the bytes written. */
size_t pdt_format_lines(char *buf, pdt_lines kind, const void *items, size_t n, uint64_t first);
/* The bytes pdt_format_lines would write for the same arguments. */
uint64_t pdt_lines_bytes(pdt_lines kind, const void *items, size_t n, uint64_t first);
/* The header of a triangle file of format fmt for npts points and ntri
 * triangles (.ele: comment and counts; .off: "OFF" and counts; .tri: none)
 * at buf (room for 256 bytes).  Returns its bytes. */
size_t pdt_format_tri_header(char *buf, pdt_tri_format fmt, uint64_t npts, uint64_t ntri);
/* The header of a .node file of npts points (comment and counts) at buf
 * (room for 256 bytes).  Returns its bytes. */
size_t pdt_format_node_header(char *buf, uint64_t npts);

/* Read a canonical .tri file (or a Triangle .ele file by extension). */
pdt_status pdt_read_tris(const char *path, pdt_tri **tris, size_t *ntri, pdt_err *err);

/* As pdt_read_tris, and every index must be < npts: a larger one is a parse
 * error naming its line ("t.tri:4: point index 12 out of range (10 points)"). */
pdt_status pdt_read_tris_n(const char *path, size_t npts, pdt_tri **tris, size_t *ntri,
                           pdt_err *err);

#endif
