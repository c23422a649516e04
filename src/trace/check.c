/* pdt — pdt trace check: the invariants a correct run's trace satisfies.
 *
 * One streaming pass per rank (cursor: memory O(block) plus what is being
 * checked), then the cross-rank checks.  The first violation found is
 * reported as "rank R event #K (the event as text): what is wrong". */
#include <errno.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "pdt/delaunay.h"
#include "pdt/hull.h"
#include "pdt/predicates.h"
#include "pdt/tracefile.h"
#include "certify.h"
#include "tf_internal.h"
#include "xsort.h"
#include "../geom/bigmem.h"

typedef struct fin {   /* a TRI_FINAL, rotated to start at its smallest index */
    pdt_tri t;
    uint32_t rank;
    uint64_t seq;
} fin;

typedef struct msg {   /* a SEND or RECV */
    uint32_t src, dst, tag, rank;
    uint64_t bytes;
    int64_t seq_no;
    uint64_t seq;      /* event index */
    pdt_event ev;
} msg;

typedef struct merge {
    uint32_t level, gl, gr, end, rank;
    uint64_t seq, lifts, discards;
    int closed;
} merge;

typedef struct chk {
    pdt_run *run;
    pdt_err *err;
    const pdt_point *pts;
    size_t npts;
    int is_tri, is_hull;
    uint8_t *mark;          /* per point: see M_* */
    size_t mark_map;        /* bytes of the marks' file mapping (0: in memory) */
    int certify;            /* T* certified on disk, not recomputed (over budget) */
    int dedup_on_disk;      /* the distinct points found by a sort on disk */
    uint64_t dedup_runs;    /* sorted runs that sort wrote */
    int give_back;          /* give back the pages of the points and marks (tick) */
    uint64_t ticks;
    uint64_t cert_runs;     /* sorted runs the certificate wrote */
    fin *fin;               /* final triangles not yet spilled (see spill_finals) */
    size_t nfin, capfin;
    size_t maxfin;          /* finals held in memory before a spill (from the budget) */
    uint64_t budget;        /* the memory budget (bytes) */
    pdt_tstar_fn tstar;     /* recomputes T* (NULL: pdt_triangulate) */
    int tstar_strips;       /* the strips it worked on (0: the whole kernel) */
    FILE **runs;            /* sorted runs of finals spilled to temporary files */
    size_t nruns, capruns;
    uint64_t totfin;        /* final triangles recorded in all */
    uint64_t spills;        /* sorted runs written (before any compaction) */
    msg *msg;
    size_t nmsg, capmsg;
    merge *mg;
    size_t nmg, capmg;
    u32vec graham_final;    /* last finished Graham stack of rank 0 */
    uint64_t events, pushes, pops, instances, lifts_local, lifts_merge, sorts, hulls;
    uint64_t edge_scopes;   /* kernel runs whose level-2 edges were replayed */
    uint64_t edge_spills;   /* of them, replayed on disk (over a quarter of the budget) */
    /* the strip of each rank: lexicographic keys of its local lift-ups */
    uint64_t *kmin, *kmax, *nlocal;
} chk;

enum { M_SORTED = 1, M_DELETED = 2, M_PUSHED = 4, M_LIFTED = 8, M_REP = 16 };

static pdt_status nomem(chk *c)
{
    return pdt_err_set(c->err, PDT_ERR_NOMEM, "out of memory");
}

static pdt_status viol(chk *c, uint32_t rank, uint64_t seq, const pdt_event *e, const char *fmt,
                       ...) __attribute__((format(printf, 5, 6)));
static pdt_status viol(chk *c, uint32_t rank, uint64_t seq, const pdt_event *e, const char *fmt,
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

static int grow(void **p, size_t *cap, size_t n, size_t size)
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
    return viol(c, rank, seq, e, "point %" PRIu32 " does not exist (the run has %zu points)", p,
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

typedef struct rank_state {
    u32vec stack[256];      /* by stack id */
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

static void rank_state_free(rank_state *s)
{
    for (int i = 0; i < 256; i++) free(s->stack[i].v);
    free(s->phases.v);
    free(s->phase_seq_lo.v);
    free(s->edges.k);
    free(s->scope_tris.v);
    pdt_xsort_free(s->spill);
}

/* Graham's stack of rank 0 finished: remember its content. */
static pdt_status graham_done(chk *c, const u32vec *s)
{
    c->graham_final.n = 0;
    for (size_t i = 0; i < s->n; i++)
        if (u32_push(&c->graham_final, s->v[i])) return nomem(c);
    return PDT_OK;
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
                st = viol(c, r, seq, e, "edge %" PRIu32 " %" PRIu32 " of triangle %" PRIu32
                                        " %" PRIu32 " %" PRIu32 " was never added or was deleted",
                          v[k], v[(k + 1) % 3], v[0], v[1], v[2]);
            else if (edge_add(&tri, key))
                st = nomem(c);
        }
    }
    if (st == PDT_OK && tri.n != rs->edges.n)
        st = viol(c, r, seq, e, "%zu edges alive at the end of the kernel run (begun at event #%"
                                PRIu64 "), but its %zu triangles have %zu edges",
                  rs->edges.n, rs->scope_seq, nt, tri.n);
    free(tri.k);
    if (st == PDT_OK) c->edge_scopes++;
    return st;
}

static int cmp_tri(const void *a, const void *b)
{
    const uint32_t *x = a, *y = b;
    for (int i = 0; i < 3; i++)
        if (x[i] != y[i]) return x[i] < y[i] ? -1 : 1;
    return 0;
}

static int cmp_fin(const void *a, const void *b)
{
    int k = cmp_tri(&((const fin *)a)->t, &((const fin *)b)->t);
    if (k) return k;
    const fin *x = a, *y = b;
    if (x->rank != y->rank) return x->rank < y->rank ? -1 : 1;
    return x->seq < y->seq ? -1 : x->seq > y->seq;
}

/* ---- sorting the finals in place ---------------------------------------------
 *
 * glibc's qsort (2.36) sorts a big array with a merge sort through a
 * temporary copy of it (480 MB more for the 2*10^7 finals of a 10^7-point
 * run: the check's peak) and calls the comparison through a pointer.  This
 * sort needs no copy: one in-place pass of an American flag sort on the high
 * bits of the smallest corner spreads the finals into buckets of a few
 * hundred, each then sorted by an introsort (quicksort, insertion sort for
 * small parts, heapsort when the quicksort goes too deep) with the order of
 * cmp_fin inlined. */

static inline int fin_less(const fin *x, const fin *y)
{
    for (int i = 0; i < 3; i++)
        if (x->t.v[i] != y->t.v[i]) return x->t.v[i] < y->t.v[i];
    if (x->rank != y->rank) return x->rank < y->rank;
    return x->seq < y->seq;
}

static inline void fin_swap(fin *x, fin *y)
{
    fin t = *x;
    *x = *y;
    *y = t;
}

static void fin_insertion(fin *a, size_t n)
{
    for (size_t i = 1; i < n; i++) {
        fin v = a[i];
        size_t j = i;
        for (; j > 0 && fin_less(&v, &a[j - 1]); j--) a[j] = a[j - 1];
        a[j] = v;
    }
}

static void fin_sift(fin *a, size_t i, size_t n)
{
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= n) return;
        if (c + 1 < n && fin_less(&a[c], &a[c + 1])) c++;
        if (!fin_less(&a[i], &a[c])) return;
        fin_swap(&a[i], &a[c]);
        i = c;
    }
}

