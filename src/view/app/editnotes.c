/* pdt — the comments of the editor's point file (editnotes.h).
 *
 * A teacher's point file says what its points are for: "# the three
 * collinear points", "5 10  # the witness".  The editor rewrites the file
 * after every change, so it keeps those comments: the lines before the
 * first point (the header) stay first; a comment block before a point and
 * a comment at the end of a point's line stay with that point — found by
 * its coordinates, so that deleting, undoing or re-ordering keeps them
 * with it, and moving a point takes them along; the comments of a deleted
 * point's block and the lines after the last point go to the end. */
#include "editnotes.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pdt/io.h"

typedef struct note {
    pdt_point p;
    char *pre;      /* comment lines before the point (each ending "\n"), or NULL */
    char *inl;      /* "# ..." after the coordinates, or NULL */
} note;

struct pdt_edit_notes {
    char *head, *tail;
    note *v;
    size_t n, cap;
};

/* Append line (with "\n") to *block. */
static int add_line(char **block, const char *line)
{
    size_t a = *block ? strlen(*block) : 0, b = strlen(line);
    char *s = realloc(*block, a + b + 2);
    if (!s) return -1;
    memcpy(s + a, line, b);
    s[a + b] = '\n';
    s[a + b + 1] = 0;
    *block = s;
    return 0;
}

/* A point line "x y [# comment]": the note for it, if it has any comment. */
static int add_point(pdt_edit_notes *N, const char *line, char **pending)
{
    char *e;
    long long x = strtoll(line, &e, 10), y = strtoll(e, &e, 10);
    const char *hash = strchr(line, '#');
    if (!*pending && !hash) return 0;
    if (N->n == N->cap) {
        size_t cap = N->cap ? 2 * N->cap : 16;
        note *v = realloc(N->v, cap * sizeof *v);
        if (!v) return -1;
        N->v = v;
        N->cap = cap;
    }
    note *t = &N->v[N->n++];
    t->p = (pdt_point){(int32_t)x, (int32_t)y};
    t->pre = *pending;
    *pending = NULL;
    t->inl = hash ? strdup(hash) : NULL;
    return hash && !t->inl ? -1 : 0;
}

static int read_lines(pdt_edit_notes *N, FILE *f)
{
    char buf[4096], *pending = NULL;
    int seen_point = 0, bad = 0;
    while (!bad && fgets(buf, sizeof buf, f)) {
        buf[strcspn(buf, "\r\n")] = 0;
        const char *s = buf + strspn(buf, " \t");
        if (!*s || *s == '#') {
            bad = add_line(seen_point ? &pending : &N->head, buf);
            continue;
        }
        seen_point = 1;
        bad = add_point(N, buf, &pending);
    }
    N->tail = pending;
    return bad;
}

pdt_status pdt_edit_notes_read(const char *path, pdt_edit_notes **out, pdt_err *err)
{
    *out = NULL;
    FILE *f = fopen(path, "r");
    if (!f) return PDT_OK; /* no file yet: no comments */
    pdt_edit_notes *N = calloc(1, sizeof *N);
    int bad = !N || read_lines(N, f);
    fclose(f);
    if (bad) {
        pdt_edit_notes_free(N);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    if (!N->head && !N->tail && !N->n) {
        pdt_edit_notes_free(N);
        N = NULL;
    }
    *out = N;
    return PDT_OK;
}

void pdt_edit_notes_free(pdt_edit_notes *N)
{
    if (!N) return;
    for (size_t i = 0; i < N->n; i++) {
        free(N->v[i].pre);
        free(N->v[i].inl);
    }
    free(N->v);
    free(N->head);
    free(N->tail);
    free(N);
}

void pdt_edit_notes_moved(pdt_edit_notes *N, pdt_point from, pdt_point to)
{
    for (size_t i = 0; N && i < N->n; i++)
        if (N->v[i].p.x == from.x && N->v[i].p.y == from.y) {
            N->v[i].p = to;
            return;
        }
}

/* The points with their comments, then the comments of points gone. */
static void emit(const pdt_edit_notes *N, FILE *f, const pdt_point *pts, size_t n, uint8_t *used)
{
    if (N->head) fputs(N->head, f);
    for (size_t i = 0; i < n; i++) {
        const note *t = NULL;
        for (size_t j = 0; j < N->n && !t; j++)
            if (!used[j] && N->v[j].p.x == pts[i].x && N->v[j].p.y == pts[i].y) {
                used[j] = 1;
                t = &N->v[j];
            }
        if (t && t->pre) fputs(t->pre, f);
        if (t && t->inl) fprintf(f, "%d %d  %s\n", pts[i].x, pts[i].y, t->inl);
        else fprintf(f, "%d %d\n", pts[i].x, pts[i].y);
    }
    for (size_t j = 0; j < N->n; j++)
        if (!used[j] && N->v[j].pre) fputs(N->v[j].pre, f);
    if (N->tail) fputs(N->tail, f);
}

pdt_status pdt_edit_notes_write(const pdt_edit_notes *N, const char *path, const pdt_point *pts,
                                size_t n, pdt_err *err)
{
    if (!N) return pdt_write_points(path, pts, n, err);
    uint8_t *used = calloc(N->n ? N->n : 1, 1);
    if (!used) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    pdt_outfile o;
    pdt_status st = pdt_out_open(&o, path, err);
    if (st == PDT_OK) {
        emit(N, o.fp, pts, n, used);
        st = pdt_out_commit(&o, err);
    }
    free(used);
    return st;
}
