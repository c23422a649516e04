/* pdt — the SRM driver: moves the data between the phases of algorithm.md §3
 * with the pdt_comm wrappers.
 *
 *   Phase 0  rank 0 scatters index blocks; sample sort by key (equal keys to
 *            one rank); duplicates removed (smallest index kept); strip
 *            descriptors allgathered.
 *   Phase 1-2 pdt_srm_local: lift-up, kernel, strip hull, classification.
 *   Phase 3  for each level: every rank of a pair sends one message (its
 *            pending triangles for that level, and the hull if it holds one)
 *            to the merge rank, which runs pdt_srm_merge.
 *   Phase 4  final triangles gathered at rank 0 and put in canonical order. */
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "pdt/delaunay.h"
#include "srm.h"

enum {
    TAG_SCATTER = 1,
    TAG_SAMPLES = 2,
    TAG_COUNTS = 3,
    TAG_RECORDS = 4,
    TAG_STRIPS = 5,
    TAG_GATHER = 6,
    TAG_STATS = 7,
    TAG_MERGE = 100 /* + level */
};

/* Per-rank bookkeeping of the driver. */
typedef struct drv {
    pdt_comm *c;
    int rank, p;
    pdt_trace *tr;
    uint32_t *seq_send, *seq_recv; /* per-peer message sequence numbers */
    uint64_t bytes_sent, bytes_recv, merge_sent, merge_recv;
} drv;

/* Trace one message (or one pair's share of a collective) and count it. */
static void note_send(drv *d, int tag, int peer, size_t bytes)
{
    d->bytes_sent += bytes;
    if (tag >= TAG_MERGE) d->merge_sent += bytes;
    PDT_TRACE(d->tr, 1, PDT_EV_SEND, tag, peer, bytes, 0, d->seq_send[peer]);
    d->seq_send[peer]++;
}

static void note_recv(drv *d, int tag, int peer, size_t bytes)
{
    d->bytes_recv += bytes;
    if (tag >= TAG_MERGE) d->merge_recv += bytes;
    PDT_TRACE(d->tr, 1, PDT_EV_RECV, tag, peer, bytes, 0, d->seq_recv[peer]);
    d->seq_recv[peer]++;
}

/* Collective with uniform block size: every pair exchanges `bytes`. */
static void note_all(drv *d, int tag, size_t bytes)
{
    for (int q = 0; q < d->p; q++)
        if (q != d->rank && bytes) {
            note_send(d, tag, q, bytes);
            note_recv(d, tag, q, bytes);
        }
}

static double wclock(void *user)
{
    return pdt_comm_wtime(user);
}

/* Test-only: PDT_TEST_SLEEP_BEFORE_MERGE="RANK:SECONDS" makes RANK sleep
 * before its first merge step (to kill it there in a test). */
static void test_sleep(int rank)
{
    const char *e = getenv("PDT_TEST_SLEEP_BEFORE_MERGE");
    int r;
    double sec;
    if (e && sscanf(e, "%d:%lf", &r, &sec) == 2 && r == rank && sec > 0) {
        struct timespec ts = {(time_t)sec, (long)((sec - (double)(time_t)sec) * 1e9)};
        nanosleep(&ts, NULL);
    }
}

/* Everything the driver gathers at rank 0 from each rank. */
typedef struct rank_report {
    pdt_par_rank_stats st;
    uint64_t n_dup, hull, holds_final_hull;
    int64_t hull_degenerate;
} rank_report;

void pdt_par_stats_free(pdt_par_stats *s)
{
    if (!s) return;
    free(s->rank);
    s->rank = NULL;
}

/* ---- Phase 0 ---------------------------------------------------------------- */

