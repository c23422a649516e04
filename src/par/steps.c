/* pdt — the local phase and the merge tree (driver.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pdt/testhook.h"
#include "driver.h"

static double wclock(void *user)
{
    return pdt_comm_wtime(user);
}

/* ---- local ---------------------------------------------------------------------- */

/* The SRM state of each of this rank's strips (on the bisection's tree
 * when there is one). */
static pdt_status local_init(drv *d, pdt_err *err)
{
    int k = d->k;
    for (int j = 0; j < k; j++) {
        srm_rank *s = &d->s[j];
        pdt_status st = pdt_srm_init(s, d->rank * k + j, d->p * k, d->strip, d->tr, err);
        if (st != PDT_OK) return st;
        d->s_init[j] = 1;
        pdt_srm_per_rank(s, k);
        if (d->tree.cut) {
            d->tree.k = k;
            st = pdt_srm_use_tree(s, &d->tree, err);
            if (st != PDT_OK) return st;
        }
        s->clock = wclock;
        s->clock_user = d->c;
    }
    return PDT_OK;
}

/* The bytes of the block the kernels' edges reach: strip j's kernel works
 * right behind the final triangles of the strips before it. */
static size_t local_need(const drv *d)
{
    size_t need = 0;
    for (int j = 0; j < d->k; j++) {
        size_t mj = d->first[j + 1] - d->first[j];
        size_t end = (j ? 24 * d->first[j] : 0) + PDT_DELAUNAY_WORK(mj);
        need = end > need ? end : need;
    }
    return need;
}

/* The kernel of strip j at blk + *off; its finals stay there (an even
 * number: the next strip's edges stay 8-byte aligned; an odd one is set
 * aside in d->more), *off moved past them, *nfin counting them. */
static pdt_status local_strip(drv *d, int j, unsigned char *blk, size_t *off, size_t *nfin,
                              pdt_err *err)
{
    size_t a = d->first[j], mj = d->first[j + 1] - a;
    srm_rank *s = &d->s[j];
    pdt_status st = pdt_srm_local(s, blk + *off, block_pts(d) + a, block_gid(d) + a, block_id(d),
                                  mj, err);
    if (st != PDT_OK) return st;
    if (j + 1 < d->k && s->nfin % 2) {
        pdt_tri *more = realloc(d->more, (d->nmore + 1) * sizeof *more);
        if (!more) return pdt_drv_nomem(d, "local");
        d->more = more;
        d->more[d->nmore++] = s->fin[--s->nfin];
    }
    *off += s->nfin * sizeof(pdt_tri);
    *nfin += s->nfin;
    if (j) { /* (the block is strip 0's: its finals hold every strip's, in order) */
        s->fin = NULL;
        s->nfin = s->capfin = 0;
    }
    return PDT_OK;
}

/* Phases 1 and 2 on this rank's strips, in its block (which the SRM state
 * owns from here on, as the array of final triangles); with `prefault` a
 * second thread faults the kernel's part of the block in ahead of it. */
pdt_status pdt_drv_local(drv *d, int prefault, pdt_err *err)
{
    pdt_status st = local_init(d, err);
    if (st == PDT_OK) st = pdt_drv_order_hist(d);
    if (st != PDT_OK) return st;
    unsigned char *blk = d->blk;
    size_t need = local_need(d);
    pdt_prefault *pf = NULL;
    if (prefault) { /* the kernel's edges grow past the partition's records, up to its
                     * bound for this strip's points (the block has room for more) */
        size_t front = 2 * d->blk_cap * sizeof(srm_rec);
        pdt_range edges = {blk + front, need > front ? need - front : 0};
        pf = pdt_prefault_start(&edges, 1);
        d->me->prefault = pf != NULL;
    }
    size_t off = 0, nfin = 0;
    for (int j = 0; j < d->k && st == PDT_OK; j++) st = local_strip(d, j, blk, &off, &nfin, err);
    d->blk = NULL;
    if (st == PDT_OK) {
        d->s[0].nfin = nfin;
        d->s[0].capfin = nfin;
    }
    d->more_counted = d->nmore; /* (the finals set aside) */
    for (int j = 0; j < d->k; j++) d->s[j].order_hist = NULL;
    pdt_prefault_stop(pf); /* every page of the block has been touched */
    return st;
}

