/* pdt trace — look into a run folder: info, dump, check, export --chrome. */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "pdt/safefile.h"
#include "pdt/io.h"
#include "pdt/par.h"
#include "pdt/tracefile.h"

static const char help_main[] =
    "usage: pdt trace info DIR\n"
    "       pdt trace dump DIR [--rank R] [--kind K] [--from N] [--count M]\n"
    "       pdt trace check DIR [--mem BYTES]\n"
    "       pdt trace export --chrome DIR -o run.json [--events]\n"
    "       pdt trace export --otf2 DIR -o ARCHIVE_DIR\n"
    "\n"
    "DIR is a run folder written by `pdt triangulate --trace DIR` or `pdt hull --trace DIR`\n"
    "(format: docs/trace-format.md).\n"
    "  info    ranks, events per kind per rank, phases with durations, bytes\n"
    "  dump    one line per event: rank, index in the rank, aligned time, event\n"
    "  check   verify the invariants of a correct run; exit 1 naming the first violation,\n"
    "          2 if DIR cannot be read as a run folder.  --mem BYTES (or $PDT_TRACE_MEM;\n"
    "          e.g. 64M, default 1G): its memory budget; beyond it the final triangles\n"
    "          and the points are sorted on temporary files ($TMPDIR), and T* or a hull\n"
    "          run's hull is certified instead of recomputed\n"
    "  export  Chrome trace-event JSON (chrome://tracing, ui.perfetto.dev): one row per\n"
    "          rank, phases and merge steps as slices, messages as flow arrows; or an\n"
    "          OTF2 archive (Vampir, otf2-print): ARCHIVE_DIR/run.otf2\n";

static const char help_dump[] =
    "usage: pdt trace dump DIR [--rank R] [--kind K] [--from N] [--count M]\n"
    "One line per event: `r2 #17 t=1.234567ms pop graham pt=17 depth=3 cause=12`\n"
    "(#17 = index of the event in its rank's file, t = time aligned across ranks).\n"
    "--rank R   only rank R, in its recording order (default: all ranks merged in a\n"
    "           causally consistent order)\n"
    "--kind K   only events of kind K (push, pop, lift, sort, delete, tri-new, tri-final,\n"
    "           ra-defer, ship, discard, merge-begin, merge-end, send, recv, hull,\n"
    "           phase-begin, phase-end, edge-add, edge-del, incircle)\n"
    "--from N   start at event N (of rank R, or of the merged order)\n"
    "--count M  print at most M lines\n";

static int open_run(const char *dir, pdt_run **run)
{
    pdt_err err = {0};
    if (pdt_run_open(dir, run, &err) != PDT_OK) return pdt_cli_fail(&err);
    return PDT_EXIT_OK;
}

static void print_warnings(const pdt_run *run, FILE *f)
{
    const char *w = pdt_run_warnings(run);
    while (*w) {
        const char *nl = strchr(w, '\n');
        int len = (int)(nl ? nl - w : (long)strlen(w));
        fprintf(f, "warning: %.*s\n", len, w);
        w += len + (nl ? 1 : 0);
    }
}

/* ---- info ------------------------------------------------------------------ */

typedef struct phase_rec {
    pdt_event begin;
    uint64_t t, end;  /* end = UINT64_MAX while open */
    size_t depth;
} phase_rec;

/* info: the manifest's lines. */
static void info_manifest(const char *dir, const pdt_manifest *m, int p)
{
    printf("run folder   %s (format %d.%d)\n", dir, m->format_version, m->format_minor);
    printf("command      %s  (pdt %s)\n", m->command[0] ? m->command : "?",
           m->program_version[0] ? m->program_version : "?");
    if (m->command_line) printf("command line %s\n", m->command_line);
    printf("input        %s  n=%" PRIu64 "  checksum %s:%016" PRIx64 "\n",
           m->input_name ? m->input_name : "?", m->n,
           m->input_checksum_kind == PDT_CHECKSUM_FNV1A64 ? "fnv1a64" : "crc64",
           m->input_checksum);
    if (m->wall_start_ns) {
        time_t s = (time_t)(m->wall_start_ns / 1000000000u);
        struct tm tm;
        char when[64];
        gmtime_r(&s, &tm);
        strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S UTC", &tm);
        printf("started      %s\n", when);
    }
    printf("ranks        %d   trace level %d\n\n", p, m->level);
}

