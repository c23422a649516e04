/* pdt — internals of the pdt program (src/cli): the command table, the
 * option parser, and helpers shared by the commands.  Not a library API:
 * these functions may print and decide exit statuses.  pdtview links the
 * option parser too (opts.c: pdt_cli_parse, pdt_cli_usage). */
#ifndef PDT_CLI_H
#define PDT_CLI_H

#include <stdint.h>

#include "pdt/common.h"

/* Exit statuses of every command. */
enum {
    PDT_EXIT_OK = 0,    /* success */
    PDT_EXIT_CHECK = 1, /* `pdt check` found a violation */
    PDT_EXIT_USAGE = 2  /* bad usage, unreadable or malformed input, write failure */
};

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

/* ---- option parsing --------------------------------------------------------- */

typedef enum pdt_cli_optkind {
    PDT_OPT_FLAG,   /* int *: set to 1 */
    PDT_OPT_STR,    /* const char **: the next argument */
    PDT_OPT_POSNUM, /* double *: a finite number > 0 */
    PDT_OPT_LEVEL,  /* int *: 0, 1 or 2 */
    PDT_OPT_U64,    /* uint64_t *: a whole number >= 0 */
    PDT_OPT_NUM     /* double *: a finite number >= 0 */
} pdt_cli_optkind;

/* An option: long name ("--scale"), optional short name ("-o"), where to
 * store it.  Both "--scale K" and "--scale=K" are accepted. */
typedef struct pdt_cli_opt {
    const char *name;
    const char *shortname;
    pdt_cli_optkind kind;
    void *dst;
} pdt_cli_opt;

/* `cmd` names the command in messages: a pdt command ("hull": "pdt hull: ...")
 * or a whole program whose name starts with "pdt" ("pdtview: ...").
 *
 * Parse argv[1..argc) of command `cmd` against `opts` (terminated by an
 * entry with name NULL); positional arguments go to pos[0..*npos), at most
 * `maxpos`.  "--" ends the options; a lone "-" is positional.  Returns 0 on
 * success, 1 if --help/-h was given (help already printed from `help`),
 * 2 on a usage error (message already printed to stderr). */
int pdt_cli_parse(const char *cmd, const char *help, int argc, char **argv,
                  const pdt_cli_opt *opts, const char **pos, int maxpos, int *npos);

/* Print "pdt CMD: MESSAGE\n(see: pdt CMD --help)" to stderr (CMD a program
 * name starting with "pdt": without the "pdt ") and return PDT_EXIT_USAGE. */
/* A byte count: digits with an optional K, M or G (powers of 1024), an
 * optional B ("512M", "1G", "64KB").  Returns 0 and sets *out, or -1 if `s` is
 * not one (or is 0).  Used by --mem of pdtview and of pdt trace check. */
int pdt_cli_bytes(const char *s, uint64_t *out);
int pdt_cli_usage(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Print "pdt: " + the error's message to stderr; return the exit status for
 * it (PDT_EXIT_CHECK for PDT_ERR_CHECK, PDT_EXIT_USAGE otherwise). */
int pdt_cli_fail(const pdt_err *err);

/* 1 if paths a and b name the same existing file (never for "-"). */
int pdt_cli_same_file(const char *a, const char *b);

/* Peak resident memory of this process in KiB (getrusage), or 0. */
long pdt_cli_peak_kib(void);

#endif
