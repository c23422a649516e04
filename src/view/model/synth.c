/* pdt — synthetic runs for the viewer (see pdt/view/viewsynth.h). */
#include "pdt/view/viewsynth.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct gen {
    pdt_rec *recs;
    size_t m, cap;
    uint64_t *clock;   /* per rank */
    uint32_t *seq;     /* per rank */
    uint32_t *msgseq;  /* per (src, dst) pair */
    int nranks, level, failed;
    const pdt_point *pts;
} gen;

static uint64_t emit(gen *g, int rank, int kind, int sub, uint32_t a, uint32_t b, uint32_t c,
                     int64_t v, int lvl)
{
    if (lvl > g->level || g->failed) return 0;
    if (g->m == g->cap) {
        size_t cap = g->cap ? 2 * g->cap : 4096;
        pdt_rec *r = realloc(g->recs, cap * sizeof *r);
        if (!r) {
            g->failed = 1;
            return 0;
        }
        g->recs = r;
        g->cap = cap;
    }
    pdt_rec *r = &g->recs[g->m++];
    memset(r, 0, sizeof *r);
    r->ev.kind = (uint8_t)kind;
    r->ev.sub = (uint8_t)sub;
    r->ev.a = a;
    r->ev.b = b;
    r->ev.c = c;
    r->ev.v = v;
    r->ev.t = ++g->clock[rank];
    r->rank = (uint32_t)rank;
    r->seq = g->seq[rank]++;
    return r->ev.t;
}

#define EV(g, rank, kind, sub, a, b, c, v) emit((g), (rank), (kind), (sub), (a), (b), (c), (v), 1)

static void send_msg(gen *g, int src, int dst, int tag, uint32_t bytes, uint64_t *send_t,
                     uint32_t *seq)
{
    *seq = g->msgseq[(size_t)src * (size_t)g->nranks + (size_t)dst]++;
    *send_t = EV(g, src, PDT_EV_SEND, tag, (uint32_t)dst, bytes, 0, *seq);
}

static void recv_msg(gen *g, int src, int dst, int tag, uint32_t bytes, uint64_t send_t,
                     uint32_t seq)
{
    if (g->clock[dst] < send_t) g->clock[dst] = send_t;
    EV(g, dst, PDT_EV_RECV, tag, (uint32_t)src, bytes, 0, seq);
}

static int64_t orient(pdt_point a, pdt_point b, pdt_point c)
{
    return ((int64_t)b.x - a.x) * ((int64_t)c.y - a.y) - ((int64_t)b.y - a.y) * ((int64_t)c.x - a.x);
}

static int cmp_rec(const void *pa, const void *pb)
{
    const pdt_rec *a = pa, *b = pb;
    if (a->ev.t != b->ev.t) return a->ev.t < b->ev.t ? -1 : 1;
    if (a->rank != b->rank) return a->rank < b->rank ? -1 : 1;
    return a->seq < b->seq ? -1 : a->seq > b->seq;
}

/* Monotone chain over lex-sorted point ids, reporting push/pop on two stacks;
 * returns the hull size (lower + upper - 2) and writes the hull vertices
 * (lower chain then upper chain without the shared ends) to out. */
static size_t chain(gen *g, int rank, const uint32_t *ids, size_t k, int st_lo, int st_up,
                    uint32_t *stack, uint32_t *out)
{
    size_t nout = 0;
    for (int pass = 0; pass < 2; pass++) {
        size_t d = 0;
        int st = pass ? st_up : st_lo;
        for (size_t j = 0; j < k; j++) {
            uint32_t p = ids[pass ? k - 1 - j : j];
            while (d >= 2 && orient(g->pts[stack[d - 2]], g->pts[stack[d - 1]], g->pts[p]) < 0) {
                d--;
                EV(g, rank, PDT_EV_POP, st, stack[d], (uint32_t)d, p, 0);
            }
            stack[d++] = p;
            EV(g, rank, PDT_EV_PUSH, st, p, (uint32_t)d, 0, 0);
        }
        for (size_t j = 0; j + 1 < d; j++) out[nout++] = stack[j];
    }
    return nout;
}

