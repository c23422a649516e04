/* pdt — input and output of a parallel run (see pdt_par_read, pdt_par_write
 * in pdt/par.h), and the agreement step that every collective phase of the
 * pipeline ends with. */
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
    double v = st != PDT_OK ? (double)(p - r) * 256.0 + (double)st : 0.0;
    pdt_err tmp;
    pdt_err_clear(&tmp);
    pdt_status cst = pdt_comm_allmax(c, &v, 1, st != PDT_OK ? &tmp : err);
    if (cst != PDT_OK) {
        if (who) *who = r;
        return st != PDT_OK ? st : cst;
    }
    if (v == 0.0) return PDT_OK;
    long k = (long)v;
    if (who) *who = p - (int)(k / 256);
    if (st == PDT_OK) { /* failed elsewhere: the status, no message of ours */
        err->code = (pdt_status)(k % 256);
        err->msg[0] = '\0';
    }
    return (pdt_status)(k % 256);
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

/* Gather every rank's block (elem bytes each, n elements here) at rank 0. */
static pdt_status gather_all(pdt_comm *c, const void *mine, size_t n, size_t elem,
                             void **all, uint64_t *total, pdt_err *err)
{
    int p = pdt_comm_size(c), r = pdt_comm_rank(c);
    uint64_t k = n, *ks = malloc((size_t)p * sizeof *ks);
    size_t *cnt = malloc((size_t)p * sizeof *cnt);
    *all = NULL;
    *total = 0;
    pdt_status st = ks && cnt ? PDT_OK
                              : pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: write: out of memory", r);
    if (st == PDT_OK) st = pdt_comm_allgather(c, &k, sizeof k, ks, err);
    if (st == PDT_OK) {
        for (int q = 0; q < p; q++) {
            cnt[q] = (size_t)ks[q] * elem;
            *total += ks[q];
        }
        if (r == 0 && !(*all = malloc((size_t)*total * elem + 1)))
            st = pdt_err_set(err, PDT_ERR_NOMEM, "rank 0: write: out of memory");
    }
    if (st == PDT_OK) st = pdt_comm_gatherv(c, mine, n * elem, *all, cnt, 0, err);
    free(ks);
    free(cnt);
    return st;
}

/* ---- the .tri file written by every rank at its offset ------------------------ */

