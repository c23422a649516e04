/* pdt — questions about a replay state (see pdt/view/query.h). */
#include "pdt/view/query.h"
#include "pdt/view/describe.h"
#include "pdt/predicates.h"

#include <math.h>
#include <stdlib.h>

size_t pdt_replay_stack_list(const pdt_replay *r, int32_t top, uint32_t *out, size_t cap)
{
    size_t nn;
    const pdt_rnode *N = pdt_replay_nodes(r, &nn);
    size_t d = top >= 0 ? N[top].depth : 0;
    if (d > cap) d = cap;
    size_t i = d;
    for (int32_t t = top; t >= 0 && i > 0; t = N[t].parent) out[--i] = N[t].pt;
    return d;
}

int pdt_replay_hull_live(const pdt_replay *r, const pdt_rstate *s, int q, int32_t h)
{
    size_t nh, ng;
    const pdt_rhull *Hs = pdt_replay_hulls(r, &nh);
    const pdt_rmerge *M = pdt_replay_merges(r, &ng);
    for (size_t g = 0; g < ng; g++) {
        if (M[g].begin_ev <= Hs[h].ev || M[g].begin_ev >= s->k) continue;
        if ((uint32_t)q < M[g].gl || (uint32_t)q >= M[g].gend) continue;
        int32_t h2 = pdt_rstate_slot(r, s, (int)M[g].rank, PDT_SLOT_HULL);
        if (h2 >= 0 && h2 != h && Hs[h2].ev > M[g].begin_ev) return 0;
    }
    return 1;
}

int pdt_replay_graham_scan_ended(const pdt_replay *r, const pdt_rstate *s, int q)
{
    size_t np;
    const pdt_rphase *Ph = pdt_replay_phases(r, &np);
    int ended = 0;
    uint32_t last = 0;
    for (size_t i = 0; i < np; i++) {
        if (Ph[i].rank != (uint32_t)q || Ph[i].phase != PDT_PH_GRAHAM_SCAN) continue;
        if (Ph[i].begin_ev >= s->k || (ended && Ph[i].begin_ev < last)) continue;
        last = Ph[i].begin_ev;
        ended = Ph[i].end_ev != UINT32_MAX && Ph[i].end_ev < s->k;
    }
    return ended;
}

int pdt_replay_stack_open(const pdt_replay *r, const pdt_rstate *s, int32_t top)
{
    size_t nn;
    const pdt_rnode *N = pdt_replay_nodes(r, &nn);
    return N[top].hull_ev >= s->k;
}

size_t pdt_replay_inside_count(const pdt_replay *r, const uint32_t v[3])
{
    size_t n;
    const pdt_point *P = pdt_replay_points(r, &n);
    if (v[0] >= n || v[1] >= n || v[2] >= n) return 0;
    int ccw = pdt_orient(P[v[0]], P[v[1]], P[v[2]]);
    size_t k = 0;
    if (ccw)
        for (size_t p = 0; p < n; p++) k += ccw * pdt_incircle0(P[v[0]], P[v[1]], P[v[2]], P[p]) > 0;
    return k;
}

/* The phase event e of state s is in (-1: none but the run) and whether it
 * is inside a merge (*in_merge). */
static int event_phase(const pdt_replay *r, const pdt_rstate *s, const pdt_rec *e, int *in_merge)
{
    int32_t ph = pdt_rstate_slot(r, s, (int)e->rank, PDT_SLOT_PHASE);
    size_t np;
    const pdt_rphase *Ph = pdt_replay_phases(r, &np);
    *in_merge = pdt_rstate_slot(r, s, (int)e->rank, PDT_SLOT_MERGE) >= 0;
    int phase = -1;
    for (int32_t p = ph; p >= 0; p = Ph[p].parent) {
        if (phase < 0 && Ph[p].phase != PDT_PH_RUN) phase = (int)Ph[p].phase;
        if (Ph[p].phase == PDT_PH_MERGE) *in_merge = 1;
    }
    if (e->ev.kind == PDT_EV_PHASE_BEGIN || e->ev.kind == PDT_EV_PHASE_END) phase = e->ev.sub;
    return phase;
}

/* The line of Graham's listing for event ev in phase. */
static int graham_line(const pdt_event *ev, int phase)
{
    switch (ev->kind) {
    case PDT_EV_SORT: return ev->b == 0 ? 0 : 1;
    case PDT_EV_DELETE: return 2;
    case PDT_EV_PUSH: return ev->b <= 2 ? 3 : 7;
    case PDT_EV_POP: return 8;
    case PDT_EV_HULL: return 9;
    case PDT_EV_PHASE_BEGIN: return phase == PDT_PH_GRAHAM_SCAN ? 4 : 0;
    case PDT_EV_PHASE_END: return phase == PDT_PH_GRAHAM_SCAN ? 9 : 1;
    default: return 5;
    }
}