typedef struct tri3 {
    uint32_t v[3];
} tri3;

typedef struct box {
    double x0, y0, x1, y1;
} box;

static int touches(const gen *g, tri3 t, box b)
{
    pdt_point A = g->pts[t.v[0]], B = g->pts[t.v[1]], C = g->pts[t.v[2]];
    double bx = B.x - A.x, by = B.y - A.y, cx = C.x - A.x, cy = C.y - A.y;
    double d = 2 * (bx * cy - by * cx);
    double ux = (cy * (bx * bx + by * by) - by * (cx * cx + cy * cy)) / d;
    double uy = (bx * (cx * cx + cy * cy) - cx * (bx * bx + by * by)) / d;
    double r2 = ux * ux + uy * uy;
    double ox = A.x + ux, oy = A.y + uy;
    double qx = ox < b.x0 ? b.x0 : ox > b.x1 ? b.x1 : ox;
    double qy = oy < b.y0 ? b.y0 : oy > b.y1 ? b.y1 : oy;
    return (qx - ox) * (qx - ox) + (qy - oy) * (qy - oy) <= r2 * (1 + 1e-9);
}

static void gen_init(gen *g, int nranks, int level)
{
    memset(g, 0, sizeof *g);
    g->nranks = nranks;
    g->level = level;
    g->clock = calloc((size_t)nranks, sizeof *g->clock);
    g->seq = calloc((size_t)nranks, sizeof *g->seq);
    g->msgseq = calloc((size_t)nranks * (size_t)nranks, sizeof *g->msgseq);
    if (!g->clock || !g->seq || !g->msgseq) g->failed = 1;
}

static pdt_status gen_finish(gen *g, pdt_point *pts, size_t n, pdt_synth *out, pdt_err *err)
{
    free(g->clock);
    free(g->seq);
    free(g->msgseq);
    if (g->failed) {
        free(g->recs);
        free(pts);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    }
    qsort(g->recs, g->m, sizeof *g->recs, cmp_rec);
    out->pts = pts;
    out->n = n;
    out->recs = g->recs;
    out->m = g->m;
    out->nranks = g->nranks;
    return PDT_OK;
}

/* ---- SRM on a grid ---------------------------------------------------------------- */

typedef struct tlist {
    tri3 *t;
    size_t n, cap;
} tlist;

static int tl_push(tlist *l, tri3 t)
{
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 64;
        tri3 *q = realloc(l->t, cap * sizeof *q);
        if (!q) return 0;
        l->t = q;
        l->cap = cap;
    }
    l->t[l->n++] = t;
    return 1;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* The grid SRM run being made: the points (cols x rows, column-major), the
 * ranks' first columns and boxes, what each rank holds (its deferred
 * triangles, its group's hull, the rank holding a group's hull), and
 * scratch for point lists, Graham's stacks and the border set's marks. */
typedef struct srm_grid {
    gen g;
    int cols, rows, nranks;
    size_t R;
    pdt_point *pts;
    int *first;        /* first column of each rank; nranks + 1 */
    box *bx;
    tlist *pend;       /* per rank: deferred triangles it holds */
    uint32_t **hull;   /* hull held by a rank */
    size_t *nhull;
    int *holder;       /* per group start: the rank holding its hull */
    uint32_t *ids, *stack, *hbuf;
    uint8_t *inB;
} srm_grid;

#define P(c, j) ((uint32_t)((size_t)(c) * G->R + (size_t)(j)))

/* Emit TRI_FINAL for T on rank r, or defer it to the first rank whose box
 * its circle touches (outside [lo, hi) when lo < hi; else any but r). */
static void classify(srm_grid *G, int r, tri3 T, int lo, int hi)
{
    gen *g = &G->g;
    int q = -1;
    for (int o = 0; o < G->nranks && q < 0; o++)
        if ((lo < hi ? (o < lo || o >= hi) : o != r) && touches(g, T, G->bx[o])) q = o;
    if (q < 0) {
        EV(g, r, PDT_EV_TRI_FINAL, 0, T.v[0], T.v[1], T.v[2], 0);
    } else {
        EV(g, r, PDT_EV_RA_DEFER, 0, T.v[0], T.v[1], T.v[2], q);
        if (!tl_push(&G->pend[r], T)) g->failed = 1;
    }
}

