/* pdt — live runs for the editor (include/pdt/view/live.h): the real algorithm
 * traced into memory, in the order and with the framing events of the
 * commands' own tracing (src/cli/trace_run.c). */
#include "pdt/view/live.h"

#include <stdlib.h>
#include <string.h>

#include "pdt/delaunay.h"
#include "pdt/hull.h"
#include "pdt/io.h"
#include "pdt/par.h"
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

/* ---- P simulated ranks: the parallel pipeline on the local communicator --------- */

/* One rank's recording: its events stamped with the shared monotonic clock
 * (every rank is a thread of this process: no clock offsets), and its block
 * of T*. */
typedef struct rank_rec {
    pdt_trace_buf buf;    /* its events, t in ns since the run's start */
    pdt_par_output out;
} rank_rec;

typedef struct par_job {
    const pdt_point *pts;
    size_t n;
    int level;
    rank_rec *rk;         /* one per rank */
    uint64_t *first;      /* P + 1: rank q's block is points first[q] .. first[q+1] - 1 */
    uint64_t t0;          /* the run's start, ns (pdt_trace_ns) */
} par_job;

/* The blocks pdt_par_read deals from the file pdt_write_points writes for
 * these points (text "x y" lines, or .node): rank q gets the point lines
 * that start in [size q / P, size (q + 1) / P) of the file. */
static void file_blocks(const pdt_point *pts, size_t n, int p, int node, uint64_t *first)
{
    char hdr[256];
    uint64_t head = node ? pdt_format_node_header(hdr, n) : 0, at = head;
    pdt_lines kind = node ? PDT_LINES_NODE : PDT_LINES_XY;
    uint64_t size = head + pdt_lines_bytes(kind, pts, n, 0);
    size_t k = 0; /* point k's line starts at byte `at` */
    first[0] = 0;
    for (int q = 1; q < p; q++) {
        unsigned __int128 bound = (unsigned __int128)size * (unsigned)q / (unsigned)p;
        for (; k < n && at < bound; k++) at += pdt_lines_bytes(kind, &pts[k], 1, k);
        first[q] = k;
    }
    first[p] = n;
}

/* One rank of `mpirun -np P pdt triangulate FILE --trace DIR`: its block of
 * the input as pdt_par_read deals it ([n q / P, n (q+1) / P)), and the
 * events the command records around the library calls (run, read, the
 * triangulation, write). */
