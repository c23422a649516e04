/* pdt — tracing of a command run (run_opts.h): the run folder of
 * docs/trace-format.md, one rank file per rank, written through the trace
 * writer; points.bin by every rank at its place (no rank holds the whole
 * input; the checksums of the blocks are combined at rank 0), the manifest
 * by rank 0. */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pdt/io.h"
#include "pdt/safefile.h"
#include "pdt/par.h"
#include "pdt/tracefile.h"
#include "pdt/testhook.h"
#include "run_opts.h"

struct pdt_cli_trace {
    pdt_trace_writer *w;
    int64_t *offsets; /* clock offsets of the ranks (rank 0's matter) */
    int nranks;
    pdt_safe_dir dir; /* rank 0: the run folder, written whole beside it */
    char wdir[4096];  /* the folder every rank writes into (dir.tmp) */
    const char *shown; /* the user's name of the folder (messages) */
};

/* The command line as one string, arguments separated by spaces. */
static char *join_args(int argc, char **argv)
{
    size_t len = 1;
    for (int i = 0; i < argc; i++) len += strlen(argv[i]) + 1;
    char *s = malloc(len), *p = s;
    if (!s) return NULL;
    for (int i = 0; i < argc; i++) {
        size_t k = strlen(argv[i]);
        if (i) *p++ = ' ';
        memcpy(p, argv[i], k);
        p += k;
    }
    *p = '\0';
    return s;
}

/* Refuse what cannot be traced (no error: PDT_OK). */
static pdt_status traceable(const pdt_run_opts *o, pdt_err *err)
{
#ifdef PDT_NO_TRACE
    return pdt_err_set(err, PDT_ERR_ARG, "--trace %s: this pdt was built with TRACE=0 (tracing "
                       "compiled out); rebuild with make TRACE=1", o->trace_dir);
#endif
    if (o->trace_level < 1)
        return pdt_err_set(err, PDT_ERR_ARG, "--trace %s with --trace-level 0: nothing would "
                           "be recorded (use level 1 or 2)", o->trace_dir);
    return PDT_OK;
}

/* The manifest of a run of o->command on n points (checksum: the CRC-64 of
 * their points.bin bytes) over p ranks, into *m (free m->command_line). */
static pdt_status fill_manifest(const pdt_run_opts *o, int p, const int64_t *offsets,
                                uint64_t checksum, uint64_t n, pdt_manifest *m, pdt_err *err)
{
    memset(m, 0, sizeof *m);
    m->format_version = PDT_TRACE_FORMAT_MAJOR;
    strncpy(m->program_version, PDT_VERSION, sizeof m->program_version - 1);
    strncpy(m->command, o->command, sizeof m->command - 1);
    m->command_line = join_args(o->argc, o->argv);
    m->input_name = (char *)(o->input ? o->input : "-");
    m->input_checksum = checksum;
    m->input_checksum_kind = PDT_CHECKSUM_CRC64;
    m->n = n;
    m->nranks = p;
    m->level = o->trace_level;
    pdt_par_partition part = o->partition == PDT_PART_AUTO ? pdt_par_partition_for(p)
                                                           : (pdt_par_partition)o->partition;
    m->partition = p > 1 && part == PDT_PART_BISECT; /* (one rank: no regions) */
    m->clock_offset_ns = (int64_t *)offsets;
    m->wall_start_ns = pdt_wall_ns();
    return m->command_line ? PDT_OK : pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
}

/* A one-process run (pdt hull): points.bin and the manifest, by this process. */
static pdt_status write_manifest(const pdt_run_opts *o, const char *dir, const pdt_point *pts,
                                 size_t n, pdt_err *err)
{
    pdt_manifest m;
    int64_t offset0 = 0;
    pdt_status st = fill_manifest(o, 1, &offset0, pdt_points_checksum(pts, n), n, &m, err);
    if (st == PDT_OK) st = pdt_run_write_meta(dir, &m, pts, n, err);
    free(m.command_line);
    return st;
}

/* An input is never an output: --trace DIR replaces the whole of DIR, so
 * the input, -o and an .ele's .node must not lie inside it. */
