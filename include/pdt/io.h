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
#include "pdt/safefile.h"

/* ---- atomic output ---------------------------------------------------- */

typedef struct pdt_outfile {
    FILE *fp;        /* write here */
    char *path;      /* final name (NULL for standard output) */
    char *tmp;       /* temporary name (NULL: writing directly) */
    pdt_safe_file sf; /* the rule of pdt/safefile.h */
} pdt_outfile;

/* Open `path` for atomic writing ("-" or NULL = standard output) by the
 * rule of pdt/safefile.h (mode, owner and links kept; read-only targets
 * refused).  A path that names an existing device or pipe (/dev/null, a
 * fifo) is written directly, never replaced. */
pdt_status pdt_out_open(pdt_outfile *o, const char *path, pdt_err *err);
/* Flush, close and rename into place.  On any write error the temporary is
 * removed and an error returned. */
pdt_status pdt_out_commit(pdt_outfile *o, pdt_err *err);
/* Flush and close both, then replace both targets together (an .ele and its
 * .node): both or neither. */
pdt_status pdt_out_commit_pair(pdt_outfile *a, pdt_outfile *b, pdt_err *err);
/* Close and remove the temporary (nothing is left behind). */
void pdt_out_abort(pdt_outfile *o);

/* Files written completely but not yet in place: a write whose commit waits
 * for something else to succeed (a traced run's folder). */
typedef struct pdt_pending_write {
    pdt_safe_file f[2];
    int n;               /* 0: nothing to put in place (standard output) */
} pdt_pending_write;
/* As pdt_out_commit_pair (b may be NULL), the files left in *pw for
 * pdt_pending_commit or pdt_pending_drop. */
pdt_status pdt_out_finish_pair(pdt_outfile *a, pdt_outfile *b, pdt_pending_write *pw,
                              pdt_err *err);
/* Put pw's files in place together (or none); pw is empty afterwards. */
pdt_status pdt_pending_commit(pdt_pending_write *pw, pdt_err *err);
/* Remove pw's temporaries; the targets are untouched. */
void pdt_pending_drop(pdt_pending_write *pw);
/* Put the finished temporary `tmp` in the place of `path` (same folder),
 * atomically: rename(2), or, when `path` is an existing regular file, an
 * exchange of the two names (renameat2 RENAME_EXCHANGE) and the removal of
 * the old file under the temporary's name.  A plain rename over an existing
 * file makes ext4 start writing the new file back to disk inside the call
 * (its "auto_da_alloc" replace-by-rename rule: 0.2-0.3 s for the .tri of
 * 10^7 points); the exchange does not.  0, or -1 with errno set. */
int pdt_replace_file(const char *tmp, const char *path);

/* ---- opening a file to read ---------------------------------------------- */

/* Open `path` read only for a reader of the user's files (points, triangles,
 * run folders, indexes) without blocking (a FIFO with no writer does not
 * hang the open) and only if, once open, it is a regular file: a folder, a
 * FIFO, a socket or a device (also through a symbolic link: /dev/zero) is
 * refused.  Returns the descriptor (close-on-exec, blocking), or -1 with
 * errno set (open's own; EISDIR for a folder, EINVAL for anything else that
 * is not a regular file) and a phrase for the message "PATH: WHY" in why
 * ("cannot open: REASON", "is a FIFO (named pipe), not a regular file ...").
 * Not for standard input ("-": the caller reads it as it is). */
int pdt_open_input(const char *path, char *why, size_t cap);
/* What a file of mode `mode` (st_mode) is, for messages: "a FIFO (named
 * pipe)", "a character device", ... (a string constant). */
const char *pdt_file_kind(unsigned mode);

/* The longest line a text reader accepts from a stream (standard input):
 * a stream with no end of line in this many bytes is refused at once,
 * "NAME:LINE: no end of line in N bytes", rather than read on into memory
 * without bound (`pdt triangulate - < /dev/zero`). */
#define PDT_IO_LINE_SPAN ((size_t)1 << 20)

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

/* Flags of pdt_read_points_ex and pdt_points_part_parse. */
enum {
    /* a second thread faults the point array in ahead of the parser (on a
     * machine where memory new to a process is dear on first touch and a
     * core is idle: docs/geometry.md, "Fresh memory"); arrays under 8 MiB
     * are left alone.  Same points either way. */
    PDT_READ_PREFAULT = 1
};

/* pdt_read_points with flags (PDT_READ_PREFAULT or 0). */
pdt_status pdt_read_points_ex(const char *path, double scale, int flags, pdt_point **pts,
                              size_t *n, size_t *collisions, pdt_err *err);

/* ---- a point file read in parts, one per rank (pdt_par_read) -----------------
 *
 * The first reader calls pdt_points_head_read; every reader q of p then
 * loads its part (pdt_points_part_load: whole lines, about size/p bytes,
 * after the header), parses it knowing the line number of its first byte
 * (pdt_points_part_parse: the '\n' counts of the parts before it, summed),
 * and checks it against the whole file (pdt_points_part_check: the point
 * counts of the parts before it, summed).  The failure to report is the one
 * of smallest err_key over all parts: it is the failure, and the message,
 * that pdt_read_points gives for the whole file. */