/* ---- merge --------------------------------------------------------------------- */

/* The merge tree's schedule: the bisection tree, or NULL for strips. */
const srm_tree *pdt_drv_sched(const drv *d)
{
    return d->tree.cut ? &d->tree : NULL;
}

/* Whether strip q sends a message at `level`: every strip of a pair, or
 * with relay (the bisection's tree) the holders of its two groups only. */
static int sends(const drv *d, int q, int level)
{
    return !d->tree.cut || pdt_srm_holder_of(pdt_drv_sched(d), q, d->p * d->k, level) == q;
}

/* A merge-tree message sent or received, and counted (and traced). */
static pdt_status send_note(drv *d, int to, int tag, const void *buf, size_t len, pdt_err *err)
{
    pdt_status st = pdt_comm_send(d->c, to, tag, buf, len, err);
    if (st == PDT_OK) pdt_drv_note_send(d, tag, to, len);
    return st;
}

static pdt_status recv_note(drv *d, int from, int tag, void **buf, size_t *len, pdt_err *err)
{
    pdt_status st = pdt_comm_recv(d->c, from, tag, buf, len, err);
    if (st == PDT_OK) pdt_drv_note_recv(d, tag, from, *len);
    return st;
}

/* ---- a merge shared along its seam (srm_share.c) --------------------------- */

/* The verdict of a shared merge, from the merge rank to the others. */
static pdt_status tell_verdict(drv *d, const srm_share_plan *pl, int level, unsigned char ok,
                               pdt_err *err)
{
    pdt_status st = PDT_OK;
    for (int i = 1; i < pl->n && st == PDT_OK; i++)
        st = send_note(d, pl->rank[i], TAG_VERDICT + level, &ok, 1, err);
    return st;
}

/* At the merge rank: the border set cut into pieces, one to each rank of
 * the plan (its own the first), their replies, the verdict. */
static pdt_status shared_merge(drv *d, int level, int j, const srm_share_plan *pl, void **msg,
                               size_t *lens, pdt_err *err)
{
    int n = pl->n, ok = 0;
    srm_job *job = NULL;
    void *piece[PDT_SHARE_MAX] = {0}, *reply[PDT_SHARE_MAX] = {0};
    size_t plen[PDT_SHARE_MAX] = {0}, rlen[PDT_SHARE_MAX] = {0};
    srm_held held = {0};
    pdt_status st = pdt_srm_share_open(&d->s[j], level, msg, lens, &job, err);
    if (st == PDT_OK) st = pdt_srm_share_pieces(job, n, piece, plen);
    for (int i = 1; i < n && st == PDT_OK; i++)
        st = send_note(d, pl->rank[i], TAG_SHARE + level, piece[i], plen[i], err);
    if (st == PDT_OK)
        st = pdt_srm_share_work(&d->s[j], piece[0], plen[0], &reply[0], &rlen[0], &held, err);
    for (int i = 1; i < n && st == PDT_OK; i++)
        st = recv_note(d, pl->rank[i], TAG_SHARE_BACK + level, &reply[i], &rlen[i], err);
    if (st == PDT_OK) st = pdt_srm_share_join(job, reply, rlen, n, &ok);
    if (st == PDT_OK) st = tell_verdict(d, pl, level, (unsigned char)ok, err);
    pdt_status cst = pdt_srm_share_commit(&d->s[j], &held, ok && st == PDT_OK);
    if (st == PDT_OK) st = cst != PDT_OK ? pdt_drv_nomem(d, "merge") : PDT_OK;
    st = job ? pdt_srm_share_close(job, ok, st) : st;
    for (int i = 0; i < n; i++) {
        free(piece[i]);
        free(reply[i]);
    }
    return st;
}

