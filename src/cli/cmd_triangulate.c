/* pdt triangulate — read points, compute T*, write the canonical triangles.
 *
 * One pipeline for every run: a plain run is one rank (a serial context, no
 * MPI), a run under mpirun / srun has P ranks, and every rank goes through
 * the same steps (pdt/par.h): read its block of the input, triangulate,
 * write its block of the output, then the figures.  The library returns
 * statuses; this file alone prints and chooses exit codes (cli.h). */
#include <malloc.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "pdt/safefile.h"
#include "pdt/delaunay.h"
#include "pdt/io.h"
#include "pdt/par.h"
#include "pdt/testhook.h"
#include "run_opts.h"

static const char help[] =
    "usage: pdt triangulate INPUT [-o OUT] [--scale K] [--stats]\n"
    "                             [--trace DIR] [--trace-level N]\n"
    "                             [--partition strips|bisect]\n"
    "\n"
    "Compute T*, the Delaunay triangulation of the points in INPUT (exact; ties\n"
    "broken by the lexicographic rule, so the answer is unique).\n"
    "\n"
    "INPUT   one point 'x y' per line (32-bit integers; blank lines and '#' comments\n"
    "        allowed); 'x,y', 'x;y' or tab-separated also, with an optional header\n"
    "        line naming the columns (x,y); or Triangle's .node format when the\n"
    "        name ends in .node;\n"
    "        '-' reads standard input.\n"
    "-o OUT  write to OUT instead of standard output; the format follows the\n"
    "        extension: .tri canonical (default), .ele Triangle's format (with a\n"
    "        matching .node beside it), .off Geomview OFF.  OUT is replaced\n"
    "        atomically: on any error no file is left behind.\n"
    "--scale K       accept decimal coordinates: multiply by K, round to nearest\n"
    "                (halves away from zero); points that collide are reported.\n"
    "--stats         print one JSON object with counts, times and peak memory\n"
    "                to standard error.\n"
    "--trace DIR     record every step into the run folder DIR (for pdtview).\n"
    "--trace-level N 1 (default) or 2 (also every edge the kernel makes).\n"
    "--partition strips|bisect\n"
    "                how the ranks of a parallel run cut the plane: strips\n"
    "                (lexicographic blocks, every seam as tall as the input)\n"
    "                or bisect (boxes by recursive bisection across the longer\n"
    "                side: deeper seams are shorter).  Default: bisect from 16\n"
    "                ranks on, strips below, traced or not.  The output\n"
    "                is the same bytes either way.\n"
    "\n"
    "Output (.tri): one triangle per line, 'i j k', 0-based input indices,\n"
    "counter-clockwise, rotated to start at the smallest index, lines sorted.\n"
    "Duplicate points are represented by their first occurrence.  Fewer than 3\n"
    "distinct points, or all collinear: no triangles, and a message says why.\n"
    "\n"
    "Under mpirun / srun every rank reads, computes and writes its share; the\n"
    "output is the same bytes as a plain run's.\n"
    "\n"
    "Exit status: 0 success, 2 usage, input or write error (or a failed rank).\n";

/* The state of one run at this rank. */
typedef struct run {
    const pdt_run_opts *o;
    pdt_comm *c;
    int rank, p;
    pdt_par_input in;        /* this rank's block of the input */
    pdt_par_output out;      /* this rank's block of T* */
    pdt_par_rank_stats me;   /* this rank's figures */
    pdt_cli_trace *trace;    /* NULL = not traced */
    double t_start;
    const char *phase;       /* the step running, for messages */
} run;

/* ---- when the launcher ends the job -------------------------------------------- */

/* mpirun ends every rank with SIGTERM when one rank died (killed, crashed) or
 * the job was interrupted; its own message names the rank that died, not
 * what the job was doing.  Rank 0 says which step it was in, and every rank
 * removes the temporaries of a write in progress.  Once the steps are over
 * (done, or failed and reported) the handler is silent: mpirun also ends
 * the ranks still finishing when one has exited with a failure status.  (Set by the pipeline,
 * read by the handler: plain values, the step a string constant.) */