/* What the first reader learns from the start of the file. */
typedef struct pdt_points_head {
    int parts;           /* 1: the file can be read in parts (a regular, non-empty file) */
    int node;            /* Triangle's .node format */
    uint64_t size;       /* bytes in the file */
    uint64_t body;       /* first byte after the byte-order mark and header line */
    uint64_t body_nl;    /* '\n' bytes before body */
    int64_t count;       /* .node: points the header announces; -1 without a header */
    int64_t nattr, nmark;
    int32_t last_nl;     /* the file ends with '\n' */
} pdt_points_head;

/* Open `path` and read its start: h->parts = 0 for standard input ("-"), a
 * pipe, a device or an empty file (read those whole with pdt_read_points).
 * Errors as pdt_read_points ("FILE: cannot open: ...", a bad .node header
 * "FILE:LINE: ..."). */
pdt_status pdt_points_head_read(const char *path, double scale, pdt_points_head *h,
                                pdt_err *err);

/* One part of a file: its bytes, then its points. */
typedef struct pdt_points_part {
    char *buf;              /* bytes [lo, hi) of the file, '\0'-terminated */
    void *map;              /* maplen > 0: buf lies in this read-only mapping */
    size_t maplen;
    uint64_t lo, hi;
    uint64_t nl;            /* '\n' bytes in [lo, hi) */
    uint64_t line0;         /* line number of byte lo (pdt_points_part_parse) */
    pdt_point *pts;         /* malloc'd; the caller may take it (set to NULL) */
    size_t n;
    void *orig;             /* --scale: the values as written (pdt_points_part_written) */
    int32_t has_idx0;       /* .node: the first point line's index was read */
    int64_t idx0;
    uint64_t err_key;       /* UINT64_MAX: no failure; else smaller = reported first */
} pdt_points_part;

/* Load part q of p of the file (path as given to pdt_points_head_read):
 * the lines that start in [size q / p, size (q + 1) / p), none before
 * h->body.  On failure pt->err_key = 0. */
pdt_status pdt_points_part_load(const char *path, const pdt_points_head *h, int q, int p,
                                pdt_points_part *pt, pdt_err *err);

/* Parse the loaded part; line0 = 1 + the '\n' bytes before pt->lo; flags as
 * pdt_read_points_ex's.  A bad
 * line sets err ("FILE:LINE: what") and pt->err_key.  In a .node file the
 * indices are checked within the part only. */
pdt_status pdt_points_part_parse(pdt_points_part *pt, const char *path, const pdt_points_head *h,
                                 double scale, uint64_t line0, int flags, pdt_err *err);

/* The checks that need the parts before this one (.node: first index 0 or
 * 1, consecutive indices across parts, the point count of the header).
 * first = points in the parts before, total = points in all parts, base =
 * the index of the file's first point line (if any part has one), last = 1
 * for the last part, last_line = the number of the file's last line.  May
 * replace the part's failure with an earlier one. */
pdt_status pdt_points_part_check(pdt_points_part *pt, const char *path, const pdt_points_head *h,
                                 uint64_t first, uint64_t total, int64_t base, int last,
                                 uint64_t last_line, pdt_err *err);

/* --scale: a point with its two coordinates as written, to count across
 * parts the points that became equal to a point written differently. */
typedef struct pdt_points_written {
    pdt_point p;
    unsigned char as_written[32];
} pdt_points_written;

/* The part's points as pdt_points_written records (*w malloc'd, pt->n of them). */
pdt_status pdt_points_part_written(const pdt_points_part *pt, pdt_points_written **w,
                                   pdt_err *err);

/* Sort w and count the collisions among them (every record of a key must
 * be here): as pdt_read_points' *collisions. */
pdt_status pdt_points_collisions(pdt_points_written *w, size_t n, uint64_t *collisions,
                                 pdt_err *err);

void pdt_points_part_free(pdt_points_part *pt);

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

/* pdt_write_tris, and the pages of `tris` are given back to the system as
 * they are written (whole 2 MiB pages): their contents are lost, so the
 * caller frees tris next and reads nothing from it, whatever the status.
 * The file's page cache then reuses memory that was just in use. */
pdt_status pdt_write_tris_releasing(const char *path, pdt_tri_format fmt, const pdt_point *pts,
                                    size_t n, pdt_tri *tris, size_t ntri, pdt_err *err);
/* pdt_write_tris (releasing when `release`), the file(s) complete but left
 * in *defer for pdt_pending_commit / pdt_pending_drop. */
pdt_status pdt_write_tris_deferred(const char *path, pdt_tri_format fmt, const pdt_point *pts,
                                   size_t n, pdt_tri *tris, size_t ntri, int release,
                                   pdt_pending_write *defer, pdt_err *err);

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
