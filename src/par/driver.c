/* pdt — the SRM driver (one file per phase, listed in driver.h): moves the
 * data between the phases of docs/algorithm.md §3
 * with the pdt_comm wrappers.  pdt_par_triangulate reads as its phases:
 *
 *   partition  every rank's input block is sample-sorted by key (equal keys
 *              to one rank); duplicates removed (smallest index kept); strip
 *              descriptors allgathered.
 *   local      pdt_srm_local: lift-up, kernel, strip hull, classification.
 *   merge      for each level: every rank of a pair sends one message (its
 *              pending triangles for that level, and the hull if it holds
 *              one) to the merge rank, which runs pdt_srm_merge.
 *   order      the final triangles go to the rank of their smallest index's
 *              range (ranges balanced by a histogram) and are put in
 *              canonical order there: rank q ends with a consecutive block.
 *
 * With one rank the sequential pipeline does all of it: pdt_triangulate_inplace,
 * or for a large untraced .tri run the same SRM on two strips one after the
 * other in one process (pdt_srm_plain, plain.c), to hold less memory.  By the
 * same rule a rank of a large untraced .tri run holds two strips (rank_strips):
 * the SRM then runs on 2P strips, rank r holding strips 2r and 2r + 1, which
 * it triangulates one after the other in its block and merges first, at
 * level 0, with no message; the levels above are the P ranks' own. */
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>
#include "pdt/testhook.h"
#include "driver.h"

/* One message (or one pair's share of a collective) as a trace event;
 * pdt_drv_note_send and _recv also count it. */
static void trace_send(drv *d, int tag, int peer, size_t bytes)
{
    PDT_TRACE(d->tr, 1, PDT_EV_SEND, tag, peer, (uint32_t)bytes, (uint32_t)((uint64_t)bytes >> 32),
              d->seq_send[peer]);
    d->seq_send[peer]++;
}

static void trace_recv(drv *d, int tag, int peer, size_t bytes)
{
    PDT_TRACE(d->tr, 1, PDT_EV_RECV, tag, peer, (uint32_t)bytes, (uint32_t)((uint64_t)bytes >> 32),
              d->seq_recv[peer]);
    d->seq_recv[peer]++;
}

void pdt_drv_note_send(drv *d, int tag, int peer, size_t bytes)
{
    d->bytes_sent += bytes;
    if (tag >= TAG_MERGE) d->merge_sent += bytes;
    trace_send(d, tag, peer, bytes);
}

void pdt_drv_note_recv(drv *d, int tag, int peer, size_t bytes)
{
    d->bytes_recv += bytes;
    if (tag >= TAG_MERGE) d->merge_recv += bytes;
    trace_recv(d, tag, peer, bytes);
}

/* A collective as the viewer draws it: every pair exchanges `bytes` (traced
 * peer by peer up to PDT_DRV_TRACE_PEERS ranks, nothing beyond). */
static void trace_pairs(drv *d, int tag, size_t bytes)
{
    if (!d->tr || d->p > PDT_DRV_TRACE_PEERS) return;
    for (int q = 0; q < d->p; q++)
        if (q != d->rank) {
            trace_send(d, tag, q, bytes);
            trace_recv(d, tag, q, bytes);
        }
}

void pdt_drv_note_all(drv *d, int tag, size_t bytes)
{
    if (!bytes) return;
    trace_pairs(d, tag, bytes);
    d->bytes_sent += (uint64_t)bytes * (uint64_t)(d->p - 1);
    d->bytes_recv += (uint64_t)bytes * (uint64_t)(d->p - 1);
}

void pdt_drv_note_reduce(drv *d, int tag, size_t bytes)
{
    if (!bytes || d->p < 2) return;
    trace_pairs(d, tag, bytes);
    d->bytes_sent += bytes;
    d->bytes_recv += bytes;
}

void pdt_drv_note_gather(drv *d, int tag, size_t bytes, int root)
{
    if (!bytes || d->p < 2) return;
    trace_pairs(d, tag, bytes);
    if (d->rank == root) d->bytes_recv += (uint64_t)bytes * (uint64_t)(d->p - 1);
    else d->bytes_sent += bytes;
}

/* An alltoallv: count what went to and came from each peer (traced as
 * pdt_drv_note_all is). */
void pdt_drv_note_v(drv *d, int tag, const size_t *sent, const size_t *recvd)
{
    int peers = d->tr && d->p <= PDT_DRV_TRACE_PEERS;
    for (int q = 0; q < d->p; q++) {
        if (q == d->rank) continue;
        if (!peers) {
            d->bytes_sent += sent[q];
            d->bytes_recv += recvd[q];
            continue;
        }
        if (sent[q]) pdt_drv_note_send(d, tag, q, sent[q]);
        if (recvd[q]) pdt_drv_note_recv(d, tag, q, recvd[q]);
    }
}

