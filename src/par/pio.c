/* pdt — input of a parallel run (see pdt_par_read in pdt/par.h; the output
 * is src/par/pwrite.c), and the agreement step that every collective phase
 * of the pipeline ends with. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pdt/io.h"
#include "pdt/par.h"

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

pdt_status pdt_par_read(pdt_comm *c, const char *path, double scale, pdt_par_input *in,
                        pdt_err *err)
{
    memset(in, 0, sizeof *in);
    int r = pdt_comm_rank(c);
    pdt_status st = PDT_OK;
    size_t n = 0, coll = 0;
    if (r == 0) st = pdt_read_points(path, scale, &in->pts, &n, &coll, err);
    st = pdt_par_agree(c, st, NULL, err);
    if (st != PDT_OK) {
        pdt_par_input_free(in);
        return st;
    }
    uint64_t hdr[2] = {n, coll};
    if (pdt_comm_size(c) > 1) st = pdt_comm_bcast(c, hdr, sizeof hdr, 0, err);
    in->n = n;
    in->n_total = hdr[0];
    in->collisions = hdr[1];
    if (st == PDT_OK && pdt_comm_size(c) > 1) st = scatter_blocks(c, in, err);
    st = pdt_par_agree(c, st, NULL, err);
    if (st != PDT_OK) pdt_par_input_free(in);
    return st;
}
