/* pdt — the output of a parallel run (pdt_par_write in pdt/par.h).
 *
 * A file is a header and one or two sections (.off: the points, then the
 * triangles); every rank holds a consecutive block of each section (its
 * input block of points, its block of the canonical triangles).  Each rank
 * counts its bytes, a prefix sum gives its offset, and it formats its block
 * with the plain writer's own printer (pdt_format_lines) a piece at a time
 * and writes each piece at its place (pdt_comm_file_write_at: MPI-IO).
 * Everything goes to temporaries rank 0 creates by the rule of
 * pdt/safefile.h, put in place by rank 0 once every rank succeeded (an .ele
 * and its .node together), removed otherwise.  Standard output, a device or a pipe cannot be
 * written at offsets: the blocks are gathered at rank 0 and written there. */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "pdt/io.h"
#include "pdt/par.h"
#include "pdt/safefile.h"

#include "pdt/bigmem.h"
#include "pdt/testhook.h"

/* Bytes formatted at once (then written): 4 MiB of the longest lines. */
enum { PIECE_LINES = 65536 };

/* One section of a file: this rank's block of lines. */
typedef struct section {
    pdt_lines kind;
    const void *items;
    size_t elem, n;
    uint64_t first;   /* number of this block's first line (.ele, .node) */
    int release;      /* give the items' pages back once printed */
} section;

/* One file: its final name, its temporary, its header, its sections. */
typedef struct outfile {
    const char *path;
    char tmp[4096];
    char head[256];
    size_t hlen;
    section sec[2];
    int nsec;
} outfile;

/* ---- gathering at rank 0 (standard output, devices, pipes) ---------------------- */

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

static pdt_status write_gathered(pdt_comm *c, const char *path, pdt_tri_format fmt,
                                 const pdt_par_input *in, const pdt_par_output *out,
                                 pdt_pending_write *defer, pdt_err *err)
{
    void *pts = NULL, *tris = NULL;
    uint64_t np = 0, nt = 0;
    pdt_status st = PDT_OK;
    if (fmt != PDT_FMT_TRI) st = gather_all(c, in->pts, in->n, sizeof(pdt_point), &pts, &np, err);
    if (st == PDT_OK) st = gather_all(c, out->tris, out->ntri, sizeof(pdt_tri), &tris, &nt, err);
    if (st == PDT_OK && pdt_comm_rank(c) == 0)
        st = defer ? pdt_write_tris_deferred(path, fmt, pts, (size_t)np, tris, (size_t)nt, 0,
                                             defer, err)
                   : pdt_write_tris(path, fmt, pts, (size_t)np, tris, (size_t)nt, err);
    free(pts);
    free(tris);
    return pdt_par_agree(c, st, NULL, err);
}

/* ---- every rank at its offset ------------------------------------------------ */

/* The temporaries this rank's write has named and not yet seen renamed: what
 * pdt_par_write_abandon removes (from a signal handler: a fixed array, a
 * count that is set after the name is complete). */
static char pending[2][4096];
static volatile sig_atomic_t npending;

void pdt_par_test_sleep(const char *var, int rank)
{
    const char *e = pdt_test_hook(var);
    int r;
    double sec;
    if (!e || sscanf(e, "%d:%lf", &r, &sec) != 2 || r != rank || !(sec > 0)) return;
    const char *m = pdt_test_hook("PDT_TEST_MARK");
    if (m && *m) {
        int fd = open(m, O_WRONLY | O_CREAT, 0644);
        if (fd >= 0) close(fd);
    }
    struct timespec ts = {(time_t)sec, (long)((sec - (double)(time_t)sec) * 1e9)};
    nanosleep(&ts, NULL);
}

void pdt_par_write_abandon(void)
{
    for (int k = 0; k < npending && k < 2; k++) unlink(pending[k]);
}

/* Test-only: PDT_TEST_FAIL_WRITE=RANK makes RANK fail its share of the
 * parallel write (after the temporary file exists), as a full disk would. */
static pdt_status test_fail_write(int rank, const char *path, pdt_err *err)
{
    const char *e = pdt_test_hook("PDT_TEST_FAIL_WRITE");
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

/* The temporary could not be created: name the user's file and why. */
static pdt_status cannot_create(const char *path, pdt_err *err)
{
    struct stat sb;
    const char *slash = strrchr(path, '/');
    char dir[4096];
    pdt_err_clear(err);
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) : 1, slash ? path : ".");
    return pdt_err_set(err, PDT_ERR_IO, "%s: cannot create: %s", path,
                       stat(dir, &sb) != 0 ? "no such folder" : "cannot create a file there");
}

/* This rank's block of section s, formatted a piece at a time, written from
 * byte `at` of f.  Returns this rank's status (message in err). */