/* info: every rank's events, blocks and bytes. */
static void info_ranks(pdt_run *run, int p)
{
    printf("rank      events   blocks        bytes  bytes/event  complete\n");
    uint64_t tev = 0, tbytes = 0;
    for (int r = 0; r < p; r++) {
        pdt_rank_info in;
        pdt_run_rank_info(run, r, &in);
        tev += in.events;
        tbytes += in.bytes;
        printf("%4d %11" PRIu64 " %8" PRIu64 " %12" PRIu64 " %12.2f  %s\n", r, in.events,
               in.blocks, in.bytes, in.events ? (double)in.bytes / (double)in.events : 0.0,
               !in.present ? "missing" : in.complete ? "yes" : "NO");
    }
    if (p > 1)
        printf(" all %11" PRIu64 " %8s %12" PRIu64 " %12.2f\n", tev, "", tbytes,
               tev ? (double)tbytes / (double)tev : 0.0);
}

/* The earliest aligned time of any rank's first event. */
static uint64_t first_time(pdt_run *run, int p)
{
    uint64_t t0 = UINT64_MAX;
    for (int r = 0; r < p; r++) {
        pdt_cursor *c;
        pdt_event e;
        if (pdt_cursor_open(run, r, &c, NULL) != PDT_OK) continue;
        if (pdt_cursor_next(c, &e, NULL) && e.t < t0) t0 = e.t;
        pdt_cursor_close(c);
    }
    return t0;
}

/* One phase line of rank r (times from t0). */
static void print_phase(int r, const phase_rec *ph, uint64_t t0)
{
    const pdt_event *b = &ph->begin;
    const char *pn = pdt_phase_name(b->sub);
    char name[80];
    if (b->kind == PDT_EV_MERGE_BEGIN)
        snprintf(name, sizeof name, "merge step level %u: [%u,%u)+[%u,%u)", b->sub, b->a,
                 b->b, b->b, b->c);
    else if (b->a)
        snprintf(name, sizeof name, "%s %u", pn ? pn : "?", b->a);
    else
        snprintf(name, sizeof name, "%s", pn ? pn : "?");
    printf("  r%-3d %*s%-*s start %12.6f ms  ", r, (int)(2 * ph->depth), "",
           (int)(34 - 2 * (ph->depth < 8 ? ph->depth : 8)), name, (double)(ph->t - t0) / 1e6);
    if (ph->end == UINT64_MAX) printf("never ends\n");
    else printf("duration %12.6f ms\n", (double)(ph->end - ph->t) / 1e6);
}

/* info: one pass over rank r: its counts per kind (cnt) and its phases,
 * listed in the order they begin, nested ones indented. */
static void info_rank_phases(pdt_run *run, int r, uint64_t t0, uint64_t *cnt)
{
    pdt_cursor *c;
    pdt_err err = {0};
    if (pdt_cursor_open(run, r, &c, &err) != PDT_OK) return;
    phase_rec *ph = NULL;
    size_t nph = 0, cap = 0, *open = NULL, depth = 0, capo = 0;
    pdt_event e;
    int nomem = 0;
    while (!nomem && pdt_cursor_next(c, &e, NULL)) {
        cnt[e.kind < PDT_EV_KIND_COUNT ? e.kind : PDT_EV_KIND_COUNT]++;
        if (e.kind == PDT_EV_PHASE_BEGIN || e.kind == PDT_EV_MERGE_BEGIN) {
            if (nph == cap) {
                cap = cap ? 2 * cap : 64;
                phase_rec *q = realloc(ph, cap * sizeof *q);
                if (!q) { nomem = 1; break; }
                ph = q;
            }
            if (depth == capo) {
                capo = capo ? 2 * capo : 16;
                size_t *q = realloc(open, capo * sizeof *q);
                if (!q) { nomem = 1; break; }
                open = q;
            }
            ph[nph] = (phase_rec){e, e.t, UINT64_MAX, depth};
            open[depth++] = nph++;
        } else if ((e.kind == PDT_EV_PHASE_END || e.kind == PDT_EV_MERGE_END) && depth > 0) {
            ph[open[--depth]].end = e.t;
        }
    }
    for (size_t i = 0; i < nph; i++) print_phase(r, &ph[i], t0);
    if (nomem) printf("  r%-3d (out of memory: phase list cut short)\n", r);
    free(ph);
    free(open);
    pdt_cursor_close(c);
}