static void fin_heapsort(fin *a, size_t n)
{
    for (size_t i = n / 2; i-- > 0;) fin_sift(a, i, n);
    for (size_t e = n; e-- > 1;) {
        fin_swap(&a[0], &a[e]);
        fin_sift(a, 0, e);
    }
}

static void fin_introsort(fin *a, size_t n, int depth)
{
    while (n > 16) {
        if (depth-- == 0) {
            fin_heapsort(a, n);
            return;
        }
        /* median of three to a[0], then Hoare's partition around it */
        size_t mid = n / 2;
        if (fin_less(&a[mid], &a[0])) fin_swap(&a[mid], &a[0]);
        if (fin_less(&a[n - 1], &a[0])) fin_swap(&a[n - 1], &a[0]);
        if (fin_less(&a[n - 1], &a[mid])) fin_swap(&a[n - 1], &a[mid]);
        fin_swap(&a[0], &a[mid]);
        fin p = a[0];
        size_t i = 0, j = n;
        for (;;) {
            do i++; while (i < n && fin_less(&a[i], &p));
            do j--; while (fin_less(&p, &a[j]));
            if (i >= j) break;
            fin_swap(&a[i], &a[j]);
        }
        fin_swap(&a[0], &a[j]);
        /* recurse into the smaller side, loop on the larger */
        if (j < n - j - 1) {
            fin_introsort(a, j, depth);
            a += j + 1;
            n -= j + 1;
        } else {
            fin_introsort(a + j + 1, n - j - 1, depth);
            n = j;
        }
    }
    fin_insertion(a, n);
}

static void fin_sort_buckets(fin *a, size_t n)
{
    int depth = 2;
    for (size_t k = n; k > 1; k >>= 1) depth += 2;
    fin_introsort(a, n, depth);
}

#define FIN_SORT_BITS 16

/* Sort a[0..n) by cmp_fin, in place; every corner is below npts. */
static void sort_fins(fin *a, size_t n, size_t npts)
{
    int shift = 0;
    while (npts && (npts - 1) >> shift >= ((size_t)1 << FIN_SORT_BITS)) shift++;
    size_t nb = npts ? ((npts - 1) >> shift) + 1 : 1, *next = NULL, *end = NULL;
    if (n < 4096 || !npts || !(next = calloc(nb, sizeof *next)) || !(end = calloc(nb, sizeof *end))) {
        free(next);
        fin_sort_buckets(a, n);
        return;
    }
    for (size_t i = 0; i < n; i++) end[a[i].t.v[0] >> shift]++;  /* (counts, for now) */
    size_t o = 0;
    for (size_t b = 0; b < nb; b++) {
        next[b] = o;
        o += end[b];
        end[b] = o;
    }
    for (size_t b = 0; b < nb; b++)  /* every final to its bucket, by cycles of swaps */
        while (next[b] < end[b]) {
            size_t d = a[next[b]].t.v[0] >> shift;
            if (d == b) next[b]++;
            else fin_swap(&a[next[b]], &a[next[d]++]);
        }
    for (size_t b = 0, lo = 0; b < nb; lo = end[b], b++) fin_sort_buckets(a + lo, end[b] - lo);
    free(next);
    free(end);
}

/* ---- final triangles in bounded memory --------------------------------------
 *
 * The finals are collected in a buffer of at most c->maxfin records (from the
 * memory budget).  A full buffer is sorted and written to a temporary file as
 * one sorted run; at the end the runs (and what is left in memory) are merged
 * into one sorted stream, which is compared with T* of the run's points.  When
 * more than MAX_RUNS runs pile up they are first merged into one, so the
 * number of open files stays bounded too. */
#define MAX_RUNS 64
/* What recomputing T* takes per point (the kernel's arrays and the reference
 * triangles; measured: some 90 bytes per point at 2*10^6 points).  When the
 * finals still in memory and this do not fit the budget together, the
 * finals go to disk before T* is recomputed. */
#define TSTAR_BYTES_PER_POINT 96u

/* A sorted source of finals: a temporary file or the memory buffer. */
typedef struct fin_src {
    FILE *f;                /* NULL: the memory buffer */
    const fin *mem;
    size_t nmem, imem;
    fin head;
    int has;
} fin_src;

static void src_advance(fin_src *s)
{
    if (s->f) s->has = fread(&s->head, sizeof s->head, 1, s->f) == 1;
    else if ((s->has = s->imem < s->nmem)) s->head = s->mem[s->imem++];
}

/* The sources merged in sorted order: a small heap of source indices. */
typedef struct fin_merge {
    fin_src *src;
    size_t *heap, n;
} fin_merge;

static int src_less(const void *ctx, size_t a, size_t b)
{
    const fin_merge *m = ctx;
    return cmp_fin(&m->src[a].head, &m->src[b].head) < 0;
}

static void fm_sift(fin_merge *m, size_t i)
{
    pdt_heap_sift(m->heap, m->n, i, src_less, m);
}

/* Open a merge over the spilled runs and mem[0..nmem) (sorted).  0 or -1. */
static int fm_open(fin_merge *m, FILE **runs, size_t nruns, const fin *mem, size_t nmem)
{
    m->src = calloc(nruns + 1, sizeof *m->src);
    m->heap = calloc(nruns + 1, sizeof *m->heap);
    m->n = 0;
    if (!m->src || !m->heap) return -1;
    for (size_t i = 0; i <= nruns; i++) {
        fin_src *s = &m->src[i];
        if (i < nruns) {
            s->f = runs[i];
            rewind(s->f);
        } else {
            s->mem = mem;
            s->nmem = nmem;
        }
        src_advance(s);
        if (s->has) m->heap[m->n++] = i;
    }
    for (size_t i = m->n / 2; i-- > 0;) fm_sift(m, i);
    return 0;
}

