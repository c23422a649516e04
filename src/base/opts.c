/* pdt — the option parser of the pdt commands and of pdtview (one parser:
 * the same spellings, the same messages, no silent replacement of a bad
 * value). */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pdt/exit.h"
#include "pdt/opts.h"

/* "pdt " before a command name ("hull"), nothing before a program name
 * ("pdtview"). */
static const char *prog_prefix(const char *cmd)
{
    return strncmp(cmd, "pdt", 3) == 0 ? "" : "pdt ";
}

int pdt_cli_usage(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "%s%s: ", prog_prefix(cmd), cmd);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\n(see: %s%s --help)\n", prog_prefix(cmd), cmd);
    return PDT_EXIT_USAGE;
}

int pdt_cli_bytes(const char *s, uint64_t *out)
{
    char *end;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (end == s || errno || *s == '-') return -1;
    unsigned shift = 0;
    if (*end == 'K' || *end == 'k') shift = 10;
    else if (*end == 'M' || *end == 'm') shift = 20;
    else if (*end == 'G' || *end == 'g') shift = 30;
    if (shift) end++;
    if (*end == 'B' || *end == 'b') end++;
    if (*end || v == 0 || v > (UINT64_MAX >> shift)) return -1;
    *out = (uint64_t)v << shift;
    return 0;
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
    case PDT_OPT_POSNUM:
    case PDT_OPT_NUM: {
        errno = 0;
        double x = strtod(v, &end);
        int pos = o->kind == PDT_OPT_POSNUM;
        if (end == v || *end || errno || !isfinite(x) || x < 0 || (pos && x == 0)) {
            pdt_cli_usage(cmd, "%s needs a %s number, not '%s'", o->name,
                          pos ? "positive" : "non-negative", v);
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