static const char *volatile stop_phase = "start";
static volatile sig_atomic_t stop_rank, stop_size, stop_written;

static size_t put_str(char *b, size_t at, const char *s)
{
    while (*s && at < 255) b[at++] = *s++;
    return at;
}

static size_t put_uint(char *b, size_t at, unsigned v)
{
    char d[12];
    int k = 0;
    do d[k++] = (char)('0' + v % 10); while ((v /= 10) && k < 11);
    while (k > 0 && at < 255) b[at++] = d[--k];
    return at;
}

static void on_stop(int sig)
{
    pdt_par_write_abandon();
    if (stop_rank == 0 && stop_phase) {
        char b[256];
        size_t n = put_str(b, 0, "pdt: the job was ended (signal ");
        n = put_uint(b, n, (unsigned)sig);
        n = put_str(b, n, ") while rank 0 was in its ");
        n = put_str(b, n, stop_phase);
        n = put_str(b, n, " step");
        const char *ph = pdt_par_phase();
        if (ph) {
            n = put_str(b, n, " (");
            n = put_str(b, n, ph);
            n = put_str(b, n, " phase)");
        }
        n = put_str(b, n, ": another of the ");
        n = put_uint(b, n, (unsigned)stop_size);
        n = put_str(b, n, " ranks ended first (the launcher names it) or the job was "
                          "interrupted; ");
        n = put_str(b, n, stop_written ? "the output had been written whole before\n"
                                       : "no output written\n");
        ssize_t w = write(STDERR_FILENO, b, n);
        (void)w;
    }
    _exit(PDT_EXIT_USAGE);
}

/* A job told to stop (mpirun interrupted, or a rank died) hears it in two
 * steps: mpirun sends every rank SIGCONT at once, SIGTERM a second later
 * (Open MPI's odls_base_sigkill_timeout).  A rank that finished in between
 * would commit a new output behind the failure status mpirun then reports.
 * So a rank remembers a SIGCONT, and at the commit point (stop_query) a
 * rank that saw one waits for the SIGTERM (on_stop ends it) before it lets
 * the commit go on; a SIGCONT of job control (fg after Ctrl-Z) costs that
 * wait and nothing else.  A launcher that is gone (SIGKILL) is seen by the
 * parent's death signal (SIGTERM: on_stop) and, at the commit, by a changed
 * parent. */
enum { CONT_WAIT_MS = 5000 };
static volatile sig_atomic_t cont_seen;
static pid_t launcher;

static void on_cont(int sig)
{
    (void)sig;
    cont_seen = 1;
}

static int stop_query(void *ctx)
{
    (void)ctx;
    for (int ms = 0; cont_seen && ms < CONT_WAIT_MS; ms += 10) {
        struct timespec ts = {0, 10 * 1000000L};
        nanosleep(&ts, NULL);
    }
    cont_seen = 0; /* (no SIGTERM came: job control; the next question waits no more) */
    return getppid() != launcher;
}

static void catch_stop(const run *R)
{
    stop_rank = R->rank;
    stop_size = R->p;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGHUP, &sa, NULL);
    sa.sa_handler = on_cont;
    sa.sa_flags = SA_RESTART; /* (reads and writes go on; a sleep ends) */
    sigaction(SIGCONT, &sa, NULL);
    launcher = getppid();
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != launcher) raise(SIGTERM); /* (gone before the line above) */
    pdt_comm_set_stop_query(R->c, stop_query, NULL);
}

static void set_phase(run *R, const char *phase)
{
    R->phase = phase;
    stop_phase = phase;
}

/* Print the failure of a step, at the rank that failed (who): the message
 * alone when it names the user's input or options, else with the rank and
 * the step.  Returns st. */
static pdt_status report_failure(const run *R, pdt_status st, int who, const pdt_err *err)
{
    if (st == PDT_OK || who != R->rank) return st;
    const char *msg = err->msg[0] ? err->msg : pdt_status_str(err->code);
    if (R->p == 1 || st == PDT_ERR_PARSE || st == PDT_ERR_ARG || strncmp(msg, "rank ", 5) == 0)
        fprintf(stderr, "pdt: %s\n", msg);
    else
        fprintf(stderr, "pdt: rank %d, %s: %s\n", R->rank, R->phase, msg);
    fflush(stderr);
    return st;
}