pdt_status pdt_drv_nomem(drv *d, const char *phase)
{
    return pdt_err_set(d->err, PDT_ERR_NOMEM, "rank %d: %s: out of memory", d->rank, phase);
}

void pdt_par_stats_free(pdt_par_stats *s)
{
    if (!s) return;
    free(s->rank);
    s->rank = NULL;
}

void pdt_par_output_free(pdt_par_output *out)
{
    free(out->tris);
    memset(out, 0, sizeof *out);
}

/* ---- partition -------------------------------------------------------------- */
/* ---- figures -------------------------------------------------------------------- */

static void figures(drv *d)
{
    pdt_par_rank_stats *me = d->me;
    me->points = d->m;
    me->received = d->nrecv + d->local_dups;
    me->n_dup = me->received - d->m;
    me->bytes_sent = d->bytes_sent;
    me->bytes_recv = d->bytes_recv;
    me->merge_bytes_sent = d->merge_sent;
    me->merge_bytes_recv = d->merge_recv;
    me->strips = d->k > 1 ? d->k : 0;
    me->levels = d->s[0].levels;
    me->partition = d->tree.cut ? PDT_PART_BISECT : PDT_PART_STRIPS;
    for (int j = 0; j < d->k; j++) { /* the strips' counts summed; the longest chain */
        const srm_rank *s = &d->s[j];
        me->local_tris += s->cnt.local_tris;
        me->final_at_once += s->cnt.final_at_once;
        me->deferred += s->cnt.deferred;
        me->shipped += s->cnt.shipped;
        me->merges += s->cnt.merges;
        if (s->cnt.border_max > me->border_max) me->border_max = s->cnt.border_max;
        for (int l = 0; l < PDT_PAR_MAX_LEVELS; l++)
            if (s->cnt.border_level[l] > me->border_level[l])
                me->border_level[l] = s->cnt.border_level[l];
        me->kept += s->cnt.kept;
        me->discarded += s->cnt.discarded;
        me->final_merge += s->cnt.final_merge;
        me->shared += s->cnt.shared;
        me->share_fallbacks += s->cnt.share_fallbacks;
        if (s->cnt.critical_path > me->critical_path) me->critical_path = s->cnt.critical_path;
        if (s->cnt.critical_cpu > me->critical_cpu) me->critical_cpu = s->cnt.critical_cpu;
        int g = d->rank * d->k + j;
        if (s->holds_hull && pdt_srm_holder_of(pdt_drv_sched(d), g, d->p * d->k, s->levels) == g) {
            me->holds_final_hull = 1;
            me->hull = s->nhull;
            me->hull_degenerate = s->hull_degenerate;
        }
    }
}

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* How many strips a plain run works on one after the other (pdt_srm_plain):
 * 2 for an untraced run of at least 2^21 points whose points may be spent
 * (a .tri output), else 0 (the whole kernel at once: traces keep the events
 * of one kernel run, the lessons count them; below 2^21 points, some 180 MB,
 * the 22 bytes per point saved are worth less than the 8-12 % of time), or
 * when a sample says the merge would redo most of the work (pdt_srm_plain_pays).
 * $PDT_PLAIN_STRIPS=K decides for every size: 0 the whole kernel (about 8 %
 * faster at 10^7 points, 84 bytes per point instead of 62), 2..16 strips. */
static int strips_for(const pdt_point *pts, size_t n)
{
    const char *t = getenv("PDT_PLAIN_STRIPS");
    if (t && *t) {
        int k = atoi(t);
        return k >= 2 && k <= PDT_PLAIN_MAX_STRIPS ? k : 0;
    }
    return n >= ((size_t)1 << 21) && pdt_srm_plain_pays(pts, n) ? 2 : 0;
}

static int plain_strips(const pdt_par_input *in, const pdt_trace *tr)
{
    return tr || !in->release_pts ? 0 : strips_for(in->pts, in->n);
}

/* T* of the points (pdt/par.h): on a copy the pipeline may spend, on
 * strips_for strips like a plain run's .tri output. */
pdt_status pdt_par_tstar(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri,
                         int *strips)
{
    *tris = NULL;
    *ntri = 0;
    *strips = strips_for(pts, n);
    pdt_point *copy = malloc(n ? n * sizeof *copy : 1);
    if (!copy) return PDT_ERR_NOMEM;
    memcpy(copy, pts, n * sizeof *copy);
    pdt_tri_stats ts;
    pdt_err err = {0};
    pdt_status st = *strips ? pdt_srm_plain(copy, n, *strips, 0, tris, ntri, &ts, &err)
                            : pdt_triangulate_inplace(copy, n, PDT_PTS_SPEND, tris, ntri, &ts, NULL);
    free(copy);
    return st;
}