static pdt_status partition(drv *d, const pdt_point *pts, uint64_t n, srm_rec **out, size_t *m,
                            uint64_t *nrecv, pdt_err *err)
{
    int p = d->p, r = d->rank;
    pdt_status st = PDT_OK;
    size_t *cnt = calloc((size_t)p, sizeof *cnt), *rcnt = calloc((size_t)p, sizeof *rcnt);
    uint64_t *samp = NULL, *all = NULL, *split = NULL, *sc = NULL, *rc = NULL;
    srm_rec *rec = NULL, *tmp = NULL, *got = NULL;
    pdt_point *mine = NULL;
    if (!cnt || !rcnt) goto nomem;
    /* index blocks: rank q gets [n q / p, n (q+1) / p) */
    uint64_t lo = n * (uint64_t)r / (uint64_t)p, hi = n * (uint64_t)(r + 1) / (uint64_t)p;
    size_t mine_n = (size_t)(hi - lo);
    for (int q = 0; q < p; q++)
        cnt[q] = (size_t)(n * (uint64_t)(q + 1) / (uint64_t)p - n * (uint64_t)q / (uint64_t)p) *
                 sizeof(pdt_point);
    mine = malloc((mine_n + 1) * sizeof *mine);
    if (!mine) goto nomem;
    st = pdt_comm_scatterv(d->c, pts, cnt, mine, mine_n * sizeof *mine, 0, err);
    if (st != PDT_OK) goto done;
    if (r == 0) {
        for (int q = 1; q < p; q++)
            if (cnt[q]) note_send(d, TAG_SCATTER, q, cnt[q]);
    } else if (mine_n) {
        note_recv(d, TAG_SCATTER, 0, mine_n * sizeof *mine);
    }

    rec = malloc((mine_n + 1) * sizeof *rec);
    tmp = malloc((mine_n + 1) * sizeof *tmp);
    if (!rec || !tmp) goto nomem;
    for (size_t i = 0; i < mine_n; i++) rec[i] = (srm_rec){pdt_key(mine[i]), (uint32_t)(lo + i), 0};
    free(mine);
    mine = NULL;
    /* samples at a regular stride of the input order (no sort needed here),
     * allgathered: [count, S keys] per rank */
    size_t S = (size_t)64 * (size_t)p;
    samp = calloc(S + 1, sizeof *samp);
    all = malloc((size_t)p * (S + 1) * sizeof *all);
    split = malloc((size_t)p * sizeof *split);
    if (!samp || !all || !split) goto nomem;
    size_t k = mine_n < S ? mine_n : S;
    samp[0] = k;
    for (size_t i = 0; i < k; i++) samp[1 + i] = rec[i * mine_n / k].key;
    st = pdt_comm_allgather(d->c, samp, (S + 1) * sizeof *samp, all, err);
    if (st != PDT_OK) goto done;
    note_all(d, TAG_SAMPLES, (S + 1) * sizeof *samp);
    size_t ns = 0; /* compact in place: the write index never passes the read index */
    for (int q = 0; q < p; q++) {
        const uint64_t *b = all + (size_t)q * (S + 1);
        size_t cnt_q = b[0] < S ? (size_t)b[0] : S;
        for (size_t i = 0; i < cnt_q; i++) all[ns++] = b[1 + i];
    }
    pdt_srm_pick_splitters(all, ns, p, split);

    /* destination of each record; a stable counting pass groups them by
     * destination (input order, hence index order, kept within a group) */
    for (int q = 0; q < p; q++) cnt[q] = 0;
    if (p > 1) {
        for (size_t i = 0; i < mine_n; i++) {
            rec[i].pad = (uint32_t)pdt_srm_dest_rank(split, p, rec[i].key);
            cnt[rec[i].pad]++;
        }
        size_t off = 0;
        for (int q = 0; q < p; q++) {
            rcnt[q] = off; /* scratch: start of group q */
            off += cnt[q];
        }
        for (size_t i = 0; i < mine_n; i++) tmp[rcnt[rec[i].pad]++] = rec[i];
        srm_rec *t = rec;
        rec = tmp;
        tmp = t;
    } else {
        cnt[0] = mine_n;
    }
    sc = malloc((size_t)p * sizeof *sc);
    rc = malloc((size_t)p * sizeof *rc);
    if (!sc || !rc) goto nomem;
    for (int q = 0; q < p; q++) sc[q] = cnt[q];
    st = pdt_comm_alltoall(d->c, sc, sizeof *sc, rc, err);
    if (st != PDT_OK) goto done;
    note_all(d, TAG_COUNTS, sizeof *sc);
    size_t total = 0;
    for (int q = 0; q < p; q++) {
        cnt[q] *= sizeof(srm_rec);
        rcnt[q] = (size_t)rc[q] * sizeof(srm_rec);
        total += (size_t)rc[q];
    }
    got = malloc((total + 1) * sizeof *got);
    if (!got) goto nomem;
    st = pdt_comm_alltoallv(d->c, rec, cnt, got, rcnt, err);
    if (st != PDT_OK) goto done;
    for (int q = 0; q < p; q++) {
        if (q == r) continue;
        if (cnt[q]) note_send(d, TAG_RECORDS, q, cnt[q]);
        if (rcnt[q]) note_recv(d, TAG_RECORDS, q, rcnt[q]);
    }
    free(rec);
    rec = NULL;
    free(tmp);
    tmp = malloc((total + 1) * sizeof *tmp);
    if (!tmp) goto nomem;
    /* blocks arrive in rank order, each in index order, and rank q's indices
     * are all below rank q+1's, so a stable sort by key orders equal keys by
     * index: the first copy is the smallest index */
    pdt_srm_radix_sort(got, tmp, total);
    *nrecv = total;
    *m = pdt_srm_dedupe(got, total);
    *out = got;
    got = NULL;
    goto done;
nomem:
    st = pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: partition: out of memory", r);
done:
    free(cnt);
    free(rcnt);
    free(samp);
    free(all);
    free(split);
    free(sc);
    free(rc);
    free(rec);
    free(tmp);
    free(got);
    free(mine);
    return st;
}

