/* pdt — the sequential Delaunay kernel's entry points and the pipeline
 * around it (pdt_triangulate_inplace): sort and dedupe (dt_sort.c), the
 * kernel on the distinct points (dt_kernel.c, on the cuts of dt_cut.c), the
 * canonical order (dt_order.c).  dt_int.h lists the files; the result is
 * always T*(P) (docs/algorithm.md §2.3). */
#include "dt_int.h"

#include "pdt/bigmem.h"
#include "pdt/predicates.h"

#include <stdlib.h>
#include <string.h>

typedef dt_edge edge;

pdt_status pdt_delaunay(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri, int run,
                        pdt_trace *tr)
{
    *tris = NULL;
    *ntri = 0;
    if (n < 2) return PDT_OK;
    if (n > PDT_KERNEL_MAX_POINTS) return PDT_ERR_ARG;
    for (size_t i = 1; i < n; i++) /* the precondition: distinct and sorted */
        if (pdt_key(pts[i - 1]) >= pdt_key(pts[i])) return PDT_ERR_ARG;
    size_t cap = dt_edge_cap(n);
    uint32_t *id = malloc(n * sizeof *id);
    pdt_point *q = pdt_big_alloc(n * sizeof *q);
    edge *e = malloc(cap * sizeof *e); /* becomes the triangle array */
    if (!id || !q || !e) {
        free(id);
        pdt_big_free(q, n * sizeof *q);
        free(e);
        return PDT_ERR_NOMEM;
    }
    pdt_big_advise(e, cap * sizeof *e);
    for (uint32_t i = 0; i < (uint32_t)n; i++) id[i] = i;
    memcpy(q, pts, n * sizeof *q);
    size_t nt = 0;
    pdt_status s = pdt_dt_kernel(id, q, n, e, cap, &nt, run, tr, NULL, NULL, DT_SPREAD);
    free(id);
    pdt_big_free(q, n * sizeof *q);
    if (s != PDT_OK || nt == 0) {
        free(e);
        return s;
    }
    pdt_tri *shrunk = realloc(e, nt * sizeof *shrunk);
    *tris = shrunk ? shrunk : (pdt_tri *)(void *)e;
    *ntri = nt;
    return PDT_OK;
}

/* The contract of the kernels on the caller's memory: not too many points,
 * work_bytes >= PDT_DELAUNAY_WORK(n), the points distinct and sorted. */
static int on_args_ok(const pdt_point *pts, size_t n, size_t work_bytes)
{
    if (n > PDT_KERNEL_MAX_POINTS || work_bytes < PDT_DELAUNAY_WORK(n)) return 0;
    for (size_t i = 1; i < n; i++)
        if (pdt_key(pts[i - 1]) >= pdt_key(pts[i])) return 0;
    return 1;
}

/* The kernel on the caller's memory, with no copy of the points: they are
 * the kernel's (leaf-order) array during the call and are put back from
 * id afterwards, through scratch in work beyond the triangles (8 bytes per
 * point; the triangles take at most 24 of the 72). */
pdt_status pdt_delaunay_hull_on(pdt_point *pts, size_t n, uint32_t *id, void *work,
                                size_t work_bytes, size_t *ntri, uint32_t **hull, size_t *nhull,
                                int run, pdt_trace *tr)
{
    *ntri = 0;
    if (hull) {
        *hull = NULL;
        *nhull = 0;
    }
    if (n < 2) return PDT_OK;
    if (!on_args_ok(pts, n, work_bytes)) return PDT_ERR_ARG;
    for (uint32_t i = 0; i < (uint32_t)n; i++) id[i] = i;
    size_t nt = 0;
    pdt_status s =
        pdt_dt_kernel(id, pts, n, (edge *)work, dt_edge_cap(n), &nt, run, tr, hull, nhull, 0);
    pdt_point *tmp = (pdt_point *)(void *)((pdt_tri *)work + (s == PDT_OK ? nt : 0));
    memcpy(tmp, pts, n * sizeof *tmp);
    for (size_t v = 0; v < n; v++) pts[id[v]] = tmp[v];
    if (s == PDT_OK) *ntri = nt;
    if (hull && (s != PDT_OK || nt == 0)) { /* (none on a line) */
        free(*hull);
        *hull = NULL;
        *nhull = 0;
    }
    return s;
}

