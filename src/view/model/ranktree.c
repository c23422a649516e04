/* pdt — the ranks as the merge tree (pdt/view/ranktree.h): built from the
 * merge steps, with each step's time, bytes and the critical path; the
 * groups a screen shows and the rows of a timeline. */
#include "pdt/view/ranktree.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define NONE32 UINT32_MAX

struct pdt_ranktree {
    pdt_rtnode *nd;
    size_t n;
    int nranks;
    int32_t *leaf;      /* per rank */
    int32_t *of_merge;  /* per merge step */
    size_t nmerge;
    /* the run's clock: times as fractions of [t_lo, t_hi] */
    const pdt_replay *r;
    uint64_t t_lo, t_hi;  /* t_hi == t_lo: no times, event order instead */
    double *ph_at;        /* per phase: begin, end */
    double *msg_at;       /* per message: send, receive */
};

typedef struct mkey {
    uint32_t gl, gend, i;
} mkey;

typedef struct build {
    pdt_ranktree *t;
    const pdt_rmerge *M;
    mkey *ord;          /* merge steps sorted by (gl, gend) */
    size_t nm;
} build;

static int by_range(const void *a, const void *b)
{
    const mkey *x = a, *y = b;
    if (x->gl != y->gl) return x->gl < y->gl ? -1 : 1;
    if (x->gend != y->gend) return x->gend < y->gend ? -1 : 1;
    return x->i < y->i ? -1 : x->i > y->i;
}

/* The merge step that joins exactly [lo, hi), or -1. */
static int32_t find_merge(const build *B, uint32_t lo, uint32_t hi)
{
    size_t a = 0, b = B->nm;
    while (a < b) {
        size_t m = (a + b) / 2;
        const mkey *g = &B->ord[m];
        if (g->gl < lo || (g->gl == lo && g->gend < hi)) a = m + 1;
        else b = m;
    }
    if (a < B->nm && B->ord[a].gl == lo && B->ord[a].gend == hi) return (int32_t)B->ord[a].i;
    return -1;
}

static int32_t build_node(build *B, uint32_t lo, uint32_t hi, int32_t parent, uint32_t depth)
{
    pdt_ranktree *t = B->t;
    int32_t id = (int32_t)t->n++;
    pdt_rtnode *d = &t->nd[id];
    memset(d, 0, sizeof *d);
    d->lo = lo;
    d->hi = hi;
    d->parent = parent;
    d->kid[0] = d->kid[1] = -1;
    d->depth = depth;
    d->merge = hi - lo > 1 ? find_merge(B, lo, hi) : -1;
    if (d->merge >= 0) t->of_merge[d->merge] = id;
    if (hi - lo == 1) {
        t->leaf[lo] = id;
        return id;
    }
    uint32_t split = d->merge >= 0 ? B->M[d->merge].gr : lo + (hi - lo) / 2;
    if (split <= lo || split >= hi) split = lo + (hi - lo) / 2;
    int32_t k0 = build_node(B, lo, split, id, depth + 1);
    int32_t k1 = build_node(B, split, hi, id, depth + 1);
    t->nd[id].kid[0] = k0;
    t->nd[id].kid[1] = k1;
    return id;
}

static uint64_t ev_time(const pdt_replay *r, uint32_t ev)
{
    if (ev == NONE32) return 0;
    const pdt_rec *e = pdt_replay_rec(r, ev);
    return e ? e->ev.t : 0;
}

/* The first event of a merge step's phase on its merge rank (its shipping
 * and receiving come before MERGE_BEGIN), or its MERGE_BEGIN. */