/* info: the events per kind, per rank (the first 16) and in all. */
static void info_kinds(int p, uint64_t (*cnt)[PDT_EV_KIND_COUNT + 1])
{
    printf("\nevents per kind:\n%-12s", "kind");
    for (int r = 0; r < p && r < 16; r++) printf(" %10s%d", "r", r);
    if (p > 1) printf(" %11s", "all");
    printf("\n");
    for (int k = 0; k <= PDT_EV_KIND_COUNT; k++) {
        uint64_t tot = 0;
        for (int r = 0; r < p; r++) tot += cnt[r][k];
        if (!tot) continue;
        printf("%-12s", k < PDT_EV_KIND_COUNT ? pdt_event_kind_name(k) : "(unknown)");
        for (int r = 0; r < p && r < 16; r++) printf(" %11" PRIu64, cnt[r][k]);
        if (p > 1) printf(" %11" PRIu64, tot);
        printf("\n");
    }
    if (p > 16) printf("(per-rank columns shown for ranks 0..15)\n");
}

static int cmd_info(const char *dir)
{
    pdt_run *run;
    int rc = open_run(dir, &run);
    if (rc) return rc;
    int p = pdt_run_nranks(run);
    info_manifest(dir, pdt_run_manifest(run), p);
    uint64_t (*cnt)[PDT_EV_KIND_COUNT + 1] = calloc((size_t)p, sizeof *cnt);
    if (!cnt) {
        fprintf(stderr, "pdt: out of memory\n");
        pdt_run_close(run);
        return PDT_EXIT_USAGE;
    }
    info_ranks(run, p);
    printf("\nphases (rank, phase, start on the aligned clock, duration; nested ones "
           "indented):\n");
    uint64_t t0 = first_time(run, p);
    for (int r = 0; r < p; r++) info_rank_phases(run, r, t0, cnt[r]);
    info_kinds(p, cnt);
    free(cnt);
    print_warnings(run, stdout);
    pdt_run_close(run);
    return PDT_EXIT_OK;
}

/* ---- dump ------------------------------------------------------------------ */

static void dump_line(uint32_t rank, uint64_t seq, const pdt_event *e)
{
    char text[200];
    printf("r%" PRIu32 " #%" PRIu64 " t=%.6fms %s\n", rank, seq, (double)e->t / 1e6,
           pdt_event_format(e, text, sizeof text));
}

/* The events of one rank, from its event `from` on, at most count of kind
 * k (any when k < 0). */
static int dump_rank(pdt_run *run, uint64_t rank, uint64_t from, uint64_t count, int k)
{
    pdt_err err = {0};
    pdt_cursor *c;
    if (pdt_cursor_open(run, (int)rank, &c, &err) != PDT_OK ||
        pdt_cursor_seek(c, from, &err) != PDT_OK)
        return pdt_cli_fail(&err);
    pdt_event e;
    uint64_t seq;
    while (count > 0 && pdt_cursor_next(c, &e, &seq)) {
        if (k >= 0 && e.kind != k) continue;
        dump_line((uint32_t)rank, seq, &e);
        count--;
    }
    pdt_cursor_close(c);
    return PDT_EXIT_OK;
}

/* The events of all ranks merged by time, streamed (memory independent of
 * the run's size), from the merged event `from` on, as dump_rank. */
static int dump_merged(pdt_run *run, uint64_t from, uint64_t count, int k)
{
    pdt_err err = {0};
    pdt_merge *mg;
    if (pdt_merge_open(run, &mg, &err) != PDT_OK) return pdt_cli_fail(&err);
    pdt_rec rec;
    int got = 0;
    for (uint64_t i = 0; count > 0 && (got = pdt_merge_next(mg, &rec, &err)) == 1; i++) {
        if (i < from || (k >= 0 && rec.ev.kind != k)) continue;
        dump_line(rec.rank, rec.seq, &rec.ev);
        count--;
    }
    pdt_merge_close(mg);
    return got < 0 ? pdt_cli_fail(&err) : PDT_EXIT_OK;
}