/* The next final in sorted order into *f: 1, or 0 at the end. */
static int fm_next(fin_merge *m, fin *f)
{
    if (!m->n) return 0;
    fin_src *s = &m->src[m->heap[0]];
    *f = s->head;
    src_advance(s);
    if (!s->has) m->heap[0] = m->heap[--m->n];
    fm_sift(m, 0);
    return 1;
}

static void fm_close(fin_merge *m)
{
    free(m->src);
    free(m->heap);
}

/* A temporary file's failure: "temporary file for <of> in DIR: <what>: why". */
static pdt_status tmp_fail(chk *c, const char *of, const char *what)
{
    const char *dir = getenv("TMPDIR");
    if (errno == ENOMEM) return nomem(c);
    return pdt_err_set(c->err, PDT_ERR_IO, "temporary file for %s in %s: %s: %s", of,
                       dir && *dir ? dir : "/tmp", what, strerror(errno));
}

static pdt_status io_fail(chk *c, const char *what)
{
    return tmp_fail(c, "the final triangles", what);
}

/* A new anonymous temporary file in $TMPDIR (else /tmp), or NULL (errno). */
static FILE *spill_file(void)
{
    const char *dir = getenv("TMPDIR");
    char path[4096];
    snprintf(path, sizeof path, "%s/pdt-finals.XXXXXX", dir && *dir ? dir : "/tmp");
    int fd = mkstemp(path);
    if (fd < 0) return NULL;
    unlink(path);  /* gone when closed, even if we are killed */
    FILE *f = fdopen(fd, "w+b");
    if (!f) close(fd);
    return f;
}

/* Merge every spilled run into one (when too many piled up). */
static pdt_status compact_runs(chk *c)
{
    FILE *out = spill_file();
    if (!out) return io_fail(c, "cannot create");
    fin_merge m;
    pdt_status st = PDT_OK;
    if (fm_open(&m, c->runs, c->nruns, NULL, 0)) st = nomem(c);
    fin f;
    while (st == PDT_OK && fm_next(&m, &f))
        if (fwrite(&f, sizeof f, 1, out) != 1) st = io_fail(c, "cannot write");
    fm_close(&m);
    if (st == PDT_OK && fflush(out) != 0) st = io_fail(c, "cannot write");
    if (st != PDT_OK) {
        fclose(out);
        return st;
    }
    for (size_t i = 0; i < c->nruns; i++) fclose(c->runs[i]);
    c->runs[0] = out;
    c->nruns = 1;
    return PDT_OK;
}

/* Sort the buffered finals and write them out as one run; empties the buffer. */
static pdt_status spill_finals(chk *c)
{
    if (!c->nfin) return PDT_OK;
    sort_fins(c->fin, c->nfin, c->npts);
    if (grow((void **)&c->runs, &c->capruns, c->nruns, sizeof *c->runs)) return nomem(c);
    FILE *f = spill_file();
    if (!f) return io_fail(c, "cannot create");
    c->runs[c->nruns++] = f;
    c->spills++;
    if (fwrite(c->fin, sizeof *c->fin, c->nfin, f) != c->nfin || fflush(f) != 0)
        return io_fail(c, "cannot write");
    c->nfin = 0;
    if (c->nruns >= MAX_RUNS) return compact_runs(c);
    return PDT_OK;
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
    if (!(rs->spill = pdt_xsort_new(c->budget / 4))) return nomem(c);
    for (size_t i = 0; i < rs->edges.cap; i++)
        if (rs->edges.k[i] && pdt_xsort_put(rs->spill, rs->edges.k[i], rs->scope_seq << 2 | SP_ADD))
            return tmp_fail(c, "the kernel's edges", "cannot write");
    for (size_t i = 0; i + 2 < rs->scope_tris.n; i += 3)
        if (spill_tri(rs->spill, rs->scope_tris.v[i], rs->scope_tris.v[i + 1], rs->scope_tris.v[i + 2]))
            return tmp_fail(c, "the kernel's edges", "cannot write");
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
    if (pdt_xsort_done(x)) st = tmp_fail(c, "the kernel's edges", "cannot read back");
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
            } else if (n == cap && grow((void **)&ev, &cap, n, sizeof *ev)) {
                st = nomem(c);
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
            st = viol(c, r, 0, NULL, "rank %" PRIu32 ", the kernel run begun at event #%" PRIu64
                      ": edge %" PRIu32 " %" PRIu32 " of triangle %" PRIu32 " %" PRIu32 " %" PRIu64
                      " was never added or was deleted", r, rs->scope_seq, a, b, a, b, far);
        alive_n += alive;
        sides_n += tris > 0;
    }
    if (st == PDT_OK && have < 0) st = tmp_fail(c, "the kernel's edges", "cannot read back");
    if (st == PDT_OK && alive_n != sides_n)
        st = viol(c, r, 0, NULL, "rank %" PRIu32 ": %" PRIu64 " edges alive at the end of the "
                  "kernel run (begun at event #%" PRIu64 "), but its %" PRIu64 " triangles have %"
                  PRIu64 " edges", r, alive_n, rs->scope_seq, rs->spill_tris, sides_n);
    if (st == PDT_OK) c->edge_scopes++;
    free(ev);
    pdt_xsort_free(x);
    return st;
}

