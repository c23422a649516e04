/* pdt — internals of the pdt program (src/cli): the command table and
 * helpers shared by the commands.  Not a library API: these functions may
 * print and decide exit statuses.  The exit table (pdt/exit.h) and the
 * option parser (pdt/opts.h, src/base/opts.c) are shared with pdtview. */
#ifndef PDT_CLI_H
#define PDT_CLI_H

#include <stdint.h>

#include "pdt/common.h"
#include "pdt/exit.h"
#include "pdt/opts.h"

/* One command: `pdt NAME ...` runs fn(argc, argv) with argv[0] = NAME. */
typedef struct pdt_cli_cmd {
    const char *name;
    int (*fn)(int argc, char **argv);
    const char *summary;
} pdt_cli_cmd;

int pdt_cmd_triangulate(int argc, char **argv);
int pdt_cmd_hull(int argc, char **argv);
int pdt_cmd_check(int argc, char **argv);
int pdt_cmd_gen(int argc, char **argv);
int pdt_cmd_trace(int argc, char **argv);


/* Print "pdt: " + the error's message to stderr; return the exit status for
 * it (PDT_EXIT_CHECK for PDT_ERR_CHECK, PDT_EXIT_USAGE otherwise). */
int pdt_cli_fail(const pdt_err *err);


/* Peak resident memory of this process in KiB (getrusage), or 0. */
long pdt_cli_peak_kib(void);

#endif