static void merge_starts(const pdt_ranktree *t, const pdt_replay *r, uint32_t *from)
{
    size_t np, nm;
    const pdt_rphase *P = pdt_replay_phases(r, &np);
    const pdt_rmerge *M = pdt_replay_merges(r, &nm);
    for (size_t i = 0; i < nm; i++) from[i] = M[i].begin_ev;
    for (size_t i = 0; i < np; i++) {
        const pdt_rphase *p = &P[i];
        if (p->phase != PDT_PH_MERGE || p->rank >= (uint32_t)t->nranks) continue;
        for (int32_t id = t->leaf[p->rank]; id >= 0; id = t->nd[id].parent) {
            int32_t mi = t->nd[id].merge;
            if (mi >= 0 && M[mi].rank == p->rank && M[mi].level == p->sub && p->begin_ev < from[mi])
                from[mi] = p->begin_ev;
        }
    }
}

/* Each merge node's time and bytes (messages its merge rank received in
 * its merge phase, up to MERGE_END). */
static void merge_facts(pdt_ranktree *t, const pdt_replay *r)
{
    size_t nm, ng;
    const pdt_rmerge *M = pdt_replay_merges(r, &nm);
    const pdt_rmsg *G = pdt_replay_msgs(r, &ng);
    uint32_t *from = malloc((nm ? nm : 1) * sizeof *from);
    if (!from) return;
    merge_starts(t, r, from);
    for (size_t i = 0; i < nm; i++) {
        int32_t id = t->of_merge[i];
        if (id < 0) continue;
        uint64_t b = M[i].begin_t, e = M[i].end_t;  /* (0 when it never ended) */
        t->nd[id].t_ns = e > b ? e - b : 0;
        t->nd[id].ready_ns = e;
    }
    for (size_t j = 0; j < ng; j++) {
        if (G[j].recv_ev == NONE32 || G[j].dst >= (uint32_t)t->nranks) continue;
        /* the merge steps led by the receiver: walk up from its leaf */
        for (int32_t id = t->leaf[G[j].dst]; id >= 0; id = t->nd[id].parent) {
            int32_t mi = t->nd[id].merge;
            if (mi < 0 || M[mi].rank != G[j].dst) continue;
            if (G[j].recv_ev >= from[mi] && G[j].recv_ev <= M[mi].end_ev) {
                t->nd[id].bytes += G[j].bytes;
                break;
            }
        }
    }
    free(from);
}

/* A leaf's ready time: the end of its last phase (not a merge) before the
 * merge step above it began. */
static void leaf_ready(pdt_ranktree *t, const pdt_replay *r)
{
    size_t np, nm;
    const pdt_rphase *P = pdt_replay_phases(r, &np);
    const pdt_rmerge *M = pdt_replay_merges(r, &nm);
    uint32_t *last = malloc((size_t)t->nranks * sizeof *last);
    uint64_t *at = malloc((size_t)t->nranks * sizeof *at);  /* its time (0: none) */
    if (!last || !at) {
        free(last);
        free(at);
        return;
    }
    for (int q = 0; q < t->nranks; q++) {
        last[q] = NONE32;
        at[q] = 0;
    }
    for (size_t i = 0; i < np; i++) {
        const pdt_rphase *p = &P[i];
        if (p->rank >= (uint32_t)t->nranks || p->end_ev == NONE32) continue;
        if (p->phase == PDT_PH_MERGE || p->phase == PDT_PH_RUN) continue;
        int32_t up = t->nd[t->leaf[p->rank]].parent;
        uint32_t bound = up >= 0 && t->nd[up].merge >= 0 ? M[t->nd[up].merge].begin_ev : NONE32;
        if (p->end_ev < bound && (last[p->rank] == NONE32 || p->end_ev > last[p->rank])) {
            last[p->rank] = p->end_ev;
            at[p->rank] = p->end_t;
        }
    }
    for (int q = 0; q < t->nranks; q++) t->nd[t->leaf[q]].ready_ns = at[q];
    free(at);
    free(last);
}

static void mark_critical(pdt_ranktree *t)
{
    int32_t id = 0;
    while (id >= 0) {
        pdt_rtnode *d = &t->nd[id];
        d->critical = 1;
        if (d->kid[0] < 0) break;
        const pdt_rtnode *a = &t->nd[d->kid[0]], *b = &t->nd[d->kid[1]];
        id = a->ready_ns > b->ready_ns ? d->kid[0] : d->kid[1];
    }
}

