/* pdt — `pdt triangulate` on an MPI job: read (rank 0), compute (all ranks),
 * write (rank 0, atomically), report.
 *
 * This is the command layer of the parallel driver (it prints messages and
 * decides exit codes); the algorithm is in driver.c and srm.c.  A run that
 * fails on any rank aborts the whole job before rank 0 has opened the output,
 * so a failed run never leaves an output file. */
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "pdt/io.h"
#include "pdt/par.h"
#include "pdt/tracefile.h"

enum { TAG_CLOCK = 9, CLOCK_ROUNDS = 8 };

/* Clock offsets by ping-pong with rank 0 (the round with the smallest round
 * trip wins): offset[q] is what to add to rank q's clock to get rank 0's.
 * off (size p) matters at rank 0 only. */
static pdt_status clock_offsets(pdt_comm *c, const pdt_trace_writer *w, int64_t *off,
                                pdt_err *err)
{
    int r = pdt_comm_rank(c), p = pdt_comm_size(c);
    pdt_status st = PDT_OK;
    if (r == 0) {
        off[0] = 0;
        for (int q = 1; q < p && st == PDT_OK; q++) {
            int64_t best = INT64_MAX;
            for (int k = 0; k < CLOCK_ROUNDS && st == PDT_OK; k++) {
                int64_t t0 = (int64_t)pdt_tw_now(w), tq;
                void *buf = NULL;
                size_t len = 0;
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
                free(buf);
            }
        }
    } else {
        for (int k = 0; k < CLOCK_ROUNDS && st == PDT_OK; k++) {
            void *buf = NULL;
            size_t len = 0;
            st = pdt_comm_recv(c, 0, TAG_CLOCK, &buf, &len, err);
            free(buf);
            int64_t t = (int64_t)pdt_tw_now(w);
            if (st == PDT_OK) st = pdt_comm_send(c, 0, TAG_CLOCK, &t, sizeof t, err);
        }
    }
    return st;
}

static pdt_status write_meta(const pdt_par_job *job, int p, const pdt_point *pts, size_t n,
                             int64_t *off, pdt_err *err)
{
    pdt_manifest m;
    memset(&m, 0, sizeof m);
    m.format_version = PDT_TRACE_FORMAT_MAJOR;
    snprintf(m.program_version, sizeof m.program_version, "%s", PDT_VERSION);
    size_t len = 4;
    for (int i = 0; i < job->argc && job->argv; i++) len += strlen(job->argv[i]) + 1;
    char *line = malloc(len + 1);
    if (!line) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    strcpy(line, "pdt");
    for (int i = 0; i < job->argc && job->argv; i++) {
        strcat(line, " ");
        strcat(line, job->argv[i]);
    }
    m.command_line = line;
    m.input_name = (char *)job->input;
    m.input_checksum = pdt_points_checksum(pts, n);
    m.n = n;
    m.nranks = p;
    m.level = job->trace_level;
    snprintf(m.command, sizeof m.command, "triangulate");
    m.clock_offset_ns = off;
    m.wall_start_ns = pdt_wall_ns();
    pdt_status st = pdt_run_write_meta(job->trace_dir, &m, pts, n, err);
    free(line);
    return st;
}

/* 1 if paths a and b name the same existing file. */
static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
           sa.st_ino == sb.st_ino;
}

/* The output (or the .node written beside an .ele) must not replace the
 * input: 1 and a message if it would. */
static int output_clash(const pdt_par_job *job, pdt_err *err)
{
    if (!job->output || !strcmp(job->input, "-")) return 0;
    if (pdt_tri_format_of(job->output) == PDT_FMT_ELE) {
        size_t len = strlen(job->output);
        char *node = malloc(len + 2);
        if (!node) return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory") != PDT_OK;
        memcpy(node, job->output, len - 4);
        memcpy(node + len - 4, ".node", 6);
        int clash = same_file(node, job->input);
        if (clash)
            pdt_err_set(err, PDT_ERR_ARG, "%s: writing %s would replace the input %s; choose "
                        "another -o name", job->output, node, job->input);
        free(node);
        return clash;
    }
    if (!same_file(job->output, job->input)) return 0;
    pdt_err_set(err, PDT_ERR_ARG, "%s: output would replace the input; choose another -o name",
                job->output);
    return 1;
}