static pdt_status check_inputs(const pdt_run_opts *o, pdt_err *err)
{
    const char *dir = o->trace_dir;
    if (o->input && strcmp(o->input, "-") && pdt_safe_inside(o->input, dir))
        return pdt_err_set(err, PDT_ERR_ARG, "%s: the input is inside the run folder %s that "
                           "--trace replaces; choose another --trace folder; nothing written",
                           o->input, dir);
    if (o->output && strcmp(o->output, "-") && pdt_safe_inside(o->output, dir))
        return pdt_err_set(err, PDT_ERR_ARG, "%s: the output is inside the run folder %s that "
                           "--trace replaces; choose another -o name; nothing written",
                           o->output, dir);
    size_t len = o->output ? strlen(o->output) : 0;
    if (len > 4 && !strcmp(o->output + len - 4, ".ele")) {
        char node[4096];
        snprintf(node, sizeof node, "%.*s.node", (int)(len - 4), o->output);
        if (pdt_safe_inside(node, dir))
            return pdt_err_set(err, PDT_ERR_ARG, "%s: the .node of -o %s is inside the run "
                               "folder %s that --trace replaces; nothing written", node,
                               o->output, dir);
    }
    return PDT_OK;
}

/* Rank 0: check the options, then the temporary run folder beside DIR. */
static pdt_status open_folder(const pdt_run_opts *o, pdt_cli_trace *ct, pdt_err *err)
{
    pdt_status st = traceable(o, err);
    ct->shown = o->trace_dir;
    if (st == PDT_OK) st = check_inputs(o, err);
    if (st == PDT_OK) st = pdt_safe_dir_open(&ct->dir, o->trace_dir, err);
    if (st == PDT_OK && strlen(ct->dir.tmp) >= sizeof ct->wdir) {
        pdt_safe_dir_abort(&ct->dir);
        st = pdt_err_set(err, PDT_ERR_ARG, "%s: name too long", o->trace_dir);
    }
    if (st == PDT_OK) snprintf(ct->wdir, sizeof ct->wdir, "%s", ct->dir.tmp);
    return st;
}