/* Under SMPI the kernel's own phase clock is this machine's, not the
 * simulated one: its three phases are scaled to the simulated span they
 * fill (critical_path, which then holds nothing else). */
static void simulated_phases(pdt_par_rank_stats *me)
{
    double sum = me->t_partition + me->t_local + me->t_order;
    double f = sum > 0 ? me->critical_path / sum : 0;
    me->t_partition *= f;
    me->t_local *= f;
    me->t_order *= f;
}

/* One rank: the sequential pipeline on the whole input (the whole kernel, or
 * plain_strips strips one after the other), its figures in the same shape;
 * the trace gets the final triangles as a parallel run does. */
static pdt_status sequential(pdt_comm *c, pdt_par_input *in, pdt_par_output *out,
                             pdt_par_rank_stats *me, pdt_trace *tr, pdt_err *err)
{
    pdt_tri_stats ts;
    double c0 = cpu_seconds(), w0 = pdt_comm_wtime(c);
    int how = (in->release_pts ? PDT_PTS_SPEND : PDT_PTS_RESTORE) |
              (in->prefault ? PDT_TRI_PREFAULT : 0);
    int k = plain_strips(in, tr);
    pdt_status st;
    if (k) {
        st = pdt_srm_plain(in->pts, in->n, k, in->prefault, &out->tris, &out->ntri, &ts, err);
    } else {
        st = pdt_triangulate_inplace(in->pts, in->n, how, &out->tris, &out->ntri, &ts, tr);
        if (st != PDT_OK)
            pdt_err_set(err, st, "triangulation failed: %s", pdt_status_str(st));
    }
    if (in->release_pts) {
        free(in->pts);
        in->pts = NULL;
    }
    if (st != PDT_OK) return st;
    out->first = 0;
    out->n_total = out->ntri;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_OUTPUT, 0, 0, 0, 0);
    for (size_t i = 0; i < out->ntri && PDT_TRACING(tr, 1); i++)
        PDT_TRACE(tr, 1, PDT_EV_TRI_FINAL, 0, out->tris[i].v[0], out->tris[i].v[1],
                  out->tris[i].v[2], 0);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_OUTPUT, 0, 0, 0, 0);
    me->points = ts.n_unique;
    me->received = ts.n_in;
    me->n_dup = ts.n_dup;
    me->local_tris = me->final_at_once = me->emitted = ts.n_tri;
    me->hull = ts.n_hull;
    me->holds_final_hull = 1;
    me->prefault = ts.prefaulted;
    me->strips = k;
    me->hull_degenerate = ts.collinear;
    me->t_partition = ts.t_sort;
    me->t_local = ts.t_kernel;
    me->t_order = ts.t_canon;
    me->critical_path = pdt_comm_wtime(c) - w0;
    if (pdt_comm_is_simulated(c)) simulated_phases(me);
    me->critical_cpu = cpu_seconds() - c0;
    return PDT_OK;
}

/* The phase of pdt_par_triangulate this process is in (NULL outside it), for
 * a message when the job is ended from outside (pdt_par_phase). */
static _Atomic(const char *) cur_phase;

const char *pdt_par_phase(void)
{
    return atomic_load_explicit(&cur_phase, memory_order_relaxed);
}

static void enter(const char *phase)
{
    atomic_store_explicit(&cur_phase, phase, memory_order_relaxed);
}

/* ---- the whole run ------------------------------------------------------------ */

/* The phases of a run of several ranks, each timed into d->me. */
static pdt_status par_phases(drv *d, pdt_par_input *in, pdt_par_output *out, pdt_err *err)
{
    pdt_trace *tr = d->tr;
    pdt_par_rank_stats *me = d->me;
    double t0 = pdt_comm_wtime(d->c);
    enter("partition");
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_PARTITION, 0, 0, 0, 0);
    pdt_status st = pdt_drv_partition(d, in, err);
    if (st == PDT_OK) st = pdt_drv_rank_strips(d, in, err);
    if (st == PDT_OK) st = pdt_drv_strips(d, err);
    if (st != PDT_OK) return st;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_PARTITION, 0, 0, 0, 0);
    double t1 = pdt_comm_wtime(d->c);
    enter("local");
    st = pdt_drv_local(d, in->prefault, err);
    if (st != PDT_OK) return st;
    double t2 = pdt_comm_wtime(d->c);
    enter("merge");
    st = pdt_drv_merge_tree(d, err);
    /* the merge phase ends when the last merge does: ranks done early sleep
     * here (counted as merge time, not as order time) */
    if (st == PDT_OK) st = pdt_comm_quiet_barrier(d->c, err);
    if (st != PDT_OK) return st;
    double t3 = pdt_comm_wtime(d->c);
    st = pdt_drv_gather_more(d);
    if (st != PDT_OK) return st;
    me->emitted = d->s[0].nfin + d->nmore;
    pdt_drv_release_points(d);
    enter("order");
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_ORDER, 0, 0, 0, 0);
    st = pdt_drv_order(d, out, err);
    if (st != PDT_OK) return st;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_ORDER, 0, 0, 0, 0);
    me->t_partition = t1 - t0;
    me->t_local = t2 - t1;
    me->t_merge = t3 - t2;
    me->t_order = pdt_comm_wtime(d->c) - t3;
    figures(d);
    return PDT_OK;
}