/* ---- the run's clock ---- */

/* The span of the run's times: the first and last events, every phase's
 * ends and every message's ends (a trace's clocks are aligned, but the
 * merged order is causal, not sorted by time). */
static void clock_span(pdt_ranktree *t, const pdt_replay *r, const uint64_t *pt, size_t np,
                       const uint64_t *mt, size_t ng)
{
    size_t m = pdt_replay_count(r);
    uint64_t lo = UINT64_MAX, hi = 0;
    uint64_t ends[2] = {m ? ev_time(r, 0) : 0, m ? ev_time(r, (uint32_t)(m - 1)) : 0};
    for (int i = 0; i < 2; i++) {
        if (ends[i] < lo) lo = ends[i];
        if (ends[i] > hi) hi = ends[i];
    }
    for (size_t i = 0; i < 2 * np; i++) {
        if (pt[i] < lo) lo = pt[i];
        if (pt[i] > hi) hi = pt[i];
    }
    for (size_t i = 0; i < 2 * ng; i++) {
        if (mt[i] < lo) lo = mt[i];
        if (mt[i] > hi) hi = mt[i];
    }
    t->t_lo = lo <= hi ? lo : 0;
    t->t_hi = lo <= hi ? hi : 0;
}

static double clock_frac(const pdt_ranktree *t, uint64_t ns)
{
    return ((double)ns - (double)t->t_lo) / ((double)t->t_hi - (double)t->t_lo);
}

/* Each phase's and message's ends on the clock: their events' times, or,
 * in a run without times, their events' places in the merged order. */
static int clock_build(pdt_ranktree *t, const pdt_replay *r)
{
    size_t np, ng, m = pdt_replay_count(r);
    const pdt_rphase *P = pdt_replay_phases(r, &np);
    const pdt_rmsg *G = pdt_replay_msgs(r, &ng);
    uint64_t *pt = malloc((2 * np + 1) * sizeof *pt), *mt = malloc((2 * ng + 1) * sizeof *mt);
    t->ph_at = malloc((2 * np + 1) * sizeof *t->ph_at);
    t->msg_at = malloc((2 * ng + 1) * sizeof *t->msg_at);
    t->r = r;
    if (!pt || !mt || !t->ph_at || !t->msg_at) {
        free(pt);
        free(mt);
        return 0;
    }
    /* the times the tables hold (read when they were made): no event decoded
     * but the first and the last */
    uint64_t t_first = m ? ev_time(r, 0) : 0, t_last = m ? ev_time(r, (uint32_t)(m - 1)) : 0;
    for (size_t i = 0; i < np; i++) {
        pt[2 * i] = P[i].begin_t;
        pt[2 * i + 1] = P[i].end_ev == NONE32 ? t_last : P[i].end_t;
    }
    for (size_t i = 0; i < ng; i++) { /* a missing end: the other's time */
        uint32_t s = G[i].send_ev, d = G[i].recv_ev;
        uint64_t any = s != NONE32 ? G[i].send_t : d != NONE32 ? G[i].recv_t : t_first;
        mt[2 * i] = s != NONE32 ? G[i].send_t : any;
        mt[2 * i + 1] = d != NONE32 ? G[i].recv_t : any;
    }
    clock_span(t, r, pt, np, mt, ng);
    if (t->nranks < PDT_RANKTREE_TIMED_RANKS) t->t_hi = t->t_lo; /* a step per event */
    double em = m ? (double)m : 1;
    for (size_t i = 0; i < np; i++) {
        double e1 = P[i].end_ev == NONE32 ? em : P[i].end_ev + 1.0;
        t->ph_at[2 * i] = t->t_hi > t->t_lo ? clock_frac(t, pt[2 * i]) : P[i].begin_ev / em;
        t->ph_at[2 * i + 1] = t->t_hi > t->t_lo ? clock_frac(t, pt[2 * i + 1]) : e1 / em;
    }
    for (size_t i = 0; i < ng; i++) {
        t->msg_at[2 * i] = t->t_hi > t->t_lo ? clock_frac(t, mt[2 * i]) : (G[i].send_ev + 0.5) / em;
        t->msg_at[2 * i + 1] = t->t_hi > t->t_lo ? clock_frac(t, mt[2 * i + 1]) : (G[i].recv_ev + 0.5) / em;
    }
    free(pt);
    free(mt);
    return 1;
}

