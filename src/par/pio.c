/* pdt — input of a parallel run (see pdt_par_read in pdt/par.h; the output
 * is src/par/pwrite.c), and the agreement step that every collective phase
 * of the pipeline ends with. */
#include <errno.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pdt/io.h"
#include "pdt/par.h"
#include "pdt/testhook.h"

pdt_status pdt_par_agree(pdt_comm *c, pdt_status st, int *who, pdt_err *err)
{
    int p = pdt_comm_size(c), r = pdt_comm_rank(c);
    if (who) *who = st != PDT_OK ? r : -1;
    if (p == 1) return st;
    /* the largest (p - rank) * 256 + status is the lowest failing rank */
    uint64_t v = st != PDT_OK ? (uint64_t)(p - r) * 256u + (uint64_t)st : 0;
    pdt_err tmp;
    pdt_err_clear(&tmp);
    pdt_status cst = pdt_comm_allreduce_u64(c, &v, 1, PDT_COMM_MAX, st != PDT_OK ? &tmp : err);
    if (cst != PDT_OK) {
        if (who) *who = r;
        return st != PDT_OK ? st : cst;
    }
    if (v == 0) return PDT_OK;
    if (who) *who = p - (int)(v / 256);
    if (st == PDT_OK) { /* failed elsewhere: the status, no message of ours */
        err->code = (pdt_status)(v % 256);
        err->msg[0] = '\0';
    }
    return (pdt_status)(v % 256);
}

/* pdt_par_bcast_outcome's message: rank 0's status, then its bytes. */
typedef struct outcome_msg {
    int32_t status;
    unsigned char b[PDT_PAR_OUTCOME_MAX];
} outcome_msg;

pdt_status pdt_par_bcast_outcome(pdt_comm *c, pdt_status st, void *buf, size_t bytes,
                                 pdt_err *err)
{
    if (pdt_comm_size(c) == 1) return st;
    int r = pdt_comm_rank(c);
    outcome_msg m;
    if (bytes > sizeof m.b) /* (the same at every rank) */
        return pdt_err_set(err, PDT_ERR_ARG, "rank %d: broadcast of %zu bytes", r, bytes);
    m.status = (int32_t)st;
    memcpy(m.b, buf, bytes);
    pdt_err berr;
    pdt_err_clear(&berr);
    pdt_status bst = pdt_comm_bcast(c, &m, offsetof(outcome_msg, b) + bytes, 0, &berr);
    if (bst != PDT_OK) {
        if (r != 0 || st == PDT_OK) *err = berr;
        return bst;
    }
    memcpy(buf, m.b, bytes);
    st = (pdt_status)m.status;
    if (st != PDT_OK && r != 0) { /* (rank 0 has the message) */
        err->code = st;
        err->msg[0] = '\0';
    }
    return st;
}

void pdt_par_input_free(pdt_par_input *in)
{
    free(in->pts);
    memset(in, 0, sizeof *in);
}

/* Rank 0 holds all n points in *pts; every rank gets block
 * [n q / p, n (q+1) / p) in place of it. */
static pdt_status scatter_blocks(pdt_comm *c, pdt_par_input *in, pdt_err *err)
{
    int p = pdt_comm_size(c), r = pdt_comm_rank(c);
    uint64_t n = in->n_total;
    size_t *cnt = malloc((size_t)p * sizeof *cnt);
    if (!cnt) return pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: read: out of memory", r);
    for (int q = 0; q < p; q++)
        cnt[q] = (size_t)(n * (uint64_t)(q + 1) / (uint64_t)p - n * (uint64_t)q / (uint64_t)p) *
                 sizeof(pdt_point);
    size_t mine = cnt[r] / sizeof(pdt_point);
    pdt_point *b = malloc((mine + 1) * sizeof *b);
    pdt_status st = b ? PDT_OK : pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: read: out of memory", r);
    if (st == PDT_OK) st = pdt_comm_scatterv(c, in->pts, cnt, b, mine * sizeof *b, 0, err);
    free(cnt);
    if (st != PDT_OK) {
        free(b);
        return st;
    }
    free(in->pts);
    in->pts = b;
    in->n = mine;
    in->first = n * (uint64_t)r / (uint64_t)p;
    return PDT_OK;
}

/* Standard input, a pipe or a device: rank 0 reads it whole and scatters
 * the blocks. */
