/* Level of detail: the triangles of a replay state counted per cell of a
 * grid (pdt_replay_coverage), so that a picture of millions of triangles
 * shows their density, makers and statuses (src/view/render/render_lod.c paints
 * it).  One pass over the triangles born so far, in their order, shared
 * by two threads on big runs; a kept index's pages are given back behind
 * it. */
#include "pdt/view/replay.h"
#include "replay_int.h"
#include "pdt/bigmem.h"

#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define NONE32 UINT32_MAX

/* Add triangle t (status st, maker q) to cell (i, j). */
static void cov_add(pdt_cov_cell *cell, uint32_t q, uint8_t st)
{
    if (cell->n == 0) cell->rank_lo = cell->rank_hi = q;
    cell->rank_lo = q < cell->rank_lo ? q : cell->rank_lo;
    cell->rank_hi = q > cell->rank_hi ? q : cell->rank_hi;
    cell->rank = cell->n == 0 || cell->rank == q ? q : PDT_COV_MIXED;
    cell->n++;
    cell->by_status[st]++;
}

/* The x range of triangle (grid coordinates x[], y[]) within the band
 * lo <= y <= hi: from its vertices in the band and its edges' crossings of
 * the band's two lines.  0 if it does not reach the band.  (The numbers are
 * finite: plain comparisons, not calls to fmin and fmax, for the millions of
 * triangles across a cell's edge.) */
static int band_range(const double x[3], const double y[3], double lo, double hi, double *xmin,
                      double *xmax)
{
    int any = 0;
    double mn = INFINITY, mx = -INFINITY;
    for (int k = 0; k < 3; k++) {
        int k1 = k == 2 ? 0 : k + 1;
        double ax = x[k], ay = y[k], bx = x[k1], by = y[k1];
        if (ay >= lo && ay <= hi) {
            mn = ax < mn ? ax : mn;
            mx = ax > mx ? ax : mx;
            any = 1;
        }
        if ((ay < lo && by > lo) || (ay > lo && by < lo)) {
            double xc = ax + (bx - ax) * (lo - ay) / (by - ay);
            mn = xc < mn ? xc : mn;
            mx = xc > mx ? xc : mx;
            any = 1;
        }
        if ((ay < hi && by > hi) || (ay > hi && by < hi)) {
            double xc = ax + (bx - ax) * (hi - ay) / (by - ay);
            mn = xc < mn ? xc : mn;
            mx = xc > mx ? xc : mx;
            any = 1;
        }
    }
    *xmin = mn;
    *xmax = mx;
    return any;
}

#define COV_AHEAD 16  /* triangles ahead whose points are fetched (pdt_replay_coverage) */
#define COV_AHEAD_CELL 8  /* ... and whose first corner's cell is fetched (its point
                           * is in the cache by then): the grid is megabytes, and
                           * triangles in the order they were born hit it at random */
#define COV_RELEASE ((size_t)1 << 16) /* triangles between givings back of a kept
                                       * index's pages (pdt_index_release) */


/* One share of the coverage pass: triangles t0 .. t1-1 of state s into
 * cells (zeroed), what touches the box counted in binned. */
typedef struct cov_job {
    const pdt_replay *r;
    const pdt_rstate *s;
    double x0, y0, sx, sy;
    int cols, rows;
    const uint8_t *vis;
    uint64_t fade; /* discarded this many events before the cursor: left out (0: never) */
    pdt_cov_cell *cells;
    size_t t0, t1, binned;
} cov_job;

/* The least and greatest of three finite numbers (fmin and fmax are calls
 * here, a few per triangle of millions). */
static inline double min3(double a, double b, double c)
{
    double m = a < b ? a : b;
    return m < c ? m : c;
}

static inline double max3(double a, double b, double c)
{
    double m = a > b ? a : b;
    return m > c ? m : c;
}