static int tri_less(const pdt_tri *a, const pdt_tri *b)
{
    for (int k = 0; k < 3; k++)
        if (a->v[k] != b->v[k]) return a->v[k] < b->v[k];
    return 0;
}

/* Restore the heap order below heap[k]: the block whose next triangle is
 * smallest comes first. */
static void sift_down(int *heap, int h, int k, const pdt_tri *a, const size_t *pos)
{
    for (;;) {
        int m = k, l = 2 * k + 1, r = l + 1;
        if (l < h && tri_less(&a[pos[heap[l]]], &a[pos[heap[m]]])) m = l;
        if (r < h && tri_less(&a[pos[heap[r]]], &a[pos[heap[m]]])) m = r;
        if (m == k) return;
        int t = heap[k];
        heap[k] = heap[m];
        heap[m] = t;
        k = m;
    }
}

/* Merge p sorted blocks (count[q] bytes each, contiguous) of *all into one
 * sorted array with a binary heap of block cursors: O(T log p). */
static pdt_status merge_blocks(pdt_tri **all, const size_t *count, int p, size_t total,
                               pdt_err *err)
{
    size_t *pos = malloc((size_t)p * sizeof *pos), *end = malloc((size_t)p * sizeof *end);
    int *heap = malloc((size_t)p * sizeof *heap);
    pdt_tri *out = malloc((total + 1) * sizeof *out);
    if (!pos || !end || !heap || !out) {
        free(pos);
        free(end);
        free(heap);
        free(out);
        return pdt_err_set(err, PDT_ERR_NOMEM, "rank 0: out of memory merging %zu triangles",
                           total);
    }
    const pdt_tri *a = *all;
    size_t off = 0;
    int h = 0;
    for (int q = 0; q < p; q++) {
        pos[q] = off;
        off += count[q] / sizeof(pdt_tri);
        end[q] = off;
        if (pos[q] < end[q]) heap[h++] = q;
    }
    for (int i = h / 2 - 1; i >= 0; i--) /* heapify */
        sift_down(heap, h, i, a, pos);
    for (size_t o = 0; o < total; o++) {
        int q = heap[0];
        out[o] = a[pos[q]++];
        if (pos[q] == end[q]) heap[0] = heap[--h];
        sift_down(heap, h, 0, a, pos);
    }
    free(pos);
    free(end);
    free(heap);
    free(*all);
    *all = out;
    return PDT_OK;
}