static pdt_status check_event(chk *c, rank_state *rs, uint32_t r, uint64_t seq, const pdt_event *e)
{
    pdt_status st = PDT_OK;
    switch (e->kind) {
    case PDT_EV_PHASE_BEGIN:
        if (e->sub == PDT_PH_KERNEL) scope_open(rs, seq);
        if (u32_push(&rs->phases, e->sub) || u32_push(&rs->phase_seq_lo, (uint32_t)seq))
            return nomem(c);
        break;
    case PDT_EV_PHASE_END:
        if (rs->phases.n == 0 || rs->phases.v[rs->phases.n - 1] != e->sub) {
            const char *open = rs->phases.n ? pdt_phase_name((int)rs->phases.v[rs->phases.n - 1])
                                            : NULL;
            return viol(c, r, seq, e, "ends a phase that is not the innermost open one (%s)",
                        rs->phases.n ? (open ? open : "?") : "none open");
        }
        rs->phases.n--;
        rs->phase_seq_lo.n--;
        if (e->sub == PDT_PH_KERNEL) return scope_close(c, rs, r, seq, e);
        break;
    case PDT_EV_EDGE_ADD:
    case PDT_EV_EDGE_DEL: {
        if ((st = need_pt(c, r, seq, e, e->a)) != PDT_OK) return st;
        if ((st = need_pt(c, r, seq, e, e->b)) != PDT_OK) return st;
        if (e->a == e->b) return viol(c, r, seq, e, "an edge from a point to itself");
        uint64_t key = edge_key(e->a, e->b);
        rs->edge_events++;
        if (!rs->spill && edges_held(rs) > c->budget / 4 && (st = spill_start(c, rs)) != PDT_OK)
            return st;
        if (rs->spill) {
            if (pdt_xsort_put(rs->spill, key, seq << 2 | (e->kind == PDT_EV_EDGE_ADD ? SP_ADD : SP_DEL)))
                return tmp_fail(c, "the kernel's edges", "cannot write");
            break;
        }
        int alive = edge_has(&rs->edges, key);
        if (e->kind == PDT_EV_EDGE_ADD) {
            if (alive) return viol(c, r, seq, e, "the edge already exists");
            if (edge_add(&rs->edges, key)) return nomem(c);
        } else {
            if (!alive) return viol(c, r, seq, e, "the edge does not exist");
            edge_del(&rs->edges, key);
        }
        break;
    }
    case PDT_EV_TRI_NEW:
        /* kept for the edges' replay only (a level-1 trace has none: its
         * kernel's triangles would take 12 bytes each for nothing) */
        if (!rs->edges_traced) break;
        if (!rs->spill && edges_held(rs) > c->budget / 4 && (st = spill_start(c, rs)) != PDT_OK)
            return st;
        if (rs->spill) {
            rs->spill_tris++;
            if (spill_tri(rs->spill, e->a, e->b, e->c))
                return tmp_fail(c, "the kernel's edges", "cannot write");
            break;
        }
        if (u32_push(&rs->scope_tris, e->a) || u32_push(&rs->scope_tris, e->b) ||
            u32_push(&rs->scope_tris, e->c))
            return nomem(c);
        break;
    case PDT_EV_PUSH: {
        u32vec *s = &rs->stack[e->sub];
        if ((st = need_pt(c, r, seq, e, e->a)) != PDT_OK) return st;
        if (e->b == 1) {  /* a new stack instance begins */
            if (r == 0 && e->sub == PDT_STACK_GRAHAM && s->n && (st = graham_done(c, s)))
                return st;
            s->n = 0;
            c->instances++;
        } else if (e->b != s->n + 1) {
            return viol(c, r, seq, e, "depth after push should be %zu", s->n + 1);
        }
        if (u32_push(s, e->a)) return nomem(c);
        c->pushes++;
        rs->last_stack = e->sub;
        if (e->sub == PDT_STACK_GRAHAM) c->mark[e->a] |= M_PUSHED;
        break;
    }
    case PDT_EV_POP: {
        u32vec *s = &rs->stack[e->sub];
        if (s->n == 0) return viol(c, r, seq, e, "pop from an empty stack");
        if (s->v[s->n - 1] != e->a)
            return viol(c, r, seq, e, "the top of the %s stack is pt %" PRIu32 ", not pt %" PRIu32,
                        pdt_stack_name(e->sub) ? pdt_stack_name(e->sub) : "?",
                        s->v[s->n - 1], e->a);
        if (e->b != s->n - 1)
            return viol(c, r, seq, e, "depth after pop should be %zu", s->n - 1);
        s->n--;
        c->pops++;
        rs->last_stack = e->sub;
        break;
    }
    case PDT_EV_LIFT: {
        if ((st = need_pt(c, r, seq, e, e->a)) != PDT_OK) return st;
        pdt_point p = c->pts[e->a];
        uint64_t z = (uint64_t)((int64_t)p.x * p.x) + (uint64_t)((int64_t)p.y * p.y);
        if ((uint64_t)e->v != z)
            return viol(c, r, seq, e, "z should be x*x + y*y = %" PRIu64, z);
        if (rs->open_merge >= 0) {
            c->mg[rs->open_merge].lifts++;
            c->lifts_merge++;
            break;
        }
        c->lifts_local++;
        uint64_t key = pdt_key(p);
        if (!c->nlocal[r] || key < c->kmin[r]) c->kmin[r] = key;
        if (!c->nlocal[r] || key > c->kmax[r]) c->kmax[r] = key;
        c->nlocal[r]++;
        if (!(c->mark[e->a] & M_REP))
            return viol(c, r, seq, e, "pt %" PRIu32 " is a duplicate of an earlier input point "
                                      "and should not be lifted", e->a);
        if (c->mark[e->a] & M_LIFTED)
            return viol(c, r, seq, e, "pt %" PRIu32 " was already lifted (local lift-ups must "
                                      "cover each distinct point once)", e->a);
        c->mark[e->a] |= M_LIFTED;
        break;
    }
    case PDT_EV_SORT:
        if ((st = need_pt(c, r, seq, e, e->a)) != PDT_OK) return st;
        c->mark[e->a] |= M_SORTED;
        c->sorts++;
        break;
    case PDT_EV_DELETE:
        if ((st = need_pt(c, r, seq, e, e->a)) != PDT_OK) return st;
        if ((st = need_pt(c, r, seq, e, e->b)) != PDT_OK) return st;
        c->mark[e->a] |= M_DELETED;
        break;
    case PDT_EV_TRI_FINAL: {
        uint32_t v[3] = {e->a, e->b, e->c};
        for (int i = 0; i < 3; i++)
            if ((st = need_pt(c, r, seq, e, v[i])) != PDT_OK) return st;
        if (pdt_orient(c->pts[v[0]], c->pts[v[1]], c->pts[v[2]]) <= 0)
            return viol(c, r, seq, e, "the triangle is not counter-clockwise");
        for (int i = 0; i < 3; i++)
            if (!(c->mark[v[i]] & M_REP))
                return viol(c, r, seq, e, "pt %" PRIu32 " is a copy of an earlier input point and "
                                          "cannot be a corner of T*", v[i]);
        int k = v[0] < v[1] ? (v[0] < v[2] ? 0 : 2) : (v[1] < v[2] ? 1 : 2);
        if (c->nfin == c->maxfin && (st = spill_finals(c)) != PDT_OK) return st;
        if (c->nfin == c->capfin && c->capfin == 0) {
            /* room for T*'s triangles (at most 2n) at once, within the
             * budget: growing by doubling held the old and the new buffer
             * together for a moment (the peak of the whole check) */
            size_t want = 2 * c->npts + 64 < c->maxfin ? 2 * c->npts + 64 : c->maxfin;
            if (!(c->fin = malloc(want * sizeof *c->fin))) return nomem(c);
            c->capfin = want;
            pdt_big_advise(c->fin, c->capfin * sizeof *c->fin);
        }
        if (c->nfin == c->capfin) {
            if (grow((void **)&c->fin, &c->capfin, c->nfin, sizeof *c->fin)) return nomem(c);
            /* up to half the budget, filled once: huge pages spare most page faults */
            pdt_big_advise(c->fin, c->capfin * sizeof *c->fin);
        }
        c->totfin++;
        fin *f = &c->fin[c->nfin++];
        for (int i = 0; i < 3; i++) f->t.v[i] = v[(k + i) % 3];
        f->rank = r;
        f->seq = seq;
        break;
    }
    case PDT_EV_HULL: {
        /* after a monotone chain (lower stack, then upper stack): the hull is
         * the lower chain plus the upper chain without its two ends */
        int up = rs->last_stack;
        rs->last_stack = -1;
        if (e->b || (up != PDT_STACK_UPPER && up != PDT_STACK_MERGE_UPPER)) break;
        const u32vec *lo = &rs->stack[up - 1], *hi = &rs->stack[up];
        if (lo->n < 2 || hi->n < 2 || lo->v[0] != hi->v[hi->n - 1] ||
            lo->v[lo->n - 1] != hi->v[0])
            return viol(c, r, seq, e, "the %s and %s stacks do not form a closed chain",
                        pdt_stack_name(up - 1), pdt_stack_name(up));
        if (e->a != lo->n + hi->n - 2)
            return viol(c, r, seq, e, "the %s and %s stacks hold %zu hull vertices",
                        pdt_stack_name(up - 1), pdt_stack_name(up), lo->n + hi->n - 2);
        c->hulls++;
        break;
    }
    case PDT_EV_DISCARD:
        if (rs->open_merge >= 0) c->mg[rs->open_merge].discards++;
        break;
    case PDT_EV_MERGE_BEGIN:
        if (rs->open_merge >= 0)
            return viol(c, r, seq, e, "the merge begun at event #%" PRIu64 " has not ended",
                        c->mg[rs->open_merge].seq);
        if (!(e->a < e->b && e->b < e->c && e->c <= (uint32_t)pdt_run_nranks(c->run)))
            return viol(c, r, seq, e, "groups must be ranks [left, right) and [right, end) "
                                      "with left < right < end <= %d", pdt_run_nranks(c->run));
        if (e->v != (int64_t)r || e->b != r)
            return viol(c, r, seq, e, "the merge rank must be the first rank of the right "
                                      "group (%" PRIu32 ") and the rank recording it", e->b);
        if (grow((void **)&c->mg, &c->capmg, c->nmg, sizeof *c->mg)) return nomem(c);
        c->mg[c->nmg] = (merge){e->sub, e->a, e->b, e->c, r, seq, 0, 0, 0};
        rs->open_merge = (long)c->nmg++;
        scope_open(rs, seq);
        break;
    case PDT_EV_MERGE_END: {
        if (rs->open_merge < 0) return viol(c, r, seq, e, "no merge step is open");
        merge *m = &c->mg[rs->open_merge];
        if (e->sub != m->level)
            return viol(c, r, seq, e, "the open merge (event #%" PRIu64 ") is at level %" PRIu32,
                        m->seq, m->level);
        if (m->lifts != e->b)
            return viol(c, r, seq, e, "the merge lifted %" PRIu64 " points, its border set has %"
                                      PRIu32, m->lifts, e->b);
        if (m->discards != (uint64_t)e->v)
            return viol(c, r, seq, e, "%" PRIu64 " discard events were recorded in this merge",
                        m->discards);
        m->closed = 1;
        rs->open_merge = -1;
        return scope_close(c, rs, r, seq, e);
    }
    case PDT_EV_SEND:
    case PDT_EV_RECV: {
        if (grow((void **)&c->msg, &c->capmsg, c->nmsg, sizeof *c->msg)) return nomem(c);
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
        break;
    }
    default:
        break;
    }
    return PDT_OK;
}