/* At a rank of a shared merge's plan other than the merge rank: its piece,
 * its reply, the verdict. */
static pdt_status share_help(drv *d, int level, const srm_share_plan *pl, pdt_err *err)
{
    int m = pl->rank[0];
    void *piece = NULL, *reply = NULL, *verdict = NULL;
    size_t plen = 0, rlen = 0, vlen = 0;
    srm_held held = {0};
    pdt_status st = recv_note(d, m, TAG_SHARE + level, &piece, &plen, err);
    if (st == PDT_OK) st = pdt_srm_share_work(&d->s[0], piece, plen, &reply, &rlen, &held, err);
    if (st == PDT_OK) st = send_note(d, m, TAG_SHARE_BACK + level, reply, rlen, err);
    if (st == PDT_OK) st = recv_note(d, m, TAG_VERDICT + level, &verdict, &vlen, err);
    int ok = st == PDT_OK && vlen == 1 && *(unsigned char *)verdict;
    pdt_status cst = pdt_srm_share_commit(&d->s[0], &held, ok);
    if (st == PDT_OK && cst != PDT_OK) st = pdt_drv_nomem(d, "merge");
    free(piece);
    free(reply);
    free(verdict);
    return st;
}

/* Whether this rank shares the merge of its group at `level` without
 * being its merge rank, and then its part. */
static pdt_status maybe_help(drv *d, int level, pdt_err *err)
{
    srm_share_plan pl;
    if (!pdt_srm_share_plan(&d->s[0], level, &pl)) return PDT_OK;
    for (int i = 1; i < pl.n; i++)
        if (pl.rank[i] == d->rank) return share_help(d, level, &pl, err);
    return PDT_OK;
}

/* At the merge strip g of a level (this rank's strip j): the messages of the
 * pair's strips [gl, ge) that send (all, or with relay the two holders):
 * this rank's own (in own[], taken: freed here), the others received from
 * their ranks, in strip order (a rank sends its strips' messages in that
 * order, and messages from one rank with one tag arrive in the order
 * sent); merged. */
static pdt_status merge_at(drv *d, int level, int j, int gl, int ge, void **own, size_t *own_len,
                           pdt_err *err)
{
    int k = d->k, nm = ge - gl, relay = d->tree.cut != NULL, np = d->p * k;
    int hold[2] = {relay ? pdt_srm_holder_of(pdt_drv_sched(d), gl, np, level) : 0,
                   relay ? pdt_srm_holder_of(pdt_drv_sched(d), d->rank * k + j, np, level) : 0};
    pdt_par_test_sleep("PDT_TEST_SLEEP_BEFORE_MERGE", d->rank); /* kill before a merge */
    void **msg = calloc((size_t)nm, sizeof *msg);
    size_t *lens = calloc((size_t)nm, sizeof *lens);
    pdt_status st = msg && lens ? PDT_OK : pdt_drv_nomem(d, "merge");
    for (int i = 0; i < (relay ? 2 : nm) && st == PDT_OK; i++) {
        int q = relay ? hold[i] : gl + i, from = q / k;
        if (from == d->rank) {
            msg[q - gl] = own[q % k];
            lens[q - gl] = own_len[q % k];
            own[q % k] = NULL;
            continue;
        }
        st = recv_note(d, from, TAG_MERGE + level, &msg[q - gl], &lens[q - gl], err);
    }
    srm_share_plan pl;
    if (st == PDT_OK && pdt_srm_share_plan(&d->s[j], level, &pl))
        st = shared_merge(d, level, j, &pl, msg, lens, err);
    else if (st == PDT_OK)
        st = pdt_srm_merge(&d->s[j], level, msg, lens, err);
    for (int i = 0; msg && i < nm; i++) free(msg[i]);
    free(msg);
    free(lens);
    return st;
}

/* One level of the merge tree on this rank: each of its strips whose group
 * has a partner packs its message (in strip order) and sends it to the rank
 * of the pair's merge strip, or keeps it when that strip is its own; then
 * the merges at its own merge strips. */