/* A step every rank ends together: agree on its status, report a failure.
 * A status the library already agreed on carries an empty message at the
 * ranks where it did not start: they are not the ones to report.  (After a
 * library step that returns the same status at every rank, only a failure
 * needs this: a success costs no agreement, at 1024 simulated ranks
 * 0.1-0.2 ms each.) */
static pdt_status agreed(run *R, pdt_status st, pdt_err *err)
{
    int who = -1;
    if (st != PDT_OK && !err->msg[0]) st = PDT_OK;
    st = pdt_par_agree(R->c, st, &who, err);
    return report_failure(R, st, who, err);
}

/* The output (or the .node written beside an .ele) must not replace the
 * input (checked at rank 0). */
static pdt_status check_output(run *R, pdt_err *err)
{
    const pdt_run_opts *o = R->o;
    pdt_status st = PDT_OK;
    set_phase(R, "options");
    if (R->rank == 0 && o->output && strcmp(o->input, "-") != 0) {
        if (pdt_tri_format_of(o->output) == PDT_FMT_ELE) {
            size_t len = strlen(o->output);
            char *node = malloc(len + 2);
            if (!node) return agreed(R, pdt_err_set(err, PDT_ERR_NOMEM, "out of memory"), err);
            memcpy(node, o->output, len - 4);
            memcpy(node + len - 4, ".node", 6);
            if (pdt_safe_same_file(node, o->input))
                st = pdt_err_set(err, PDT_ERR_ARG, "%s: writing %s would replace the input %s; "
                                 "choose another -o name", o->output, node, o->input);
            free(node);
        } else if (pdt_safe_same_file(o->output, o->input)) {
            st = pdt_err_set(err, PDT_ERR_ARG, "%s: output would replace the input; choose "
                             "another -o name", o->output);
        }
    }
    return agreed(R, st, err);
}

/* (Untraced, no step and no agreement: every rank has the same options.) */
static pdt_status open_trace(run *R, pdt_err *err)
{
    set_phase(R, "trace");
    if (!R->o->trace_dir) return PDT_OK;
    return agreed(R, pdt_cli_trace_open_ranks(R->o, R->c, &R->trace, err), err);
}

/* The hook that records the read and write phases: parallel runs only (the
 * lessons name the events of plain runs by their place in the trace). */
static pdt_trace *io_hook(const run *R)
{
    return R->p > 1 ? pdt_cli_trace_hook(R->trace) : NULL;
}

/* The kernel takes at most PDT_KERNEL_MAX_POINTS points per run, and the
 * partition gives every rank n/P of them (rounded up): a run whose ranks
 * would hold more is refused before computing, naming the limit and the
 * number of ranks that would do.  Every rank knows n and P, so every rank
 * decides alike, with no agreement; rank 0 says why.  (PDT_TEST_KERNEL_LIMIT=K
 * lowers the limit for the tests: 2^29 points do not fit a test machine.) */
static pdt_status check_size(run *R, pdt_err *err)
{
    set_phase(R, "options");
    uint64_t limit = PDT_KERNEL_MAX_POINTS, n = R->in.n_total, p = (uint64_t)R->p;
    const char *t = pdt_test_hook("PDT_TEST_KERNEL_LIMIT");
    if (t && strtoull(t, NULL, 10) > 0) limit = strtoull(t, NULL, 10);
    if ((n + p - 1) / p <= limit) return PDT_OK;
    if (R->rank != 0) { /* (failed alike, with no message of its own) */
        err->code = PDT_ERR_ARG;
        err->msg[0] = '\0';
        return PDT_ERR_ARG;
    }
    uint64_t need = (n + limit - 1) / limit;
    pdt_status st = pdt_err_set(err, PDT_ERR_ARG,
                                "%s: %llu points on %d rank%s: more than %llu points per rank, "
                                "the kernel's limit (its edge records have 32-bit indices); run "
                                "on at least %llu ranks (mpirun -np %llu ...)",
                                strcmp(R->o->input, "-") ? R->o->input : "standard input",
                                (unsigned long long)n, R->p, R->p == 1 ? "" : "s",
                                (unsigned long long)limit, (unsigned long long)need,
                                (unsigned long long)need);
    return report_failure(R, st, 0, err);
}