#define CHECK_AHEAD 16

static int is_tri_event(int kind)
{
    return kind == PDT_EV_TRI_NEW || kind == PDT_EV_TRI_FINAL || kind == PDT_EV_RA_DEFER ||
           kind == PDT_EV_SHIP || kind == PDT_EV_DISCARD;
}

static void tick(chk *c);

static pdt_status check_rank(chk *c, uint32_t r)
{
    rank_state *rs = calloc(1, sizeof *rs);
    pdt_cursor *cur = NULL;
    if (!rs) return nomem(c);
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
        tick(c);
        st = check_event(c, rs, r, seqs[done % CHECK_AHEAD], &ring[done % CHECK_AHEAD]);
        done++;
    }
    if (st == PDT_OK && rs->phases.n) {
        uint32_t ph = rs->phases.v[rs->phases.n - 1];
        st = viol(c, r, 0, NULL, "rank %" PRIu32 ": phase %s begun at event #%" PRIu32
                                 " never ends", r,
                  pdt_phase_name((int)ph) ? pdt_phase_name((int)ph) : "?",
                  rs->phase_seq_lo.v[rs->phases.n - 1]);
    }
    if (st == PDT_OK && rs->open_merge >= 0)
        st = viol(c, r, 0, NULL, "rank %" PRIu32 ": the merge step begun at event #%" PRIu64
                                 " never ends", r, c->mg[rs->open_merge].seq);
    if (st == PDT_OK && r == 0 && rs->stack[PDT_STACK_GRAHAM].n)
        st = graham_done(c, &rs->stack[PDT_STACK_GRAHAM]);
    pdt_cursor_close(cur);
    rank_state_free(rs);
    free(rs);
    return st;
}

/* "made final twice" for two equal finals met in sorted order. */
static pdt_status twice(chk *c, const fin *f, const fin *prev)
{
    return viol(c, 0, 0, NULL, "triangle %" PRIu32 " %" PRIu32 " %" PRIu32 " made final twice: "
                "rank %" PRIu32 " event #%" PRIu64 " and rank %" PRIu32 " event #%" PRIu64,
                f->t.v[0], f->t.v[1], f->t.v[2], prev->rank, prev->seq, f->rank, f->seq);
}