static int output_phase(int phase)
{
    return phase == PDT_PH_OUTPUT || phase == PDT_PH_ORDER || phase == PDT_PH_WRITE;
}

/* The line of the SRM listing for event ev (-2: none by its kind). */
static int srm_event_line(const pdt_event *ev, int phase, int in_merge)
{
    switch (ev->kind) {
    case PDT_EV_LIFT: return in_merge ? 7 : 1;
    case PDT_EV_TRI_NEW: return in_merge ? 7 : 2;
    case PDT_EV_EDGE_ADD:
    case PDT_EV_EDGE_DEL:
    case PDT_EV_INCIRCLE: return in_merge ? 7 : 2;
    case PDT_EV_PUSH:
    case PDT_EV_POP:
    case PDT_EV_HULL: return in_merge ? 9 : 2;
    case PDT_EV_TRI_FINAL:
    case PDT_EV_RA_DEFER:
        if (in_merge) return 9;
        if (output_phase(phase)) return 10;
        return ev->kind == PDT_EV_TRI_FINAL ? 3 : 4;
    case PDT_EV_SHIP:
    case PDT_EV_SEND:
    case PDT_EV_RECV: return output_phase(phase) ? 10 : 6;
    case PDT_EV_DISCARD: return 8;
    case PDT_EV_MERGE_BEGIN: return 7;
    case PDT_EV_MERGE_END: return 9;
    default: return -2;
    }
}

/* The line of the SRM listing for an event of no line of its own: its phase's. */
static int srm_phase_line(int phase)
{
    switch (phase) {
    case PDT_PH_READ:
    case PDT_PH_PARTITION: return 0;
    case PDT_PH_LIFT: return 1;
    case PDT_PH_KERNEL:
    case PDT_PH_HULL: return 2;
    case PDT_PH_CLASSIFY: return 3;
    case PDT_PH_MERGE: return 5;
    case PDT_PH_OUTPUT:
    case PDT_PH_ORDER:
    case PDT_PH_WRITE: return 10;
    default: return -1;
    }
}

int pdt_replay_code_line(const pdt_replay *r, const pdt_rstate *s, int *id)
{
    /* a hull run keeps Graham's listing from before its first event to its
     * last ("run" lights no line) */
    int graham_run = pdt_replay_kind_count(r, PDT_EV_SORT) > 0 &&
                     pdt_replay_kind_count(r, PDT_EV_TRI_NEW) == 0;
    *id = graham_run ? PDT_CODE_GRAHAM : PDT_CODE_SRM;
    if (!s->k || s->k > pdt_replay_count(r)) return -1;
    const pdt_rec held = *pdt_replay_rec(r, s->k - 1); /* (a kept index's pointer is short-lived) */
    const pdt_event *ev = &held.ev;
    int in_merge;
    int phase = event_phase(r, s, &held, &in_merge);
    int gr = phase == PDT_PH_GRAHAM_SORT || phase == PDT_PH_GRAHAM_SCAN || ev->kind == PDT_EV_SORT ||
             ev->kind == PDT_EV_DELETE ||
             ((ev->kind == PDT_EV_PUSH || ev->kind == PDT_EV_POP) && ev->sub == PDT_STACK_GRAHAM);
    if (gr) *id = PDT_CODE_GRAHAM;
    if (graham_run && !gr) return -1;
    if (gr) return graham_line(ev, phase);
    int line = srm_event_line(ev, phase, in_merge);
    return line != -2 ? line : srm_phase_line(phase);
}


size_t pdt_replay_find_rank(const pdt_replay *r, size_t k, int dir, int rank)
{
    size_t m = pdt_replay_count(r);
    if (k > m) k = m;
    if (dir > 0) {
        for (size_t i = k; i < m; i++)
            if (pdt_replay_rank_of(r, i) == (uint32_t)rank) return i + 1;
    } else {
        for (size_t i = k > 1 ? k - 1 : 0; i-- > 0;)
            if (pdt_replay_rank_of(r, i) == (uint32_t)rank) return i + 1;
    }
    return k;
}