static char *put_u32(char *p, uint32_t v)
{
    char t[12];
    int k = 0;
    do {
        t[k++] = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    while (k) *p++ = t[--k];
    return p;
}

/* This rank's triangles as .tri lines ("i j k\n"); *buf malloc'd. */
static pdt_status format_tri(const pdt_par_output *out, int rank, char **buf, size_t *len,
                             pdt_err *err)
{
    char *b = malloc(out->ntri * 33 + 1), *p = b;
    if (!b) return pdt_err_set(err, PDT_ERR_NOMEM, "rank %d: write: out of memory", rank);
    for (size_t i = 0; i < out->ntri; i++) {
        p = put_u32(p, out->tris[i].v[0]);
        *p++ = ' ';
        p = put_u32(p, out->tris[i].v[1]);
        *p++ = ' ';
        p = put_u32(p, out->tris[i].v[2]);
        *p++ = '\n';
    }
    *buf = b;
    *len = (size_t)(p - b);
    return PDT_OK;
}

/* Test-only: PDT_TEST_FAIL_WRITE=RANK makes RANK fail its share of the
 * parallel write (after the temporary file exists), as a full disk would. */
static pdt_status test_fail_write(int rank, const char *path, pdt_err *err)
{
    const char *e = getenv("PDT_TEST_FAIL_WRITE");
    if (e && *e && atoi(e) == rank)
        return pdt_err_set(err, PDT_ERR_IO, "%s: write error: injected by PDT_TEST_FAIL_WRITE",
                           path);
    return PDT_OK;
}

/* 1 if `path` can be replaced by a renamed temporary (a regular file or no
 * file yet), 0 for standard output, a device or a pipe. */
static int renamable(const char *path)
{
    struct stat sb;
    if (!path || strcmp(path, "-") == 0) return 0;
    return stat(path, &sb) != 0 || S_ISREG(sb.st_mode);
}

/* Every rank writes its lines at the prefix sum of the byte counts into
 * "DIR/.BASE.tmp.PID" (rank 0's pid), renamed by rank 0 once every rank
 * succeeded, removed by rank 0 otherwise. */
static pdt_status write_tri_parallel(pdt_comm *c, const char *path, const pdt_par_output *out,
                                     pdt_err *err)
{
    int r = pdt_comm_rank(c);
    char tmp[4096];
    memset(tmp, 0, sizeof tmp);
    if (r == 0) {
        const char *slash = strrchr(path, '/');
        int dl = slash ? (int)(slash - path + 1) : 0;
        snprintf(tmp, sizeof tmp, "%.*s.%s.tmp.%ld", dl, path, slash ? slash + 1 : path,
                 (long)getpid());
    }
    pdt_status st = pdt_comm_bcast(c, tmp, sizeof tmp, 0, err);
    if (st != PDT_OK) return st;
    char *buf = NULL;
    size_t len = 0;
    uint64_t off = 0;
    st = pdt_par_agree(c, format_tri(out, r, &buf, &len, err), NULL, err);
    if (st == PDT_OK) st = pdt_comm_exscan_u64(c, len, &off, err);
    if (st != PDT_OK) {
        free(buf);
        return st;
    }
    pdt_comm_file *f = NULL;
    st = pdt_comm_file_open(c, tmp, &f, err);
    if (st != PDT_OK) { /* name the user's file, not our temporary */
        free(buf);
        if (r == 0) {
            struct stat sb;
            pdt_err_clear(err);
            const char *slash = strrchr(path, '/');
            char dir[4096];
            snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) : 1,
                     slash ? path : ".");
            pdt_err_set(err, PDT_ERR_IO, "%s: cannot create: %s", path,
                        stat(dir, &sb) != 0 ? "no such folder" : "cannot create a file there");
        }
        return pdt_par_agree(c, r == 0 ? PDT_ERR_IO : PDT_OK, NULL, err);
    }
    pdt_status wst = test_fail_write(r, path, err);
    pdt_err werr;
    pdt_err_clear(&werr);
    pdt_status cst = pdt_comm_file_write_at(f, off, buf, wst == PDT_OK ? len : 0, &werr);
    if (wst == PDT_OK && cst != PDT_OK) {
        wst = cst;
        *err = werr;
    }
    free(buf);
    cst = pdt_comm_file_close(f, &werr);
    if (wst == PDT_OK && cst != PDT_OK) {
        wst = cst;
        *err = werr;
    }
    st = pdt_par_agree(c, wst, NULL, err);
    if (st != PDT_OK) {
        if (r == 0) unlink(tmp);
        return st;
    }
    if (r == 0 && rename(tmp, path) != 0) {
        st = pdt_err_set(err, PDT_ERR_IO, "%s: cannot rename into place: %s", path,
                         strerror(errno));
        unlink(tmp);
    }
    return pdt_par_agree(c, st, NULL, err);
}

pdt_status pdt_par_write(pdt_comm *c, const char *path, pdt_tri_format fmt,
                         const pdt_par_input *in, const pdt_par_output *out, pdt_err *err)
{
    if (pdt_comm_size(c) == 1)
        return pdt_write_tris(path, fmt, in->pts, in->n, out->tris, out->ntri, err);
    int r = pdt_comm_rank(c);
    int direct = fmt == PDT_FMT_TRI && renamable(path);
    if (pdt_par_agree(c, direct ? PDT_OK : PDT_ERR_ARG, NULL, err) == PDT_OK)
        return write_tri_parallel(c, path, out, err);
    void *pts = NULL, *tris = NULL;
    uint64_t np = 0, nt = 0;
    pdt_status st = PDT_OK;
    if (fmt != PDT_FMT_TRI) st = gather_all(c, in->pts, in->n, sizeof(pdt_point), &pts, &np, err);
    if (st == PDT_OK) st = gather_all(c, out->tris, out->ntri, sizeof(pdt_tri), &tris, &nt, err);
    if (st == PDT_OK && r == 0)
        st = pdt_write_tris(path, fmt, pts, (size_t)np, tris, (size_t)nt, err);
    free(pts);
    free(tris);
    return pdt_par_agree(c, st, NULL, err);
}
