/* pdt — the option parser both programs use (src/base/opts.c).  For
 * programs only: it prints usage errors and help to stderr and stdout. */
#ifndef PDT_OPTS_H
#define PDT_OPTS_H

#include <stdint.h>

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

/* A byte count: digits with an optional K, M or G (powers of 1024), an
 * optional B ("512M", "1G", "64KB").  Returns 0 and sets *out, or -1 if `s` is
 * not one (or is 0).  Used by --mem of pdtview and of pdt trace check. */
int pdt_cli_bytes(const char *s, uint64_t *out);

/* Print "pdt CMD: MESSAGE\n(see: pdt CMD --help)" to stderr (CMD a program
 * name starting with "pdt": without the "pdt ") and return PDT_EXIT_USAGE. */
int pdt_cli_usage(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