/* Whether a thread may fault a rank's memory in ahead of it (the point
 * array while it reads, the working memory while it computes): when the
 * machine has a CPU for every rank of the job on it, and one more for a lone
 * rank (mpirun binds a rank to one CPU: the thread is moved to another).
 * On this project's VM first touches of memory wait for the host; a second
 * thread hides that wait even when both CPUs compute ($PDT_PREFAULT=0 turns
 * it off). */
static int prefault_wanted(const run *R)
{
    if (pdt_comm_is_simulated(R->c)) return 0; /* see no_helpers */
    const char *pf = getenv("PDT_PREFAULT");
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    int node = pdt_comm_node_size(R->c);
    return !(pf && strcmp(pf, "0") == 0) && (R->p == 1 ? cpus > 1 : (long)node <= cpus);
}

/* Under SMPI a rank's computing time is its own thread's CPU time: a helper
 * thread's work would be free and its concurrency unsimulated.  The prefault
 * threads are off (prefault_wanted) and so are the writer's (one process for
 * all ranks: every rank sets the same value). */
static void no_helpers(const run *R)
{
    if (pdt_comm_is_simulated(R->c)) setenv("PDT_WRITE_THREADS", "1", 1);
}

static pdt_status read_input(run *R, pdt_err *err)
{
    pdt_trace *tr = io_hook(R);
    set_phase(R, "read");
    double t0 = pdt_comm_wtime(R->c);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_READ, 0, 0, 0, 0);
    pdt_status st = pdt_par_read(R->c, R->o->input, R->o->scale, prefault_wanted(R), &R->in, err);
    if (st != PDT_OK) st = agreed(R, st, err); /* (the same status at every rank) */
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_READ, 0, 0, 0, 0);
    R->me.t_read = pdt_comm_wtime(R->c) - t0;
    if (st == PDT_OK) st = check_size(R, err);
    if (st == PDT_OK && R->trace) {
        set_phase(R, "trace");
        st = agreed(R, pdt_cli_trace_manifest(R->trace, R->o, R->c, &R->in, err), err);
    }
    return st;
}

/* The triangulation.  A rank that fails here cannot wait for the others
 * (they may wait for it): it reports and ends the whole job. */
static pdt_status compute(run *R, pdt_err *err)
{
    set_phase(R, "triangulate");
    /* a .tri output names points by index only: the points can go once
     * partitioned (the other formats write them; a trace keeps them) */
    R->in.release_pts = pdt_tri_format_of(R->o->output) == PDT_FMT_TRI && !R->trace;
    R->in.prefault = prefault_wanted(R);
    R->in.partition = R->o->partition;
    pdt_status st = pdt_par_triangulate(R->c, &R->in, &R->out, &R->me,
                                        pdt_cli_trace_hook(R->trace), err);
    if (st != PDT_OK && R->p > 1) {
        report_failure(R, st, R->rank, err);
        pdt_comm_abort(R->c, PDT_EXIT_USAGE);
    }
    return report_failure(R, st, R->rank, err);
}

/* A traced run: the rank files complete, then (rank 0) the run folder and
 * the output put in place together, or neither. */
static pdt_status put_in_place(run *R, pdt_pending_write *pw, pdt_err *err)
{
    set_phase(R, "trace");
    pdt_status st = agreed(R, pdt_cli_trace_end(R->trace, err), err);
    if (st == PDT_OK) st = pdt_comm_commit_ok(R->c, R->o->output, err); /* (not if stopped) */
    if (st != PDT_OK) {
        pdt_cli_trace_finish(R->trace, 0);
        R->trace = NULL;
        return st;
    }
    if (R->rank == 0) st = pdt_cli_trace_swap(R->trace, err);
    if (R->rank == 0 && st == PDT_OK) st = pdt_pending_commit(pw, err);
    st = agreed(R, st, err);
    pdt_cli_trace_finish(R->trace, st == PDT_OK);
    R->trace = NULL;
    return st;
}

