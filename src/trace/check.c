/* pdt — pdt trace check: the invariants a correct run's trace satisfies.
 *
 * One streaming pass per rank (cursor: memory O(block) plus what is being
 * checked), then the cross-rank checks.  The first violation found is
 * reported as "rank R event #K (the event as text): what is wrong".  The
 * final triangles and what grows with the points are check_finals.c's, the
 * checks of the whole run after the ranks' passes check_run.c's. */
#include <errno.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pdt/hull.h"
#include "pdt/predicates.h"
#include "pdt/tracefile.h"
#include "check_int.h"
#include "hullcert.h"
#include "pdt/xsort.h"
#include "pdt/bigmem.h"

pdt_status chk_nomem(chk *c)
{
    return pdt_err_set(c->err, PDT_ERR_NOMEM, "out of memory");
}

pdt_status chk_viol(chk *c, uint32_t rank, uint64_t seq, const pdt_event *e, const char *fmt,
                   ...)
{
    char what[600], text[160];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (e)
        return pdt_err_set(c->err, PDT_ERR_CHECK, "rank %" PRIu32 " event #%" PRIu64 " (%s): %s",
                           rank, seq, pdt_event_format(e, text, sizeof text), what);
    return pdt_err_set(c->err, PDT_ERR_CHECK, "%s", what);
}

int chk_grow(void **p, size_t *cap, size_t n, size_t size)
{
    if (n < *cap) return 0;
    size_t nc = *cap ? 2 * *cap : 64;
    void *q = realloc(*p, nc * size);
    if (!q) return -1;
    *p = q;
    *cap = nc;
    return 0;
}

/* A point argument must name a point of the run. */
static pdt_status need_pt(chk *c, uint32_t rank, uint64_t seq, const pdt_event *e, uint32_t p)
{
    if (p < c->npts) return PDT_OK;
    return chk_viol(c, rank, seq, e, "point %" PRIu32 " does not exist (the run has %zu points)", p,
                c->npts);
}

/* A set of undirected edges (key: smaller point << 32 | larger point; 0 is
 * never a key because the two points differ).  Linear probing with
 * backward-shift deletion. */
typedef struct edge_set {
    uint64_t *k;
    size_t cap, n;
} edge_set;

static uint64_t edge_key(uint32_t a, uint32_t b)
{
    return a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
}

static size_t edge_slot(const edge_set *e, uint64_t key)
{
    uint64_t h = key * 0x9e3779b97f4a7c15u;
    size_t i = (size_t)(h >> 20) & (e->cap - 1);
    while (e->k[i] && e->k[i] != key) i = (i + 1) & (e->cap - 1);
    return i;
}

static int edge_has(const edge_set *e, uint64_t key)
{
    return e->cap && e->k[edge_slot(e, key)] == key;
}

/* 0 ok, -1 no memory. */
static int edge_add(edge_set *e, uint64_t key)
{
    if (2 * (e->n + 1) > e->cap) {
        edge_set g = {calloc(e->cap ? 2 * e->cap : 1024, sizeof *g.k), e->cap ? 2 * e->cap : 1024, 0};
        if (!g.k) return -1;
        for (size_t i = 0; i < e->cap; i++)
            if (e->k[i]) g.k[edge_slot(&g, e->k[i])] = e->k[i];
        g.n = e->n;
        free(e->k);
        *e = g;
    }
    size_t i = edge_slot(e, key);
    if (!e->k[i]) {
        e->k[i] = key;
        e->n++;
    }
    return 0;
}

static void edge_del(edge_set *e, uint64_t key)
{
    size_t i = edge_slot(e, key), j = i;
    if (!e->k[i]) return;
    e->k[i] = 0;
    e->n--;
    for (;;) {  /* move later entries of the cluster back into the hole */
        j = (j + 1) & (e->cap - 1);
        if (!e->k[j]) break;
        size_t home = (size_t)((e->k[j] * 0x9e3779b97f4a7c15u) >> 20) & (e->cap - 1);
        if ((j > i && (home <= i || home > j)) || (j < i && home <= i && home > j)) {
            e->k[i] = e->k[j];
            e->k[j] = 0;
            i = j;
        }
    }
}

/* ---- the stacks within the budget ----------------------------------------------
 *
 * A stack of one instance can hold every point (a Graham scan over points
 * in convex position, a chain over collinear ones): the stacks are
 * malloc'd while together they take at most an eighth of the budget; a
 * stack that would take more grows on in a temporary file's mapping, whose
 * resident pages are given back every GIVE_BACK_EVERY events. */