static void drv_free(drv *d)
{
    for (int j = 0; j < PDT_RANK_MAX_STRIPS; j++)
        if (d->s_init[j]) pdt_srm_free(&d->s[j]);
    free(d->more);
    free(d->order_hist);
    free(d->blk);
    free(d->strip);
    free(d->tree.cut);
    free(d->seq_send);
    free(d->seq_recv);
}

pdt_status pdt_par_triangulate(pdt_comm *c, pdt_par_input *in, pdt_par_output *out,
                               pdt_par_rank_stats *me, pdt_trace *tr, pdt_err *err)
{
    memset(out, 0, sizeof *out);
    if (in->n_total > UINT32_MAX - 1)
        return pdt_err_set(err, PDT_ERR_ARG, "%llu points: more than 2^32 - 2",
                           (unsigned long long)in->n_total);
    const uint32_t *saved_gid = tr ? tr->gid : NULL;
    if (tr) tr->gid = NULL; /* the driver reports global indices itself */
    pdt_status st;
    if (in->partition == PDT_PART_AUTO)
        in->partition = (int)pdt_par_partition_for(pdt_comm_size(c));
    if (pdt_comm_size(c) == 1) {
        st = sequential(c, in, out, me, tr, err);
    } else {
        drv d = {.c = c, .rank = pdt_comm_rank(c), .p = pdt_comm_size(c), .tr = tr,
                 .n_total = in->n_total, .me = me, .err = err};
        d.seq_send = calloc((size_t)d.p, sizeof *d.seq_send);
        d.seq_recv = calloc((size_t)d.p, sizeof *d.seq_recv);
        st = d.seq_send && d.seq_recv ? par_phases(&d, in, out, err) : pdt_drv_nomem(&d, "start");
        enter(NULL);
        drv_free(&d);
    }
    if (tr) tr->gid = saved_gid;
    return st;
}

/* ---- figures of the whole run ------------------------------------------------------ */

pdt_status pdt_par_stats_collect(pdt_comm *c, const pdt_par_rank_stats *me, uint64_t n_in,
                                 pdt_par_stats *all, pdt_err *err)
{
    memset(all, 0, sizeof *all);
    int p = pdt_comm_size(c), r = pdt_comm_rank(c);
    pdt_par_rank_stats *reps = r == 0 ? malloc((size_t)p * sizeof *reps) : NULL;
    size_t *counts = malloc((size_t)p * sizeof *counts);
    if ((r == 0 && !reps) || !counts) {
        free(reps);
        free(counts);
        return pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: out of memory", r);
    }
    for (int q = 0; q < p; q++) counts[q] = sizeof *me;
    pdt_status st = pdt_comm_gatherv(c, me, sizeof *me, reps, counts, 0, err);
    free(counts);
    if (st != PDT_OK || r != 0) {
        free(reps);
        return st;
    }
    all->nranks = p;
    all->rank = reps;
    all->n_in = n_in;
    for (int q = 0; q < p; q++) {
        const pdt_par_rank_stats *rp = &reps[q];
        all->n_unique += rp->points;
        all->n_dup += rp->n_dup;
        all->n_tri += rp->written;
        all->bytes_total += rp->bytes_sent;
        all->merge_bytes += rp->merge_bytes_sent;
        if (rp->critical_path > all->critical_path) all->critical_path = rp->critical_path;
        if (rp->critical_cpu > all->critical_cpu) all->critical_cpu = rp->critical_cpu;
        if (rp->border_max > all->border_max) all->border_max = rp->border_max;
        for (int l = 0; l < PDT_PAR_MAX_LEVELS; l++)
            if (rp->border_level[l] > all->border_level[l])
                all->border_level[l] = rp->border_level[l];
        if (rp->levels > all->levels) all->levels = rp->levels;
        all->partition = rp->partition;
        double tc = rp->t_partition + rp->t_local + rp->t_merge + rp->t_order;
        if (tc > all->t_compute) all->t_compute = tc;
        if (rp->holds_final_hull) {
            all->hull = rp->hull;
            all->collinear = rp->hull_degenerate || all->n_unique < 3;
        }
    }
    if (all->n_unique < 3) all->collinear = 1;
    return PDT_OK;
}
