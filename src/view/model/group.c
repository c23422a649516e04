/* pdt — the replay's build: triangle events grouped by triangle, in buckets
 * of bounded size, and the triangles' histories. */
#include "pdt/view/replay.h"
#include "replay_int.h"
#include "build_int.h"
#include "pdt/bigmem.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <pthread.h>
#include <stdatomic.h>
#include <sys/mman.h>
#include <unistd.h>

size_t pdt_replay_fine_of(const pdt_rec *rec, size_t n, int nranks)
{
    const pdt_event *e = &rec->ev;
    if (!is_tri_kind(e->kind) || rec->rank >= (uint32_t)nranks || e->a >= n || e->b >= n ||
        e->c >= n)
        return NFINE;
    uint32_t in[3] = {e->a, e->b, e->c}, s[3];
    sort3(s, in);
    return pdt_rp_fine_of(s, FINE_BITS);
}

/* Write k records of `rec` bytes from buf where scratch stream scr ends, a
 * chunk of bucket f in lg.  0 when out of memory or the write failed. */
int pdt_rp_spill_put(builder *b, int scr, spill_log *lg, const void *buf, size_t k, size_t rec,
                     size_t f)
{
    if (!k) return 1;
    if (!pdt_rp_grow((void **)&lg->chunk, &lg->cap, lg->n + 1, sizeof *lg->chunk)) return 0;
    if (!b->pl->sput(b->pl->ctx, scr, lg->end, buf, k * rec)) {
        b->failed = 1;
        return 0;
    }
    lg->chunk[lg->n++] = (spill_chunk){lg->end, (uint32_t)f, (uint32_t)k};
    lg->end += k * rec;
    return 1;
}

/* lg's chunks ordered by bucket, each bucket's in the order written (its
 * records' order): start[f] .. start[f + 1] - 1 are bucket f's (start: nb +
 * 1 entries, zeroed by the caller).  0 when out of memory. */
int pdt_rp_spill_group(spill_log *lg, size_t nb, size_t *start)
{
    spill_chunk *sorted = malloc((lg->n ? lg->n : 1) * sizeof *sorted);
    size_t *fill = malloc((nb + 1) * sizeof *fill);
    if (!sorted || !fill) {
        free(sorted);
        free(fill);
        return 0;
    }
    for (size_t c = 0; c < lg->n; c++) start[lg->chunk[c].f + 1]++;
    for (size_t f = 0; f < nb; f++) start[f + 1] += start[f];
    memcpy(fill, start, (nb + 1) * sizeof *fill);
    for (size_t c = 0; c < lg->n; c++) sorted[fill[lg->chunk[c].f]++] = lg->chunk[c];
    free(fill);
    free(lg->chunk);
    lg->chunk = sorted;
    lg->cap = lg->n;
    return 1;
}

/* One slot of tri_groups' hash table: a key and its group, UINT32_MAX = empty. */
typedef struct gslot {
    uint32_t s[3], g;
} gslot;

/* The history entry of triangle event ev (the status it sets), from what
 * the first pass left in ev_ent (its sub field) and ev_obj (a border
 * kernel's candidate: the merge step open on its rank, else -1).  That step
 * is the one whose MERGE_END the candidate waits for: a merge step that ends
 * was its rank's open one from its MERGE_BEGIN to its MERGE_END. */
static pdt_rtri_hist hist_of(const pdt_replay *r, uint32_t ev)
{
    int kind = kind_at(r, ev);
    uint8_t sub = (uint8_t)r->ev_ent[ev];
    int32_t g = r->ev_obj[ev];
    pdt_rtri_hist h = {ev, NONE32, tri_status_of(kind), sub, {0, 0}};
    if (kind == PDT_EV_TRI_NEW && sub == 1 && g >= 0 && (size_t)g < r->nmerge)
        h.until = r->merges[g].end_ev;  /* (NONE32: it never ended) */
    return h;
}

/* One thread's share of tri_groups: runs of fine buckets (run[] holds
 * their bounds) taken in turn from *next; each thread its own buffers of
 * `most` events (the largest run). */
typedef struct group_job {
    builder *b;
    const size_t *run;      /* bucket bounds: run k is [run[k], run[k + 1]) */
    size_t nrun, most;
    _Atomic size_t next;    /* next run to take */
    _Atomic int failed;     /* out of memory, or (io) a read or write of the place failed */
    _Atomic int io;
    _Atomic size_t ntri;    /* triangles found */
} group_job;