static pdt_status read_whole(pdt_comm *c, const char *path, double scale, int flags,
                             pdt_par_input *in, pdt_err *err)
{
    int r = pdt_comm_rank(c);
    pdt_status st = PDT_OK;
    size_t n = 0, coll = 0;
    if (r == 0) st = pdt_read_points_ex(path, scale, flags, &in->pts, &n, &coll, err);
    st = pdt_par_agree(c, st, NULL, err);
    if (st != PDT_OK) return st;
    uint64_t hdr[2] = {n, coll};
    if (pdt_comm_size(c) > 1) st = pdt_comm_bcast(c, hdr, sizeof hdr, 0, err);
    in->n = n;
    in->n_total = hdr[0];
    in->collisions = hdr[1];
    if (st == PDT_OK && pdt_comm_size(c) > 1) st = scatter_blocks(c, in, err);
    return pdt_par_agree(c, st, NULL, err);
}

/* What every rank tells the others about its part once parsed. */
typedef struct part_info {
    uint64_t n, nl, has_idx0;
    int64_t idx0;
} part_info;

/* The failure to report: the smallest err_key over the ranks (the first bad
 * line of the file, as a plain read finds it), at the lowest rank holding
 * it.  The other ranks get its status and an empty message. */
static pdt_status first_failure(pdt_comm *c, uint64_t key, pdt_status st, pdt_err *err)
{
    int r = pdt_comm_rank(c);
    uint64_t v = key;
    pdt_err tmp;
    pdt_err_clear(&tmp);
    pdt_status cst = pdt_comm_allreduce_u64(c, &v, 1, PDT_COMM_MIN, &tmp);
    if (cst == PDT_OK && v == UINT64_MAX) return PDT_OK;
    uint64_t w = cst == PDT_OK && key == v ? (uint64_t)r * 256 + (uint64_t)st : UINT64_MAX;
    if (cst == PDT_OK) cst = pdt_comm_allreduce_u64(c, &w, 1, PDT_COMM_MIN, &tmp);
    if (cst != PDT_OK) {
        pdt_err_clear(err);
        *err = tmp;
        return cst;
    }
    if ((int)(w / 256) != r) {
        pdt_err_clear(err);
        err->code = (pdt_status)(w % 256);
    }
    return (pdt_status)(w % 256);
}

/* --scale: the points that became equal to a point written differently,
 * counted over the whole file: every rank sends each of its points with
 * its coordinates as written to the rank its key hashes to. */
static pdt_status collisions_across(pdt_comm *c, const pdt_points_part *pt, uint64_t *coll,
                                    pdt_err *err)
{
    int p = pdt_comm_size(c), r = pdt_comm_rank(c);
    pdt_points_written *w = NULL, *sorted = NULL, *got = NULL;
    size_t *scnt = calloc((size_t)p, sizeof *scnt), *rcnt = calloc((size_t)p, sizeof *rcnt);
    size_t *at = calloc((size_t)p, sizeof *at);
    uint64_t *sc = calloc((size_t)p, sizeof *sc), *rc = calloc((size_t)p, sizeof *rc);
    uint64_t mine = 0, total = 0;
    pdt_status st = scnt && rcnt && at && sc && rc ? pdt_points_part_written(pt, &w, err)
                                                   : PDT_ERR_NOMEM;
    if (st == PDT_OK && !(sorted = malloc((pt->n + 1) * sizeof *sorted))) st = PDT_ERR_NOMEM;
    if (st == PDT_OK) {
        for (size_t i = 0; i < pt->n; i++)
            sc[(pdt_key(w[i].p) * 0x9E3779B97F4A7C15ull >> 32) % (uint64_t)p]++;
        for (int q = 1; q < p; q++) at[q] = at[q - 1] + (size_t)sc[q - 1];
        for (size_t i = 0; i < pt->n; i++)
            sorted[at[(pdt_key(w[i].p) * 0x9E3779B97F4A7C15ull >> 32) % (uint64_t)p]++] = w[i];
        free(w);
        w = NULL;
    }
    st = pdt_par_agree(c, st == PDT_ERR_NOMEM ? pdt_err_set(err, st, "rank %d: read: out of "
                                                            "memory", r) : st, NULL, err);
    if (st == PDT_OK) st = pdt_comm_alltoall(c, sc, sizeof *sc, rc, err);
    if (st == PDT_OK) {
        for (int q = 0; q < p; q++) {
            scnt[q] = (size_t)sc[q] * sizeof *sorted;
            rcnt[q] = (size_t)rc[q] * sizeof *sorted;
            total += rc[q];
        }
        got = malloc(((size_t)total + 1) * sizeof *got);
        st = pdt_par_agree(c, got ? PDT_OK : pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: read: "
                                                         "out of memory", r), NULL, err);
    }
    if (st == PDT_OK) st = pdt_comm_alltoallv(c, sorted, scnt, got, rcnt, err);
    if (st == PDT_OK) st = pdt_points_collisions(got, (size_t)total, &mine, err);
    if (st == PDT_OK) st = pdt_comm_allreduce_u64(c, &mine, 1, PDT_COMM_SUM, err);
    *coll = mine;
    free(w);
    free(sorted);
    free(got);
    free(scnt);
    free(rcnt);
    free(at);
    free(sc);
    free(rc);
    return st;
}