static int cmd_dump(int argc, char **argv)
{
    const char *pos[1];
    int npos = 0;
    uint64_t rank = UINT64_MAX, from = 0, count = UINT64_MAX;
    const char *kind = NULL;
    const pdt_cli_opt opts[] = {
        {"--rank", NULL, PDT_OPT_U64, &rank},
        {"--kind", NULL, PDT_OPT_STR, &kind},
        {"--from", NULL, PDT_OPT_U64, &from},
        {"--count", NULL, PDT_OPT_U64, &count},
        {NULL, NULL, PDT_OPT_FLAG, NULL},
    };
    int rc = pdt_cli_parse("trace dump", help_dump, argc, argv, opts, pos, 1, &npos);
    if (rc == 1) return PDT_EXIT_OK;
    if (rc) return PDT_EXIT_USAGE;
    if (npos != 1) return pdt_cli_usage("trace dump", "needs one run folder DIR");
    int k = -1;
    if (kind && (k = pdt_event_kind_by_name(kind)) < 0)
        return pdt_cli_usage("trace dump", "unknown event kind '%s'", kind);
    pdt_run *run;
    if ((rc = open_run(pos[0], &run))) return rc;
    print_warnings(run, stderr);
    if (rank != UINT64_MAX && rank >= (uint64_t)pdt_run_nranks(run)) {
        int last = pdt_run_nranks(run) - 1;
        pdt_run_close(run);
        return pdt_cli_usage("trace dump", "--rank %" PRIu64 ": the run has ranks 0..%d", rank,
                             last);
    }
    rc = rank != UINT64_MAX ? dump_rank(run, rank, from, count, k)
                            : dump_merged(run, from, count, k);
    pdt_run_close(run);
    if (rc) return rc;
    return fflush(stdout) == 0 && !ferror(stdout) ? PDT_EXIT_OK : PDT_EXIT_USAGE;
}

/* ---- check ------------------------------------------------------------------ */


/* The memory budget: --mem, else $PDT_TRACE_MEM, else the default. */
static int trace_budget(const char *cmd, const char *opt, uint64_t *budget)
{
    const char *env = getenv("PDT_TRACE_MEM");
    *budget = PDT_TRACE_MEM_DEFAULT;
    if (opt && pdt_cli_bytes(opt, budget))
        return pdt_cli_usage(cmd, "--mem %s: not a byte count (e.g. 4096, 64M, 1G)", opt);
    if (!opt && env && *env && pdt_cli_bytes(env, budget))
        return pdt_cli_usage(cmd, "PDT_TRACE_MEM=%s: not a byte count (e.g. 4096, 64M, 1G)", env);
    return PDT_EXIT_OK;
}

/* Exit 0 when the run passes, 1 naming the first violated invariant (or the
 * damage found), 2 when the folder cannot be read as a run at all (no
 * manifest nor rank file, a malformed manifest, another major version). */
static int cmd_check(const char *dir, uint64_t budget)
{
    pdt_run *run;
    pdt_err err = {0};
    if (pdt_run_open(dir, &run, &err) != PDT_OK) {
        fprintf(stderr, "pdt trace check: %s\n", err.msg);
        return PDT_EXIT_USAGE;
    }
    char summary[1024];
    pdt_status st = pdt_run_check_tstar(run, budget, pdt_par_tstar, summary, sizeof summary, &err);
    pdt_run_close(run);
    if (st != PDT_OK) {
        fprintf(stderr, "pdt trace check: %s: %s\n", dir, err.msg);
        return st == PDT_ERR_CHECK ? PDT_EXIT_CHECK : PDT_EXIT_USAGE;
    }
    printf("ok: %s\n", summary);
    return PDT_EXIT_OK;
}

/* ---- export --chrome ----------------------------------------------------------- */

static void json_str(FILE *f, const char *s)
{
    fputc('"', f);
    for (; s && *s; s++) {
        unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\') fprintf(f, "\\%c", ch);
        else if (ch < 0x20) fprintf(f, "\\u%04x", ch);
        else fputc(ch, f);
    }
    fputc('"', f);
}