static pdt_status merge_level(drv *d, int level, pdt_err *err)
{
    int k = d->k, np = d->p * k;
    void *own[PDT_RANK_MAX_STRIPS] = {0};
    size_t own_len[PDT_RANK_MAX_STRIPS] = {0};
    pdt_status st = PDT_OK;
    for (int j = 0; j < k && st == PDT_OK; j++) {
        int g = d->rank * k + j, gl, gr, ge;
        if (!pdt_srm_pair_of(pdt_drv_sched(d), g, np, level, &gl, &gr, &ge)) continue;
        if (!sends(d, g, level)) continue;
        st = pdt_srm_pack(&d->s[j], level, &own[j], &own_len[j], err);
        if (st != PDT_OK || gr / k == d->rank) continue;
        st = send_note(d, gr / k, TAG_MERGE + level, own[j], own_len[j], err);
        free(own[j]);
        own[j] = NULL;
    }
    for (int j = 0; j < k && st == PDT_OK; j++) {
        int g = d->rank * k + j, gl, gr, ge;
        if (pdt_srm_pair_of(pdt_drv_sched(d), g, np, level, &gl, &gr, &ge) && gr == g)
            st = merge_at(d, level, j, gl, ge, own, own_len, err);
    }
    for (int j = 0; j < k; j++) free(own[j]);
    if (st == PDT_OK) st = maybe_help(d, level, err);
    return st;
}

/* Phase 3: the merge tree, level by level; this rank takes part in the
 * levels where one of its strips' groups has a partner. */
pdt_status pdt_drv_merge_tree(drv *d, pdt_err *err)
{
    pdt_status st = PDT_OK;
    int k = d->k, np = d->p * k;
    for (int level = 0; level < d->s[0].levels && st == PDT_OK; level++) {
        int gl, gr, ge, any = 0;
        for (int j = 0; j < k; j++)
            any |= pdt_srm_pair_of(pdt_drv_sched(d), d->rank * k + j, np, level, &gl, &gr, &ge);
        if (!any) continue;
        PDT_TRACE(d->tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_MERGE, level, 0, 0, 0);
        st = merge_level(d, level, err);
        if (st == PDT_OK) PDT_TRACE(d->tr, 1, PDT_EV_PHASE_END, PDT_PH_MERGE, level, 0, 0, 0);
    }
    for (int j = 0; j < k && st == PDT_OK; j++)
        if (d->s[j].npend)
            st = pdt_err_set(err, PDT_ERR_CHECK, "%s: %zu triangles still pending after the "
                             "last merge", d->s[j].who, d->s[j].npend);
    return st;
}

/* After the merges: the finals besides the block's (the strips' merges' and
 * those set aside) in one array, d->more. */
pdt_status pdt_drv_gather_more(drv *d)
{
    size_t n = d->nmore;
    for (int j = 0; j < d->k; j++) n += d->s[j].nmore;
    pdt_tri *all = realloc(d->more, (n + 1) * sizeof *all);
    if (!all) return pdt_drv_nomem(d, "order");
    for (int j = 0; j < d->k; j++) {
        if (d->s[j].nmore) memcpy(all + d->nmore, d->s[j].more, d->s[j].nmore * sizeof *all);
        d->nmore += d->s[j].nmore;
        free(d->s[j].more);
        d->s[j].more = NULL;
        d->s[j].nmore = d->s[j].capmore = 0;
    }
    d->more = all;
    return PDT_OK;
}

/* After the merges the strip's points and their names in the block are done
 * with: their pages go back before the order phase (which may take that room
 * again: it is the block's far end) -- 16 bytes a point of the peak. */
void pdt_drv_release_points(drv *d)
{
    if (!d->s[0].fin) return;
    unsigned char *blk = (unsigned char *)d->s[0].fin;
    size_t at = PDT_DELAUNAY_WORK(d->blk_cap);
    pdt_release_pages(blk + at, d->blk_bytes - at);
}