size_t pdt_replay_nearest_of_rank(const pdt_replay *r, size_t k, int rank)
{
    size_t m = pdt_replay_count(r);
    if (m == 0) return (size_t)-1;
    size_t e = k ? k - 1 : 0; /* the event at that cursor */
    if (e >= m) e = m - 1;
    for (size_t d = 0; d < m; d++) {
        if (e + d < m && pdt_replay_rank_of(r, e + d) == (uint32_t)rank) return e + d + 1;
        if (d <= e && pdt_replay_rank_of(r, e - d) == (uint32_t)rank) return e - d + 1;
        if (e + d >= m && d > e) break;
    }
    return (size_t)-1;
}

typedef struct vedge {
    uint32_t a, b, t; /* a < b; triangle */
} vedge;

static int cmp_vedge(const void *x, const void *y)
{
    const vedge *p = x, *q = y;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    if (p->b != q->b) return p->b < q->b ? -1 : 1;
    return (p->t > q->t) - (p->t < q->t);
}

/* Circumcentre in double precision; 0 if degenerate. */
static int centre(const pdt_point *P, const uint32_t v[3], double *ox, double *oy)
{
    double ax = P[v[0]].x, ay = P[v[0]].y;
    double bx = P[v[1]].x - ax, by = P[v[1]].y - ay, cx = P[v[2]].x - ax, cy = P[v[2]].y - ay;
    double d = 2 * (bx * cy - by * cx);
    if (d == 0) return 0;
    *ox = ax + (cy * (bx * bx + by * by) - by * (cx * cx + cy * cy)) / d;
    *oy = ay + (bx * (cx * cx + cy * cy) - cx * (bx * bx + by * by)) / d;
    return 1;
}

pdt_status pdt_replay_voronoi(const pdt_replay *r, const pdt_rstate *s, const uint8_t *hidden,
                              pdt_vseg **out, size_t *nout, pdt_err *err)
{
    *out = NULL;
    *nout = 0;
    size_t nt, n;
    const pdt_rtri *T = pdt_replay_tris(r, &nt);
    const pdt_rtri_hist *H = pdt_replay_tri_hist(r);
    const pdt_point *P = pdt_replay_points(r, &n);
    int nr = pdt_replay_nranks(r);
    vedge *E = malloc((3 * nt + 1) * sizeof *E);
    if (!E) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    size_t ne = 0;
    for (size_t t = 0; t < nt; t++) {
        uint32_t h = pdt_rstate_tri_entry(r, s, t);
        if (h == UINT32_MAX || H[h].status != PDT_TS_FINAL) continue;
        if (hidden && T[t].maker < (uint32_t)nr && hidden[T[t].maker]) continue;
        for (int j = 0; j < 3; j++) {
            uint32_t a = T[t].v[j], b = T[t].v[(j + 1) % 3];
            E[ne++] = (vedge){a < b ? a : b, a < b ? b : a, (uint32_t)t};
        }
    }
    qsort(E, ne, sizeof *E, cmp_vedge);
    pdt_vseg *S = malloc((ne + 1) * sizeof *S);
    if (!S) {
        free(E);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    size_t ns = 0;
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && E[j].a == E[i].a && E[j].b == E[i].b) j++;
        double x0, y0, x1, y1;
        if (!centre(P, T[E[i].t].v, &x0, &y0)) {
            i = j;
            continue;
        }
        pdt_vseg g = {x0, y0, 0, 0, 0, E[i].a, E[i].b};
        if (j - i >= 2 && centre(P, T[E[i + 1].t].v, &x1, &y1)) {
            g.x1 = x1;
            g.y1 = y1;
        } else {
            /* a hull edge: a ray from the centre, perpendicular to the edge,
             * away from the triangle's third corner */
            const uint32_t *v = T[E[i].t].v;
            uint32_t third = v[0] != E[i].a && v[0] != E[i].b ? v[0] : v[1] != E[i].a && v[1] != E[i].b ? v[1] : v[2];
            double ex = (double)P[E[i].b].x - P[E[i].a].x, ey = (double)P[E[i].b].y - P[E[i].a].y;
            double nx = ey, ny = -ex;
            double mx = ((double)P[E[i].a].x + P[E[i].b].x) / 2, my = ((double)P[E[i].a].y + P[E[i].b].y) / 2;
            if (nx * ((double)P[third].x - mx) + ny * ((double)P[third].y - my) > 0) nx = -nx, ny = -ny;
            double len = sqrt(nx * nx + ny * ny);
            g.x1 = nx / len;
            g.y1 = ny / len;
            g.ray = 1;
        }
        S[ns++] = g;
        i = j;
    }
    free(E);
    *out = S;
    *nout = ns;
    return PDT_OK;
}
