/* pdt — option parsing and small helpers shared by the commands. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>

#include "cli.h"
#include "run_opts.h"

int pdt_cli_usage(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "pdt %s: ", cmd);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\n(see: pdt %s --help)\n", cmd);
    return PDT_EXIT_USAGE;
}

int pdt_cli_fail(const pdt_err *err)
{
    fprintf(stderr, "pdt: %s\n", err->msg[0] ? err->msg : pdt_status_str(err->code));
    return err->code == PDT_ERR_CHECK ? PDT_EXIT_CHECK : PDT_EXIT_USAGE;
}

int pdt_cli_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (!a || !b || strcmp(a, "-") == 0 || strcmp(b, "-") == 0) return 0;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
           sa.st_ino == sb.st_ino;
}

double pdt_cli_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

long pdt_cli_peak_kib(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
    return ru.ru_maxrss; /* KiB on Linux */
}

/* Store the value of option `o` from text `v`; 0 on success. */
static int store(const char *cmd, const pdt_cli_opt *o, const char *v)
{
    char *end;
    switch (o->kind) {
    case PDT_OPT_FLAG:
        *(int *)o->dst = 1;
        return 0;
    case PDT_OPT_STR:
        *(const char **)o->dst = v;
        return 0;
    case PDT_OPT_POSNUM: {
        errno = 0;
        double x = strtod(v, &end);
        if (end == v || *end || errno || !isfinite(x) || x <= 0) {
            pdt_cli_usage(cmd, "%s needs a positive number, not '%s'", o->name, v);
            return 1;
        }
        *(double *)o->dst = x;
        return 0;
    }
    case PDT_OPT_LEVEL:
        if (strlen(v) != 1 || v[0] < '0' || v[0] > '2') {
            pdt_cli_usage(cmd, "%s needs 0, 1 or 2, not '%s'", o->name, v);
            return 1;
        }
        *(int *)o->dst = v[0] - '0';
        return 0;
    case PDT_OPT_U64: {
        errno = 0;
        unsigned long long x = strtoull(v, &end, 10);
        if (end == v || *end || errno || v[0] == '-' || v[0] == '+') {
            pdt_cli_usage(cmd, "%s needs a whole number, not '%s'", o->name, v);
            return 1;
        }
        *(uint64_t *)o->dst = (uint64_t)x;
        return 0;
    }
    }
    return 1;
}

int pdt_cli_parse(const char *cmd, const char *help, int argc, char **argv,
                  const pdt_cli_opt *opts, const char **pos, int maxpos, int *npos)
{
    int only_pos = 0;
    *npos = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!only_pos && (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0)) {
            fputs(help, stdout);
            return 1;
        }
        if (!only_pos && strcmp(a, "--") == 0) {
            only_pos = 1;
            continue;
        }
        if (only_pos || a[0] != '-' || a[1] == '\0') {
            if (*npos >= maxpos) {
                pdt_cli_usage(cmd, "unexpected argument '%s'", a);
                return 2;
            }
            pos[(*npos)++] = a;
            continue;
        }
        const pdt_cli_opt *o = NULL;
        const char *val = NULL;
        for (const pdt_cli_opt *q = opts; q->name; q++) {
            size_t len = strlen(q->name);
            if (strcmp(a, q->name) == 0 || (q->shortname && strcmp(a, q->shortname) == 0)) {
                o = q;
                break;
            }
            if (strncmp(a, q->name, len) == 0 && a[len] == '=' && q->kind != PDT_OPT_FLAG) {
                o = q;
                val = a + len + 1;
                break;
            }
        }
        if (!o) {
            pdt_cli_usage(cmd, "unknown option '%s'", a);
            return 2;
        }
        if (o->kind != PDT_OPT_FLAG && !val) {
            if (i + 1 >= argc) {
                pdt_cli_usage(cmd, "%s needs a value", a);
                return 2;
            }
            val = argv[++i];
        }
        if (store(cmd, o, val) != 0) return 2;
    }
    return 0;
}

int pdt_cli_parse_run_opts(const char *cmd, const char *help, int argc, char **argv,
                           pdt_run_opts *o)
{
    memset(o, 0, sizeof *o);
    o->command = cmd;
    o->trace_level = 1;
    o->argc = argc;
    o->argv = argv;
    const pdt_cli_opt opts[] = {
        { "--output", "-o", PDT_OPT_STR, &o->output },
        { "--scale", NULL, PDT_OPT_POSNUM, &o->scale },
        { "--stats", NULL, PDT_OPT_FLAG, &o->stats },
        { "--trace", NULL, PDT_OPT_STR, &o->trace_dir },
        { "--trace-level", NULL, PDT_OPT_LEVEL, &o->trace_level },
        { NULL, NULL, PDT_OPT_FLAG, NULL },
    };
    const char *pos[1];
    int npos;
    int rc = pdt_cli_parse(cmd, help, argc, argv, opts, pos, 1, &npos);
    if (rc == 1) return PDT_EXIT_OK;
    if (rc) return PDT_EXIT_USAGE;
    if (npos != 1) return pdt_cli_usage(cmd, "needs one INPUT file");
    o->input = pos[0];
    return -1;
}