/* ---- the whole run ------------------------------------------------------------ */

pdt_status pdt_par_triangulate(pdt_comm *c, const pdt_point *pts, size_t n_in, pdt_tri **tris,
                               size_t *ntri, pdt_par_stats *stats, pdt_trace *tr, pdt_err *err)
{
    *tris = NULL;
    *ntri = 0;
    if (stats) memset(stats, 0, sizeof *stats);
    drv d = {c, pdt_comm_rank(c), pdt_comm_size(c), tr, NULL, NULL, 0, 0, 0, 0};
    int p = d.p, r = d.rank;
    pdt_status st = PDT_OK;
    srm_rec *rec = NULL;
    pdt_point *lp = NULL;
    uint32_t *lg = NULL;
    srm_strip *strip = NULL;
    srm_rank s;
    int s_init = 0;
    pdt_tri *all = NULL;
    size_t *counts = NULL;
    rank_report *reps = NULL;
    rank_report me;
    memset(&me, 0, sizeof me);
    const uint32_t *saved_gid = tr ? tr->gid : NULL;
    if (tr) tr->gid = NULL; /* the driver reports global indices itself */

    d.seq_send = calloc((size_t)p, sizeof *d.seq_send);
    d.seq_recv = calloc((size_t)p, sizeof *d.seq_recv);
    if (!d.seq_send || !d.seq_recv) {
        st = pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: out of memory", r);
        goto done;
    }
    double t_start = pdt_comm_wtime(c);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);

    /* Phase 0 */
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_PARTITION, 0, 0, 0, 0);
    uint64_t n = n_in;
    st = pdt_comm_bcast(c, &n, sizeof n, 0, err);
    if (st != PDT_OK) goto done;
    if (n > UINT32_MAX) {
        st = pdt_err_set(err, PDT_ERR_ARG, "%llu points: more than 2^32 - 1",
                         (unsigned long long)n);
        goto done;
    }
    size_t m = 0;
    uint64_t nrecv = 0;
    st = partition(&d, pts, n, &rec, &m, &nrecv, err);
    if (st != PDT_OK) goto done;
    lp = malloc((m + 1) * sizeof *lp);
    lg = malloc((m + 1) * sizeof *lg);
    strip = malloc((size_t)p * sizeof *strip);
    if (!lp || !lg || !strip) {
        st = pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: out of memory", r);
        goto done;
    }
    srm_strip mine = {m, 0, 0, 0, 0, 0, 0};
    for (size_t i = 0; i < m; i++) {
        lp[i] = srm_key_point(rec[i].key);
        lg[i] = rec[i].idx;
        if (i == 0 || lp[i].y < mine.ymin) mine.ymin = lp[i].y;
        if (i == 0 || lp[i].y > mine.ymax) mine.ymax = lp[i].y;
    }
    if (m) {
        mine.first_key = rec[0].key;
        mine.last_key = rec[m - 1].key;
        mine.xmin = lp[0].x;
        mine.xmax = lp[m - 1].x;
    }
    free(rec);
    rec = NULL;
    st = pdt_comm_allgather(c, &mine, sizeof mine, strip, err);
    if (st != PDT_OK) goto done;
    note_all(&d, TAG_STRIPS, sizeof mine);
    me.st.points = m;
    me.st.received = nrecv;
    me.n_dup = nrecv - m;
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_PARTITION, 0, 0, 0, 0);
    double t_part = pdt_comm_wtime(c);
    me.st.t_partition = t_part - t_start;

    /* Phases 1 and 2 */
    st = pdt_srm_init(&s, r, p, strip, tr, err);
    if (st != PDT_OK) goto done;
    s_init = 1;
    s.clock = wclock;
    s.clock_user = c;
    st = pdt_srm_local(&s, lp, lg, m, err);
    if (st != PDT_OK) goto done;
    free(lp);
    free(lg);
    lp = NULL;
    lg = NULL;
    double t_local = pdt_comm_wtime(c);
    me.st.t_local = t_local - t_part;

    /* Phase 3: the merge tree */
    for (int level = 0; level < s.levels; level++) {
        int gl, gr, ge;
        if (!pdt_srm_pair(r, p, level, &gl, &gr, &ge)) continue;
        PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_MERGE, level, 0, 0, 0);
        void *buf = NULL;
        size_t len = 0;
        st = pdt_srm_pack(&s, level, &buf, &len, err);
        if (st != PDT_OK) goto done;
        if (r != gr) {
            st = pdt_comm_send(c, gr, TAG_MERGE + level, buf, len, err);
            if (st == PDT_OK) note_send(&d, TAG_MERGE + level, gr, len);
            free(buf);
            if (st != PDT_OK) goto done;
        } else {
            test_sleep(r);
            int nm = ge - gl;
            void **msg = calloc((size_t)nm, sizeof *msg);
            size_t *lens = calloc((size_t)nm, sizeof *lens);
            if (!msg || !lens) {
                free(msg);
                free(lens);
                free(buf);
                st = pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: out of memory", r);
                goto done;
            }
            msg[r - gl] = buf;
            lens[r - gl] = len;
            for (int q = gl; q < ge && st == PDT_OK; q++) {
                if (q == r) continue;
                st = pdt_comm_recv(c, q, TAG_MERGE + level, &msg[q - gl], &lens[q - gl], err);
                if (st == PDT_OK) note_recv(&d, TAG_MERGE + level, q, lens[q - gl]);
            }
            if (st == PDT_OK) st = pdt_srm_merge(&s, level, msg, lens, err);
            for (int i = 0; i < nm; i++) free(msg[i]);
            free(msg);
            free(lens);
            if (st != PDT_OK) goto done;
        }
        PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_MERGE, level, 0, 0, 0);
    }
    if (s.npend) {
        st = pdt_err_set(err, PDT_ERR_CHECK, "rank %d: %zu triangles still pending after the "
                                             "last merge", r, s.npend);
        goto done;
    }
    double t_merge = pdt_comm_wtime(c);
    me.st.t_merge = t_merge - t_local;

    /* Phase 4: every rank puts its triangles in canonical order, rank 0
     * gathers the sorted blocks and merges them */
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_OUTPUT, 0, 0, 0, 0);
    pdt_tri_canonical(s.fin, s.nfin);
    st = pdt_comm_quiet_barrier(c, err); /* ranks done early sleep until the last merge ends */
    if (st != PDT_OK) goto done;
    uint64_t nf = s.nfin, *nfs = malloc((size_t)p * sizeof *nfs);
    counts = malloc((size_t)p * sizeof *counts);
    if (!nfs || !counts) {
        free(nfs);
        st = pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: out of memory", r);
        goto done;
    }
    st = pdt_comm_allgather(c, &nf, sizeof nf, nfs, err);
    if (st == PDT_OK) note_all(&d, TAG_GATHER, sizeof nf);
    size_t total = 0;
    for (int q = 0; q < p; q++) {
        counts[q] = (size_t)nfs[q] * sizeof(pdt_tri);
        total += (size_t)nfs[q];
    }
    free(nfs);
    if (st != PDT_OK) goto done;
    if (r == 0) {
        all = malloc((total + 1) * sizeof *all);
        if (!all) {
            st = pdt_err_set(err, PDT_ERR_NOMEM, "rank 0: out of memory (%zu triangles)", total);
            goto done;
        }
    }
    st = pdt_comm_gatherv(c, s.fin, s.nfin * sizeof(pdt_tri), all, counts, 0, err);
    if (st != PDT_OK) goto done;
    if (r == 0) {
        for (int q = 1; q < p; q++)
            if (counts[q]) note_recv(&d, TAG_GATHER, q, counts[q]);
        int blocks = 0;
        for (int q = 0; q < p; q++) blocks += counts[q] != 0;
        if (blocks > 1) st = merge_blocks(&all, counts, p, total, err);
        if (st != PDT_OK) goto done;
    } else if (s.nfin) {
        note_send(&d, TAG_GATHER, 0, s.nfin * sizeof(pdt_tri));
    }
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_OUTPUT, 0, 0, 0, 0);
    double t_end = pdt_comm_wtime(c);

    /* figures */
    me.st.local_tris = s.cnt.local_tris;
    me.st.final_at_once = s.cnt.final_at_once;
    me.st.deferred = s.cnt.deferred;
    me.st.shipped = s.cnt.shipped;
    me.st.merges = s.cnt.merges;
    me.st.border_max = s.cnt.border_max;
    me.st.kept = s.cnt.kept;
    me.st.discarded = s.cnt.discarded;
    me.st.final_merge = s.cnt.final_merge;
    me.st.emitted = s.nfin;
    me.st.bytes_sent = d.bytes_sent;
    me.st.bytes_recv = d.bytes_recv;
    me.st.merge_bytes_sent = d.merge_sent;
    me.st.merge_bytes_recv = d.merge_recv;
    me.st.t_gather = t_end - t_merge;
    me.st.critical_path = s.cnt.critical_path;
    me.st.critical_cpu = s.cnt.critical_cpu;
    {
        struct rusage ru;
        me.st.peak_rss_kib = getrusage(RUSAGE_SELF, &ru) == 0 ? (int64_t)ru.ru_maxrss : -1;
    }
    me.holds_final_hull = s.holds_hull && pdt_srm_holder(r, p, s.levels) == r;
    me.hull = s.nhull;
    me.hull_degenerate = s.hull_degenerate;
    reps = r == 0 ? malloc((size_t)p * sizeof *reps) : NULL;
    if (r == 0 && !reps) {
        st = pdt_err_set(err, PDT_ERR_NOMEM, "rank 0: out of memory");
        goto done;
    }
    for (int q = 0; q < p; q++) counts[q] = sizeof me;
    st = pdt_comm_gatherv(c, &me, sizeof me, reps, counts, 0, err);
    if (st != PDT_OK) goto done;
    if (r == 0) {
        if (stats) {
            stats->nranks = p;
            stats->rank = malloc((size_t)p * sizeof *stats->rank);
            if (!stats->rank) {
                st = pdt_err_set(err, PDT_ERR_NOMEM, "rank 0: out of memory");
                goto done;
            }
            stats->n_in = n;
            for (int q = 0; q < p; q++) {
                const rank_report *rp = &reps[q];
                stats->rank[q] = rp->st;
                stats->n_unique += rp->st.points;
                stats->n_dup += rp->n_dup;
                stats->bytes_total += rp->st.bytes_sent;
                stats->merge_bytes += rp->st.merge_bytes_sent;
                if (rp->st.critical_path > stats->critical_path)
                    stats->critical_path = rp->st.critical_path;
                if (rp->st.critical_cpu > stats->critical_cpu)
                    stats->critical_cpu = rp->st.critical_cpu;
                if (rp->st.border_max > stats->border_max) stats->border_max = rp->st.border_max;
                if (rp->holds_final_hull) {
                    stats->hull = rp->hull;
                    stats->collinear = (int)rp->hull_degenerate;
                }
            }
            stats->n_tri = total;
            stats->t_total = t_end - t_start;
        }
        *tris = all;
        *ntri = total;
        all = NULL;
    }
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_RUN, 0, 0, 0, 0);