/* Phase 2's kernel on rank r: two triangles per cell of its columns, with
 * the kernel's edges at level 2. */
static void local_kernel(srm_grid *G, int r, tlist *local)
{
    gen *g = &G->g;
    for (int c = G->first[r]; c + 1 < G->first[r + 1]; c++)
        for (int j = 0; j + 1 < G->rows; j++) {
            uint32_t p00 = P(c, j), p10 = P(c + 1, j), p11 = P(c + 1, j + 1), p01 = P(c, j + 1);
            if (j == 0) emit(g, r, PDT_EV_EDGE_ADD, 0, p00, p10, 0, 0, 2);
            if (c == G->first[r]) emit(g, r, PDT_EV_EDGE_ADD, 0, p00, p01, 0, 0, 2);
            if (c == G->first[r] && j == 0) { /* the kernel tries the other diagonal first */
                emit(g, r, PDT_EV_EDGE_ADD, 0, p10, p01, 0, 0, 2);
                emit(g, r, PDT_EV_EDGE_DEL, 0, p10, p01, 0, 0, 2);
            }
            emit(g, r, PDT_EV_EDGE_ADD, 0, p10, p11, 0, 0, 2);
            emit(g, r, PDT_EV_EDGE_ADD, 0, p00, p11, 0, 0, 2);
            emit(g, r, PDT_EV_EDGE_ADD, 0, p01, p11, 0, 0, 2);
            tri3 t1 = {{p00, p10, p11}}, t2 = {{p00, p11, p01}};
            EV(g, r, PDT_EV_TRI_NEW, 0, p00, p10, p11, 0);
            EV(g, r, PDT_EV_TRI_NEW, 0, p00, p11, p01, 0);
            if (!tl_push(local, t1) || !tl_push(local, t2)) g->failed = 1;
        }
}

/* Phases 1 and 2 on rank r: lift its points, triangulate its strip, its
 * hull, and classify its triangles by their restricted areas. */