static pdt_status live_rank(pdt_comm *c, void *arg, pdt_err *err)
{
    par_job *J = arg;
    int r = pdt_comm_rank(c), p = pdt_comm_size(c);
    rank_rec *R = &J->rk[r];
    pdt_trace tr;
    pdt_trace_buf_init_timed(&tr, &R->buf, J->level, r, J->t0);
    PDT_TRACE(&tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    PDT_TRACE(&tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_READ, 0, 0, 0, 0);
    (void)p;
    uint64_t n = J->n, lo = J->first[r], hi = J->first[r + 1];
    pdt_par_input in = {malloc((size_t)(hi - lo) * sizeof(pdt_point) + 1), (size_t)(hi - lo), lo,
                        n, 0, 0, 0, PDT_PART_STRIPS};
    pdt_status st = in.pts ? PDT_OK : pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: out of memory", r);
    if (st == PDT_OK && in.n) memcpy(in.pts, J->pts + lo, in.n * sizeof *in.pts); /* J->pts: NULL when empty */
    st = pdt_par_agree(c, st, NULL, err);
    PDT_TRACE(&tr, 1, PDT_EV_PHASE_END, PDT_PH_READ, 0, 0, 0, 0);
    pdt_par_rank_stats me;
    memset(&me, 0, sizeof me);
    if (st == PDT_OK) st = pdt_par_triangulate(c, &in, &R->out, &me, &tr, err);
    if (st == PDT_OK) {
        PDT_TRACE(&tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_WRITE, 0, 0, 0, 0);
        PDT_TRACE(&tr, 1, PDT_EV_PHASE_END, PDT_PH_WRITE, 0, 0, 0, 0);
        PDT_TRACE(&tr, 1, PDT_EV_PHASE_END, PDT_PH_RUN, 0, 0, 0, 0);
    }
    pdt_par_input_free(&in);
    if (st == PDT_OK && R->buf.failed)
        st = pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: out of memory while recording", r);
    return st;
}

/* May event e of rank r be placed now?  A RECV waits for its SEND (matched
 * by source, destination and sequence number: the driver numbers the
 * messages of each pair of ranks). */
static int placeable(const pdt_event *e, int r, int p, const uint64_t *sent)
{
    if (e->kind != PDT_EV_RECV || e->a >= (uint32_t)p) return 1;
    return sent[(size_t)e->a * (size_t)p + (size_t)r] > (uint64_t)e->v;
}

/* The ranks' events in one causally consistent order, as the reader merges
 * a run folder (pdt_run_merged): each rank's order kept, a RECV never before
 * its SEND, otherwise by time, ties by rank. */
static pdt_status merge_ranks(const rank_rec *rk, int p, pdt_live_result *res, pdt_err *err)
{
    size_t total = 0;
    for (int q = 0; q < p; q++) total += rk[q].buf.n;
    size_t *pos = calloc((size_t)p, sizeof *pos);
    uint64_t *sent = calloc((size_t)p * (size_t)p, sizeof *sent);
    res->recs = malloc((total ? total : 1) * sizeof *res->recs);
    if (!pos || !sent || !res->recs) {
        free(pos);
        free(sent);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    for (size_t k = 0; k < total; k++) {
        int best = -1, forced = -1;
        for (int q = 0; q < p; q++) {
            if (pos[q] == rk[q].buf.n) continue;
            const pdt_event *e = &rk[q].buf.ev[pos[q]];
            int ok = placeable(e, q, p, sent);
            int *slot = ok ? &best : &forced;
            if (*slot < 0 || e->t < rk[*slot].buf.ev[pos[*slot]].t) *slot = q;
        }
        int q = best >= 0 ? best : forced; /* a RECV without its SEND: by its time */
        const pdt_event *e = &rk[q].buf.ev[pos[q]];
        if (e->kind == PDT_EV_SEND && e->a < (uint32_t)p) sent[(size_t)q * (size_t)p + e->a]++;
        res->recs[k] = (pdt_rec){*e, (uint32_t)q, (uint32_t)pos[q]};
        pos[q]++;
    }
    res->m = total;
    res->nranks = p;
    free(pos);
    free(sent);
    return PDT_OK;
}

/* T*: the ranks' blocks of the canonical output, in rank order. */
static pdt_status gather_tris(const rank_rec *rk, int p, pdt_live_result *res, pdt_err *err)
{
    size_t total = 0;
    for (int q = 0; q < p; q++) total += rk[q].out.ntri;
    res->tris = malloc((total ? total : 1) * sizeof *res->tris);
    if (!res->tris) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    res->ntri = 0;
    for (int q = 0; q < p; q++) {
        memcpy(res->tris + res->ntri, rk[q].out.tris, rk[q].out.ntri * sizeof *res->tris);
        res->ntri += rk[q].out.ntri;
    }
    return PDT_OK;
}

static pdt_status run_ranks(const pdt_point *pts, size_t n, const pdt_live_opts *o,
                            pdt_live_result *res, pdt_err *err)
{
    int p = o->ranks;
    rank_rec *rk = calloc((size_t)p, sizeof *rk);
    if (!rk) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    uint64_t t0 = pdt_trace_ns();
    uint64_t *first = malloc((size_t)(p + 1) * sizeof *first);
    if (!first) {
        free(rk);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    file_blocks(pts, n, p, o->node, first);
    par_job J = {pts, n, o->level == 2 ? 2 : 1, rk, first, t0};
    pdt_status st = pdt_comm_local_run(p, live_rank, &J, err);
    if (st == PDT_OK) st = merge_ranks(rk, p, res, err);
    if (st == PDT_OK) st = gather_tris(rk, p, res, err);
    if (st == PDT_OK) st = pdt_live_ties(pts, n, res->tris, res->ntri, &res->ties, &res->nties, err);
    for (int q = 0; q < p; q++) {
        pdt_trace_buf_free(&rk[q].buf);
        pdt_par_output_free(&rk[q].out);
    }
    free(rk);
    free(first);
    return st;
}

pdt_status pdt_live_run(const pdt_point *pts, size_t n, const pdt_live_opts *o,
                        pdt_live_result *res, pdt_err *err)
{
    memset(res, 0, sizeof *res);
    if (o->ranks < 1 || o->ranks > PDT_LIVE_MAX_RANKS)
        return pdt_err_set(err, PDT_ERR_ARG, "%d simulated ranks: a live run takes 1 .. %d",
                           o->ranks, PDT_LIVE_MAX_RANKS);
    if (n > UINT32_MAX / 4)
        return pdt_err_set(err, PDT_ERR_ARG, "%zu points: too many for a live run", n);
    if (!o->hull && o->ranks > 1) return run_ranks(pts, n, o, res, err);
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
