/* pdt — small helpers shared by the commands, and the options triangulate
 * and hull share (the parser itself is in opts.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include "cli.h"
#include "run_opts.h"

int pdt_cli_fail(const pdt_err *err)
{
    fprintf(stderr, "pdt: %s\n", err->msg[0] ? err->msg : pdt_status_str(err->code));
    return err->code == PDT_ERR_CHECK ? PDT_EXIT_CHECK : PDT_EXIT_USAGE;
}

long pdt_cli_peak_kib(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
    return ru.ru_maxrss; /* KiB on Linux */
}

int pdt_cli_parse_run_opts(const char *cmd, const char *help, int argc, char **argv,
                           pdt_run_opts *o)
{
    memset(o, 0, sizeof *o);
    o->command = cmd;
    o->trace_level = 1;
    o->partition = PDT_PART_DEFAULT;
    o->argc = argc;
    o->argv = argv;
    const char *part = NULL;
    const pdt_cli_opt opts[] = {
        { "--output", "-o", PDT_OPT_STR, &o->output },
        { "--scale", NULL, PDT_OPT_POSNUM, &o->scale },
        { "--stats", NULL, PDT_OPT_FLAG, &o->stats },
        { "--trace", NULL, PDT_OPT_STR, &o->trace_dir },
        { "--trace-level", NULL, PDT_OPT_LEVEL, &o->trace_level },
        /* last: for hull, the end of the list (a hull has no partition) */
        { strcmp(cmd, "triangulate") == 0 ? "--partition" : NULL, NULL, PDT_OPT_STR, &part },
        { NULL, NULL, PDT_OPT_FLAG, NULL },
    };
    const char *pos[1];
    int npos;
    int rc = pdt_cli_parse(cmd, help, argc, argv, opts, pos, 1, &npos);
    if (rc == 1) return PDT_EXIT_OK;
    if (rc) return PDT_EXIT_USAGE;
    if (npos != 1) return pdt_cli_usage(cmd, "needs one INPUT file");
    if (part && !strcmp(part, "strips")) o->partition = PDT_PART_STRIPS;
    else if (part && !strcmp(part, "bisect")) o->partition = PDT_PART_BISECT;
    else if (part) return pdt_cli_usage(cmd, "--partition needs strips or bisect, not '%s'", part);
    o->input = pos[0];
    return -1;
}