static pdt_status write_output(run *R, pdt_err *err)
{
    pdt_trace *tr = io_hook(R);
    set_phase(R, "write");
    double t0 = pdt_comm_wtime(R->c);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_BEGIN, PDT_PH_WRITE, 0, 0, 0, 0);
    R->out.release_tris = 1; /* nothing reads them after the write: their memory
                              * serves the output's page cache */
    pdt_pending_write pw = {.n = 0};
    pdt_status st = pdt_par_write_deferred(R->c, R->o->output, pdt_tri_format_of(R->o->output),
                                           &R->in, &R->out, R->trace ? &pw : NULL, err);
    PDT_TRACE(tr, 1, PDT_EV_PHASE_END, PDT_PH_WRITE, 0, 0, 0, 0);
    R->me.t_write = pdt_comm_wtime(R->c) - t0;
    R->me.written = R->out.ntri;
    if (st != PDT_OK) st = agreed(R, st, err); /* (the same status at every rank) */
    if (st == PDT_OK && R->trace) st = put_in_place(R, &pw, err);
    pdt_pending_drop(&pw);
    R->me.t_total = pdt_comm_wtime(R->c) - R->t_start;
    return st;
}

/* ---- what the user reads -------------------------------------------------------- */

static void json_seconds(const pdt_par_rank_stats *r)
{
    fprintf(stderr, "{\"read\": %.6f, \"partition\": %.6f, \"local\": %.6f, \"merge\": %.6f, "
            "\"order\": %.6f, \"write\": %.6f}", r->t_read, r->t_partition, r->t_local,
            r->t_merge, r->t_order, r->t_write);
}

static void json_rank(int q, const pdt_par_rank_stats *r)
{
    fprintf(stderr,
            "%s{\"rank\": %d, \"seconds\": ", q ? ", " : "", q);
    json_seconds(r);
    fprintf(stderr,
            ", \"peak_rss_kib\": %lld, \"points\": %llu, \"local_triangles\": %llu, "
            "\"final_at_once\": %llu, \"deferred\": %llu, \"shipped\": %llu, "
            "\"merges\": %llu, \"border_max\": %llu, \"kept\": %llu, \"discarded\": %llu, "
            "\"final_by_merge\": %llu, \"emitted\": %llu, \"written\": %llu, "
            "\"bytes_sent\": %llu, \"bytes_received\": %llu, \"merge_bytes_sent\": %llu, "
            "\"merge_bytes_received\": %llu, \"critical_path_s\": %.6f, \"prefault\": %s, "
            "\"strips\": %d}",
            (long long)r->peak_rss_kib, (unsigned long long)r->points,
            (unsigned long long)r->local_tris, (unsigned long long)r->final_at_once,
            (unsigned long long)r->deferred, (unsigned long long)r->shipped,
            (unsigned long long)r->merges, (unsigned long long)r->border_max,
            (unsigned long long)r->kept, (unsigned long long)r->discarded,
            (unsigned long long)r->final_merge, (unsigned long long)r->emitted,
            (unsigned long long)r->written, (unsigned long long)r->bytes_sent,
            (unsigned long long)r->bytes_recv, (unsigned long long)r->merge_bytes_sent,
            (unsigned long long)r->merge_bytes_recv, r->critical_path,
            r->prefault ? "true" : "false", (int)r->strips);
}

/* The communication figures of an MPI run and per_rank[] again (what make
 * table1 and scripts/simulate-scaling.sh read). */