pdt_status pdt_delaunay_on(pdt_point *pts, size_t n, uint32_t *id, void *work, size_t work_bytes,
                           size_t *ntri, int run, pdt_trace *tr)
{
    return pdt_delaunay_hull_on(pts, n, id, work, work_bytes, ntri, NULL, NULL, run, tr);
}

/* A point and its name, for putting a strip back in order (below). */
typedef struct named_pt {
    pdt_point p;
    uint32_t name;
} named_pt;

static int named_cmp(const void *a, const void *b)
{
    uint64_t ka = pdt_key(((const named_pt *)a)->p), kb = pdt_key(((const named_pt *)b)->p);
    return ka < kb ? -1 : ka > kb;
}

/* The kernel without putting the points back: the caller reads the
 * triangles against the leaf order, which is the order they come out in
 * (the restore was a random scatter of every point, and the caller's pass
 * over the triangles then read the points out of order).  Only a strip with
 * no hull (a line, or fewer than 3 points) is put back in order, by a sort:
 * the caller runs its own chain on it. */
pdt_status pdt_delaunay_strip(pdt_point *pts, size_t n, uint32_t *name, void *work,
                              size_t work_bytes, size_t *ntri, uint32_t **hull, size_t *nhull)
{
    *ntri = 0;
    *hull = NULL;
    *nhull = 0;
    if (n < 2) return PDT_OK;
    if (!on_args_ok(pts, n, work_bytes)) return PDT_ERR_ARG;
    size_t nt = 0;
    pdt_status s =
        pdt_dt_kernel(name, pts, n, (edge *)work, dt_edge_cap(n), &nt, 0, NULL, hull, nhull,
                      DT_BY_VERTEX);
    if (s == PDT_OK && *hull && nt > 0) {
        *ntri = nt;
        return PDT_OK;
    }
    free(*hull);
    *hull = NULL;
    *nhull = 0;
    named_pt *tmp = work; /* no triangle to keep: 12 of the 72 bytes per point */
    for (size_t i = 0; i < n; i++) tmp[i] = (named_pt){pts[i], name[i]};
    qsort(tmp, n, sizeof *tmp, named_cmp);
    for (size_t i = 0; i < n; i++) {
        pts[i] = tmp[i].p;
        name[i] = tmp[i].name;
    }
    return s;
}

/* ---- the pipeline ---- */

/* Working memory below this is not worth a thread faulting it in. */
enum { PREFAULT_MIN = 8 << 20 };

/* Put pts back as they were: the distinct points from q (== pts[0, nu), in
 * the kernel's order, id naming them) through a copy in `scratch` (room for
 * nu points), then each dropped copy from the point kept for it. */
static void restore_points(pdt_point *pts, size_t nu, const uint32_t *id, const uint32_t *dup,
                           size_t ndup, pdt_point *scratch)
{
    memcpy(scratch, pts, nu * sizeof *pts);
    for (size_t v = 0; v < nu; v++) pts[id[v]] = scratch[v];
    for (size_t k = 0; k < ndup; k++) pts[dup[2 * k]] = pts[dup[2 * k + 1]];
}

/* One run of the pipeline: its memory (below) and what each step found. */
typedef struct tri_run {
    pdt_point *pts;        /* the caller's points */
    size_t n, cap;         /* input points; edge records in R */
    int keep;              /* PDT_PTS_RESTORE, PDT_TRI_PREFAULT */
    pdt_trace *tr;
    edge *R;               /* the sort's scratch, then edges, then triangles */
    uint32_t *order;       /* the distinct points' input indices */
    size_t *cnt, *hc;      /* the sort's counters */
    uint32_t *dup;         /* (copy, kept) pairs, kept for PDT_PTS_RESTORE */
    pdt_prefault *pf;
    pdt_dt_sorted so;
    size_t nt;             /* triangles */
} tri_run;

/* R, order and the sort's counters; R and order faulted in ahead of use by
 * a second thread with PDT_TRI_PREFAULT, in the order the sort and the
 * kernel need them: the buckets the sort's counting pass writes (R[16n, 24n)
 * bytes: the helper starts there while the sort scans the points twice, then
 * both fault it), the index list, the sort's other records and points, then
 * the rest of R, where the kernel's edges grow.  Returns 0 (nothing held)
 * when out of memory. */