/* The merged finals compared with T* recomputed: both in sorted order. */
static pdt_status compare_tstar(chk *c, fin_merge *m, const pdt_tri *ref, size_t nref)
{
    pdt_status st = PDT_OK;
    fin f, prev;
    int have = fm_next(m, &f), had = 0;
    size_t j = 0;
    while (st == PDT_OK && (have || j < nref)) {
        if (have && had && !cmp_tri(&f.t, &prev.t)) return twice(c, &f, &prev);
        int k = !have ? 1 : j == nref ? -1 : cmp_tri(&f.t, &ref[j]);
        if (k < 0) {
            st = viol(c, 0, 0, NULL, "rank %" PRIu32 " event #%" PRIu64 ": final triangle %"
                                     PRIu32 " %" PRIu32 " %" PRIu32 " is not in T* of the "
                                     "run's points", f.rank, f.seq, f.t.v[0], f.t.v[1], f.t.v[2]);
        } else if (k > 0) {
            st = viol(c, 0, 0, NULL, "triangle %" PRIu32 " %" PRIu32 " %" PRIu32 " of T* was "
                                     "never made final (%" PRIu64 " final triangles recorded, "
                                     "T* has %zu)", ref[j].v[0], ref[j].v[1], ref[j].v[2],
                      c->totfin, nref);
        } else {
            j++;
        }
        if (k <= 0) {
            prev = f;
            had = 1;
            have = fm_next(m, &f);
        }
    }
    return st;
}

/* With no final triangles, T* must be empty: fewer than three distinct
 * points, or all of them on one line. */
static pdt_status check_no_finals(chk *c, size_t nu)
{
    size_t first = SIZE_MAX, second = SIZE_MAX;
    for (size_t i = 0; nu >= 3 && i < c->npts; i++) {
        tick(c);
        if (!(c->mark[i] & M_REP)) continue;
        if (first == SIZE_MAX) first = i;
        else if (second == SIZE_MAX) second = i;
        else if (pdt_orient(c->pts[first], c->pts[second], c->pts[i]) != 0)
            return viol(c, 0, 0, NULL, "no triangle was made final, but T* of the run's points "
                                       "has triangles: points %zu, %zu and %zu are distinct and not "
                                       "on one line", first, second, i);
    }
    return PDT_OK;
}

/* The merged finals certified to be T* edge by edge on disk (certify.h),
 * when recomputing T* would not fit the budget. */
static pdt_status certify_tstar(chk *c, fin_merge *m, size_t nu)
{
    pdt_cert *cert = pdt_cert_new(c->run, c->budget);
    if (!cert) return nomem(c);
    pdt_status st = PDT_OK;
    fin f, prev;
    int had = 0;
    while (st == PDT_OK && fm_next(m, &f)) {
        if (had && !cmp_tri(&f.t, &prev.t)) st = twice(c, &f, &prev);
        else st = pdt_cert_add(cert, f.t.v, c->err);
        prev = f;
        had = 1;
    }
    if (st == PDT_OK && !had) st = check_no_finals(c, nu);
    if (st == PDT_OK) st = pdt_cert_finish(cert, nu, c->err);
    c->cert_runs = pdt_cert_runs(cert);
    pdt_cert_free(cert);
    return st;
}

/* Every final triangle once, and their set equals T* of the run's points.
 * The finals come sorted out of the runs and the buffer; T* is recomputed
 * after the buffer has been given back (the kernel needs its memory), or
 * certified on disk when recomputing it would not fit the budget. */
static pdt_status check_finals(chk *c, size_t nu)
{
    uint64_t held = (uint64_t)c->capfin * sizeof *c->fin;  /* the buffer as allocated */
    if (c->nruns || c->certify || held + (uint64_t)c->npts * TSTAR_BYTES_PER_POINT > c->budget) {
        /* out of memory's reach (or T* needs the room): the rest goes to disk too */
        pdt_status st = spill_finals(c);
        if (st != PDT_OK) return st;
        free(c->fin);
        c->fin = NULL;
        c->capfin = 0;
    } else if (c->nfin) {
        sort_fins(c->fin, c->nfin, c->npts);
    }
    pdt_tri *ref = NULL;
    size_t nref = 0;
    pdt_status st = PDT_OK;
    if (!c->certify)
        st = c->tstar ? c->tstar(c->pts, c->npts, &ref, &nref, &c->tstar_strips)
                      : pdt_triangulate(c->pts, c->npts, &ref, &nref, NULL, NULL);
    if (st != PDT_OK) {
        free(ref);
        return pdt_err_set(c->err, st, "recomputing T* of the run's points failed: %s",
                           pdt_status_str(st));
    }
    fin_merge m;
    if (fm_open(&m, c->runs, c->nruns, c->fin, c->nfin)) st = nomem(c);
    else st = c->certify ? certify_tstar(c, &m, nu) : compare_tstar(c, &m, ref, nref);
    fm_close(&m);
    free(ref);
    return st;
}

static int cmp_msg(const void *a, const void *b)
{
    const msg *x = a, *y = b;
    if (x->src != y->src) return x->src < y->src ? -1 : 1;
    if (x->dst != y->dst) return x->dst < y->dst ? -1 : 1;
    if (x->tag != y->tag) return x->tag < y->tag ? -1 : 1;
    if (x->seq_no != y->seq_no) return x->seq_no < y->seq_no ? -1 : 1;
    /* the SEND before the RECV of the same message */
    return (x->ev.kind == PDT_EV_RECV) - (y->ev.kind == PDT_EV_RECV);
}

static pdt_status check_messages(chk *c)
{
    if (c->nmsg) qsort(c->msg, c->nmsg, sizeof *c->msg, cmp_msg);
    for (size_t i = 0; i < c->nmsg;) {
        const msg *m = &c->msg[i];
        const msg *n = i + 1 < c->nmsg ? &c->msg[i + 1] : NULL;
        if (n && !(m->ev.kind == PDT_EV_SEND && n->ev.kind == PDT_EV_RECV && n->src == m->src &&
                   n->dst == m->dst && n->tag == m->tag && n->seq_no == m->seq_no))
            n = NULL;
        if (!n) {
            if (m->ev.kind == PDT_EV_SEND)
                return viol(c, m->rank, m->seq, &m->ev, "no matching recv on rank %" PRIu32,
                            m->dst);
            return viol(c, m->rank, m->seq, &m->ev, "no matching send on rank %" PRIu32, m->src);
        }
        if (n->bytes != m->bytes)
            return viol(c, n->rank, n->seq, &n->ev, "the send (rank %" PRIu32 " event #%" PRIu64
                                                    ") has %" PRIu64 " bytes",
                        m->rank, m->seq, m->bytes);
        i += 2;
    }
    return PDT_OK;
}