/* Group the nb records at buf (stride bytes apart, each beginning with a
 * tri_rec) by their key, with the hash table slot (room for nb at load 3/4):
 * gid[j] is record j's group, numbered by first appearance; gfirst[g] the
 * event of group g's first record, gn[g] its records.  Returns the groups. */
static uint32_t group_keys(const void *buf, size_t stride, size_t nb, gslot *slot, uint32_t *gid,
                           uint32_t *gfirst, uint32_t *gn)
{
#define KREC(j) ((const tri_rec *)(const void *)((const char *)buf + (j) * stride))
    size_t hc = 1024;
    while (hc / 4 * 3 < nb) hc *= 2;
    size_t mask = hc - 1;
    for (size_t q = 0; q < hc; q++) slot[q].g = NONE32;
    uint32_t ng = 0;
    for (size_t j = 0; j < nb; j++) {
        if (j + PREFETCH_AHEAD < nb)
            __builtin_prefetch(&slot[(size_t)pdt_rp_key_hash(KREC(j + PREFETCH_AHEAD)->s) & mask]);
        const uint32_t *s = KREC(j)->s;
        size_t q = (size_t)pdt_rp_key_hash(s) & mask;
        while (slot[q].g != NONE32 &&
               (slot[q].s[0] != s[0] || slot[q].s[1] != s[1] || slot[q].s[2] != s[2]))
            q = (q + 1) & mask;
        if (slot[q].g == NONE32 || gn[slot[q].g] == PDT_TRI_HIST_MAX) { /* (a new triangle,
                                                  * or the next of a vertex set's) */
            slot[q] = (gslot){{s[0], s[1], s[2]}, ng};
            gfirst[ng] = KREC(j)->ev;
            gn[ng++] = 0;
        }
        gid[j] = slot[q].g;
        gn[gid[j]]++;
    }
    return ng;
#undef KREC
}

/* A grouping thread's scratch (both builds): `most` records of `rec` bytes,
 * the hash table for them, the per-record group and the per-group tables
 * (group_keys), and the next place of each group (gfill). */
typedef struct group_scratch {
    void *buf;
    gslot *slot;
    uint32_t *gid, *gfirst, *gn, *gfill;
    uint8_t *glast;  /* streamed: per group, the status of its latest entry */
    size_t most, hcap, rec;
} group_scratch;

static int scratch_get(builder *b, group_scratch *s, size_t most, size_t rec)
{
    size_t hcap = 1024;
    while (hcap / 4 * 3 < most) hcap *= 2;
    *s = (group_scratch){.most = most, .hcap = hcap, .rec = rec};
    s->buf = pdt_rp_bmalloc(b, most * rec);
    s->slot = pdt_rp_bmalloc(b, hcap * sizeof *s->slot);
    s->gid = pdt_rp_bmalloc(b, most * sizeof *s->gid);
    s->gfirst = pdt_rp_bmalloc(b, most * sizeof *s->gfirst);
    s->gn = pdt_rp_bmalloc(b, most * sizeof *s->gn);
    s->gfill = pdt_rp_bmalloc(b, most * sizeof *s->gfill);
    s->glast = pdt_rp_bmalloc(b, most);
    if (!(s->buf && s->slot && s->gid && s->gfirst && s->gn && s->gfill && s->glast)) return 0;
    pdt_big_advise(s->buf, most * rec);
    pdt_big_advise(s->slot, hcap * sizeof *s->slot);
    return 1;
}

static void scratch_put(builder *b, group_scratch *s)
{
    pdt_rp_bfree(b, s->buf, s->most * s->rec);
    pdt_rp_bfree(b, s->slot, s->hcap * sizeof *s->slot);
    pdt_rp_bfree(b, s->gid, s->most * sizeof *s->gid);
    pdt_rp_bfree(b, s->gfirst, s->most * sizeof *s->gfirst);
    pdt_rp_bfree(b, s->gn, s->most * sizeof *s->gn);
    pdt_rp_bfree(b, s->gfill, s->most * sizeof *s->gfill);
    pdt_rp_bfree(b, s->glast, s->most);
}

/* Group the nb records in s->buf; gfill[g] = base + the entries of groups
 * before g (where group g's entries begin).  Returns the groups. */
static uint32_t scratch_group(group_scratch *s, size_t nb, size_t base)
{
    uint32_t ng = group_keys(s->buf, s->rec, nb, s->slot, s->gid, s->gfirst, s->gn);
    size_t h = base;
    for (uint32_t q = 0; q < ng; q++) s->gfill[q] = (uint32_t)h, h += s->gn[q];
    return ng;
}