/* Room for twice the entries of s.  0, or -1 (errno). */
static int stack_grow(chk *c, chk_stack *s)
{
    size_t cap = s->cap ? 2 * s->cap : 64, old = s->cap * sizeof *s->v;
    if (cap > SIZE_MAX / 2 / sizeof *s->v) {
        errno = ENOMEM;
        return -1;
    }
    size_t bytes = cap * sizeof *s->v;
    if (s->map.p) {
        if (pdt_temp_map_grow(&s->map, bytes)) return -1;
        s->v = s->map.p;
    } else if (c->stack_bytes - old + bytes <= c->budget / 8) {
        uint32_t *v = realloc(s->v, bytes);
        if (!v) return -1;
        s->v = v;
        c->stack_bytes += bytes - old;
    } else {  /* over its share of the budget: on to a file, for good */
        if (pdt_temp_map_new(&s->map, bytes)) return -1;
        if (s->n) memcpy(s->map.p, s->v, s->n * sizeof *s->v);
        free(s->v);
        c->stack_bytes -= old;
        s->v = s->map.p;
    }
    s->cap = cap;
    return 0;
}

static pdt_status stack_push(chk *c, chk_stack *s, uint32_t x)
{
    if (s->n == s->cap && stack_grow(c, s)) return chk_tmp_fail(c, "a stack", "cannot grow");
    s->v[s->n++] = x;
    return PDT_OK;
}

void chk_stack_free(chk *c, chk_stack *s)
{
    if (s->map.p) {
        pdt_temp_map_free(&s->map);
    } else {
        free(s->v);
        c->stack_bytes -= s->cap * sizeof *s->v;
    }
    *s = (chk_stack){0};
}

/* The resident pages of the stacks in files given back (they stay in the
 * file: the next push or pop reads its page again). */
void chk_stacks_give_back(chk_stack *st, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (st[i].map.p) pdt_release_pages(st[i].map.p, st[i].map.bytes);
}

typedef struct rank_state {
    chk_stack stack[256];   /* by stack id */
    u32vec phases;          /* open phases: (phase << 32 would not fit) ids */
    u32vec phase_seq_lo;    /* low 32 bits of the event index of each open phase */
    long open_merge;        /* index into c->mg, or -1 */
    int last_stack;         /* stack id of the latest push or pop, or -1 */
    /* level 2: the kernel's edges in the current kernel scope (a kernel
     * phase or a merge step) and the triangles it reported */
    edge_set edges;
    u32vec scope_tris;      /* 3 points per TRI_NEW */
    uint64_t edge_events;   /* in the current scope */
    uint64_t scope_seq;     /* event that opened the scope */
    int edges_traced;       /* the rank file's level has the kernel's edges (2) */
    /* a scope whose edges outgrew a quarter of the budget goes on on disk:
     * every edge event and triangle side a record, replayed at its end
     * (edges_spill) */
    pdt_xsort *spill;
    uint64_t spill_tris;    /* triangles reported in the spilled scope */
} rank_state;

static void rank_state_free(chk *c, rank_state *s)
{
    for (int i = 0; i < 256; i++) chk_stack_free(c, &s->stack[i]);
    free(s->phases.v);
    free(s->phase_seq_lo.v);
    free(s->edges.k);
    free(s->scope_tris.v);
    pdt_xsort_free(s->spill);
}

/* Graham's stack of rank 0 finished: it becomes the final one (its storage
 * moves there; the stack, emptied, takes the storage of the old final one). */
static void graham_done(chk *c, chk_stack *s)
{
    chk_stack old = c->graham_final;
    c->graham_final = *s;
    *s = old;
    s->n = 0;
}

static void scope_open(rank_state *rs, uint64_t seq)
{
    if (rs->edges.k) memset(rs->edges.k, 0, rs->edges.cap * sizeof *rs->edges.k);
    rs->edges.n = 0;
    rs->scope_tris.n = 0;
    rs->edge_events = 0;
    rs->scope_seq = seq;
    pdt_xsort_free(rs->spill);
    rs->spill = NULL;
    rs->spill_tris = 0;
}

/* End of a kernel scope: with level-2 edge events, the edges alive are
 * exactly the edges of the triangles the kernel reported. */
static pdt_status spill_replay(chk *c, rank_state *rs, uint32_t r);

static pdt_status scope_close(chk *c, rank_state *rs, uint32_t r, uint64_t seq,
                              const pdt_event *e)
{
    if (rs->spill) return spill_replay(c, rs, r);
    size_t nt = rs->scope_tris.n / 3;
    if (!rs->edge_events || nt == 0) return PDT_OK;
    edge_set tri = {0};
    pdt_status st = PDT_OK;
    for (size_t i = 0; i < nt && st == PDT_OK; i++) {
        const uint32_t *v = rs->scope_tris.v + 3 * i;
        for (int k = 0; k < 3 && st == PDT_OK; k++) {
            uint64_t key = edge_key(v[k], v[(k + 1) % 3]);
            if (!edge_has(&rs->edges, key))
                st = chk_viol(c, r, seq, e, "edge %" PRIu32 " %" PRIu32 " of triangle %" PRIu32
                                        " %" PRIu32 " %" PRIu32 " was never added or was deleted",
                          v[k], v[(k + 1) % 3], v[0], v[1], v[2]);
            else if (edge_add(&tri, key))
                st = chk_nomem(c);
        }
    }
    if (st == PDT_OK && tri.n != rs->edges.n)
        st = chk_viol(c, r, seq, e, "%zu edges alive at the end of the kernel run (begun at event #%"
                                PRIu64 "), but its %zu triangles have %zu edges",
                  rs->edges.n, rs->scope_seq, nt, tri.n);
    free(tri.k);
    if (st == PDT_OK) c->edge_scopes++;
    return st;
}