done:
    if (tr) tr->gid = saved_gid;
    if (s_init) pdt_srm_free(&s);
    free(rec);
    free(lp);
    free(lg);
    free(strip);
    free(all);
    free(counts);
    free(reps);
    free(d.seq_send);
    free(d.seq_recv);
    return st;
}

/* ---- JSON ------------------------------------------------------------------------ */

void pdt_par_stats_json(const pdt_par_stats *s, FILE *f)
{
    fprintf(f,
            "{\"ranks\": %d, \"n\": %llu, \"unique\": %llu, \"duplicates\": %llu, "
            "\"triangles\": %llu, \"hull\": %llu, \"collinear\": %s, "
            "\"largest_border_set\": %llu, \"largest_border_set_rel_n\": %.6f, "
            "\"sequential_merge\": %s, "
            "\"bytes_total\": %llu, \"merge_bytes\": %llu, \"merge_bytes_rel_input\": %.6f, "
            "\"critical_path_s\": %.6f, \"critical_path_cpu_s\": %.6f, \"time_s\": %.6f,\n"
            " \"per_rank\": [",
            s->nranks, (unsigned long long)s->n_in, (unsigned long long)s->n_unique,
            (unsigned long long)s->n_dup, (unsigned long long)s->n_tri,
            (unsigned long long)s->hull, s->collinear ? "true" : "false",
            (unsigned long long)s->border_max,
            s->n_unique ? (double)s->border_max / (double)s->n_unique : 0.0,
            s->n_unique >= 64 && 2 * s->border_max > s->n_unique ? "true" : "false",
            (unsigned long long)s->bytes_total, (unsigned long long)s->merge_bytes,
            s->n_in ? (double)s->merge_bytes / (8.0 * (double)s->n_in) : 0.0, s->critical_path,
            s->critical_cpu,
            s->t_total);
    for (int q = 0; q < s->nranks; q++) {
        const pdt_par_rank_stats *r = &s->rank[q];
        fprintf(f,
                "%s\n  {\"rank\": %d, \"points\": %llu, \"local_triangles\": %llu, "
                "\"final_at_once\": %llu, \"deferred\": %llu, \"shipped\": %llu, "
                "\"merges\": %llu, \"border_max\": %llu, \"kept\": %llu, \"discarded\": %llu, "
                "\"final_by_merge\": %llu, \"emitted\": %llu, \"bytes_sent\": %llu, "
                "\"bytes_received\": %llu, \"merge_bytes_sent\": %llu, "
                "\"merge_bytes_received\": %llu, \"partition_s\": %.6f, \"local_s\": %.6f, "
                "\"merge_s\": %.6f, \"gather_s\": %.6f, \"critical_path_s\": %.6f, "
                "\"peak_rss_kib\": %lld}",
                q ? "," : "", q, (unsigned long long)r->points,
                (unsigned long long)r->local_tris, (unsigned long long)r->final_at_once,
                (unsigned long long)r->deferred, (unsigned long long)r->shipped,
                (unsigned long long)r->merges, (unsigned long long)r->border_max,
                (unsigned long long)r->kept, (unsigned long long)r->discarded,
                (unsigned long long)r->final_merge, (unsigned long long)r->emitted,
                (unsigned long long)r->bytes_sent, (unsigned long long)r->bytes_recv,
                (unsigned long long)r->merge_bytes_sent, (unsigned long long)r->merge_bytes_recv,
                r->t_partition, r->t_local, r->t_merge, r->t_gather, r->critical_path,
                (long long)r->peak_rss_kib);
    }
    fprintf(f, "]}");
}
