/* pdt gen — write a generated point set (pdt_gen) as a point file. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "pdt/gen.h"
#include "pdt/io.h"

static const char help_head[] =
    "usage: pdt gen KIND N [--seed S] [-o FILE]\n"
    "\n"
    "Write N points of family KIND, one 'x y' per line (Triangle's .node format\n"
    "when FILE ends in .node), to standard output or FILE.  The same KIND, N and\n"
    "seed (default 1) always give the same points.\n"
    "\n"
    "kinds:";

static const char help_tail[] = "\n\nExit status: 0 success, 2 usage error.\n";

/* The help text with the list of kinds (malloc'd). */
static char *make_help(void)
{
    size_t len = sizeof help_head + sizeof help_tail;
    const char *const *k = pdt_gen_kinds();
    for (size_t i = 0; k[i]; i++) len += strlen(k[i]) + 1;
    char *h = malloc(len);
    if (!h) return NULL;
    strcpy(h, help_head);
    for (size_t i = 0; k[i]; i++) {
        strcat(h, " ");
        strcat(h, k[i]);
    }
    strcat(h, help_tail);
    return h;
}

int pdt_cmd_gen(int argc, char **argv)
{
    uint64_t seed = 1;
    const char *out = NULL;
    const pdt_cli_opt opts[] = {
        { "--seed", NULL, PDT_OPT_U64, &seed },
        { "--output", "-o", PDT_OPT_STR, &out },
        { NULL, NULL, PDT_OPT_FLAG, NULL },
    };
    char *help = make_help();
    if (!help) {
        fprintf(stderr, "pdt gen: out of memory\n");
        return PDT_EXIT_USAGE;
    }
    const char *pos[2];
    int npos;
    int rc = pdt_cli_parse("gen", help, argc, argv, opts, pos, 2, &npos);
    free(help);
    if (rc == 1) return PDT_EXIT_OK;
    if (rc) return PDT_EXIT_USAGE;
    if (npos != 2) return pdt_cli_usage("gen", "needs a KIND and a count N");
    char *end;
    unsigned long long n = strtoull(pos[1], &end, 10);
    if (end == pos[1] || *end || pos[1][0] == '-' || n >= UINT32_MAX)
        return pdt_cli_usage("gen", "N must be a whole number below 2^32 - 1, not '%s'", pos[1]);

    pdt_err err = { PDT_OK, "" };
    pdt_point *pts = NULL;
    pdt_status st = pdt_gen(pos[0], (size_t)n, seed, &pts, &err);
    if (st == PDT_OK) st = pdt_write_points(out, pts, (size_t)n, &err);
    rc = st == PDT_OK ? PDT_EXIT_OK : pdt_cli_fail(&err);
    free(pts);
    return rc;
}