pdt_status pdt_cli_trace_open(const pdt_run_opts *o, const pdt_point *pts, size_t n,
                              pdt_cli_trace **t, pdt_err *err)
{
    *t = NULL;
    if (!o->trace_dir) return PDT_OK;
    pdt_cli_trace *ct = calloc(1, sizeof *ct);
    if (!ct) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    pdt_status st = open_folder(o, ct, err);
    if (st == PDT_OK) st = pdt_tw_open(ct->wdir, 0, o->trace_level, &ct->w, err);
    /* the manifest first, so that a killed run still leaves a complete folder */
    if (st == PDT_OK) st = write_manifest(o, ct->wdir, pts, n, err);
    if (st != PDT_OK) {
        pdt_cli_trace_finish(ct, 0);
        return st;
    }
    PDT_TRACE(pdt_tw_hook(ct->w), 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    *t = ct;
    return PDT_OK;
}

enum { TAG_CLOCK = 9, CLOCK_ROUNDS = 8 };

/* Clock offsets by ping-pong with rank 0 (the round with the smallest round
 * trip wins): off[q] is what to add to rank q's clock to get rank 0's.
 * off (size p) matters at rank 0 only. */
static pdt_status clock_offsets(pdt_comm *c, const pdt_trace_writer *w, int64_t *off,
                                pdt_err *err)
{
    int r = pdt_comm_rank(c), p = pdt_comm_size(c);
    pdt_status st = PDT_OK;
    off[0] = 0;
    for (int q = 1; q < p && st == PDT_OK; q++) {
        if (r != 0 && r != q) continue;
        int64_t best = INT64_MAX;
        for (int k = 0; k < CLOCK_ROUNDS && st == PDT_OK; k++) {
            void *buf = NULL;
            size_t len = 0;
            if (r == 0) {
                int64_t t0 = (int64_t)pdt_tw_now(w), tq;
                st = pdt_comm_send(c, q, TAG_CLOCK, &t0, sizeof t0, err);
                if (st == PDT_OK) st = pdt_comm_recv(c, q, TAG_CLOCK, &buf, &len, err);
                int64_t t1 = (int64_t)pdt_tw_now(w);
                if (st == PDT_OK && len == sizeof tq) {
                    memcpy(&tq, buf, sizeof tq);
                    if (t1 - t0 < best) {
                        best = t1 - t0;
                        off[q] = t0 + (t1 - t0) / 2 - tq;
                    }
                }
            } else {
                st = pdt_comm_recv(c, 0, TAG_CLOCK, &buf, &len, err);
                int64_t t = (int64_t)pdt_tw_now(w);
                if (st == PDT_OK) st = pdt_comm_send(c, 0, TAG_CLOCK, &t, sizeof t, err);
            }
            free(buf);
        }
    }
    return st;
}

/* The simulated clock in nanoseconds (SMPI: user is the pdt_comm). */
static uint64_t simulated_ns(void *user)
{
    return (uint64_t)(pdt_comm_wtime(user) * 1e9);
}

pdt_status pdt_cli_trace_open_ranks(const pdt_run_opts *o, pdt_comm *c, pdt_cli_trace **t,
                                    pdt_err *err)
{
    *t = NULL;
    if (!o->trace_dir) return PDT_OK;
    int r = pdt_comm_rank(c), p = pdt_comm_size(c);
    pdt_cli_trace *ct = calloc(1, sizeof *ct);
    int64_t *off = calloc((size_t)p, sizeof *off);
    pdt_status st = ct && off ? PDT_OK : pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    /* rank 0 makes the temporary folder; every rank writes into it */
    if (st == PDT_OK && r == 0) st = open_folder(o, ct, err);
    st = pdt_par_agree(c, st, NULL, err);
    if (st == PDT_OK) st = pdt_comm_bcast(c, ct->wdir, sizeof ct->wdir, 0, err);
    if (ct) ct->shown = o->trace_dir;
    if (st == PDT_OK) st = pdt_tw_open(ct->wdir, r, o->trace_level, &ct->w, err);
    st = pdt_par_agree(c, st, NULL, err);
    if (st == PDT_OK && pdt_comm_is_simulated(c)) pdt_tw_set_clock(ct->w, simulated_ns, c);
    if (st == PDT_OK && p > 1) st = clock_offsets(c, ct->w, off, err);
    st = pdt_par_agree(c, st, NULL, err);
    if (ct) ct->offsets = off;
    if (st != PDT_OK) {
        if (ct) pdt_cli_trace_finish(ct, 0);
        else free(off);
        return st;
    }
    ct->nranks = p;
    PDT_TRACE(pdt_tw_hook(ct->w), 1, PDT_EV_PHASE_BEGIN, PDT_PH_RUN, 0, 0, 0, 0);
    *t = ct;
    return PDT_OK;
}

/* ---- points.bin written by every rank ------------------------------------------- */

enum { POINTS_PIECE = 65536 }; /* points encoded and written at once (512 KiB) */

/* What a rank tells rank 0 about its block of points.bin. */
typedef struct block_sums {
    uint64_t bytes;  /* 8 * points */
    uint64_t crc64;  /* CRC-64/XZ of the block's bytes */
    uint64_t crc32c; /* CRC-32C of the same bytes (in the low 32 bits) */
} block_sums;

/* Test-only: PDT_TEST_FAIL_TRACE_POINTS=RANK makes RANK fail its block of
 * points.bin (after the temporary exists), as a full disk would. */
static pdt_status test_fail_points(int rank, const char *path, pdt_err *err)
{
    const char *e = pdt_test_hook("PDT_TEST_FAIL_TRACE_POINTS");
    if (e && *e && atoi(e) == rank)
        return pdt_err_set(err, PDT_ERR_IO, "%s: write error: injected by "
                           "PDT_TEST_FAIL_TRACE_POINTS", path);
    return PDT_OK;
}

/* This rank's block of points.bin: encoded a piece at a time, checksummed,
 * written at byte 24 + 8 * in->first of f.  Returns this rank's status. */
static pdt_status write_block(pdt_comm_file *f, const pdt_par_input *in, block_sums *s,
                              pdt_err *err)
{
    s->bytes = 8 * (uint64_t)in->n;
    s->crc64 = s->crc32c = 0;
    uint8_t *buf = in->n ? malloc(8 * (size_t)(in->n < POINTS_PIECE ? in->n : POINTS_PIECE))
                         : NULL;
    if (in->n && !buf) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    pdt_status st = PDT_OK;
    uint32_t crc32 = 0;
    for (size_t i = 0; i < in->n && st == PDT_OK; i += POINTS_PIECE) {
        size_t k = in->n - i < POINTS_PIECE ? in->n - i : POINTS_PIECE;
        pdt_points_encode(buf, in->pts + i, k);
        crc32 = pdt_crc32c(crc32, buf, 8 * k);
        s->crc64 = pdt_crc64(s->crc64, buf, 8 * k);
        st = pdt_comm_file_write_at(f, PDT_POINTS_HEADER_BYTES + 8 * (in->first + i), buf, 8 * k,
                                    err);
    }
    s->crc32c = crc32;
    free(buf);
    return st;
}

/* Rank 0: the checksums of the whole data from the blocks' (rank order). */
static void combine_sums(const block_sums *b, int p, uint32_t *crc32c, uint64_t *crc64)
{
    *crc32c = 0;
    *crc64 = 0;
    for (int q = 0; q < p; q++) {
        *crc32c = pdt_crc32c_combine(*crc32c, (uint32_t)b[q].crc32c, b[q].bytes);
        *crc64 = pdt_crc64_combine(*crc64, b[q].crc64, b[q].bytes);
    }
}

/* Collective: write DIR/points.bin's temporary `tmp`, every rank its block
 * of the input, rank 0 the header; *checksum (rank 0) = the manifest's.
 * Same status at every rank; the temporary may be left on failure. */
static pdt_status write_points_tmp(pdt_comm *c, const char *tmp, const pdt_par_input *in,
                                   uint64_t *checksum, pdt_err *err)
{
    int r = pdt_comm_rank(c), p = pdt_comm_size(c);
    block_sums mine = {0, 0, 0}, *all = r == 0 ? malloc((size_t)p * sizeof *all) : NULL;
    size_t *cnt = r == 0 ? malloc((size_t)p * sizeof *cnt) : NULL;
    pdt_status st = r == 0 && (!all || !cnt) ? pdt_err_set(err, PDT_ERR_NOMEM, "out of memory")
                                             : PDT_OK;
    pdt_comm_file *f = NULL;
    if (pdt_par_agree(c, st, NULL, err) == PDT_OK) st = pdt_comm_file_open(c, tmp, PDT_POINTS_HEADER_BYTES + 8 * in->n_total, &f, err);
    else st = PDT_ERR_NOMEM;
    if (st != PDT_OK) {
        free(all);
        free(cnt);
        return st;
    }
    for (int q = 0; r == 0 && q < p; q++) cnt[q] = sizeof *all;
    pdt_err werr;
    pdt_err_clear(&werr);
    pdt_status wst = test_fail_points(r, tmp, &werr);
    if (wst == PDT_OK) wst = write_block(f, in, &mine, &werr);
    /* the sums travel even after a failed write: the gather is collective */
    pdt_err gerr;
    pdt_err_clear(&gerr);
    st = pdt_comm_gatherv(c, &mine, sizeof mine, all, cnt, 0, &gerr);
    if (st == PDT_OK && wst == PDT_OK && r == 0) {
        uint32_t crc32c;
        uint8_t h[PDT_POINTS_HEADER_BYTES];
        combine_sums(all, p, &crc32c, checksum);
        pdt_points_header(h, in->n_total, crc32c);
        wst = pdt_comm_file_write_at(f, 0, h, sizeof h, &werr);
    }
    free(all);
    free(cnt);
    pdt_err cerr;
    pdt_err_clear(&cerr);
    pdt_status cst = pdt_comm_file_close(f, &cerr); /* collective: agrees on the writes */
    if (st != PDT_OK) {
        *err = gerr;
        cst = st;
    } else if (wst != PDT_OK) {
        *err = werr;
        cst = wst;
    } else if (cst != PDT_OK) {
        *err = cerr;
    }
    return pdt_par_agree(c, cst, NULL, err);
}

/* A message about our temporary names the user's file instead. */
static void name_final(pdt_err *err, const char *tmp, const char *path)
{
    size_t k = strlen(tmp);
    if (strncmp(err->msg, tmp, k) != 0) return;
    char rest[sizeof err->msg];
    snprintf(rest, sizeof rest, "%s", err->msg + k);
    snprintf(err->msg, sizeof err->msg, "%s%s", path, rest);
}

/* Collective: points.bin written by every rank at its place (a temporary,
 * renamed by rank 0 once every rank succeeded), then the manifest (rank 0).
 * Same bytes whatever the number of ranks. */
static pdt_status write_run_meta(pdt_cli_trace *t, const pdt_run_opts *o, pdt_comm *c,
                                 const pdt_par_input *in, pdt_err *err)
{
    int r = pdt_comm_rank(c);
    long pid = (long)getpid();
    pdt_status st = pdt_comm_bcast(c, &pid, sizeof pid, 0, err);
    if (st != PDT_OK) return st;
    size_t len = strlen(t->wdir) + 64;
    char *path = malloc(len), *tmp = malloc(len);
    st = path && tmp ? PDT_OK : pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    st = pdt_par_agree(c, st, NULL, err);
    uint64_t checksum = 0;
    if (st == PDT_OK) {
        snprintf(path, len, "%s/points.bin", t->wdir);
        snprintf(tmp, len, "%s/.points.bin.tmp.%ld", t->wdir, pid);
        st = write_points_tmp(c, tmp, in, &checksum, err);
        if (st != PDT_OK) {
            char shown[4096 + 16];
            snprintf(shown, sizeof shown, "%s/points.bin", o->trace_dir);
            name_final(err, tmp, shown);
        }
    }
    if (r == 0 && st == PDT_OK && pdt_replace_file(tmp, path) != 0)
        st = pdt_err_set(err, PDT_ERR_IO, "%s: cannot rename into place: %s", path,
                         strerror(errno));
    if (r == 0 && st != PDT_OK && tmp) unlink(tmp);
    if (r == 0 && st == PDT_OK) {
        pdt_manifest m;
        st = fill_manifest(o, t->nranks, t->offsets, checksum, in->n_total, &m, err);
        if (st == PDT_OK) st = pdt_run_write_manifest(t->wdir, &m, err);
        free(m.command_line);
    }
    free(path);
    free(tmp);
    return pdt_par_agree(c, st, NULL, err);
}

pdt_status pdt_cli_trace_manifest(pdt_cli_trace *t, const pdt_run_opts *o, pdt_comm *c,
                                  const pdt_par_input *in, pdt_err *err)
{
    if (!t) return PDT_OK;
    return write_run_meta(t, o, c, in, err);
}

pdt_trace *pdt_cli_trace_hook(pdt_cli_trace *t)
{
    return t ? pdt_tw_hook(t->w) : NULL;
}

void pdt_cli_trace_finals(pdt_cli_trace *t, const pdt_tri *tris, size_t ntri)
{
    if (!t) return;
    pdt_trace *tr = pdt_tw_hook(t->w);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_OUTPUT, 0, 0, 0, 0);
    for (size_t i = 0; i < ntri; i++)
        PDT_TRACE(tr, 1, PDT_EV_TRI_FINAL, 0, tris[i].v[0], tris[i].v[1], tris[i].v[2], 0);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_OUTPUT, 0, 0, 0, 0);
}

pdt_status pdt_cli_trace_end(pdt_cli_trace *t, pdt_err *err)
{
    if (!t || !t->w) return PDT_OK;
    PDT_TRACE(pdt_tw_hook(t->w), 1, PDT_EV_PHASE_END, PDT_PH_RUN, 0, 0, 0, 0);
    pdt_status st = pdt_tw_close(t->w, err);
    t->w = NULL;
    if (st != PDT_OK) name_final(err, t->wdir, t->shown);
    return st;
}

pdt_status pdt_cli_trace_swap(pdt_cli_trace *t, pdt_err *err)
{
    if (!t || !t->dir.target) return PDT_OK;
    return pdt_safe_dir_swap(&t->dir, err);
}

void pdt_cli_trace_finish(pdt_cli_trace *t, int keep)
{
    if (!t) return;
    if (t->w) pdt_tw_abort(t->w);
    pdt_safe_dir_finish(&t->dir, keep);
    free(t->offsets);
    free(t);
}