static int run_alloc(tri_run *r, pdt_tri_stats *st)
{
    size_t n = r->n, cap = r->cap;
    r->R = malloc(cap * sizeof *r->R);
    r->order = malloc(n * sizeof *r->order);
    r->cnt = malloc(PDT_DT_SORT_COUNTERS * sizeof *r->cnt);
    r->hc = malloc(PDT_DT_SORT_COUNTERS * sizeof *r->hc);
    if (!r->R || !r->order || !r->cnt || !r->hc) {
        free(r->R);
        free(r->order);
        free(r->cnt);
        free(r->hc);
        return 0;
    }
    pdt_big_advise(r->R, cap * sizeof *r->R);
    pdt_big_advise(r->order, n * sizeof *r->order);
    if ((r->keep & PDT_TRI_PREFAULT) && cap * sizeof *r->R >= PREFAULT_MIN) {
        char *rb = (char *)(void *)r->R;
        pdt_range rr[4] = { { rb + 16 * n, 8 * n }, { r->order, n * sizeof *r->order },
                            { rb, 16 * n }, { rb + 24 * n, cap * sizeof *r->R - 24 * n } };
        r->pf = pdt_prefault_start(rr, 4);
        st->prefaulted = r->pf != NULL;
    }
    return 1;
}

/* The distinct points sorted, in R[32n, 40n) bytes and then in pts[0, nu);
 * the copies dropped kept for PDT_PTS_RESTORE.  Returns 0 (nothing held, pts
 * untouched) when out of memory. */
static int run_sort(tri_run *r)
{
    size_t n = r->n;
    pdt_point *q = (pdt_point *)(void *)((char *)(void *)r->R + 32 * n);
    r->so = (pdt_dt_sorted){ r->order, q, (uint32_t *)(void *)(q + n), 0, 0 };
    pdt_dt_sort(r->pts, n, r->R, r->cnt, r->hc, &r->so);
    free(r->cnt);
    free(r->hc);
    if (r->so.ndup && (r->keep & PDT_PTS_RESTORE)) {
        r->dup = malloc(2 * r->so.ndup * sizeof *r->dup);
        if (!r->dup) {
            pdt_prefault_stop(r->pf);
            free(r->R);
            free(r->order);
            return 0;
        }
        memcpy(r->dup, r->so.dup, 2 * r->so.ndup * sizeof *r->dup);
    }
    memcpy(r->pts, q, r->so.nu * sizeof *r->pts); /* from here on pts[0, nu) are the kernel's */
    return 1;
}

/* Trace level 1: every distinct point's lifted height. */
static void trace_lift(pdt_trace *tr, const pdt_point *pts, const uint32_t *order, size_t nu)
{
    if (!PDT_TRACING(tr, 1)) return;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_LIFT, 0, 0, 0, 0);
    for (size_t i = 0; i < nu; i++)
        PDT_TRACE(tr, 1, PDT_EV_LIFT, 0, PDT_TRACE_PT(tr, order[i]), 0, 0,
                  (int64_t)pdt_lift(pts[i]).z);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_LIFT, 0, 0, 0, 0);
}

/* The kernel on the distinct points, named by their input indices:
 * triangles come out as input indices in R[0, nt), the trace names points
 * as before (tr->gid composed). */
static pdt_status run_kernel(tri_run *r)
{
    size_t nu = r->so.nu;
    pdt_trace *tr = r->tr;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_KERNEL, 0, 0, 0, 0);
    pdt_status s = nu >= 2 ? pdt_dt_kernel(r->order, r->pts, nu, r->R, r->cap, &r->nt, 0, tr,
                                           NULL, NULL, 0)
                           : PDT_OK;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_KERNEL, 0, 0, 0, 0);
    pdt_prefault_stop(r->pf); /* (long done, but it must end before R shrinks) */
    return s;
}

/* The points put back (PDT_PTS_RESTORE), the triangles in canonical order,
 * R shrunk to them (NULL when there are none): R beyond the triangles is
 * the scratch of both.  order and dup are freed; on an error, R too. */
