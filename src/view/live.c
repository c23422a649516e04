/* pdt — live runs for the editor (include/pdt/live.h): the real algorithm
 * traced into memory, in the order and with the framing events of the
 * commands' own tracing (src/cli/trace_run.c). */
#include "pdt/live.h"

#include <stdlib.h>
#include <string.h>

#include "pdt/delaunay.h"
#include "pdt/hull.h"
#include "pdt/predicates.h"
#include "pdt/trace.h"

void pdt_live_free(pdt_live_result *res)
{
    free(res->recs);
    free(res->tris);
    free(res->ties);
    memset(res, 0, sizeof *res);
}

/* The buffered events of rank 0 as merged records. */
static pdt_status to_recs(const pdt_trace_buf *b, pdt_live_result *res, pdt_err *err)
{
    if (b->failed) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory while recording");
    res->recs = malloc((b->n ? b->n : 1) * sizeof *res->recs);
    if (!res->recs) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < b->n; i++) {
        res->recs[i].ev = b->ev[i];
        res->recs[i].rank = 0;
        res->recs[i].seq = (uint32_t)i;
    }
    res->m = b->n;
    res->nranks = 1;
    return PDT_OK;
}

static pdt_status run_triangulate(const pdt_point *pts, size_t n, pdt_trace *tr,
                                  pdt_live_result *res, pdt_err *err)
{
    pdt_status st = pdt_triangulate(pts, n, &res->tris, &res->ntri, NULL, tr);
    if (st != PDT_OK) return pdt_err_set(err, st, "triangulation failed: %s", pdt_status_str(st));
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_OUTPUT, 0, 0, 0, 0);
    for (size_t i = 0; i < res->ntri; i++)
        PDT_TRACE(tr, 1, PDT_EV_TRI_FINAL, 0, res->tris[i].v[0], res->tris[i].v[1],
                  res->tris[i].v[2], 0);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_OUTPUT, 0, 0, 0, 0);
    return pdt_live_ties(pts, n, res->tris, res->ntri, &res->ties, &res->nties, err);
}

static pdt_status run_hull(const pdt_point *pts, size_t n, pdt_trace *tr, pdt_live_result *res,
                           pdt_err *err)
{
    uint32_t *out = malloc((n ? n : 1) * sizeof *out);
    if (!out) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    pdt_status st = pdt_hull_graham(pts, n, out, &res->nhull, tr);
    free(out);
    if (st != PDT_OK) return pdt_err_set(err, st, "hull failed: %s", pdt_status_str(st));
    return PDT_OK;
}

pdt_status pdt_live_run(const pdt_point *pts, size_t n, const pdt_live_opts *o,
                        pdt_live_result *res, pdt_err *err)
{
    memset(res, 0, sizeof *res);
    if (o->ranks != 1)
        return pdt_err_set(err, PDT_ERR_ARG, "%d simulated ranks: this viewer runs the sequential "
                           "pipeline only (1 rank)", o->ranks);
    if (n > UINT32_MAX / 4)
        return pdt_err_set(err, PDT_ERR_ARG, "%zu points: too many for a live run", n);
    pdt_trace tr;
    pdt_trace_buf buf;
    pdt_trace_buf_init(&tr, &buf, o->level == 2 ? 2 : 1, 0);
    PDT_TRACE(&tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    pdt_status st = o->hull ? run_hull(pts, n, &tr, res, err)
                            : run_triangulate(pts, n, &tr, res, err);
    PDT_TRACE(&tr, 1, PDT_EV_PHASE_END, PDT_PH_RUN, 0, 0, 0, 0);
    if (st == PDT_OK) st = to_recs(&buf, res, err);
    pdt_trace_buf_free(&buf);
    return st;
}

/* ---- where the tie rule decided ------------------------------------------------- */

typedef struct half {
    uint32_t a, b;   /* directed edge a -> b of a counter-clockwise triangle */
    uint32_t c;      /* the third point */
} half;

static int half_cmp(const void *x, const void *y)
{
    const half *p = x, *q = y;
    uint32_t pa = p->a < p->b ? p->a : p->b, pb = p->a < p->b ? p->b : p->a;
    uint32_t qa = q->a < q->b ? q->a : q->b, qb = q->a < q->b ? q->b : q->a;
    if (pa != qa) return pa < qa ? -1 : 1;
    if (pb != qb) return pb < qb ? -1 : 1;
    return 0;
}

pdt_status pdt_live_ties(const pdt_point *pts, size_t n, const pdt_tri *tris, size_t ntri,
                         uint32_t **edges, size_t *nedges, pdt_err *err)
{
    *edges = NULL;
    *nedges = 0;
    if (ntri == 0) return PDT_OK;
    half *h = malloc(3 * ntri * sizeof *h);
    if (!h) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    for (size_t t = 0; t < ntri; t++)
        for (int e = 0; e < 3; e++)
            h[3 * t + (size_t)e] = (half){tris[t].v[e], tris[t].v[(e + 1) % 3], tris[t].v[(e + 2) % 3]};
    qsort(h, 3 * ntri, sizeof *h, half_cmp);
    size_t cap = 0;
    pdt_status st = PDT_OK;
    for (size_t i = 0; i + 1 < 3 * ntri && st == PDT_OK; i++) {
        if (half_cmp(&h[i], &h[i + 1]) != 0) continue;
        const half *p = &h[i], *q = &h[i + 1];
        i++; /* an interior edge: its two sides */
        if (p->a >= n || p->b >= n || p->c >= n || q->c >= n) continue;
        if (pdt_incircle0(pts[p->a], pts[p->b], pts[p->c], pts[q->c]) != 0) continue;
        if (*nedges == cap) {
            cap = cap ? 2 * cap : 16;
            uint32_t *e = realloc(*edges, 2 * cap * sizeof *e);
            if (!e) {
                st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
                break;
            }
            *edges = e;
        }
        (*edges)[2 * *nedges] = p->a < p->b ? p->a : p->b;
        (*edges)[2 * *nedges + 1] = p->a < p->b ? p->b : p->a;
        (*nedges)++;
    }
    free(h);
    return st;
}