/* The in-memory build's grouping: the entries into r->hist, and per event
 * its entry (ev_ent) and its triangle's first event (ev_obj; see
 * tri_groups). */
static void *group_worker(void *arg)
{
    group_job *J = arg;
    builder *b = J->b;
    pdt_replay *r = b->r;
    group_scratch S;
    int ok = scratch_get(b, &S, J->most, sizeof(tri_rec));
    const tri_rec *buf = S.buf;
    size_t found = 0;
    while (ok && !J->failed) {
        size_t k = J->next++;
        if (k >= J->nrun) break;
        size_t base = b->fine_off[J->run[k]], nb = b->fine_off[J->run[k + 1]] - base;
        if (!nb) continue;
        memcpy(S.buf, &b->spill[base], nb * sizeof *buf);
        uint32_t ng = scratch_group(&S, nb, base);
        pdt_rtri_hist *to = r->hist + base;
        for (size_t j = 0; j < nb; j++) {
            if (j + PREFETCH_AHEAD < nb) { /* random places in three tables of 4, 4, 1 bytes per event */
                __builtin_prefetch(&r->ev_ent[buf[j + PREFETCH_AHEAD].ev], 1);
                __builtin_prefetch(&r->ev_obj[buf[j + PREFETCH_AHEAD].ev], 1);
                __builtin_prefetch(&r->ev_kind[buf[j + PREFETCH_AHEAD].ev]);
            }
            uint32_t q = S.gid[j], ev = buf[j].ev, at = S.gfill[q]++;
            to[at - base] = hist_of(r, ev);
            r->ev_ent[ev] = at;  /* (threads write distinct events) */
            r->ev_obj[ev] = ev == S.gfirst[q] ? -1 - (int32_t)S.gn[q] : (int32_t)S.gfirst[q];
        }
        found += ng;
    }
    if (!ok) J->failed = 1;
    J->ntri += found;
    scratch_put(b, &S);
    return NULL;
}

/* The history entry of a streamed build's spill record (hist_of, from what
 * the record carries). */
static pdt_rtri_hist hist_of_x(const pdt_replay *r, const tri_xrec *t)
{
    int kind = PDT_EV_TRI_NEW;
    uint8_t sub = 1;
    int32_t g = -1;
    uint32_t x = t->x & ~XREC_ORDER_MASK;
    if (x & XREC_BORDER) g = (int32_t)(x & ~XREC_BORDER) - 1;
    else kind = (int)(x & 0xff), sub = (uint8_t)(x >> 8);
    pdt_rtri_hist h = {t->ev, NONE32, tri_status_of(kind), sub, {0, 0}};
    if (kind == PDT_EV_TRI_NEW && sub == 1 && g >= 0 && (size_t)g < r->nmerge)
        h.until = r->merges[g].end_ev;
    return h;
}

/* The streamed build's grouping: a run's entries to the place's history
 * table; per triangle event a tri_ev (PDT_SCR_TRIEV, at its place in the
 * bucket order), per triangle a tri_first (PDT_SCR_TRIS, from its bucket's
 * first place: fine_off[f]), both in event order within each bucket, and
 * the triangles per bucket (tcount).  Nothing is written per event in
 * memory: numbering the triangles comes after (pdt_rp_tri_number). */
/* Run k's records (its buckets' spilled chunks, one after the other) into
 * buf (nb of them): 1, or 0 when they cannot be read. */
static int read_run(group_job *J, size_t k, tri_xrec *buf, size_t nb)
{
    builder *b = J->b;
    const pdt_replay_place *pl = b->pl;
    for (size_t c = b->ck_start[J->run[k]], got = 0; c < b->ck_start[J->run[k + 1]]; c++) {
        const spill_chunk *ck = &b->tlog.chunk[c]; /* the run's chunks, bucket by bucket */
        if (got + ck->n > nb ||
            !pl->sget(pl->ctx, PDT_SCR_SPILL, ck->off, buf + got, ck->n * sizeof *buf))
            return 0;
        got += ck->n;
    }
    return 1;
}

/* Run k grouped (S, its records buf from base on): bucket by bucket, its
 * triangles are the groups first seen in it; their first events and
 * corners, and the run's per-event marks, written to the scratch, its
 * entries to the history table (from base: a bucket's entries from its
 * fine_off, its triangles' one after the other).  1, or 0 when a write
 * failed. */