static void json_parallel(const pdt_par_stats *s)
{
    fprintf(stderr,
            ", \"parallel\": {\"ranks\": %d, \"n\": %llu, \"unique\": %llu, \"duplicates\": %llu, "
            "\"triangles\": %llu, \"hull\": %llu, \"collinear\": %s, "
            "\"largest_border_set\": %llu, \"largest_border_set_rel_n\": %.6f, "
            "\"sequential_merge\": %s, "
            "\"bytes_total\": %llu, \"merge_bytes\": %llu, \"merge_bytes_rel_input\": %.6f, "
            "\"critical_path_s\": %.6f, \"critical_path_cpu_s\": %.6f, \"time_s\": %.6f",
            s->nranks, (unsigned long long)s->n_in, (unsigned long long)s->n_unique,
            (unsigned long long)s->n_dup, (unsigned long long)s->n_tri,
            (unsigned long long)s->hull, s->collinear ? "true" : "false",
            (unsigned long long)s->border_max,
            s->n_unique ? (double)s->border_max / (double)s->n_unique : 0.0,
            s->n_unique >= 64 && 2 * s->border_max > s->n_unique ? "true" : "false",
            (unsigned long long)s->bytes_total, (unsigned long long)s->merge_bytes,
            s->n_in ? (double)s->merge_bytes / (8.0 * (double)s->n_in) : 0.0, s->critical_path,
            s->critical_cpu, s->t_compute);
    uint64_t shared = 0, fallbacks = 0;
    for (int q = 0; q < s->nranks; q++) {
        shared += s->rank[q].shared;
        fallbacks += s->rank[q].share_fallbacks;
    }
    fprintf(stderr, ", \"shared_merges\": %llu, \"shared_merges_done_alone\": %llu",
            (unsigned long long)shared, (unsigned long long)fallbacks);
    fprintf(stderr, ", \"partition\": \"%s\", \"largest_border_set_by_level\": [",
            s->partition == PDT_PART_BISECT ? "bisect" : "strips");
    for (int l = 0; l < s->levels && l < PDT_PAR_MAX_LEVELS; l++)
        fprintf(stderr, "%s%llu", l ? ", " : "", (unsigned long long)s->border_level[l]);
    fprintf(stderr, "]");
    fprintf(stderr, ", \"per_rank\": [");
    for (int q = 0; q < s->nranks; q++) json_rank(q, &s->rank[q]);
    fprintf(stderr, "]}");
}

/* --stats: one JSON object on one line.  "seconds" holds the largest time of each phase
 * over the ranks (a plain run also keeps its historical names: sort, kernel,
 * canonical) and the largest total: a rank's start to the output in place,
 * without the gathering of these figures (at 1024 simulated ranks a linear
 * gather of 1023 messages at rank 0, some 15 ms of a 0.1 s run); per_rank[]
 * every rank's phases and peak memory. */
static void json_stats(const run *R, const pdt_par_stats *s)
{
    pdt_par_rank_stats mx;
    memset(&mx, 0, sizeof mx);
    for (int q = 0; q < s->nranks; q++) {
        const pdt_par_rank_stats *r = &s->rank[q];
#define PDT_MAX_(f) if (r->f > mx.f) mx.f = r->f
        PDT_MAX_(t_read);
        PDT_MAX_(t_partition);
        PDT_MAX_(t_local);
        PDT_MAX_(t_merge);
        PDT_MAX_(t_order);
        PDT_MAX_(t_write);
        PDT_MAX_(t_total);
        PDT_MAX_(peak_rss_kib);
#undef PDT_MAX_
    }
    fprintf(stderr,
            "{\"command\": \"triangulate\", \"ranks\": %d, \"n\": %llu, \"unique\": %llu, "
            "\"duplicates\": %llu, \"collisions\": %llu, \"triangles\": %llu, \"hull\": %llu, "
            "\"collinear\": %s, \"seconds\": {\"read\": %.6f, \"partition\": %.6f, "
            "\"local\": %.6f, \"merge\": %.6f, \"order\": %.6f, \"write\": %.6f, ",
            s->nranks, (unsigned long long)s->n_in, (unsigned long long)s->n_unique,
            (unsigned long long)s->n_dup, (unsigned long long)R->in.collisions,
            (unsigned long long)s->n_tri, (unsigned long long)s->hull,
            s->collinear ? "true" : "false", mx.t_read, mx.t_partition, mx.t_local, mx.t_merge,
            mx.t_order, mx.t_write);
    if (s->nranks == 1)
        fprintf(stderr, "\"sort\": %.6f, \"kernel\": %.6f, \"canonical\": %.6f, ",
                mx.t_partition, mx.t_local, mx.t_order);
    fprintf(stderr, "\"total\": %.6f}, \"peak_rss_kib\": %lld, \"per_rank\": [", mx.t_total,
            (long long)mx.peak_rss_kib);
    for (int q = 0; q < s->nranks; q++) json_rank(q, &s->rank[q]);
    fprintf(stderr, "]");
    if (pdt_comm_is_simulated(R->c)) fprintf(stderr, ", \"simulated\": true");
    if (pdt_comm_is_mpi(R->c)) json_parallel(s);
    fprintf(stderr, "}\n");
}