static pdt_status write_section(pdt_comm_file *f, const section *s, uint64_t at, char *buf,
                                pdt_err *err)
{
    pdt_status st = PDT_OK;
    for (size_t i = 0; i < s->n && st == PDT_OK; i += PIECE_LINES) {
        size_t k = s->n - i < PIECE_LINES ? s->n - i : PIECE_LINES;
        size_t len = pdt_format_lines(buf, s->kind, (const char *)s->items + i * s->elem, k,
                                      s->first + i);
        if (s->release) pdt_big_release_front((void *)(uintptr_t)s->items, i * s->elem,
                                              (i + k) * s->elem);
        st = pdt_comm_file_write_at(f, at, buf, len, err);
        at += len;
    }
    return st;
}

/* Collective: write o's temporary; with `commit` (the last file of a run
 * that puts its files in place now), the commit point's stop question is
 * asked in the close's agreement.  Every rank gets the same status; the
 * temporary may be left behind on failure (the caller removes it). */
static pdt_status write_file(pdt_comm *c, outfile *o, const char *commit, pdt_err *err)
{
    int r = pdt_comm_rank(c);
    uint64_t len[2] = {0, 0}, off[2] = {0, 0}, tot[2] = {0, 0};
    for (int k = 0; k < o->nsec; k++) {
        const section *s = &o->sec[k];
        len[k] = tot[k] = pdt_lines_bytes(s->kind, s->items, s->n, s->first);
    }
    pdt_status st = PDT_OK;
    for (int k = 0; k < o->nsec && st == PDT_OK; k++)
        st = pdt_comm_exscan_u64(c, len[k], &off[k], err);
    if (st == PDT_OK) st = pdt_comm_allreduce_u64(c, tot, (size_t)o->nsec, PDT_COMM_SUM, err);
    if (st != PDT_OK) return st;
    pdt_comm_file *f = NULL;
    st = pdt_comm_file_open(c, o->tmp, o->hlen + tot[0] + tot[1], &f, err);
    if (st != PDT_OK) { /* name the user's file, not our temporary */
        if (r == 0) cannot_create(o->path, err);
        return pdt_par_agree(c, r == 0 ? PDT_ERR_IO : PDT_OK, NULL, err);
    }
    pdt_par_test_sleep("PDT_TEST_SLEEP_IN_WRITE", r); /* kill a rank mid-write */
    pdt_err werr;
    pdt_err_clear(&werr);
    pdt_status wst = test_fail_write(r, o->path, &werr);
    char *buf = NULL;
    if (wst == PDT_OK && !(buf = malloc((size_t)PIECE_LINES * PDT_LINE_MAX)))
        wst = pdt_err_set(&werr, PDT_ERR_NOMEM, "rank %d: write: out of memory", r);
    if (wst == PDT_OK && r == 0 && o->hlen)
        wst = pdt_comm_file_write_at(f, 0, o->head, o->hlen, &werr);
    uint64_t at = o->hlen;
    for (int k = 0; k < o->nsec && wst == PDT_OK; k++) {
        wst = write_section(f, &o->sec[k], at + off[k], buf, &werr);
        at += tot[k];
    }
    free(buf);
    if (wst != PDT_OK) pdt_comm_file_failed(f, &werr); /* (for the close to tell the others) */
    pdt_err cerr;
    pdt_err_clear(&cerr);
    /* collective: agrees on the writes (and the stop question) */
    pdt_status cst = pdt_comm_file_close_commit(c, f, commit, &cerr);
    if (wst != PDT_OK) {
        *err = werr;
        cst = wst;
    } else if (cst != PDT_OK) {
        *err = cerr;
    }
    return cst;
}

/* What rank 0 decides for every rank before a write: whether the files go
 * in place at offsets, the temporaries' names. */
typedef struct temps_msg {
    int32_t direct;
    char tmp[2][4096];
} temps_msg;

/* Rank 0 decides whether the files are written at offsets (a regular file
 * or no file yet, under a name of reasonable length; else they are gathered
 * and written at rank 0) and if so creates their temporaries by the rule of
 * pdt/safefile.h (O_EXCL|O_NOFOLLOW beside each target, its mode and owner;
 * a read-only target refused).  One broadcast takes its answer, its status
 * and the names (into o[k].tmp) to every rank (pdt_par_bcast_outcome). */
static pdt_status make_temps(pdt_comm *c, outfile *o, int n, pdt_safe_file *sf, int *direct,
                             pdt_err *err)
{
    int r = pdt_comm_rank(c);
    temps_msg m;
    memset(&m, 0, sizeof m);
    pdt_status st = PDT_OK;
    if (r == 0) {
        m.direct = renamable(o[0].path) && strlen(o[0].path) < 3000;
        for (int k = 0; k < n && m.direct; k++) {
            sf[k].fd = -1;
            sf[k].tmp = NULL;
            if (st == PDT_OK) st = pdt_safe_open(&sf[k], o[k].path, 0, err);
            if (st == PDT_OK && strlen(sf[k].tmp) >= sizeof m.tmp[k])
                st = pdt_err_set(err, PDT_ERR_IO, "%s: name too long", o[k].path);
            if (st == PDT_OK) snprintf(m.tmp[k], sizeof m.tmp[k], "%s", sf[k].tmp);
        }
    }
    st = pdt_par_bcast_outcome(c, st, &m, offsetof(temps_msg, tmp) + (size_t)n * sizeof m.tmp[0],
                               err);
    if (st != PDT_OK && r == 0)
        for (int k = 0; k < n && m.direct; k++) /* (the temporaries made) */
            if (sf[k].name) pdt_safe_abort(&sf[k]);
    *direct = m.direct;
    for (int k = 0; k < n && st == PDT_OK; k++) memcpy(o[k].tmp, m.tmp[k], sizeof o[k].tmp);
    return st;
}