static void us(FILE *f, uint64_t t)
{
    fprintf(f, "%" PRIu64 ".%03u", t / 1000, (unsigned)(t % 1000));
}

static void chrome_ev(FILE *f, int *first, const char *ph, const char *name, const char *cat,
                      int rank, uint64_t t)
{
    fprintf(f, "%s\n{\"ph\":\"%s\",\"name\":", *first ? "" : ",", ph);
    json_str(f, name);
    fprintf(f, ",\"cat\":\"%s\",\"pid\":0,\"tid\":%d,\"ts\":", cat, rank);
    us(f, t);
    *first = 0;
}

/* --events adds one instant per event only up to this many events: beyond,
 * the JSON would be too big for a browser to open. */
#define CHROME_EVENTS_MAX 2000000u

/* The JSON's head: the command, the process and one named thread per rank. */
static void chrome_head(FILE *f, const pdt_manifest *m, int p)
{
    fprintf(f, "{\"displayTimeUnit\":\"ns\",\"otherData\":{\"command\":");
    json_str(f, m->command);
    fprintf(f, ",\"command_line\":");
    json_str(f, m->command_line ? m->command_line : "");
    fprintf(f, ",\"n\":%" PRIu64 ",\"ranks\":%d},\n\"traceEvents\":[", m->n, p);
    fprintf(f, "\n{\"ph\":\"M\",\"name\":\"process_name\",\"pid\":0,"
               "\"args\":{\"name\":\"pdt %s\"}}", m->command);
    for (int r = 0; r < p; r++) {
        fprintf(f, ",\n{\"ph\":\"M\",\"name\":\"thread_name\",\"pid\":0,\"tid\":%d,"
                   "\"args\":{\"name\":\"rank %d\"}}", r, r);
        fprintf(f, ",\n{\"ph\":\"M\",\"name\":\"thread_sort_index\",\"pid\":0,\"tid\":%d,"
                   "\"args\":{\"sort_index\":%d}}", r, r);
    }
}

/* --events, unless the run has more than CHROME_EVENTS_MAX events (then a
 * warning). */
static int chrome_all_events(pdt_run *run, int all_events)
{
    uint64_t total = 0;
    for (int r = 0; r < pdt_run_nranks(run); r++) {
        pdt_rank_info in;
        pdt_run_rank_info(run, r, &in);
        total += in.events;
    }
    if (all_events && total > CHROME_EVENTS_MAX) {
        fprintf(stderr, "warning: the run has %" PRIu64 " events: --events ignored above %u "
                        "(phases, merge steps and messages only)\n", total, CHROME_EVENTS_MAX);
        return 0;
    }
    return all_events;
}

/* One rank's export as it goes: the open phases and merge steps. */
typedef struct chrome_rank {
    FILE *f;
    int *first;
    int r;
    uint64_t depth;
} chrome_rank;

static void chrome_phase(chrome_rank *c, const pdt_event *e)
{
    char name[200];
    const char *pn = pdt_phase_name(e->sub);
    if (e->a) snprintf(name, sizeof name, "%s %u", pn ? pn : "?", e->a);
    else snprintf(name, sizeof name, "%s", pn ? pn : "?");
    int b = e->kind == PDT_EV_PHASE_BEGIN;
    if (!b && c->depth == 0) return; /* unbalanced (damaged) */
    c->depth += b ? 1 : (uint64_t)-1;
    chrome_ev(c->f, c->first, b ? "B" : "E", name, "phase", c->r, e->t);
    fprintf(c->f, "}");
}

static void chrome_merge(chrome_rank *c, const pdt_event *e)
{
    char name[200];
    snprintf(name, sizeof name, "merge level %u", e->sub);
    if (e->kind == PDT_EV_MERGE_BEGIN) {
        c->depth++;
        chrome_ev(c->f, c->first, "B", name, "merge", c->r, e->t);
        fprintf(c->f, ",\"args\":{\"left\":%u,\"right\":%u,\"end\":%u}}", e->a, e->b, e->c);
        return;
    }
    if (c->depth == 0) return;
    c->depth--;
    chrome_ev(c->f, c->first, "E", name, "merge", c->r, e->t);
    fprintf(c->f, ",\"args\":{\"shipped\":%u,\"border\":%u,\"kept\":%u,"
                  "\"discarded\":%" PRId64 "}}", e->a, e->b, e->c, e->v);
}