/* Messages about the input (rounding collisions, duplicates, why there are
 * no triangles) and, with --stats, the figures: rank 0, on stderr. */
static pdt_status report(run *R, pdt_err *err)
{
    set_phase(R, "figures");
    R->me.peak_rss_kib = pdt_cli_peak_kib();
    pdt_par_stats s;
    pdt_status st = agreed(R, pdt_par_stats_collect(R->c, &R->me, R->in.n_total, &s, err), err);
    if (st != PDT_OK || R->rank != 0) return st;
    uint64_t coll = R->in.collisions;
    if (coll)
        fprintf(stderr, "pdt: warning: %llu point%s became equal to a different point after "
                "rounding with --scale %g\n", (unsigned long long)coll, coll == 1 ? "" : "s",
                R->o->scale);
    if (s.n_dup)
        fprintf(stderr, "pdt: %llu duplicate point%s dropped (each copy is represented by its "
                "first occurrence)\n", (unsigned long long)s.n_dup, s.n_dup == 1 ? "" : "s");
    if (s.n_unique < 3)
        fprintf(stderr, "pdt: 0 triangles: only %llu distinct point%s (a triangle needs 3)\n",
                (unsigned long long)s.n_unique, s.n_unique == 1 ? "" : "s");
    else if (s.n_tri == 0)
        fprintf(stderr, "pdt: 0 triangles: all %llu distinct points are collinear\n",
                (unsigned long long)s.n_unique);
    if (R->o->stats) json_stats(R, &s);
    pdt_par_stats_free(&s);
    return PDT_OK;
}

int pdt_cmd_triangulate(int argc, char **argv)
{
    pdt_run_opts o;
    int rc = pdt_cli_parse_run_opts("triangulate", help, argc, argv, &o);
    if (rc >= 0) return rc;
    run R;
    memset(&R, 0, sizeof R);
    R.o = &o;
    pdt_err err = { PDT_OK, "" };
    if (pdt_comm_init(NULL, NULL, 0, &R.c, &err) != PDT_OK) return pdt_cli_fail(&err);
    R.rank = pdt_comm_rank(R.c);
    R.p = pdt_comm_size(R.c);
    /* A parallel run frees arrays proportional to the input between its
     * phases (the input block, the partition's records): with glibc's
     * adaptive threshold, after the first such free they come from the heap
     * and their memory stays with the process, so the next phase's peak sits
     * on top of it (at 4*10^6 points on 2 ranks: 230 MB per rank, 199 MB
     * with a fixed threshold).  A fixed threshold hands them back. */
    if (R.p > 1) mallopt(M_MMAP_THRESHOLD, 4 << 20);
    if (R.p > 1 && pdt_comm_is_mpi(R.c)) catch_stop(&R);
    R.t_start = pdt_comm_wtime(R.c);
    no_helpers(&R);

    pdt_status st = check_output(&R, &err);
    if (st == PDT_OK) st = open_trace(&R, &err);
    if (st == PDT_OK) st = read_input(&R, &err);
    if (st == PDT_OK) st = compute(&R, &err);
    if (st == PDT_OK) st = write_output(&R, &err);
    stop_written = st == PDT_OK; /* (committed: a stop after this must not deny it) */
    if (st == PDT_OK) st = report(&R, &err);
    stop_phase = NULL;

    pdt_cli_trace_finish(R.trace, 0);
    pdt_par_input_free(&R.in);
    pdt_par_output_free(&R.out);
    pdt_comm_finalize(R.c, NULL);
    return st == PDT_OK ? PDT_EXIT_OK : PDT_EXIT_USAGE;
}