/* Collective: the files (one, or an .ele and its .node), whose temporaries
 * make_temps created, written in parallel and put in place by rank 0
 * together (both or neither: pdt_safe_commit_group). */
static pdt_status write_files(pdt_comm *c, outfile *o, int nfile, pdt_safe_file *sf,
                              pdt_pending_write *defer, pdt_err *err)
{
    int r = pdt_comm_rank(c);
    pdt_status st = PDT_OK;
    for (int k = 0; k < nfile; k++)
        if (pdt_comm_is_mpi(c)) { /* (one process per rank: the list is this rank's) */
            memcpy(pending[k], o[k].tmp, sizeof pending[k]);
            npending = k + 1;
        }
    for (int k = 0; k < nfile && st == PDT_OK; k++) /* (not if stopped: the last close asks) */
        st = write_file(c, &o[k], k == nfile - 1 && !defer ? o[0].path : NULL, err);
    if (r == 0) {
        if (st == PDT_OK && defer) {
            for (int k = 0; k < nfile; k++) defer->f[k] = sf[k];
            defer->n = nfile;
            return pdt_par_agree(c, st, NULL, err); /* (the list stays until the commit) */
        } else if (st == PDT_OK) {
            st = pdt_safe_commit_group(sf, nfile, err);
        } else {
            for (int k = 0; k < nfile; k++) pdt_safe_abort(&sf[k]);
        }
    }
    if (pdt_comm_is_mpi(c)) npending = 0;
    return pdt_par_agree(c, st, NULL, err);
}

/* "X.ele" -> "X.node" into buf. */
static void node_path(char *buf, size_t size, const char *ele)
{
    size_t n = strlen(ele);
    snprintf(buf, size, "%.*s.node", (int)(n >= 4 ? n - 4 : n), ele);
}

pdt_status pdt_par_write(pdt_comm *c, const char *path, pdt_tri_format fmt,
                         const pdt_par_input *in, const pdt_par_output *out, pdt_err *err)
{
    return pdt_par_write_deferred(c, path, fmt, in, out, NULL, err);
}

pdt_status pdt_par_write_deferred(pdt_comm *c, const char *path, pdt_tri_format fmt,
                                  const pdt_par_input *in, const pdt_par_output *out,
                                  pdt_pending_write *defer, pdt_err *err)
{
    if (defer) defer->n = 0;
    if (pdt_comm_size(c) == 1)
        return defer ? pdt_write_tris_deferred(path, fmt, in->pts, in->n, out->tris, out->ntri,
                                               out->release_tris, defer, err)
               : out->release_tris
                   ? pdt_write_tris_releasing(path, fmt, in->pts, in->n, out->tris, out->ntri, err)
                   : pdt_write_tris(path, fmt, in->pts, in->n, out->tris, out->ntri, err);
    outfile o[2];
    memset(o, 0, sizeof o);
    char npath[4096];
    const section tris = {fmt == PDT_FMT_ELE   ? PDT_LINES_ELE
                          : fmt == PDT_FMT_OFF ? PDT_LINES_OFF_TRI
                                               : PDT_LINES_TRI,
                          out->tris, sizeof(pdt_tri), out->ntri, out->first,
                          out->release_tris};
    int nfile = 1;
    o[0].path = path;
    o[0].hlen = pdt_format_tri_header(o[0].head, fmt, in->n_total, out->n_total);
    if (fmt == PDT_FMT_OFF)
        o[0].sec[o[0].nsec++] = (section){PDT_LINES_OFF_POINT, in->pts, sizeof(pdt_point), in->n,
                                          in->first, 0};
    o[0].sec[o[0].nsec++] = tris;
    if (fmt == PDT_FMT_ELE) {
        node_path(npath, sizeof npath, path);
        o[1].path = npath;
        o[1].hlen = pdt_format_node_header(o[1].head, in->n_total);
        o[1].sec[o[1].nsec++] = (section){PDT_LINES_NODE, in->pts, sizeof(pdt_point), in->n,
                                          in->first, 0};
        nfile = 2;
    }
    pdt_safe_file sf[2];
    memset(sf, 0, sizeof sf);
    int direct = 0;
    pdt_status st = make_temps(c, o, nfile, sf, &direct, err);
    if (st != PDT_OK) return st;
    if (!direct) return write_gathered(c, path, fmt, in, out, defer, err);
    return write_files(c, o, nfile, sf, defer, err);
}