static pdt_status run_output(tri_run *r, pdt_status s, pdt_tri **tris)
{
    pdt_tri *t = (pdt_tri *)(void *)r->R;
    size_t nt = r->nt;
    if ((r->keep & PDT_PTS_RESTORE))
        restore_points(r->pts, r->so.nu, r->order, r->dup, r->so.ndup,
                       (pdt_point *)(void *)(t + nt));
    free(r->order);
    free(r->dup);
    if (s != PDT_OK) {
        free(r->R);
        return s;
    }
    PDT_TRACE(r->tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_OUTPUT, 0, 0, 0, 0);
    pdt_dt_canonical(t, t, nt, t + nt);
    PDT_TRACE(r->tr, 1, PDT_EV_PHASE_END, PDT_PH_OUTPUT, 0, 0, 0, 0);
    if (nt == 0) {
        free(r->R);
        t = NULL;
    } else {
        pdt_tri *shrunk = realloc(t, nt * sizeof *shrunk);
        if (shrunk) t = shrunk;
    }
    *tris = t;
    return PDT_OK;
}

/* The counts of a finished run; Euler (thesis D5): triangles = 2n - h - 2
 * for non-collinear input. */
static void run_stats(const tri_run *r, pdt_tri_stats *st)
{
    size_t nu = r->so.nu, nt = r->nt;
    st->n_unique = nu;
    st->n_dup = r->n - nu;
    st->n_tri = nt;
    st->collinear = nt == 0;
    st->n_hull = nt ? 2 * nu - 2 - nt : nu;
}

/* Memory of the pipeline (n input points, nu distinct): one block R of
 * dt_edge_cap(n) edge records (72 bytes per point) is the sort's scratch (two
 * key arrays, the sorted points and the copies dropped: 48 bytes per point),
 * then the kernel's cut scratch, edges and triangles, then the canonical
 * order's scratch, and at last (shrunk) the triangles returned; order (4
 * bytes per point) names the distinct points; the points themselves (8 bytes
 * per point) are the caller's array, in the kernel's order during the
 * kernel.  Peak: 84 bytes per point (92 when the kernel had its own copy of
 * the points and the sort its own scratch); every page of R is touched once
 * (the fresh-page faults were a sixth of the time at 10^7 points).  With
 * PDT_TRI_PREFAULT a second thread faults R and order in ahead of use (on
 * an idle core: docs/geometry.md, "Fresh memory"). */
pdt_status pdt_triangulate_inplace(pdt_point *pts, size_t n, int keep, pdt_tri **tris,
                                   size_t *ntri, pdt_tri_stats *stats, pdt_trace *tr)
{
    *tris = NULL;
    *ntri = 0;
    pdt_tri_stats st;
    memset(&st, 0, sizeof st);
    st.n_in = n;
    if (n > PDT_KERNEL_MAX_POINTS) return PDT_ERR_ARG;
    if (n == 0) {
        st.collinear = 1;
        if (stats) *stats = st;
        return PDT_OK;
    }
    tri_run r = { .pts = pts, .n = n, .cap = dt_edge_cap(n), .keep = keep, .tr = tr };
    double t0 = pdt_seconds();
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_PARTITION, 0, 0, 0, 0);
    if (!run_alloc(&r, &st) || !run_sort(&r)) return PDT_ERR_NOMEM;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_PARTITION, 0, 0, 0, 0);
    double t1 = pdt_seconds();
    trace_lift(tr, pts, r.order, r.so.nu);
    pdt_status s = run_kernel(&r);
    double t2 = pdt_seconds();
    pdt_tri *t = NULL;
    s = run_output(&r, s, &t);
    if (s != PDT_OK) return s;
    double t3 = pdt_seconds();
    run_stats(&r, &st);
    st.t_sort = t1 - t0;
    st.t_kernel = t2 - t1;
    st.t_canon = t3 - t2;
    if (stats) *stats = st;
    *tris = t;
    *ntri = r.nt;
    return PDT_OK;
}

pdt_status pdt_triangulate(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri,
                           pdt_tri_stats *stats, pdt_trace *tr)
{
    *tris = NULL;
    *ntri = 0;
    if (n > PDT_KERNEL_MAX_POINTS) return PDT_ERR_ARG;
    pdt_point *w = pdt_big_alloc(n * sizeof *w);
    if (!w) return PDT_ERR_NOMEM;
    if (n) memcpy(w, pts, n * sizeof *w); /* (pts may be NULL when n == 0) */
    pdt_status s = pdt_triangulate_inplace(w, n, PDT_PTS_SPEND, tris, ntri, stats, tr);
    pdt_big_free(w, n * sizeof *w);
    return s;
}