static int cmp_merge(const void *a, const void *b)
{
    const merge *x = a, *y = b;
    if (x->level != y->level) return x->level < y->level ? -1 : 1;
    return x->gl < y->gl ? -1 : x->gl > y->gl;
}

static pdt_status check_merges(chk *c)
{
    if (c->nmg) qsort(c->mg, c->nmg, sizeof *c->mg, cmp_merge);
    for (size_t i = 1; i < c->nmg; i++) {
        const merge *a = &c->mg[i - 1], *b = &c->mg[i];
        if (a->level == b->level && b->gl < a->end)
            return viol(c, 0, 0, NULL, "merge steps at level %" PRIu32 " overlap: ranks [%" PRIu32
                                       ", %" PRIu32 ") (rank %" PRIu32 " event #%" PRIu64
                                       ") and [%" PRIu32 ", %" PRIu32 ") (rank %" PRIu32
                                       " event #%" PRIu64 ")",
                        a->level, a->gl, a->end, a->rank, a->seq, b->gl, b->end, b->rank, b->seq);
    }
    int p = pdt_run_nranks(c->run);
    if (c->is_tri && p > 1) {
        const merge *top = c->nmg ? &c->mg[c->nmg - 1] : NULL;
        if (!top || top->gl != 0 || top->end != (uint32_t)p)
            return viol(c, 0, 0, NULL, "no merge step joins all %d ranks (the last merge %s)", p,
                        top ? "covers fewer ranks" : "is missing");
    }
    return PDT_OK;
}

/* ---- per-point state within the budget --------------------------------------
 *
 * What grows with the points is held in memory while it fits the budget:
 * the marks (a byte per point) up to a quarter of it, the sort that finds
 * the distinct points (DEDUP_BYTES_PER_POINT) and T* recomputed
 * (TSTAR_BYTES_PER_POINT) up to all of it.  Beyond, the marks live in a
 * mapping of an anonymous temporary file, the distinct points are found by
 * a sort on disk (xsort.h) and T* is certified on disk instead of
 * recomputed (certify.h); the resident pages of the marks and of the
 * points are then given back every GIVE_BACK_EVERY reads (they stay in the
 * page cache, or go to disk under pressure), so the check's memory is the
 * budget whatever the run's size. */
#define DEDUP_BYTES_PER_POINT 36u  /* pdt_sort_unique: order 4, work 32 */
#define GIVE_BACK_EVERY ((uint64_t)1 << 16)

static int marks_new(chk *c)
{
    size_t n = c->npts ? c->npts : 1;
    if ((uint64_t)n <= c->budget / 4) return (c->mark = calloc(n, 1)) ? 0 : -1;
    FILE *f = spill_file();
    if (!f) return -1;
    void *p = MAP_FAILED;
    if (ftruncate(fileno(f), (off_t)n) == 0)
        p = mmap(NULL, n, PROT_READ | PROT_WRITE, MAP_SHARED, fileno(f), 0);
    int e = errno;
    fclose(f);  /* the mapping keeps the file */
    errno = e;
    if (p == MAP_FAILED) return -1;
    c->mark = p;
    c->mark_map = n;
    return 0;
}

static void marks_free(chk *c)
{
    if (c->mark_map) munmap(c->mark, c->mark_map);
    else free(c->mark);
}

/* Every GIVE_BACK_EVERY calls, when the points or the marks are too big to
 * keep: their resident pages are given back. */
static void tick(chk *c)
{
    if (!c->give_back || ++c->ticks % GIVE_BACK_EVERY) return;
    if (c->mark_map) madvise(c->mark, c->mark_map, MADV_DONTNEED);
    pdt_run_release_points(c->run);
}

/* (x, y) as an unsigned key in lexicographic order. */
static uint64_t lex_key(pdt_point p)
{
    return (uint64_t)((uint32_t)p.x ^ 0x80000000u) << 32 | ((uint32_t)p.y ^ 0x80000000u);
}