static void chrome_message(chrome_rank *c, const pdt_event *e)
{
    char name[200];
    int send = e->kind == PDT_EV_SEND;
    unsigned src = send ? (unsigned)c->r : e->a, dst = send ? e->a : (unsigned)c->r;
    snprintf(name, sizeof name, "%s %s %u (%u bytes)", send ? "send" : "recv",
             send ? "to" : "from", e->a, e->b);
    chrome_ev(c->f, c->first, "X", name, "message", c->r, e->t);
    fprintf(c->f, ",\"dur\":0.001,\"args\":{\"tag\":%u,\"seq\":%" PRId64 "}}", e->sub, e->v);
    chrome_ev(c->f, c->first, send ? "s" : "f", "message", "message", c->r, e->t);
    fprintf(c->f, ",\"id\":\"%u-%u-%u-%" PRId64 "\"%s}", src, dst, e->sub, e->v,
            send ? "" : ",\"bp\":\"e\"");
}

/* Rank r's phases, merge steps and messages (and with all_events every
 * other event as an instant); what a damaged trace left open is closed. */
static int chrome_rank_events(pdt_run *run, int r, FILE *f, int *first, int all_events)
{
    pdt_cursor *cur;
    pdt_err err = {0};
    if (pdt_cursor_open(run, r, &cur, &err) != PDT_OK) return pdt_cli_fail(&err);
    chrome_rank c = { f, first, r, 0 };
    pdt_event e;
    uint64_t seq, last_t = 0;
    char name[200];
    while (pdt_cursor_next(cur, &e, &seq)) {
        last_t = e.t;
        if (e.kind == PDT_EV_PHASE_BEGIN || e.kind == PDT_EV_PHASE_END) {
            chrome_phase(&c, &e);
        } else if (e.kind == PDT_EV_MERGE_BEGIN || e.kind == PDT_EV_MERGE_END) {
            chrome_merge(&c, &e);
        } else if (e.kind == PDT_EV_SEND || e.kind == PDT_EV_RECV) {
            chrome_message(&c, &e);
        } else if (all_events) {
            pdt_event_format(&e, name, sizeof name);
            chrome_ev(f, first, "i", name, "event", r, e.t);
            fprintf(f, ",\"s\":\"t\",\"args\":{\"seq\":%" PRIu64 "}}", seq);
        }
    }
    for (; c.depth > 0; c.depth--) {
        chrome_ev(f, first, "E", "(unfinished)", "phase", r, last_t);
        fprintf(f, "}");
    }
    pdt_cursor_close(cur);
    return PDT_EXIT_OK;
}

static int export_chrome(pdt_run *run, FILE *f, int all_events)
{
    int p = pdt_run_nranks(run), first = 0; /* (the head's entries come first) */
    chrome_head(f, pdt_run_manifest(run), p);
    all_events = chrome_all_events(run, all_events);
    for (int r = 0; r < p; r++) {
        int rc = chrome_rank_events(run, r, f, &first, all_events);
        if (rc) return rc;
    }
    fprintf(f, "\n]}\n");
    return PDT_EXIT_OK;
}

static int export_otf2(pdt_run *run, const char *out)
{
    pdt_err err = {0};
    pdt_otf2_counts n;
    if (pdt_run_export_otf2(run, out, &n, &err) != PDT_OK) return pdt_cli_fail(&err);
    fprintf(stderr, "%s/run.otf2: %" PRIu64 " phase and merge-step enters, %" PRIu64
                    " sends, %" PRIu64 " recvs\n", out, n.enters, n.sends, n.recvs);
    if (n.skipped)
        fprintf(stderr, "warning: %" PRIu64 " unbalanced phase ends or messages to no rank "
                        "left out\n", n.skipped);
    return PDT_EXIT_OK;
}