int pdt_ranktree_timed(const pdt_ranktree *t, double *span_ns)
{
    if (span_ns) *span_ns = (double)(t->t_hi - t->t_lo);
    return t->t_hi > t->t_lo;
}

double pdt_ranktree_at(const pdt_ranktree *t, size_t e)
{
    size_t m = pdt_replay_count(t->r);
    if (e >= m) return 1;
    if (t->t_hi <= t->t_lo) return (double)e / (double)m;
    double u = clock_frac(t, ev_time(t->r, (uint32_t)e));
    return u < 0 ? 0 : u > 1 ? 1 : u;
}

const double *pdt_ranktree_phase_at(const pdt_ranktree *t)
{
    return t->ph_at;
}

const double *pdt_ranktree_msg_at(const pdt_ranktree *t)
{
    return t->msg_at;
}

size_t pdt_ranktree_event_at(const pdt_ranktree *t, double u)
{
    size_t a = 0, b = pdt_replay_count(t->r);
    while (a < b) { /* the merged order is by time but for causality: near enough */
        size_t mid = a + (b - a) / 2;
        if (pdt_ranktree_at(t, mid) < u) a = mid + 1;
        else b = mid;
    }
    return a;
}

pdt_ranktree *pdt_ranktree_new(const pdt_replay *r)
{
    int P = pdt_replay_nranks(r);
    if (P < 1) P = 1;
    size_t nm;
    const pdt_rmerge *M = pdt_replay_merges(r, &nm);
    pdt_ranktree *t = calloc(1, sizeof *t);
    build B = {t, M, NULL, nm};
    if (!t) return NULL;
    t->nranks = P;
    t->nmerge = nm;
    t->nd = malloc((2 * (size_t)P - 1) * sizeof *t->nd);
    t->leaf = malloc((size_t)P * sizeof *t->leaf);
    t->of_merge = malloc((nm ? nm : 1) * sizeof *t->of_merge);
    B.ord = malloc((nm ? nm : 1) * sizeof *B.ord);
    if (!t->nd || !t->leaf || !t->of_merge || !B.ord) {
        free(B.ord);
        pdt_ranktree_free(t);
        return NULL;
    }
    for (size_t i = 0; i < nm; i++) {
        B.ord[i] = (mkey){M[i].gl, M[i].gend, (uint32_t)i};
        t->of_merge[i] = -1;
    }
    qsort(B.ord, nm, sizeof *B.ord, by_range);
    build_node(&B, 0, (uint32_t)P, -1, 0);
    free(B.ord);
    merge_facts(t, r);
    leaf_ready(t, r);
    mark_critical(t);
    if (!clock_build(t, r)) {
        pdt_ranktree_free(t);
        return NULL;
    }
    return t;
}

void pdt_ranktree_free(pdt_ranktree *t)
{
    if (!t) return;
    free(t->nd);
    free(t->leaf);
    free(t->of_merge);
    free(t->ph_at);
    free(t->msg_at);
    free(t);
}

const pdt_rtnode *pdt_ranktree_nodes(const pdt_ranktree *t, size_t *n)
{
    *n = t->n;
    return t->nd;
}

int pdt_ranktree_nranks(const pdt_ranktree *t)
{
    return t->nranks;
}

int32_t pdt_ranktree_leaf(const pdt_ranktree *t, int q)
{
    return q >= 0 && q < t->nranks ? t->leaf[q] : -1;
}