static void cov_range(cov_job *J)
{
    const pdt_replay *r = J->r;
    const pdt_rstate *s = J->s;
    const int cols = J->cols, rows = J->rows;
    pdt_cov_cell *cells = J->cells;
    size_t binned = 0, nt = J->t1;
    for (size_t t = J->t0; t < nt; t++) {
        if (t > J->t0 && (t - J->t0) % COV_RELEASE == 0) { /* the triangles read: behind
                                          * the pass (their entries are where the
                                          * build grouped them: not in this order) */
            const pdt_rtri *from = &r->tris[t - COV_RELEASE];
            pdt_index_release(r, from, COV_RELEASE * sizeof *r->tris);
            /* a paged state's entries behind too (the corners' points, read at
             * random, are kept until the frame is done: pdt_render) */
            if (s->paged[1]) pdt_release_pages(&s->tcur[t - COV_RELEASE], COV_RELEASE * sizeof *s->tcur);
        }
        /* the corners' points and the history entry (unless it is the last)
         * of a triangle a few ahead: random places in tables of 10^8 bytes
         * (a hint only) */
        if (t + COV_AHEAD < nt && s->tcur[t + COV_AHEAD] != PDT_TCUR_NONE) {
            const pdt_rtri *ahead = &r->tris[t + COV_AHEAD];
            for (int k = 0; k < 3; k++) __builtin_prefetch(&r->pts[ahead->v[k]]);
            if (s->tcur[t + COV_AHEAD] + 1u != ahead->hn || ahead->last == PDT_TS_CANDIDATE ||
                (ahead->last == PDT_TS_DISCARDED && J->fade))
                __builtin_prefetch(&r->hist[ahead->h0 + s->tcur[t + COV_AHEAD]]);
        }
        if (t + COV_AHEAD_CELL < nt && s->tcur[t + COV_AHEAD_CELL] != PDT_TCUR_NONE) {
            const pdt_point *p = &r->pts[r->tris[t + COV_AHEAD_CELL].v[0]];
            double gx = (p->x - J->x0) * J->sx, gy = (p->y - J->y0) * J->sy;
            if (gx >= 0 && gx < cols && gy >= 0 && gy < rows)
                __builtin_prefetch(&cells[(size_t)(int)gy * (size_t)cols + (size_t)(int)gx], 1);
        }
        uint32_t h = pdt_rstate_tri_entry(r, s, t);
        if (h == NONE32) continue;
        const pdt_rtri *tr = &r->tris[t];
        if (J->vis && !J->vis[tr->maker]) continue;
        double x[3], y[3];
        for (int k = 0; k < 3; k++) {
            x[k] = (r->pts[tr->v[k]].x - J->x0) * J->sx;
            y[k] = (r->pts[tr->v[k]].y - J->y0) * J->sy;
        }
        double xlo = min3(x[0], x[1], x[2]), xhi = max3(x[0], x[1], x[2]);
        double ylo = min3(y[0], y[1], y[2]), yhi = max3(y[0], y[1], y[2]);
        if (xhi < 0 || xlo >= cols || yhi < 0 || ylo >= rows) continue;  /* outside the box */
        uint8_t st = h + 1 == tr->h0 + tr->hn ? tr->last : r->hist[h].status;
        if (st == PDT_TS_DISCARDED && J->fade && s->k - r->hist[h].ev >= J->fade) continue;
        binned++;
        int j0 = ylo < 0 ? 0 : (int)ylo, j1 = yhi >= rows ? rows - 1 : (int)yhi;
        if ((int)xlo == (int)xhi && j0 == j1 && xlo >= 0) {  /* the usual case: one cell */
            cov_add(&cells[(size_t)j0 * (size_t)cols + (size_t)xlo], tr->maker, st);
            continue;
        }
        for (int j = j0; j <= j1; j++) {  /* every cell the triangle touches, band by band */
            double a, b;
            if (!band_range(x, y, j, j + 1.0, &a, &b)) continue;
            int i0 = a < 0 ? 0 : (int)a, i1 = b >= cols ? cols - 1 : (int)b;
            for (int i = i0; i <= i1; i++)
                cov_add(&cells[(size_t)j * (size_t)cols + (size_t)i], tr->maker, st);
        }
    }
    J->binned = binned;
}

static void *cov_thread(void *arg)
{
    cov_range(arg);
    return NULL;
}

/* Cell c of one share added to the same cell of another: the counts add
 * up, and the cell is mixed when either is or their makers differ, as
 * when one pass counts both. */
static void cov_merge(pdt_cov_cell *to, const pdt_cov_cell *from)
{
    if (!from->n) return;
    if (to->n == 0) to->rank_lo = from->rank_lo, to->rank_hi = from->rank_hi;
    to->rank_lo = from->rank_lo < to->rank_lo ? from->rank_lo : to->rank_lo;
    to->rank_hi = from->rank_hi > to->rank_hi ? from->rank_hi : to->rank_hi;
    to->rank = to->n == 0 || to->rank == from->rank ? from->rank : PDT_COV_MIXED;
    to->n += from->n;
    for (int k = 0; k < PDT_TS_COUNT; k++) to->by_status[k] += from->by_status[k];
}

/* Triangles from which the coverage pass is shared by two threads (the
 * frame of a run of millions of triangles: 2.2-2.7 s of CPU for 8*10^7);
 * the tests lower it (pdt_replay_set_cov_split). */
static size_t cov_split = (size_t)1 << 20;

void pdt_replay_set_cov_split(size_t tris) { cov_split = tris; }

size_t pdt_replay_coverage(const pdt_replay *r, const pdt_rstate *s, double x0, double y0,
                           double x1, double y1, int cols, int rows,
                           const uint8_t *rank_visible, uint64_t fade, pdt_cov_cell *cells)
{
    if (cols <= 0 || rows <= 0) return 0;
    size_t ncell = (size_t)cols * (size_t)rows;
    memset(cells, 0, ncell * sizeof *cells);
    if (!(x1 > x0) || !(y1 > y0) || !ix_check_points(r) || !ix_check_born(r, s->k)) return 0;
    size_t nt = pdt_replay_born_at_most(r, s->k);
    cov_job J[2];
    J[0] = (cov_job){r, s, x0, y0, cols / (x1 - x0), rows / (y1 - y0), cols, rows, rank_visible,
                     fade, cells, 0, nt, 0};
    J[1] = J[0];
    pthread_t th;
    int two = 0;
    if (nt >= cov_split && nt >= 2 && sysconf(_SC_NPROCESSORS_ONLN) > 1 &&
        (J[1].cells = calloc(ncell, sizeof *cells)) != NULL) {
        J[0].t1 = J[1].t0 = nt / 2;
        two = pthread_create(&th, NULL, cov_thread, &J[1]) == 0;
        if (!two) {
            free(J[1].cells);
            J[0].t1 = nt;
        }
    }
    cov_range(&J[0]);
    if (two) {
        pthread_join(th, NULL);
        for (size_t c = 0; c < ncell; c++) cov_merge(&cells[c], &J[1].cells[c]);
        free(J[1].cells);
    }
    return J[0].binned + (two ? J[1].binned : 0);
}