/* M_REP on the smallest index of each distinct point, and their number. */
static pdt_status find_distinct(chk *c, size_t *nu)
{
    *nu = 0;
    if (!c->dedup_on_disk) {
        uint32_t *order = malloc((c->npts ? c->npts : 1) * sizeof *order);
        if (!order) return nomem(c);
        pdt_status st = pdt_sort_unique(c->pts, c->npts, order, nu);
        if (st != PDT_OK)
            pdt_err_set(c->err, st, "sorting the run's points failed: %s", pdt_status_str(st));
        for (size_t i = 0; st == PDT_OK && i < *nu; i++) c->mark[order[i]] |= M_REP;
        free(order);
        return st;
    }
    pdt_xsort *x = pdt_xsort_new(c->budget / 2);
    if (!x) return nomem(c);
    pdt_status st = PDT_OK;
    for (size_t i = 0; st == PDT_OK && i < c->npts; i++) {
        tick(c);
        if (pdt_xsort_put(x, lex_key(c->pts[i]), i)) st = tmp_fail(c, "the points", "cannot write");
    }
    if (st == PDT_OK && pdt_xsort_done(x)) st = tmp_fail(c, "the points", "cannot read back");
    pdt_kv kv;
    uint64_t key = 0, rep = 0;
    int any = 0, r = 0;
    while (st == PDT_OK && (r = pdt_xsort_get(x, &kv)) == 1) {
        if (any && kv.key == key) {  /* a copy: the smallest index represents them */
            if (kv.val < rep) rep = kv.val;
            continue;
        }
        if (any) c->mark[rep] |= M_REP;
        tick(c);
        *nu += any;
        key = kv.key;
        rep = kv.val;
        any = 1;
    }
    if (st == PDT_OK && r < 0) st = tmp_fail(c, "the points", "cannot read back");
    if (st == PDT_OK && any) {
        c->mark[rep] |= M_REP;
        (*nu)++;
    }
    c->dedup_runs = pdt_xsort_runs(x);
    pdt_xsort_free(x);
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
    memset(&c, 0, sizeof c);
    c.run = run;
    c.err = err;
    c.pts = pdt_run_points(run, &c.npts);
    c.budget = budget;
    c.tstar = tstar;
    /* half the budget for the finals' buffer; at least a few, so that a tiny
     * budget spills often instead of failing */
    c.maxfin = (size_t)(budget / 2 / sizeof(fin) < 16 ? 16 : budget / 2 / sizeof(fin));
    const pdt_manifest *m = pdt_run_manifest(run);
    c.is_tri = !strcmp(m->command, "triangulate");
    c.is_hull = !strcmp(m->command, "hull");
    c.certify = (uint64_t)c.npts * TSTAR_BYTES_PER_POINT > budget;
    c.dedup_on_disk = (uint64_t)c.npts * DEDUP_BYTES_PER_POINT > budget;
    size_t nr = (size_t)pdt_run_nranks(run);
    c.kmin = calloc(nr, sizeof *c.kmin);
    c.kmax = calloc(nr, sizeof *c.kmax);
    c.nlocal = calloc(nr, sizeof *c.nlocal);
    size_t nu = 0;
    pdt_status st = PDT_OK;
    if (!c.kmin || !c.kmax || !c.nlocal) st = nomem(&c);
    else if (marks_new(&c)) st = tmp_fail(&c, "the marks of the points", "cannot create");
    c.give_back = c.mark_map || (uint64_t)c.npts * sizeof *c.pts > budget / 4;
    if (st == PDT_OK) st = find_distinct(&c, &nu);

    for (int r = 0; st == PDT_OK && r < pdt_run_nranks(run); r++) st = check_rank(&c, (uint32_t)r);

    if (st == PDT_OK && c.is_tri) {
        if (c.lifts_local == 0 && nu > 0)
            st = viol(&c, 0, 0, NULL, "no lift-up events (the run has %zu distinct points)", nu);
        for (size_t i = 0; st == PDT_OK && i < c.npts; i++)
            if ((c.mark[i] & M_REP) && !(c.mark[i] & M_LIFTED))
                st = viol(&c, 0, 0, NULL, "pt %zu was never lifted (%" PRIu64 " local lift-ups "
                                          "for %zu distinct points)", i, c.lifts_local, nu);
    }
    /* strips: the ranks' local points are consecutive lexicographic blocks */
    for (size_t r = 0, prev = SIZE_MAX; st == PDT_OK && c.is_tri && r < nr; r++) {
        if (!c.nlocal[r]) continue;
        if (prev != SIZE_MAX && c.kmin[r] <= c.kmax[prev])
            st = viol(&c, 0, 0, NULL, "the local lift-ups of rank %zu (%" PRIu64 " points) are not "
                                      "a lexicographic block after those of rank %zu: the strips "
                                      "overlap", r, c.nlocal[r], prev);
        prev = r;
    }
    if (st == PDT_OK && c.is_tri) st = check_finals(&c, nu);
    if (st == PDT_OK && c.is_hull) {
        /* every point sorted; each deleted or pushed; the final stack is the hull */
        for (size_t i = 0; st == PDT_OK && i < c.npts; i++) {
            if (!(c.mark[i] & M_SORTED))
                st = viol(&c, 0, 0, NULL, "pt %zu never appears in the angular order", i);
            else if (!(c.mark[i] & (M_DELETED | M_PUSHED)))
                st = viol(&c, 0, 0, NULL, "pt %zu was neither deleted nor pushed", i);
            else if ((c.mark[i] & M_DELETED) && (c.mark[i] & M_PUSHED))
                st = viol(&c, 0, 0, NULL, "pt %zu was deleted and also pushed", i);
        }
        uint32_t *hull = malloc((c.npts ? c.npts : 1) * sizeof *hull);
        size_t nh = 0;
        if (st == PDT_OK && !hull) st = nomem(&c);
        if (st == PDT_OK && (st = pdt_hull_graham(c.pts, c.npts, hull, &nh, NULL)) != PDT_OK)
            pdt_err_set(err, st, "recomputing the hull failed: %s", pdt_status_str(st));
        if (st == PDT_OK &&
            (nh != c.graham_final.n ||
             (nh && memcmp(hull, c.graham_final.v, nh * sizeof *hull) != 0))) {
            size_t k = 0;
            while (k < nh && k < c.graham_final.n && hull[k] == c.graham_final.v[k]) k++;
            st = viol(&c, 0, 0, NULL, "the final Graham stack (%zu points) is not the hull of the "
                                      "run's points (%zu points); first difference at position %zu",
                      c.graham_final.n, nh, k);
        }
        free(hull);
    }
    if (st == PDT_OK) st = check_merges(&c);
    if (st == PDT_OK) st = check_messages(&c);
    if (st == PDT_OK && cap)
        snprintf(summary, cap,
                 "%d rank%s, %" PRIu64 " events: %" PRIu64 " stack instances (%" PRIu64
                 " pushes, %" PRIu64 " pops, %" PRIu64 " chain hulls), %" PRIu64 " local + %" PRIu64
                 " merge lift-ups, %zu final triangles%s, %zu merge steps, %zu messages, "
                 "%" PRIu64 " kernel runs with edges replayed",
                 pdt_run_nranks(run), pdt_run_nranks(run) == 1 ? "" : "s", c.events, c.instances,
                 c.pushes, c.pops, c.hulls, c.lifts_local, c.lifts_merge, (size_t)c.totfin,
                 c.is_tri ? " = T*" : "", c.nmg, c.nmsg / 2, c.edge_scopes);
    if (st == PDT_OK && cap && c.tstar_strips) {
        size_t len = strlen(summary);
        snprintf(summary + len, cap - len, " (T* recomputed on %d strips)", c.tstar_strips);
    }
    if (st == PDT_OK && cap && c.edge_spills) {
        size_t len = strlen(summary);
        snprintf(summary + len, cap - len, " (%" PRIu64 " of them replayed on disk: over a quarter "
                 "of the memory budget)", c.edge_spills);
    }
    if (st == PDT_OK && cap && c.certify && c.is_tri) {
        size_t len = strlen(summary);
        char runs[64] = "", dedup[96] = "";
        if (c.cert_runs) snprintf(runs, sizeof runs, " on disk in %" PRIu64 " sorted runs",
                                  c.cert_runs);
        if (c.dedup_on_disk)
            snprintf(dedup, sizeof dedup, ", the distinct points found by a sort on disk in %"
                     PRIu64 " runs", c.dedup_runs);
        snprintf(summary + len, cap - len, " (T* certified side by side%s%s: recomputing it would "
                 "not fit the memory budget)", runs, dedup);
    }
    if (st == PDT_OK && cap && c.spills) {
        size_t len = strlen(summary);
        snprintf(summary + len, cap - len, " (final triangles sorted on disk in %" PRIu64
                 " runs: over the memory budget)", c.spills);
    }
    marks_free(&c);
    free(c.kmin);
    free(c.kmax);
    free(c.nlocal);
    free(c.fin);
    for (size_t i = 0; i < c.nruns; i++) fclose(c.runs[i]);
    free(c.runs);
    free(c.msg);
    free(c.mg);
    free(c.graham_final.v);
    return st;
}