static void srm_local(srm_grid *G, int r)
{
    gen *g = &G->g;
    EV(g, r, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    EV(g, r, PDT_EV_PHASE_BEGIN, PDT_PH_LIFT, 0, 0, 0, 0);
    for (int c = G->first[r]; c < G->first[r + 1]; c++)
        for (int j = 0; j < G->rows; j++) {
            pdt_point q = G->pts[P(c, j)];
            EV(g, r, PDT_EV_LIFT, 0, P(c, j), 0, 0, (int64_t)q.x * q.x + (int64_t)q.y * q.y);
        }
    EV(g, r, PDT_EV_PHASE_END, PDT_PH_LIFT, 0, 0, 0, 0);
    EV(g, r, PDT_EV_PHASE_BEGIN, PDT_PH_KERNEL, 0, 0, 0, 0);
    tlist local = {0};
    local_kernel(G, r, &local);
    EV(g, r, PDT_EV_PHASE_END, PDT_PH_KERNEL, 0, 0, 0, 0);
    EV(g, r, PDT_EV_PHASE_BEGIN, PDT_PH_HULL, 0, 0, 0, 0);
    size_t k = 0;
    for (int c = G->first[r]; c < G->first[r + 1]; c++)
        for (int j = 0; j < G->rows; j++) G->ids[k++] = P(c, j);
    size_t h = chain(g, r, G->ids, k, PDT_STACK_LOWER, PDT_STACK_UPPER, G->stack, G->hbuf);
    G->hull[r] = malloc((h + 1) * sizeof **G->hull);
    if (!G->hull[r]) g->failed = 1;
    else memcpy(G->hull[r], G->hbuf, h * sizeof *G->hbuf);
    G->nhull[r] = h;
    EV(g, r, PDT_EV_HULL, 0, (uint32_t)h, 0, 0, 0);
    EV(g, r, PDT_EV_PHASE_END, PDT_PH_HULL, 0, 0, 0, 0);
    EV(g, r, PDT_EV_PHASE_BEGIN, PDT_PH_CLASSIFY, 0, 0, 0, 0);
    for (size_t t = 0; t < local.n && !g->failed; t++) classify(G, r, local.t[t], 0, 0);
    free(local.t);
    EV(g, r, PDT_EV_PHASE_END, PDT_PH_CLASSIFY, 0, 0, 0, 0);
}

/* A merge of groups [gl, gr) and [gr, ge) at rank m = gr, before it
 * begins: each rank ships the deferred triangles touching the partner
 * group (into shipped) and tells m how many, and the two group hulls
 * travel to m. */
static void merge_gather(srm_grid *G, int gl, int gr, int ge, tlist *shipped)
{
    gen *g = &G->g;
    int m = gr;
    for (int q = gl; q < ge && !g->failed; q++) {
        int lo = q < gr ? gr : gl, hi = q < gr ? ge : gr;
        size_t keep = 0, ns = 0;
        for (size_t t = 0; t < G->pend[q].n; t++) {
            tri3 T = G->pend[q].t[t];
            int hit = 0;
            for (int o = lo; o < hi && !hit; o++) hit = touches(g, T, G->bx[o]);
            if (hit) {
                EV(g, q, PDT_EV_SHIP, 0, T.v[0], T.v[1], T.v[2], m);
                if (!tl_push(shipped, T)) g->failed = 1;
                ns++;
            } else {
                G->pend[q].t[keep++] = T;
            }
        }
        G->pend[q].n = keep;
        if (q != m) {
            uint64_t st;
            uint32_t sq;
            send_msg(g, q, m, 1, (uint32_t)(ns * 12 + 16), &st, &sq);
            recv_msg(g, q, m, 1, (uint32_t)(ns * 12 + 16), st, sq);
        }
    }
    for (int side = 0; side < 2; side++) { /* the group hulls travel to m */
        int hq = side ? G->holder[gr] : G->holder[gl];
        if (hq == m) continue;
        uint64_t st;
        uint32_t sq;
        send_msg(g, hq, m, 2, (uint32_t)(G->nhull[hq] * 16), &st, &sq);
        recv_msg(g, hq, m, 2, (uint32_t)(G->nhull[hq] * 16), st, sq);
    }
}

/* The border set at merge rank m: the shipped triangles' corners and the
 * two seam columns cl, cr, lifted in index order.  Returns its size. */
static size_t merge_border(srm_grid *G, int m, const tlist *shipped, int cl, int cr)
{
    gen *g = &G->g;
    size_t nb = 0;
    uint32_t *ids = G->ids;
    for (size_t t = 0; t < shipped->n; t++)
        for (int v = 0; v < 3; v++)
            if (!G->inB[shipped->t[t].v[v]]) G->inB[shipped->t[t].v[v]] = 1, ids[nb++] = shipped->t[t].v[v];
    for (int j = 0; j < G->rows; j++)
        for (int c = cl; c <= cr; c++)
            if (!G->inB[P(c, j)]) G->inB[P(c, j)] = 1, ids[nb++] = P(c, j);
    qsort(ids, nb, sizeof *ids, cmp_u32);
    for (size_t b = 0; b < nb; b++) {
        pdt_point q = G->pts[ids[b]];
        EV(g, m, PDT_EV_LIFT, 0, ids[b], 0, 0, (int64_t)q.x * q.x + (int64_t)q.y * q.y);
        G->inB[ids[b]] = 0;
    }
    return nb;
}

/* The border kernel at m: the seam's cells, and the shipped triangles kept
 * or (every odd row's, the grid's cocircular cells) discarded and made
 * again with the other diagonal.  Into kept; returns the discards. */
static size_t merge_kernel(srm_grid *G, int m, const tlist *shipped, int cl, int cr, tlist *kept)
{
    gen *g = &G->g;
    size_t ndisc = 0;
    const uint32_t R = (uint32_t)G->R;
    for (int j = 0; j + 1 < G->rows; j++) { /* the seam cells */
        uint32_t p00 = P(cl, j), p10 = P(cr, j), p11 = P(cr, j + 1), p01 = P(cl, j + 1);
        tri3 t1 = {{p00, p10, p11}}, t2 = {{p00, p11, p01}};
        EV(g, m, PDT_EV_TRI_NEW, 1, p00, p10, p11, 0);
        EV(g, m, PDT_EV_TRI_NEW, 1, p00, p11, p01, 0);
        if (!tl_push(kept, t1) || !tl_push(kept, t2)) g->failed = 1;
    }
    for (size_t t = 0; t < shipped->n && !g->failed; t++) {
        tri3 T = shipped->t[t];
        /* cell of T: its lowest-left corner */
        uint32_t c0 = T.v[0] / R, j0 = T.v[0] % R;
        if (j0 % 2 == 0) {
            EV(g, m, PDT_EV_TRI_NEW, 1, T.v[0], T.v[1], T.v[2], 0);
            if (!tl_push(kept, T)) g->failed = 1;
            continue;
        }
        int flip = T.v[1] == P(c0 + 1, j0); /* once per cell */
        uint32_t w = (int)c0 + 1 == cr || (int)c0 + 1 == cl ? P(c0 + 1, j0) : P(c0, j0);
        EV(g, m, PDT_EV_DISCARD, 0, T.v[0], T.v[1], T.v[2], w);
        ndisc++;
        if (flip) {
            uint32_t p00 = P(c0, j0), p10 = P(c0 + 1, j0), p11 = P(c0 + 1, j0 + 1), p01 = P(c0, j0 + 1);
            tri3 t3 = {{p00, p10, p01}}, t4 = {{p10, p11, p01}};
            EV(g, m, PDT_EV_TRI_NEW, 1, p00, p10, p01, 0);
            EV(g, m, PDT_EV_TRI_NEW, 1, p10, p11, p01, 0);
            if (!tl_push(kept, t3) || !tl_push(kept, t4)) g->failed = 1;
        }
    }
    return ndisc;
}

/* The merged group's hull at m, from both hulls' vertices (lex order). */
static void merge_hull(srm_grid *G, int m, int gl, int gr)
{
    gen *g = &G->g;
    int hl = G->holder[gl], hr = G->holder[gr];
    size_t nh = 0;
    for (size_t a = 0; a < G->nhull[hl]; a++) G->ids[nh++] = G->hull[hl][a];
    for (size_t a = 0; a < G->nhull[hr]; a++) G->ids[nh++] = G->hull[hr][a];
    G->holder[gl] = m;
    qsort(G->ids, nh, sizeof *G->ids, cmp_u32);
    size_t h = chain(g, m, G->ids, nh, PDT_STACK_MERGE_LOWER, PDT_STACK_MERGE_UPPER, G->stack, G->hbuf);
    uint32_t *nhl = realloc(G->hull[m], (h + 1) * sizeof *nhl);
    if (!nhl) {
        g->failed = 1;
    } else {
        G->hull[m] = nhl;
        memcpy(G->hull[m], G->hbuf, h * sizeof *G->hbuf);
        G->nhull[m] = h;
    }
    EV(g, m, PDT_EV_HULL, 0, (uint32_t)h, 0, 0, 0);
}

/* Phase 3's merge step of level lv joining groups [gl, gr) and [gr, ge). */
static void srm_merge(srm_grid *G, int lv, int gl, int gr, int ge)
{
    gen *g = &G->g;
    int m = gr, cl = G->first[gr] - 1, cr = G->first[gr];
    for (int q = gl; q < ge; q++) EV(g, q, PDT_EV_PHASE_BEGIN, PDT_PH_MERGE, (uint32_t)lv, 0, 0, 0);
    tlist shipped = {0}, kept = {0};
    merge_gather(G, gl, gr, ge, &shipped);
    EV(g, m, PDT_EV_MERGE_BEGIN, lv, (uint32_t)gl, (uint32_t)gr, (uint32_t)ge, m);
    size_t nb = merge_border(G, m, &shipped, cl, cr);
    size_t ndisc = merge_kernel(G, m, &shipped, cl, cr, &kept);
    merge_hull(G, m, gl, gr);
    /* reclassify the kept ones against ranks outside the group */
    for (size_t t = 0; t < kept.n && !g->failed; t++) classify(G, m, kept.t[t], gl, ge);
    EV(g, m, PDT_EV_MERGE_END, lv, (uint32_t)shipped.n, (uint32_t)nb, (uint32_t)kept.n, (int64_t)ndisc);
    for (int q = gl; q < ge; q++) EV(g, q, PDT_EV_PHASE_END, PDT_PH_MERGE, (uint32_t)lv, 0, 0, 0);
    free(shipped.t);
    free(kept.t);
}

/* Phase 4: the output gathered at rank 0. */
static void srm_output(srm_grid *G)
{
    gen *g = &G->g;
    for (int r = 0; r < G->nranks; r++) EV(g, r, PDT_EV_PHASE_BEGIN, PDT_PH_OUTPUT, 0, 0, 0, 0);
    for (int r = 1; r < G->nranks; r++) {
        uint64_t st;
        uint32_t sq;
        send_msg(g, r, 0, 3, 1024, &st, &sq);
        recv_msg(g, r, 0, 3, 1024, st, sq);
    }
    for (int r = 0; r < G->nranks; r++) {
        EV(g, r, PDT_EV_PHASE_END, PDT_PH_OUTPUT, 0, 0, 0, 0);
        EV(g, r, PDT_EV_PHASE_END, PDT_PH_RUN, 0, 0, 0, 0);
    }
}
#undef P

/* The grid's tables and points (0 when out of memory). */
static int srm_grid_open(srm_grid *G, int cols, int rows, int nranks, int level)
{
    size_t n = (size_t)cols * (size_t)rows, nr = (size_t)nranks;
    memset(G, 0, sizeof *G);
    G->cols = cols;
    G->rows = rows;
    G->nranks = nranks;
    G->R = (size_t)rows;
    gen_init(&G->g, nranks, level);
    G->pts = malloc(n * sizeof *G->pts);
    G->first = malloc((nr + 1) * sizeof *G->first);
    G->bx = malloc(nr * sizeof *G->bx);
    G->pend = calloc(nr, sizeof *G->pend);
    G->hull = calloc(nr, sizeof *G->hull);
    G->holder = malloc(nr * sizeof *G->holder);
    G->nhull = calloc(nr, sizeof *G->nhull);
    G->ids = malloc(n * sizeof *G->ids);
    G->stack = malloc((n + 1) * sizeof *G->stack);
    G->hbuf = malloc(2 * (n + 1) * sizeof *G->hbuf);
    G->inB = calloc(n, 1);
    if (!G->pts || !G->first || !G->bx || !G->pend || !G->hull || !G->nhull || !G->ids || !G->stack ||
        !G->hbuf || !G->inB || !G->holder)
        return 0;
    G->g.pts = G->pts;
    for (size_t c = 0; c < (size_t)cols; c++)
        for (size_t j = 0; j < G->R; j++) G->pts[c * G->R + j] = (pdt_point){(int32_t)c * 10, (int32_t)j * 30};
    for (int r = 0; r <= nranks; r++) G->first[r] = (int)((long)r * cols / nranks);
    for (int r = 0; r < nranks; r++) G->holder[r] = r;
    for (int r = 0; r < nranks; r++)
        G->bx[r] = (box){G->first[r] * 10.0, 0, (G->first[r + 1] - 1) * 10.0, (rows - 1) * 30.0};
    return 1;
}

static void srm_grid_close(srm_grid *G)
{
    for (int r = 0; G->pend && r < G->nranks; r++) free(G->pend[r].t);
    for (int r = 0; G->hull && r < G->nranks; r++) free(G->hull[r]);
    free(G->pend);
    free(G->hull);
    free(G->nhull);
    free(G->first);
    free(G->holder);
    free(G->bx);
    free(G->ids);
    free(G->stack);
    free(G->hbuf);
    free(G->inB);
}

pdt_status pdt_synth_srm(int cols, int rows, int nranks, int level, pdt_synth *out, pdt_err *err)
{
    memset(out, 0, sizeof *out);
    if (cols < 2 || rows < 2 || nranks < 1 || nranks > cols / 2)
        return pdt_err_set(err, PDT_ERR_ARG, "bad grid %dx%d for %d ranks", cols, rows, nranks);
    srm_grid G;
    if (!srm_grid_open(&G, cols, rows, nranks, level)) G.g.failed = 1;
    for (int r = 0; r < nranks && !G.g.failed; r++) srm_local(&G, r); /* phases 1 and 2 */
    for (int lv = 0, gs = 1; gs < nranks && !G.g.failed; lv++, gs *= 2) /* phase 3: the merge tree */
        for (int gl = 0; gl < nranks; gl += 2 * gs)
            if (gl + gs < nranks) srm_merge(&G, lv, gl, gl + gs, gl + 2 * gs < nranks ? gl + 2 * gs : nranks);
    if (!G.g.failed) srm_output(&G);
    srm_grid_close(&G);
    return gen_finish(&G.g, G.pts, (size_t)cols * (size_t)rows, out, err);
}

/* ---- Graham's scan, Version B --------------------------------------------------- */

typedef struct sorter {
    const pdt_point *pts;
    pdt_point o;
} sorter;

static int64_t dist2(pdt_point a, pdt_point b)
{
    int64_t dx = (int64_t)a.x - b.x, dy = (int64_t)a.y - b.y;
    return dx * dx + dy * dy;
}

/* Insertion-free sort helper: the angular comparison about the origin o
 * (counter-clockwise; ties by distance, closer first). */
static int ang_less(const sorter *s, uint32_t a, uint32_t b)
{
    int64_t o = orient(s->o, s->pts[a], s->pts[b]);
    if (o != 0) return o > 0;
    int64_t da = dist2(s->o, s->pts[a]), db = dist2(s->o, s->pts[b]);
    if (da != db) return da < db;
    return a < b;
}

static void ang_sort(const sorter *s, uint32_t *v, size_t n, uint32_t *tmp)
{
    if (n < 2) return;
    size_t h = n / 2;
    ang_sort(s, v, h, tmp);
    ang_sort(s, v + h, n - h, tmp);
    size_t i = 0, j = h, k = 0;
    while (i < h && j < n) tmp[k++] = ang_less(s, v[j], v[i]) ? v[j++] : v[i++];
    while (i < h) tmp[k++] = v[i++];
    while (j < n) tmp[k++] = v[j++];
    memcpy(v, tmp, n * sizeof *v);
}

/* n points from seed in a 100 x 100 square, with copies and near-collinear
 * points (ties for the sort). */
static void graham_points(pdt_point *pts, size_t n, uint64_t seed)
{
    uint64_t x = seed * 6364136223846793005ull + 1442695040888963407ull;
    for (size_t i = 0; i < n; i++) {
        x = x * 6364136223846793005ull + 1442695040888963407ull;
        int32_t px = (int32_t)((x >> 33) % 100), py = (int32_t)((x >> 13) % 100);
        if (i % 11 == 5) { px = pts[i - 1].x; py = pts[i - 1].y; }            /* a copy */
        if (i % 13 == 7) { px = pts[0].x + 2 * (pts[i - 1].x - pts[0].x) / 3; /* near-collinear */
                           py = pts[0].y + 2 * (pts[i - 1].y - pts[0].y) / 3; }
        pts[i] = (pdt_point){px, py};
    }
}

/* 2: the points but o in angular order about it (v); ties: delete the
 * closer / all but one copy.  The points kept, first in v: their number. */
static size_t graham_sort(gen *g, const pdt_point *pts, size_t n, uint32_t o, uint32_t *v,
                          uint32_t *tmp, uint8_t *del)
{
    size_t k = 0;
    for (uint32_t i = 0; i < n; i++)
        if (i != o) v[k++] = i;
    sorter s = {pts, pts[o]};
    ang_sort(&s, v, k, tmp);
    EV(g, 0, PDT_EV_SORT, 0, o, 0, 0, 0);
    for (size_t i = 0; i < k; i++) EV(g, 0, PDT_EV_SORT, 0, v[i], (uint32_t)(i + 1), 0, 0);
    for (size_t i = 0; i < k; i++) {
        pdt_point p = pts[v[i]];
        if (p.x == pts[o].x && p.y == pts[o].y) {
            del[i] = 1;
            EV(g, 0, PDT_EV_DELETE, PDT_DEL_COINCIDENT, v[i], o, 0, 0);
        } else if (i + 1 < k && orient(pts[o], p, pts[v[i + 1]]) == 0) {
            int same = pts[v[i + 1]].x == p.x && pts[v[i + 1]].y == p.y;
            del[i] = 1;
            EV(g, 0, PDT_EV_DELETE, same ? PDT_DEL_COINCIDENT : PDT_DEL_ANGULAR_TIE, v[i], v[i + 1], 0, 0);
        }
    }
    size_t kk = 0;
    for (size_t i = 0; i < k; i++)
        if (!del[i]) v[kk++] = v[i];
    return kk;
}

/* 3-10: the scan of o and the kk sorted points v, on stack. */
static void graham_scan(gen *g, const pdt_point *pts, uint32_t o, const uint32_t *v, size_t kk,
                        uint32_t *stack)
{
    size_t d = 0;
    stack[d++] = o;
    EV(g, 0, PDT_EV_PUSH, PDT_STACK_GRAHAM, o, 1, 0, 0);
    if (kk) {
        stack[d++] = v[0];
        EV(g, 0, PDT_EV_PUSH, PDT_STACK_GRAHAM, v[0], 2, 0, 0);
    }
    for (size_t i = 1; i < kk;) {
        if (d < 2 || orient(pts[stack[d - 2]], pts[stack[d - 1]], pts[v[i]]) > 0) {
            stack[d++] = v[i];
            EV(g, 0, PDT_EV_PUSH, PDT_STACK_GRAHAM, v[i], (uint32_t)d, 0, 0);
            i++;
        } else {
            d--;
            EV(g, 0, PDT_EV_POP, PDT_STACK_GRAHAM, stack[d], (uint32_t)d, v[i], 0);
        }
    }
    EV(g, 0, PDT_EV_HULL, 0, (uint32_t)d, d < 3, 0, 0);
}

pdt_status pdt_synth_graham(size_t n, uint64_t seed, pdt_synth *out, pdt_err *err)
{
    memset(out, 0, sizeof *out);
    if (n < 3) return pdt_err_set(err, PDT_ERR_ARG, "need 3 points");
    pdt_point *pts = malloc(n * sizeof *pts);
    uint32_t *v = malloc(n * sizeof *v), *tmp = malloc(n * sizeof *tmp);
    uint32_t *stack = malloc(n * sizeof *stack);
    uint8_t *del = calloc(n, 1);
    gen g;
    gen_init(&g, 1, 1);
    if (!pts || !v || !tmp || !stack || !del) g.failed = 1;
    if (g.failed) goto done;
    g.pts = pts;
    graham_points(pts, n, seed);
    /* 1: rightmost lowest point */
    uint32_t o = 0;
    for (uint32_t i = 1; i < n; i++)
        if (pts[i].y < pts[o].y || (pts[i].y == pts[o].y && pts[i].x > pts[o].x)) o = i;
    EV(&g, 0, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    EV(&g, 0, PDT_EV_PHASE_BEGIN, PDT_PH_GRAHAM_SORT, 0, 0, 0, 0);
    size_t kk = graham_sort(&g, pts, n, o, v, tmp, del);
    EV(&g, 0, PDT_EV_PHASE_END, PDT_PH_GRAHAM_SORT, 0, 0, 0, 0);
    EV(&g, 0, PDT_EV_PHASE_BEGIN, PDT_PH_GRAHAM_SCAN, 0, 0, 0, 0);
    graham_scan(&g, pts, o, v, kk, stack);
    EV(&g, 0, PDT_EV_PHASE_END, PDT_PH_GRAHAM_SCAN, 0, 0, 0, 0);
    EV(&g, 0, PDT_EV_PHASE_END, PDT_PH_RUN, 0, 0, 0, 0);
done:
    free(v);
    free(tmp);
    free(stack);
    free(del);
    return gen_finish(&g, pts, n, out, err);
}

void pdt_synth_free(pdt_synth *s)
{
    if (!s) return;
    free(s->pts);
    free(s->recs);
    memset(s, 0, sizeof *s);
}
