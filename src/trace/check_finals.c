/* pdt — pdt trace check: the final triangles (every one once, their set T*)
 * and what grows with the points (the marks, the distinct points), in
 * memory while they fit the budget and on disk beyond it. */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "pdt/delaunay.h"
#include "pdt/predicates.h"
#include "certify.h"
#include "check_int.h"
#include "pdt/xsort.h"
#include "pdt/bigmem.h"
#include "pdt/tmpfile.h"

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
pdt_status chk_tmp_fail(chk *c, const char *of, const char *what)
{
    if (errno == ENOMEM) return chk_nomem(c);
    return pdt_err_set(c->err, PDT_ERR_IO, "temporary file for %s in %s: %s: %s", of,
                       pdt_tmp_dir(), what, strerror(errno));
}

static pdt_status io_fail(chk *c, const char *what)
{
    return chk_tmp_fail(c, "the final triangles", what);
}

/* Merge every spilled run into one (when too many piled up). */
static pdt_status compact_runs(chk *c)
{
    FILE *out = pdt_tmp_file("pdt-finals", 0);
    if (!out) return io_fail(c, "cannot create");
    fin_merge m;
    pdt_status st = PDT_OK;
    if (fm_open(&m, c->runs, c->nruns, NULL, 0)) st = chk_nomem(c);
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
pdt_status chk_spill_finals(chk *c)
{
    if (!c->nfin) return PDT_OK;
    sort_fins(c->fin, c->nfin, c->npts);
    if (chk_grow((void **)&c->runs, &c->capruns, c->nruns, sizeof *c->runs)) return chk_nomem(c);
    FILE *f = pdt_tmp_file("pdt-finals", 0);
    if (!f) return io_fail(c, "cannot create");
    c->runs[c->nruns++] = f;
    c->spills++;
    if (fwrite(c->fin, sizeof *c->fin, c->nfin, f) != c->nfin || fflush(f) != 0)
        return io_fail(c, "cannot write");
    c->nfin = 0;
    if (c->nruns >= MAX_RUNS) return compact_runs(c);
    return PDT_OK;
}

/* "made final twice" for two equal finals met in sorted order. */
static pdt_status twice(chk *c, const fin *f, const fin *prev)
{
    return chk_viol(c, 0, 0, NULL, "triangle %" PRIu32 " %" PRIu32 " %" PRIu32 " made final twice: "
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
            st = chk_viol(c, 0, 0, NULL, "rank %" PRIu32 " event #%" PRIu64 ": final triangle %"
                                     PRIu32 " %" PRIu32 " %" PRIu32 " is not in T* of the "
                                     "run's points", f.rank, f.seq, f.t.v[0], f.t.v[1], f.t.v[2]);
        } else if (k > 0) {
            st = chk_viol(c, 0, 0, NULL, "triangle %" PRIu32 " %" PRIu32 " %" PRIu32 " of T* was "
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
        chk_tick(c);
        if (!(c->mark[i] & M_REP)) continue;
        if (first == SIZE_MAX) first = i;
        else if (second == SIZE_MAX) second = i;
        else if (pdt_orient(c->pts[first], c->pts[second], c->pts[i]) != 0)
            return chk_viol(c, 0, 0, NULL, "no triangle was made final, but T* of the run's points "
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
    if (!cert) return chk_nomem(c);
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
pdt_status chk_finals(chk *c, size_t nu)
{
    uint64_t held = (uint64_t)c->capfin * sizeof *c->fin;  /* the buffer as allocated */
    if (c->nruns || c->certify || held + (uint64_t)c->npts * TSTAR_BYTES_PER_POINT > c->budget) {
        /* out of memory's reach (or T* needs the room): the rest goes to disk too */
        pdt_status st = chk_spill_finals(c);
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
    if (fm_open(&m, c->runs, c->nruns, c->fin, c->nfin)) st = chk_nomem(c);
    else st = c->certify ? certify_tstar(c, &m, nu) : compare_tstar(c, &m, ref, nref);
    fm_close(&m);
    free(ref);
    return st;
}

/* ---- per-point state within the budget --------------------------------------
 *
 * What grows with the points is held in memory while it fits the budget:
 * the marks (a byte per point) up to a quarter of it, the sort that finds
 * the distinct points (DEDUP_BYTES_PER_POINT), T* recomputed
 * (TSTAR_BYTES_PER_POINT) and a hull run's hull recomputed
 * (HULL_BYTES_PER_POINT) up to all of it.  Beyond, the marks live in a
 * mapping of an anonymous temporary file, the distinct points are found by
 * a sort on disk (xsort.h), T* is certified on disk instead of recomputed
 * (certify.h) and the hull certified from the final Graham stack
 * (hullcert.h; the stacks themselves: check.c); the resident pages of the
 * marks and of the points are then given back every GIVE_BACK_EVERY reads
 * (check_int.h; they stay in the page cache, or go to disk under
 * pressure), so the check's memory is the budget whatever the run's size. */

int chk_marks_new(chk *c)
{
    size_t n = c->npts ? c->npts : 1;
    if ((uint64_t)n <= c->budget / 4) return (c->mark = calloc(n, 1)) ? 0 : -1;
    void *p = pdt_temp_zeros(n);
    if (!p) return -1;
    c->mark = p;
    c->mark_map = n;
    return 0;
}

void chk_marks_free(chk *c)
{
    if (c->mark_map) munmap(c->mark, c->mark_map);
    else free(c->mark);
}

/* Every GIVE_BACK_EVERY calls, when the points or the marks are too big to
 * keep: their resident pages are given back. */
void chk_tick(chk *c)
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
pdt_status chk_find_distinct(chk *c, size_t *nu)
{
    *nu = 0;
    if (!c->dedup_on_disk) {
        uint32_t *order = malloc((c->npts ? c->npts : 1) * sizeof *order);
        if (!order) return chk_nomem(c);
        pdt_status st = pdt_sort_unique(c->pts, c->npts, order, nu);
        if (st != PDT_OK)
            pdt_err_set(c->err, st, "sorting the run's points failed: %s", pdt_status_str(st));
        for (size_t i = 0; st == PDT_OK && i < *nu; i++) c->mark[order[i]] |= M_REP;
        free(order);
        return st;
    }
    pdt_xsort *x = pdt_xsort_new(c->budget / 2);
    if (!x) return chk_nomem(c);
    pdt_status st = PDT_OK;
    for (size_t i = 0; st == PDT_OK && i < c->npts; i++) {
        chk_tick(c);
        if (pdt_xsort_put(x, lex_key(c->pts[i]), i)) st = chk_tmp_fail(c, "the points", "cannot write");
    }
    if (st == PDT_OK && pdt_xsort_done(x)) st = chk_tmp_fail(c, "the points", "cannot read back");
    pdt_kv kv;
    uint64_t key = 0, rep = 0;
    int any = 0, r = 0;
    while (st == PDT_OK && (r = pdt_xsort_get(x, &kv)) == 1) {
        if (any && kv.key == key) {  /* a copy: the smallest index represents them */
            if (kv.val < rep) rep = kv.val;
            continue;
        }
        if (any) c->mark[rep] |= M_REP;
        chk_tick(c);
        *nu += any;
        key = kv.key;
        rep = kv.val;
        any = 1;
    }
    if (st == PDT_OK && r < 0) st = chk_tmp_fail(c, "the points", "cannot read back");
    if (st == PDT_OK && any) {
        c->mark[rep] |= M_REP;
        (*nu)++;
    }
    c->dedup_runs = pdt_xsort_runs(x);
    pdt_xsort_free(x);
    return st;
}