/* Messages about the input and, with --stats, the JSON figures (rank 0). */
static void report(const pdt_par_job *job, const pdt_par_stats *s, size_t collisions,
                   double t_read, double t_write, double t_total)
{
    if (collisions)
        fprintf(stderr, "pdt: warning: %zu point%s became equal to a different point after "
                "rounding with --scale %g\n", collisions, collisions == 1 ? "" : "s", job->scale);
    if (s->n_dup)
        fprintf(stderr, "pdt: %llu duplicate point%s dropped (each copy is represented by its "
                "first occurrence)\n", (unsigned long long)s->n_dup, s->n_dup == 1 ? "" : "s");
    if (s->n_unique < 3)
        fprintf(stderr, "pdt: 0 triangles: only %llu distinct point%s (a triangle needs 3)\n",
                (unsigned long long)s->n_unique, s->n_unique == 1 ? "" : "s");
    else if (s->n_tri == 0)
        fprintf(stderr, "pdt: 0 triangles: all %llu distinct points are collinear\n",
                (unsigned long long)s->n_unique);
    if (!job->stats) return;
    struct rusage ru;
    long rss = getrusage(RUSAGE_SELF, &ru) == 0 ? ru.ru_maxrss : -1;
    fprintf(stderr,
            "{\"command\": \"triangulate\", \"n\": %llu, \"unique\": %llu, \"duplicates\": %llu, "
            "\"collisions\": %zu, \"triangles\": %llu, \"hull\": %llu, \"collinear\": %s, "
            "\"seconds\": {\"read\": %.6f, \"parallel\": %.6f, \"write\": %.6f, "
            "\"total\": %.6f}, \"peak_rss_kib\": %ld,\n\"parallel\": ",
            (unsigned long long)s->n_in, (unsigned long long)s->n_unique,
            (unsigned long long)s->n_dup, collisions, (unsigned long long)s->n_tri,
            (unsigned long long)s->hull, s->collinear ? "true" : "false", t_read, s->t_total,
            t_write, t_total, rss);
    pdt_par_stats_json(s, stderr);
    fprintf(stderr, "}\n");
}

/* Stop the whole job after an error on this rank. */
static void die(pdt_comm *c, const pdt_err *err)
{
    fprintf(stderr, "pdt: %s\n", err->msg[0] ? err->msg : pdt_status_str(err->code));
    fflush(stderr);
    pdt_comm_abort(c, 1);
}

int pdt_par_cmd_triangulate(int *argc, char ***argv, const pdt_par_job *job)
{
    pdt_err err;
    pdt_err_clear(&err);
    pdt_comm *c = NULL;
    if (pdt_comm_init(argc, argv, 1, &c, &err) != PDT_OK) {
        fprintf(stderr, "pdt: %s\n", err.msg);
        return 1;
    }
    int r = pdt_comm_rank(c), p = pdt_comm_size(c);
    double t0 = pdt_comm_wtime(c);

    /* read at rank 0; every rank learns whether that worked */
    pdt_point *pts = NULL;
    size_t n = 0, collisions = 0;
    int32_t rc = 0;
    if (r == 0 && output_clash(job, &err)) rc = 2;
    if (r == 0 && rc == 0 &&
        pdt_read_points(job->input, job->scale, &pts, &n, &collisions, &err) != PDT_OK)
        rc = err.code == PDT_ERR_NOMEM ? 1 : 2;
    /* the others sleep while rank 0 reads */
    if (pdt_comm_quiet_barrier(c, &err) != PDT_OK) die(c, &err);
    if (pdt_comm_bcast(c, &rc, sizeof rc, 0, &err) != PDT_OK) die(c, &err);
    if (rc) {
        if (r == 0) fprintf(stderr, "pdt: %s\n", err.msg);
        free(pts);
        pdt_comm_finalize(c, NULL);
        return rc;
    }
    double t_read = pdt_comm_wtime(c) - t0;

    /* trace writers: rank 0 creates the folder first */
    pdt_trace_writer *w = NULL;
    pdt_trace *tr = NULL;
    int64_t *off = NULL;
    if (job->trace_dir) {
        int32_t ok = 1;
        if (r == 0) ok = pdt_tw_open(job->trace_dir, 0, job->trace_level, &w, &err) == PDT_OK;
        if (pdt_comm_bcast(c, &ok, sizeof ok, 0, &err) != PDT_OK) die(c, &err);
        if (!ok) {
            if (r == 0) die(c, &err);
            pdt_comm_abort(c, 1);
        }
        if (r != 0 && pdt_tw_open(job->trace_dir, r, job->trace_level, &w, &err) != PDT_OK)
            die(c, &err);
        off = calloc((size_t)p, sizeof *off);
        if (!off) {
            pdt_err_set(&err, PDT_ERR_NOMEM, "rank %d: out of memory", r);
            die(c, &err);
        }
        if (clock_offsets(c, w, off, &err) != PDT_OK) die(c, &err);
        /* the manifest goes first: a killed run still leaves a complete folder */
        if (r == 0 && write_meta(job, p, pts, n, off, &err) != PDT_OK) die(c, &err);
        tr = pdt_tw_hook(w);
        tr->rank = r;
        tr->gid = NULL;
    }

    pdt_tri *tris = NULL;
    size_t ntri = 0;
    pdt_par_stats stats;
    if (pdt_par_triangulate(c, pts, n, &tris, &ntri, &stats, tr, &err) !=
        PDT_OK)
        die(c, &err);

    if (w && pdt_tw_close(w, &err) != PDT_OK) die(c, &err);
    if (job->trace_dir && pdt_comm_barrier(c, &err) != PDT_OK) die(c, &err);
    free(off);

    if (r == 0 && rc == 0) {
        double tw = pdt_comm_wtime(c);
        if (pdt_write_tris(job->output, pdt_tri_format_of(job->output), pts, n, tris, ntri,
                           &err) != PDT_OK) {
            fprintf(stderr, "pdt: %s\n", err.msg);
            rc = 1;
        }
        double t_write = pdt_comm_wtime(c) - tw;
        if (rc == 0) report(job, &stats, collisions, t_read, t_write, pdt_comm_wtime(c) - t0);
        pdt_par_stats_free(&stats);
    }
    free(tris);
    free(pts);
    pdt_comm_finalize(c, NULL);
    return rc;
}