/* PDT_TEST_READ_NOMEM=R: rank R finds no room for the table of the ranks'
 * parts (tests: every rank fails the read, and none writes past its table). */
static int test_read_nomem(int r)
{
    const char *e = pdt_test_hook("PDT_TEST_READ_NOMEM");
    return e && *e && atoi(e) == r;
}

/* A regular file: every rank loads and parses its own part (pdt/io.h),
 * the line numbers from a prefix sum of the '\n' counts, the point indices
 * from a prefix sum of the point counts. */
static pdt_status read_parts(pdt_comm *c, const char *path, double scale, int flags,
                             const pdt_points_head *h, pdt_par_input *in, pdt_err *err)
{
    int p = pdt_comm_size(c), r = pdt_comm_rank(c);
    pdt_points_part pt;
    part_info *all = test_read_nomem(r) ? NULL : malloc((size_t)p * sizeof *all);
    pdt_status st = pdt_points_part_load(path, h, r, p, &pt, err), cst;
    if (!all && st == PDT_OK) {
        st = pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: read: out of memory", r);
        pt.err_key = 0;
    }
    uint64_t nl_mine = st == PDT_OK ? pt.nl + (r == 0 ? h->body_nl : 0) : 0, nl_before = 0;
    cst = pdt_comm_exscan_u64(c, nl_mine, &nl_before, err);
    if (cst != PDT_OK) goto done;
    if (st == PDT_OK)
        st = pdt_points_part_parse(&pt, path, h, scale,
                                   1 + nl_before + (r == 0 ? h->body_nl : 0), flags, err);
    part_info me = {pt.n, nl_mine, (uint64_t)pt.has_idx0, pt.idx0};
    /* the allgather writes p entries at every rank: a rank without the room
     * for them stops every rank before it (its message, the others' status) */
    cst = pdt_par_agree(c, all ? PDT_OK : st, NULL, err); /* (st fails without all) */
    if (cst == PDT_OK) cst = pdt_comm_allgather(c, &me, sizeof me, all, err);
    if (cst != PDT_OK) goto done;
    uint64_t first = 0, total = 0, nl = 0;
    int64_t base = 0;
    int based = 0;
    for (int q = 0; q < p; q++) {
        if (q < r) first += all[q].n;
        total += all[q].n;
        nl += all[q].nl;
        if (!based && all[q].has_idx0) {
            base = all[q].idx0;
            based = 1;
        }
    }
    if (pt.err_key != 0)
        st = pdt_points_part_check(&pt, path, h, first, total, base, r == p - 1,
                                   nl + (h->last_nl ? 0 : 1), err);
    st = first_failure(c, pt.err_key, st, err);
    if (st == PDT_OK && scale > 0) st = collisions_across(c, &pt, &in->collisions, err);
    if (st == PDT_OK) {
        in->pts = pt.pts;
        pt.pts = NULL;
        in->n = pt.n;
        in->first = first;
        in->n_total = total;
    }
done:
    if (cst != PDT_OK) st = cst;
    free(all);
    pdt_points_part_free(&pt);
    return st;
}
pdt_status pdt_par_read(pdt_comm *c, const char *path, double scale, int prefault,
                        pdt_par_input *in, pdt_err *err)
{
    int flags = prefault ? PDT_READ_PREFAULT : 0;
    memset(in, 0, sizeof *in);
    pdt_points_head h;
    memset(&h, 0, sizeof h);
    pdt_status st = PDT_OK;
    if (pdt_comm_size(c) > 1) { /* rank 0 reads the head */
        if (pdt_comm_rank(c) == 0) st = pdt_points_head_read(path, scale, &h, err);
        st = pdt_par_bcast_outcome(c, st, &h, sizeof h, err);
    }
    if (st == PDT_OK)
        st = h.parts ? read_parts(c, path, scale, flags, &h, in, err)
                     : read_whole(c, path, scale, flags, in, err);
    if (st != PDT_OK) pdt_par_input_free(in);
    return st;
}