static int write_run(group_job *J, size_t k, group_scratch *S, const tri_xrec *buf,
                     pdt_rtri_hist *out, tri_ev *eout, tri_first *tout, size_t base)
{
    builder *b = J->b;
    pdt_replay *r = b->r;
    const pdt_replay_place *pl = b->pl;
    size_t nb = b->fine_off[J->run[k + 1]] - base;
    uint32_t g0 = 0;
    for (size_t f = J->run[k]; f < J->run[k + 1]; f++) {
        size_t j0 = b->fine_off[f] - base, j1 = b->fine_off[f + 1] - base;
        uint32_t g1 = g0;
        for (size_t j = j0; j < j1; j++) {
            if (j + 2 * PREFETCH_AHEAD < j1) { /* the places of a group a few records on: its
                                                * tables, then its next entry (for writing) */
                uint32_t qa = S->gid[j + 2 * PREFETCH_AHEAD];
                __builtin_prefetch(&S->gfill[qa]);
                __builtin_prefetch(&S->gfirst[qa]);
                __builtin_prefetch(&S->glast[qa], 1);
                __builtin_prefetch(&out[S->gfill[S->gid[j + PREFETCH_AHEAD]] - base], 1);
            }
            uint32_t q = S->gid[j], ev = buf[j].ev, at = S->gfill[q]++;
            if (q >= g1) g1 = q + 1;
            out[at - base] = hist_of_x(r, &buf[j]);
            S->glast[q] = out[at - base].status;  /* (the last written is the last entry's) */
            int first = ev == S->gfirst[q];
            eout[j] = (tri_ev){ev, (q - g0) | (first ? TEV_FIRST : 0)};
            if (first) xrec_corners(&buf[j], tout[q - g0].v);
        }
        for (uint32_t q = g0; q < g1; q++) {
            tout[q - g0].ev = S->gfirst[q];
            tout[q - g0].n = S->gn[q] | (uint32_t)S->glast[q] << TF_LAST_SHIFT;
        }
        b->tcount[f] = g1 - g0;
        if (g1 > g0 && !pl->sput(pl->ctx, PDT_SCR_TRIS, (uint64_t)b->fine_off[f] * sizeof *tout,
                                 tout, (g1 - g0) * sizeof *tout))
            return 0;
        g0 = g1;
    }
    return pl->put(pl->ctx, r->hist_at + (uint64_t)base * sizeof *out, out, nb * sizeof *out) &&
           pl->sput(pl->ctx, PDT_SCR_TRIEV, (uint64_t)base * sizeof *eout, eout, nb * sizeof *eout);
}

static void *group_worker_streamed(void *arg)
{
    group_job *J = arg;
    builder *b = J->b;
    size_t most = J->most;
    group_scratch S;
    int ok = scratch_get(b, &S, most, sizeof(tri_xrec));
    tri_xrec *buf = S.buf;
    pdt_rtri_hist *out = pdt_rp_bmalloc(b, most * sizeof *out);  /* the run's entries */
    tri_ev *eout = pdt_rp_bmalloc(b, most * sizeof *eout);
    tri_first *tout = pdt_rp_bmalloc(b, most * sizeof *tout);
    ok = ok && out && eout && tout;
    size_t found = 0;
    while (ok && !J->failed) {
        size_t k = J->next++;
        if (k >= J->nrun) break;
        size_t base = b->fine_off[J->run[k]], nb = b->fine_off[J->run[k + 1]] - base;
        if (!nb) continue;
        if (!read_run(J, k, buf, nb)) {
            J->io = 1;
            ok = 0;
            break;
        }
        uint32_t ng = scratch_group(&S, nb, base);
        if (!write_run(J, k, &S, buf, out, eout, tout, base)) {
            J->io = 1;
            ok = 0;
        }
        found += ng;
    }
    if (!ok) J->failed = 1;
    J->ntri += found;
    pdt_rp_bfree(b, out, most * sizeof *out);
    pdt_rp_bfree(b, eout, most * sizeof *eout);
    pdt_rp_bfree(b, tout, most * sizeof *tout);
    scratch_put(b, &S);
    return NULL;
}

/* Threads that group triangle events at once (each with its own share of
 * the working budget): the runs are independent, and the grouping is bound
 * by cache misses and copying, which a second core halves. */
#define GROUP_THREADS 2

/* Group the triangle events (hist[], in fine buckets) by triangle, a run
 * of fine buckets at a time: each triangle's entries become consecutive, in
 * event order; ev_ent[ev] is the event's entry; ev_obj[ev] is -1 - (entries
 * of its triangle) for a triangle's first event, else that first event.
 * Working memory: about budget bytes (0: no limit), over GROUP_THREADS
 * threads when the runs are several. */