/* ---- a kernel scope's edges on disk --------------------------------------------
 *
 * Records by edge key: value = event << 2 | SP_ADD or SP_DEL for an edge
 * event, far corner << 2 | SP_TRI for a side of a reported triangle.  The
 * edges alive when the scope spills are written as added at the scope's
 * first event (their events were checked already). */
enum { SP_ADD = 0, SP_DEL = 1, SP_TRI = 2 };

static uint64_t edges_held(const rank_state *rs)
{
    return (uint64_t)rs->edges.cap * sizeof *rs->edges.k +
           (uint64_t)rs->scope_tris.cap * sizeof *rs->scope_tris.v;
}

static int spill_tri(pdt_xsort *x, uint32_t a, uint32_t b, uint32_t c)
{
    return pdt_xsort_put(x, edge_key(a, b), (uint64_t)c << 2 | SP_TRI) ||
           pdt_xsort_put(x, edge_key(b, c), (uint64_t)a << 2 | SP_TRI) ||
           pdt_xsort_put(x, edge_key(c, a), (uint64_t)b << 2 | SP_TRI);
}

static pdt_status spill_start(chk *c, rank_state *rs)
{
    if (!(rs->spill = pdt_xsort_new(c->budget / 4))) return chk_nomem(c);
    for (size_t i = 0; i < rs->edges.cap; i++)
        if (rs->edges.k[i] && pdt_xsort_put(rs->spill, rs->edges.k[i], rs->scope_seq << 2 | SP_ADD))
            return chk_tmp_fail(c, "the kernel's edges", "cannot write");
    for (size_t i = 0; i + 2 < rs->scope_tris.n; i += 3)
        if (spill_tri(rs->spill, rs->scope_tris.v[i], rs->scope_tris.v[i + 1], rs->scope_tris.v[i + 2]))
            return chk_tmp_fail(c, "the kernel's edges", "cannot write");
    rs->spill_tris = rs->scope_tris.n / 3;
    free(rs->edges.k);
    rs->edges = (edge_set){0};
    free(rs->scope_tris.v);
    rs->scope_tris = (u32vec){0};
    c->edge_spills++;
    return PDT_OK;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* The end of a spilled scope: each edge's events replayed in their order
 * (added when absent, deleted when present), then the edges alive are
 * exactly the sides of the reported triangles. */
static pdt_status spill_replay(chk *c, rank_state *rs, uint32_t r)
{
    pdt_xsort *x = rs->spill;
    rs->spill = NULL;
    if (!rs->edge_events || !rs->spill_tris) {  /* nothing to compare (as in memory) */
        pdt_xsort_free(x);
        return PDT_OK;
    }
    pdt_status st = PDT_OK;
    if (pdt_xsort_done(x)) st = chk_tmp_fail(c, "the kernel's edges", "cannot read back");
    uint64_t *ev = NULL, alive_n = 0, sides_n = 0;
    size_t cap = 0;
    pdt_kv kv;
    int have = st == PDT_OK ? pdt_xsort_get(x, &kv) : 0;
    while (st == PDT_OK && have == 1) {
        uint64_t key = kv.key, far = 0;
        size_t n = 0, tris = 0;
        while (have == 1 && kv.key == key && st == PDT_OK) {
            if ((kv.val & 3) == SP_TRI) {
                tris++;
                far = kv.val >> 2;
            } else if (n == cap && chk_grow((void **)&ev, &cap, n, sizeof *ev)) {
                st = chk_nomem(c);
            } else {
                ev[n++] = kv.val;
            }
            have = pdt_xsort_get(x, &kv);
        }
        if (st != PDT_OK) break;
        qsort(ev, n, sizeof *ev, cmp_u64);  /* the edge's events in their order */
        uint32_t a = (uint32_t)(key >> 32), b = (uint32_t)key;
        int alive = 0;
        for (size_t i = 0; i < n && st == PDT_OK; i++) {
            int add = (ev[i] & 3) == SP_ADD;
            if (add == alive)
                st = pdt_err_set(c->err, PDT_ERR_CHECK, "rank %" PRIu32 " event #%" PRIu64
                                 " (edge %" PRIu32 " %" PRIu32 "): %s", r, ev[i] >> 2, a, b,
                                 add ? "the edge already exists" : "the edge does not exist");
            alive = add;
        }
        if (st == PDT_OK && tris && !alive)
            st = chk_viol(c, r, 0, NULL, "rank %" PRIu32 ", the kernel run begun at event #%" PRIu64
                      ": edge %" PRIu32 " %" PRIu32 " of triangle %" PRIu32 " %" PRIu32 " %" PRIu64
                      " was never added or was deleted", r, rs->scope_seq, a, b, a, b, far);
        alive_n += alive;
        sides_n += tris > 0;
    }
    if (st == PDT_OK && have < 0) st = chk_tmp_fail(c, "the kernel's edges", "cannot read back");
    if (st == PDT_OK && alive_n != sides_n)
        st = chk_viol(c, r, 0, NULL, "rank %" PRIu32 ": %" PRIu64 " edges alive at the end of the "
                  "kernel run (begun at event #%" PRIu64 "), but its %" PRIu64 " triangles have %"
                  PRIu64 " edges", r, alive_n, rs->scope_seq, rs->spill_tris, sides_n);
    if (st == PDT_OK) c->edge_scopes++;
    free(ev);
    pdt_xsort_free(x);
    return st;
}

/* The checks of one event, one handler per kind: each returns PDT_OK, or
 * the violation it found (chk_viol) or what failed (out of memory, the
 * scratch file). */
#define CK_ARGS chk *c, rank_state *rs CK_MAYBE, uint32_t r CK_MAYBE, uint64_t seq CK_MAYBE, \
    const pdt_event *e CK_MAYBE
#define CK_MAYBE __attribute__((unused)) /* (not every check needs every argument) */

static pdt_status ck_phase_begin(CK_ARGS)
{
    if (e->sub == PDT_PH_KERNEL) scope_open(rs, seq);
    if (u32_push(&rs->phases, e->sub) || u32_push(&rs->phase_seq_lo, (uint32_t)seq))
        return chk_nomem(c);
    return PDT_OK;
}

static pdt_status ck_phase_end(CK_ARGS)
{
    if (rs->phases.n == 0 || rs->phases.v[rs->phases.n - 1] != e->sub) {
        const char *open = rs->phases.n ? pdt_phase_name((int)rs->phases.v[rs->phases.n - 1])
                                        : NULL;
        return chk_viol(c, r, seq, e, "ends a phase that is not the innermost open one (%s)",
                    rs->phases.n ? (open ? open : "?") : "none open");
    }
    rs->phases.n--;
    rs->phase_seq_lo.n--;
    if (e->sub == PDT_PH_KERNEL) return scope_close(c, rs, r, seq, e);
    return PDT_OK;
}

static pdt_status ck_edge(CK_ARGS)
{
    pdt_status st;
    if ((st = need_pt(c, r, seq, e, e->a)) != PDT_OK) return st;
    if ((st = need_pt(c, r, seq, e, e->b)) != PDT_OK) return st;
    if (e->a == e->b) return chk_viol(c, r, seq, e, "an edge from a point to itself");
    uint64_t key = edge_key(e->a, e->b);
    rs->edge_events++;
    if (!rs->spill && edges_held(rs) > c->budget / 4 && (st = spill_start(c, rs)) != PDT_OK)
        return st;
    if (rs->spill) {
        if (pdt_xsort_put(rs->spill, key, seq << 2 | (e->kind == PDT_EV_EDGE_ADD ? SP_ADD : SP_DEL)))
            return chk_tmp_fail(c, "the kernel's edges", "cannot write");
        return PDT_OK;
    }
    int alive = edge_has(&rs->edges, key);
    if (e->kind == PDT_EV_EDGE_ADD) {
        if (alive) return chk_viol(c, r, seq, e, "the edge already exists");
        if (edge_add(&rs->edges, key)) return chk_nomem(c);
    } else {
        if (!alive) return chk_viol(c, r, seq, e, "the edge does not exist");
        edge_del(&rs->edges, key);
    }
    return PDT_OK;
}

static pdt_status ck_tri_new(CK_ARGS)
{
    pdt_status st;
    /* kept for the edges' replay only (a level-1 trace has none: its
     * kernel's triangles would take 12 bytes each for nothing) */
    if (!rs->edges_traced) return PDT_OK;
    if (!rs->spill && edges_held(rs) > c->budget / 4 && (st = spill_start(c, rs)) != PDT_OK)
        return st;
    if (rs->spill) {
        rs->spill_tris++;
        if (spill_tri(rs->spill, e->a, e->b, e->c))
            return chk_tmp_fail(c, "the kernel's edges", "cannot write");
        return PDT_OK;
    }
    if (u32_push(&rs->scope_tris, e->a) || u32_push(&rs->scope_tris, e->b) ||
        u32_push(&rs->scope_tris, e->c))
        return chk_nomem(c);
    return PDT_OK;
}

static pdt_status ck_push(CK_ARGS)
{
    pdt_status st;
    chk_stack *s = &rs->stack[e->sub];
    if ((st = need_pt(c, r, seq, e, e->a)) != PDT_OK) return st;
    if (e->b == 1) {  /* a new stack instance begins */
        if (r == 0 && e->sub == PDT_STACK_GRAHAM && s->n) graham_done(c, s);
        s->n = 0;
        c->instances++;
    } else if (e->b != s->n + 1) {
        return chk_viol(c, r, seq, e, "depth after push should be %zu", s->n + 1);
    }
    if ((st = stack_push(c, s, e->a)) != PDT_OK) return st;
    c->pushes++;
    rs->last_stack = e->sub;
    if (e->sub == PDT_STACK_GRAHAM) c->mark[e->a] |= M_PUSHED;
    return PDT_OK;
}

static pdt_status ck_pop(CK_ARGS)
{
    chk_stack *s = &rs->stack[e->sub];
    if (s->n == 0) return chk_viol(c, r, seq, e, "pop from an empty stack");
    if (s->v[s->n - 1] != e->a)
        return chk_viol(c, r, seq, e, "the top of the %s stack is pt %" PRIu32 ", not pt %" PRIu32,
                    pdt_stack_name(e->sub) ? pdt_stack_name(e->sub) : "?",
                    s->v[s->n - 1], e->a);
    if (e->b != s->n - 1)
        return chk_viol(c, r, seq, e, "depth after pop should be %zu", s->n - 1);
    s->n--;
    c->pops++;
    rs->last_stack = e->sub;
    return PDT_OK;
}

static pdt_status ck_lift(CK_ARGS)
{
    pdt_status st;
    if ((st = need_pt(c, r, seq, e, e->a)) != PDT_OK) return st;
    pdt_point p = c->pts[e->a];
    uint64_t z = (uint64_t)((int64_t)p.x * p.x) + (uint64_t)((int64_t)p.y * p.y);
    if ((uint64_t)e->v != z)
        return chk_viol(c, r, seq, e, "z should be x*x + y*y = %" PRIu64, z);
    if (rs->open_merge >= 0) {
        c->mg[rs->open_merge].lifts++;
        c->lifts_merge++;
        return PDT_OK;
    }
    c->lifts_local++;
    uint64_t key = pdt_key(p);
    uint64_t ykey = pdt_key((pdt_point){p.y, p.x});
    if (!c->nlocal[r] || key < c->kmin[r]) c->kmin[r] = key;
    if (!c->nlocal[r] || key > c->kmax[r]) c->kmax[r] = key;
    if (!c->nlocal[r] || ykey < c->ymin[r]) c->ymin[r] = ykey;
    if (!c->nlocal[r] || ykey > c->ymax[r]) c->ymax[r] = ykey;
    c->nlocal[r]++;
    if (!(c->mark[e->a] & M_REP))
        return chk_viol(c, r, seq, e, "pt %" PRIu32 " is a duplicate of an earlier input point "
                                  "and should not be lifted", e->a);
    if (c->mark[e->a] & M_LIFTED)
        return chk_viol(c, r, seq, e, "pt %" PRIu32 " was already lifted (local lift-ups must "
                                  "cover each distinct point once)", e->a);
    c->mark[e->a] |= M_LIFTED;
    return PDT_OK;
}

static pdt_status ck_sort(CK_ARGS)
{
    pdt_status st;
    if ((st = need_pt(c, r, seq, e, e->a)) != PDT_OK) return st;
    c->mark[e->a] |= M_SORTED;
    c->sorts++;
    return PDT_OK;
}

static pdt_status ck_delete(CK_ARGS)
{
    pdt_status st;
    if ((st = need_pt(c, r, seq, e, e->a)) != PDT_OK) return st;
    if ((st = need_pt(c, r, seq, e, e->b)) != PDT_OK) return st;
    c->mark[e->a] |= M_DELETED;
    return PDT_OK;
}

static pdt_status ck_tri_final(CK_ARGS)
{
    pdt_status st;
    uint32_t v[3] = {e->a, e->b, e->c};
    for (int i = 0; i < 3; i++)
        if ((st = need_pt(c, r, seq, e, v[i])) != PDT_OK) return st;
    if (pdt_orient(c->pts[v[0]], c->pts[v[1]], c->pts[v[2]]) <= 0)
        return chk_viol(c, r, seq, e, "the triangle is not counter-clockwise");
    for (int i = 0; i < 3; i++)
        if (!(c->mark[v[i]] & M_REP))
            return chk_viol(c, r, seq, e, "pt %" PRIu32 " is a copy of an earlier input point and "
                                      "cannot be a corner of T*", v[i]);
    int k = v[0] < v[1] ? (v[0] < v[2] ? 0 : 2) : (v[1] < v[2] ? 1 : 2);
    if (c->nfin == c->maxfin && (st = chk_spill_finals(c)) != PDT_OK) return st;
    if (c->nfin == c->capfin && c->capfin == 0) {
        /* room for T*'s triangles (at most 2n) at once, within the
         * budget: growing by doubling held the old and the new buffer
         * together for a moment (the peak of the whole check) */
        size_t want = 2 * c->npts + 64 < c->maxfin ? 2 * c->npts + 64 : c->maxfin;
        if (!(c->fin = malloc(want * sizeof *c->fin))) return chk_nomem(c);
        c->capfin = want;
        pdt_big_advise(c->fin, c->capfin * sizeof *c->fin);
    }
    if (c->nfin == c->capfin) {
        if (chk_grow((void **)&c->fin, &c->capfin, c->nfin, sizeof *c->fin)) return chk_nomem(c);
        /* up to half the budget, filled once */
        pdt_big_advise(c->fin, c->capfin * sizeof *c->fin);
    }
    c->totfin++;
    fin *f = &c->fin[c->nfin++];
    for (int i = 0; i < 3; i++) f->t.v[i] = v[(k + i) % 3];
    f->rank = r;
    f->seq = seq;
    return PDT_OK;
}

static pdt_status ck_hull(CK_ARGS)
{
    /* after a monotone chain (lower stack, then upper stack): the hull is
     * the lower chain plus the upper chain without its two ends */
    int up = rs->last_stack;
    rs->last_stack = -1;
    if (e->b || (up != PDT_STACK_UPPER && up != PDT_STACK_MERGE_UPPER)) return PDT_OK;
    const chk_stack *lo = &rs->stack[up - 1], *hi = &rs->stack[up];
    if (lo->n < 2 || hi->n < 2 || lo->v[0] != hi->v[hi->n - 1] ||
        lo->v[lo->n - 1] != hi->v[0])
        return chk_viol(c, r, seq, e, "the %s and %s stacks do not form a closed chain",
                    pdt_stack_name(up - 1), pdt_stack_name(up));
    if (e->a != lo->n + hi->n - 2)
        return chk_viol(c, r, seq, e, "the %s and %s stacks hold %zu hull vertices",
                    pdt_stack_name(up - 1), pdt_stack_name(up), lo->n + hi->n - 2);
    c->hulls++;
    return PDT_OK;
}

static pdt_status ck_discard(CK_ARGS)
{
    if (rs->open_merge >= 0) c->mg[rs->open_merge].discards++;
    return PDT_OK;
}

static pdt_status ck_merge_begin(CK_ARGS)
{
    if (rs->open_merge >= 0)
        return chk_viol(c, r, seq, e, "the merge begun at event #%" PRIu64 " has not ended",
                    c->mg[rs->open_merge].seq);
    if (!(e->a < e->b && e->b < e->c && e->c <= (uint32_t)pdt_run_nranks(c->run)))
        return chk_viol(c, r, seq, e, "groups must be ranks [left, right) and [right, end) "
                                  "with left < right < end <= %d", pdt_run_nranks(c->run));
    if (e->v != (int64_t)r || e->b != r)
        return chk_viol(c, r, seq, e, "the merge rank must be the first rank of the right "
                                  "group (%" PRIu32 ") and the rank recording it", e->b);
    if (chk_grow((void **)&c->mg, &c->capmg, c->nmg, sizeof *c->mg)) return chk_nomem(c);
    c->mg[c->nmg] = (merge){e->sub, e->a, e->b, e->c, r, seq, 0, 0, 0};
    rs->open_merge = (long)c->nmg++;
    scope_open(rs, seq);
    return PDT_OK;
}

static pdt_status ck_merge_end(CK_ARGS)
{
    if (rs->open_merge < 0) return chk_viol(c, r, seq, e, "no merge step is open");
    merge *m = &c->mg[rs->open_merge];
    if (e->sub != m->level)
        return chk_viol(c, r, seq, e, "the open merge (event #%" PRIu64 ") is at level %" PRIu32,
                    m->seq, m->level);
    if (m->lifts != e->b)
        return chk_viol(c, r, seq, e, "the merge lifted %" PRIu64 " points, its border set has %"
                                  PRIu32, m->lifts, e->b);
    if (m->discards != (uint64_t)e->v)
        return chk_viol(c, r, seq, e, "%" PRIu64 " discard events were recorded in this merge",
                    m->discards);
    m->closed = 1;
    rs->open_merge = -1;
    return scope_close(c, rs, r, seq, e);
}

static pdt_status ck_msg(CK_ARGS)
{
    if (chk_grow((void **)&c->msg, &c->capmsg, c->nmsg, sizeof *c->msg)) return chk_nomem(c);
    msg *m = &c->msg[c->nmsg++];
    int send = e->kind == PDT_EV_SEND;
    m->src = send ? r : e->a;
    m->dst = send ? e->a : r;
    m->tag = e->sub;
    m->seq_no = e->v;
    m->bytes = pdt_event_bytes(e);
    m->rank = r;
    m->seq = seq;
    m->ev = *e;
    return PDT_OK;
}

#undef CK_ARGS
#undef CK_MAYBE

static pdt_status check_event(chk *c, rank_state *rs, uint32_t r, uint64_t seq, const pdt_event *e)
{
    switch (e->kind) {
    case PDT_EV_PHASE_BEGIN: return ck_phase_begin(c, rs, r, seq, e);
    case PDT_EV_PHASE_END: return ck_phase_end(c, rs, r, seq, e);
    case PDT_EV_EDGE_ADD: return ck_edge(c, rs, r, seq, e);
    case PDT_EV_EDGE_DEL: return ck_edge(c, rs, r, seq, e);
    case PDT_EV_TRI_NEW: return ck_tri_new(c, rs, r, seq, e);
    case PDT_EV_PUSH: return ck_push(c, rs, r, seq, e);
    case PDT_EV_POP: return ck_pop(c, rs, r, seq, e);
    case PDT_EV_LIFT: return ck_lift(c, rs, r, seq, e);
    case PDT_EV_SORT: return ck_sort(c, rs, r, seq, e);
    case PDT_EV_DELETE: return ck_delete(c, rs, r, seq, e);
    case PDT_EV_TRI_FINAL: return ck_tri_final(c, rs, r, seq, e);
    case PDT_EV_HULL: return ck_hull(c, rs, r, seq, e);
    case PDT_EV_DISCARD: return ck_discard(c, rs, r, seq, e);
    case PDT_EV_MERGE_BEGIN: return ck_merge_begin(c, rs, r, seq, e);
    case PDT_EV_MERGE_END: return ck_merge_end(c, rs, r, seq, e);
    case PDT_EV_SEND: return ck_msg(c, rs, r, seq, e);
    case PDT_EV_RECV: return ck_msg(c, rs, r, seq, e);
    default: return PDT_OK;
    }
}

#define CHECK_AHEAD 16

static int is_tri_event(int kind)
{
    return kind == PDT_EV_TRI_NEW || kind == PDT_EV_TRI_FINAL || kind == PDT_EV_RA_DEFER ||
           kind == PDT_EV_SHIP || kind == PDT_EV_DISCARD;
}

static pdt_status check_rank(chk *c, uint32_t r)
{
    rank_state *rs = calloc(1, sizeof *rs);
    pdt_cursor *cur = NULL;
    if (!rs) return chk_nomem(c);
    rs->open_merge = -1;
    rs->last_stack = -1;
    pdt_rank_info info;
    pdt_run_rank_info(c->run, (int)r, &info);
    rs->edges_traced = info.level >= 2;
    pdt_status st = pdt_cursor_open(c->run, (int)r, &cur, c->err);
    /* events are read CHECK_AHEAD ahead of the one checked, and the points a
     * lift or a triangle will read are fetched meanwhile (random places in
     * 8 bytes per point: cache misses were a third of the check's time) */
    pdt_event ring[CHECK_AHEAD];
    uint64_t seqs[CHECK_AHEAD];
    size_t got = 0, done = 0;
    while (st == PDT_OK) {
        while (got < done + CHECK_AHEAD &&
               pdt_cursor_next(cur, &ring[got % CHECK_AHEAD], &seqs[got % CHECK_AHEAD])) {
            const pdt_event *a = &ring[got % CHECK_AHEAD];
            if (a->kind == PDT_EV_LIFT || is_tri_event(a->kind)) {
                if (a->a < c->npts) __builtin_prefetch(&c->pts[a->a]);
                if (a->kind != PDT_EV_LIFT && a->b < c->npts) __builtin_prefetch(&c->pts[a->b]);
                if (a->kind != PDT_EV_LIFT && a->c < c->npts) __builtin_prefetch(&c->pts[a->c]);
            }
            got++;
        }
        if (done == got) break;
        c->events++;
        chk_tick(c);
        if (c->events % GIVE_BACK_EVERY == 0) chk_stacks_give_back(rs->stack, 256);
        st = check_event(c, rs, r, seqs[done % CHECK_AHEAD], &ring[done % CHECK_AHEAD]);
        done++;
    }
    if (st == PDT_OK && rs->phases.n) {
        uint32_t ph = rs->phases.v[rs->phases.n - 1];
        st = chk_viol(c, r, 0, NULL, "rank %" PRIu32 ": phase %s begun at event #%" PRIu32
                                 " never ends", r,
                  pdt_phase_name((int)ph) ? pdt_phase_name((int)ph) : "?",
                  rs->phase_seq_lo.v[rs->phases.n - 1]);
    }
    if (st == PDT_OK && rs->open_merge >= 0)
        st = chk_viol(c, r, 0, NULL, "rank %" PRIu32 ": the merge step begun at event #%" PRIu64
                                 " never ends", r, c->mg[rs->open_merge].seq);
    if (st == PDT_OK && r == 0 && rs->stack[PDT_STACK_GRAHAM].n)
        graham_done(c, &rs->stack[PDT_STACK_GRAHAM]);
    pdt_cursor_close(cur);
    rank_state_free(c, rs);
    free(rs);
    return st;
}

pdt_status pdt_run_check(pdt_run *run, char *summary, size_t cap, pdt_err *err)
{
    return pdt_run_check_mem(run, PDT_TRACE_MEM_DEFAULT, summary, cap, err);
}

pdt_status pdt_run_check_mem(pdt_run *run, uint64_t budget, char *summary, size_t cap,
                             pdt_err *err)
{
    return pdt_run_check_tstar(run, budget, NULL, summary, cap, err);
}

/* c set up for run within budget: the manifest's command, what is certified
 * rather than recomputed, the per-rank tables, the marks and the distinct
 * points (*nu of them). */
static pdt_status check_setup(chk *c, pdt_run *run, uint64_t budget, pdt_tstar_fn tstar,
                              size_t *nu, pdt_err *err)
{
    memset(c, 0, sizeof *c);
    c->run = run;
    c->err = err;
    c->pts = pdt_run_points(run, &c->npts);
    c->budget = budget;
    c->tstar = tstar;
    /* half the budget for the finals' buffer; at least a few, so that a tiny
     * budget spills often instead of failing */
    c->maxfin = (size_t)(budget / 2 / sizeof(fin) < 16 ? 16 : budget / 2 / sizeof(fin));
    const pdt_manifest *m = pdt_run_manifest(run);
    c->is_tri = !strcmp(m->command, "triangulate");
    c->is_hull = !strcmp(m->command, "hull");
    c->bisect = m->partition == 1;
    c->certify = (uint64_t)c->npts * TSTAR_BYTES_PER_POINT > budget;
    c->hull_certify = (uint64_t)c->npts * HULL_BYTES_PER_POINT > budget;
    c->dedup_on_disk = (uint64_t)c->npts * DEDUP_BYTES_PER_POINT > budget;
    size_t nr = (size_t)pdt_run_nranks(run);
    c->kmin = calloc(nr, sizeof *c->kmin);
    c->kmax = calloc(nr, sizeof *c->kmax);
    c->nlocal = calloc(nr, sizeof *c->nlocal);
    c->ymin = calloc(nr, sizeof *c->ymin);
    c->ymax = calloc(nr, sizeof *c->ymax);
    *nu = 0;
    pdt_status st = PDT_OK;
    if (!c->kmin || !c->kmax || !c->nlocal || !c->ymin || !c->ymax) st = chk_nomem(c);
    else if (chk_marks_new(c)) st = chk_tmp_fail(c, "the marks of the points", "cannot create");
    c->give_back = c->mark_map || (uint64_t)c->npts * sizeof *c->pts > budget / 4;
    if (st == PDT_OK) st = chk_find_distinct(c, nu);
    return st;
}

static void check_free(chk *c)
{
    chk_marks_free(c);
    free(c->kmin);
    free(c->kmax);
    free(c->nlocal);
    free(c->ymin);
    free(c->ymax);
    free(c->fin);
    for (size_t i = 0; i < c->nruns; i++) fclose(c->runs[i]);
    free(c->runs);
    free(c->msg);
    free(c->mg);
    chk_stack_free(c, &c->graham_final);
}

pdt_status pdt_run_check_tstar(pdt_run *run, uint64_t budget, pdt_tstar_fn tstar, char *summary,
                               size_t cap, pdt_err *err)
{
    if (cap) summary[0] = '\0';
    const char *w = pdt_run_warnings(run);
    if (*w) {
        const char *nl = strchr(w, '\n');
        return pdt_err_set(err, PDT_ERR_CHECK, "damaged run folder: %.*s",
                           (int)(nl ? nl - w : (long)strlen(w)), w);
    }
    chk c;
    size_t nu;
    pdt_status st = check_setup(&c, run, budget, tstar, &nu, err);
    for (int r = 0; st == PDT_OK && r < pdt_run_nranks(run); r++) st = check_rank(&c, (uint32_t)r);
    if (st == PDT_OK && c.is_tri) st = chk_lifts(&c, nu);
    if (st == PDT_OK && c.is_tri && !c.bisect) st = chk_strips(&c);
    if (st == PDT_OK && c.is_tri) st = chk_finals(&c, nu);
    if (st == PDT_OK && c.is_hull) st = chk_graham_hull(&c);
    if (st == PDT_OK) st = chk_merges(&c);
    if (st == PDT_OK && c.is_tri && c.bisect) st = chk_regions(&c);
    if (st == PDT_OK) st = chk_messages(&c);
    if (st == PDT_OK && cap) chk_summary(&c, summary, cap);
    check_free(&c);
    return st;
}