int32_t pdt_ranktree_of_merge(const pdt_ranktree *t, size_t i)
{
    return i < t->nmerge ? t->of_merge[i] : -1;
}

/* Ranks of node id that are on (cnt: prefix counts). */
static uint32_t on_count(const pdt_ranktree *t, const uint32_t *cnt, int32_t id)
{
    return cnt[t->nd[id].hi] - cnt[t->nd[id].lo];
}

/* Split the most populous splittable group of out[0..k) if its children
 * holding ranks that are on still fit in maxg; returns the new count (k when
 * nothing could be split). */
static size_t split_once(const pdt_ranktree *t, const uint32_t *cnt, size_t maxg, int32_t *out,
                         size_t k)
{
    size_t best = k;
    for (size_t i = 0; i < k; i++) {
        const pdt_rtnode *d = &t->nd[out[i]];
        if (d->kid[0] < 0 || on_count(t, cnt, out[i]) < 2) continue;
        if (best == k || on_count(t, cnt, out[i]) > on_count(t, cnt, out[best])) best = i;
    }
    if (best == k) return k;
    const pdt_rtnode *d = &t->nd[out[best]];
    int32_t kids[2];
    size_t nk = 0;
    for (int j = 0; j < 2; j++)
        if (on_count(t, cnt, d->kid[j]) > 0) kids[nk++] = d->kid[j];
    if (k - 1 + nk > maxg) return k;
    memmove(&out[best + nk], &out[best + 1], (k - best - 1) * sizeof *out);
    for (size_t j = 0; j < nk; j++) out[best + j] = kids[j];
    return k - 1 + nk;
}

size_t pdt_ranktree_cut(const pdt_ranktree *t, const uint8_t *on, size_t maxg, int32_t *out)
{
    if (maxg < 1) return 0;
    uint32_t *cnt = malloc(((size_t)t->nranks + 1) * sizeof *cnt);
    if (!cnt) {
        out[0] = 0;
        return 1;
    }
    cnt[0] = 0;
    for (int q = 0; q < t->nranks; q++) cnt[q + 1] = cnt[q] + (on ? on[q] != 0 : 1);
    int32_t top = 0; /* the smallest subtree holding every rank that is on */
    while (cnt[t->nranks] > 0 && t->nd[top].kid[0] >= 0) {
        const pdt_rtnode *d = &t->nd[top];
        if (on_count(t, cnt, d->kid[0]) == on_count(t, cnt, top)) top = d->kid[0];
        else if (on_count(t, cnt, d->kid[1]) == on_count(t, cnt, top)) top = d->kid[1];
        else break;
    }
    size_t k = 1;
    out[0] = top;
    for (;;) {
        size_t k2 = split_once(t, cnt, maxg, out, k);
        if (k2 == k) break;
        k = k2;
    }
    free(cnt);
    return k;
}

static void push_rows(const pdt_ranktree *t, int32_t id, const uint8_t *open, int32_t *rows,
                      size_t cap, size_t *n)
{
    const pdt_rtnode *d = &t->nd[id];
    if (open && open[id] && d->kid[0] >= 0) {
        push_rows(t, d->kid[0], open, rows, cap, n);
        push_rows(t, d->kid[1], open, rows, cap, n);
        return;
    }
    if (*n < cap) rows[*n] = id;
    (*n)++;
}

size_t pdt_ranktree_rows(const pdt_ranktree *t, const int32_t *cut, size_t ncut,
                         const uint8_t *open, int32_t *rows, size_t cap)
{
    size_t n = 0;
    for (size_t i = 0; i < ncut; i++) push_rows(t, cut[i], open, rows, cap, &n);
    return n;
}

void pdt_ranktree_name(const pdt_ranktree *t, int32_t node, char *buf, size_t cap)
{
    const pdt_rtnode *d = &t->nd[node];
    if (d->hi - d->lo == 1) snprintf(buf, cap, "r%u", d->lo);
    else snprintf(buf, cap, "r%u–%u", d->lo, d->hi - 1);
}