static int cmd_export(int argc, char **argv)
{
    static const char help[] =
        "usage: pdt trace export --chrome DIR -o run.json [--events]\n"
        "       pdt trace export --otf2 DIR -o ARCHIVE_DIR\n"
        "--chrome  Chrome trace-event JSON (open in ui.perfetto.dev or chrome://tracing):\n"
        "          one row per rank, phases and merge steps as slices, messages as flow\n"
        "          arrows.  --events adds every other event as an instant.\n"
        "--otf2    an OTF2 archive in the new folder ARCHIVE_DIR (open ARCHIVE_DIR/run.otf2\n"
        "          in Vampir, or read it with otf2-print): one location per rank, phases\n"
        "          and merge steps as regions, messages as MPI send/recv records.\n";
    const char *pos[1], *out = NULL;
    int npos = 0, chrome = 0, otf2 = 0, events = 0;
    const pdt_cli_opt opts[] = {
        {"--chrome", NULL, PDT_OPT_FLAG, &chrome},
        {"--otf2", NULL, PDT_OPT_FLAG, &otf2},
        {"--output", "-o", PDT_OPT_STR, &out},
        {"--events", NULL, PDT_OPT_FLAG, &events},
        {NULL, NULL, PDT_OPT_FLAG, NULL},
    };
    int rc = pdt_cli_parse("trace export", help, argc, argv, opts, pos, 1, &npos);
    if (rc == 1) return PDT_EXIT_OK;
    if (rc) return PDT_EXIT_USAGE;
    if (chrome == otf2) return pdt_cli_usage("trace export", "choose one of --chrome and --otf2");
    if (npos != 1) return pdt_cli_usage("trace export", "needs one run folder DIR");
    if (otf2 && (!out || !strcmp(out, "-")))
        return pdt_cli_usage("trace export", "--otf2 needs -o ARCHIVE_DIR (a new folder)");
    if (otf2 && events)
        return pdt_cli_usage("trace export", "--events is for --chrome only");
    if (out && pdt_safe_touches_run(out, pos[0])) /* an input is never an output */
        return pdt_cli_usage("trace export", "-o %s would replace a file of the run folder %s "
                             "being read; choose another -o name", out, pos[0]);
    pdt_run *run;
    if ((rc = open_run(pos[0], &run))) return rc;
    print_warnings(run, stderr);
    if (otf2) {
        rc = export_otf2(run, out);
        pdt_run_close(run);
        return rc;
    }
    pdt_outfile o;
    pdt_err err = {0};
    if (pdt_out_open(&o, out, &err) != PDT_OK) {
        pdt_run_close(run);
        return pdt_cli_fail(&err);
    }
    rc = export_chrome(run, o.fp, events);
    pdt_run_close(run);
    if (rc) {
        pdt_out_abort(&o);
        return rc;
    }
    if (pdt_out_commit(&o, &err) != PDT_OK) return pdt_cli_fail(&err);
    return PDT_EXIT_OK;
}

int pdt_cmd_trace(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        fputs(help_main, argc < 2 ? stderr : stdout);
        return argc < 2 ? PDT_EXIT_USAGE : PDT_EXIT_OK;
    }
    const char *sub = argv[1];
    if (!strcmp(sub, "dump")) return cmd_dump(argc - 1, argv + 1);
    if (!strcmp(sub, "export")) return cmd_export(argc - 1, argv + 1);
    if (!strcmp(sub, "info") || !strcmp(sub, "check")) {
        const char *pos[1], *mem = NULL;
        int npos = 0;
        const pdt_cli_opt opts[] = {{"--mem", NULL, PDT_OPT_STR, &mem},
                                    {NULL, NULL, PDT_OPT_FLAG, NULL}};
        char cmd[32];
        snprintf(cmd, sizeof cmd, "trace %s", sub);
        int rc = pdt_cli_parse(cmd, help_main, argc - 1, argv + 1, opts, pos, 1, &npos);
        if (rc == 1) return PDT_EXIT_OK;
        if (rc) return PDT_EXIT_USAGE;
        if (npos != 1) return pdt_cli_usage(cmd, "needs one run folder DIR");
        uint64_t budget;
        if ((rc = trace_budget(cmd, mem, &budget))) return rc;
        return !strcmp(sub, "info") ? cmd_info(pos[0]) : cmd_check(pos[0], budget);
    }
    return pdt_cli_usage("trace", "unknown subcommand '%s' (info, dump, check, export)", sub);
}