static int tri_groups(builder *b, uint64_t budget, size_t *ntri)
{
    *ntri = 0;
    size_t cap = budget ? (size_t)(budget / GROUP_BYTES_PER_EVENT / GROUP_THREADS) : SIZE_MAX;
    if (cap < 1024) cap = 1024;
    if (b->pl && cap > GROUP_RUN_MAX) cap = GROUP_RUN_MAX;
    size_t *run = malloc((b->nfine + 1) * sizeof *run), nrun = 0, most = 0; /* the runs' bounds; the largest run */
    if (!run) return 0;
    run[0] = 0;
    for (size_t f = 0; f < b->nfine;) {
        size_t g = f + 1;
        while (g < b->nfine && b->fine_off[g + 1] - b->fine_off[f] <= cap) g++;
        if (b->fine_off[g] - b->fine_off[f] > most) most = b->fine_off[g] - b->fine_off[f];
        run[++nrun] = g;
        f = g;
    }
    if (!most) {
        free(run);
        return 1;
    }
    group_job J = {.b = b, .run = run, .nrun = nrun, .most = most};
    pthread_t th[GROUP_THREADS];
    int started = 0;
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    /* one thread when a single fine bucket is all the budget takes (a huge
     * run under a small budget: a bucket is the least a run is) */
    int threads = budget && (uint64_t)most * GROUP_BYTES_PER_EVENT * GROUP_THREADS > budget ? 1
                                                                                       : GROUP_THREADS;
    for (int t = 1; t < threads && t < cpus && (size_t)t < nrun; t++)
        if (pthread_create(&th[t], NULL, b->pl ? group_worker_streamed : group_worker, &J) == 0)
            started |= 1 << t;
    (b->pl ? group_worker_streamed : group_worker)(&J);
    for (int t = 1; t < GROUP_THREADS; t++)
        if (started & (1 << t)) pthread_join(th[t], NULL);
    free(run);
    if (J.failed) {
        if (J.io) b->failed = 1;
        return 0;
    }
    *ntri = J.ntri;
    return 1;
}

/* The triangles' histories: grouped by triangle (tri_groups), then the
 * triangles numbered by their first event (streamed: pdt_rp_tri_number, pdt_rp_tri_join,
 * pdt_rp_ev_tables, through scratch files; in memory: pdt_rp_tri_ids). */
int pdt_rp_tri_histories(builder *b)
{
    pdt_replay *r = b->r;
    const pdt_replay_place *pl = b->pl;
    if (pl) { /* the last chunks; the buckets' places in the history table */
        for (size_t f = 0; f < b->nfine; f++)
            if (!pdt_rp_fine_flush(b, f)) return 0;
        if (!pdt_rp_chunks_by_bucket(b)) return 0;
        for (size_t f = 0; f < b->nfine; f++) b->fine_off[f + 1] = b->fine_off[f] + b->fine_fill[f];
        r->nhist = b->fine_off[b->nfine];
        if ((r->hist_at = pl->reserve(pl->ctx, (uint64_t)r->nhist * sizeof *r->hist)) == UINT64_MAX)
            return 0;
        pdt_rp_sw_free(b);
        pdt_rp_bfree(b, b->fbuf, b->nfine * b->fbuf_recs * sizeof *b->fbuf);
        b->fbuf = NULL;
    }
    size_t ntri;
    if (!tri_groups(b, pl ? pdt_rp_group_work(r, pl->budget) : 0, &ntri)) return 0;
    free(b->spill);
    b->spill = NULL;
    if (!pl) return pdt_rp_tri_ids(b);
    pl->sdrop(pl->ctx, PDT_SCR_SPILL);
    if ((r->tris_at = pl->reserve(pl->ctx, (uint64_t)ntri * sizeof *r->tris)) == UINT64_MAX ||
        !pdt_rp_tri_number(b) ||
        !pdt_rp_points_start(b) || /* (beside the join and the tables: one core each) */
        !pdt_rp_tri_join(b))
        return 0;
    pl->sdrop(pl->ctx, PDT_SCR_TRIS);
    pl->sdrop(pl->ctx, PDT_SCR_IDS);
    if (!pdt_rp_ev_tables(b)) return 0;
    pl->sdrop(pl->ctx, PDT_SCR_TRIEV);
    return pdt_rp_points_finish(b);
}
