/* pdt — internals shared by the readers and writers of src/io (not public).
 *
 * A file is read whole into memory (pdt_io_load) and then scanned line by
 * line with a cursor.  Lines end with '\n'; '\r', spaces and tabs are
 * whitespace, so CRLF files and trailing spaces are fine; '#' starts a
 * comment that runs to the end of the line. */
#ifndef PDT_IO_INTERNAL_H
#define PDT_IO_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "pdt/common.h"

/* A whole file in memory; buf[len] == '\0'. */
typedef struct pdt_io_text {
    char *buf;
    size_t len;
    size_t mapped; /* 0: buf is malloc'd; else the bytes mapped (read only) */
    void *map_base; /* where the mapping starts (NULL: at buf) */
} pdt_io_text;

/* Read the file `path` ("-" = standard input) into t.  Errors name the file:
 * "FILE: cannot open: REASON", "FILE: is a directory", "FILE: read error: REASON",
 * "FILE: is a FIFO (named pipe), not a regular file ..." (pdt_open_input:
 * only standard input may be something else), "FILE:LINE: no end of line in
 * N bytes ..." (PDT_IO_LINE_SPAN: what is read is not a text at all).
 * A regular file of 1 MiB or more is mapped (read only: its page-cache pages
 * are used as they are, no fresh memory; the file must not shrink while it
 * is read), anything else is read into a malloc'd buffer.  Free t with
 * pdt_io_text_free. */
pdt_status pdt_io_load(const char *path, pdt_io_text *t, pdt_err *err);
void pdt_io_text_free(pdt_io_text *t);
/* Bytes [lo, hi) of a regular file mapped read only, hi a line start or the
 * file's end, when hi - lo is 1 MiB or more: t->buf points at byte lo, a
 * zero byte follows at t->buf[hi - lo] (the page holding it is the only one
 * copied), t->len = hi - lo.  Returns 0, or -1 (nothing mapped: read the
 * bytes instead).  Free with pdt_io_text_free. */
int pdt_io_map_part(int fd, uint64_t lo, uint64_t hi, pdt_io_text *t);

/* A line cursor over a loaded text. */
typedef struct pdt_io_cur {
    const char *p;    /* current position */
    const char *end;  /* one past the last byte */
    const char *name; /* file name for messages */
    size_t line;      /* number of the current line, 1-based */
    int done;         /* the end was reached (line then names the last line) */
    int fields;       /* 1: ',' and ';' also end a token (point text files: CSV) */
} pdt_io_cur;

void pdt_io_cur_init(pdt_io_cur *c, const pdt_io_text *t, const char *name);

/* Move to the next line that holds something other than whitespace and a
 * comment.  Returns 1 (c->p at its first non-blank byte, c->line its number)
 * or 0 at the end of the text. */
int pdt_io_next_line(pdt_io_cur *c);

/* The next token of the current line: returns 1 and sets *tok / *len, or 0
 * when only whitespace or a comment is left on the line.  Never crosses a
 * line end. */
int pdt_io_token(pdt_io_cur *c, const char **tok, size_t *len);

/* With c->fields set: skip blanks and at most one field separator (',' or
 * ';') between two tokens of a line, so "x y", "x,y", "x;y", "x\ty" and
 * "x , y" all read as two tokens; a second separator (",,") then stops
 * pdt_io_token, which reports no token.  Without c->fields: skips blanks. */
void pdt_io_field_sep(pdt_io_cur *c);

/* Skip the rest of the current line (including its '\n'). */
void pdt_io_skip_line(pdt_io_cur *c);

/* The current line must hold nothing more: move to the next line, or report
 * "NAME:LINE: unexpected 'TOKEN' after WHAT" (PDT_ERR_PARSE) in err (a
 * leftover field separator counts as a token). */
pdt_status pdt_io_end_line(pdt_io_cur *c, const char *what, pdt_err *err);

/* Parse a plain decimal integer ([+-]digits).  Returns 0 and *v on success,
 * 1 if the token is not a plain integer, 2 if it has more than 18 digits
 * (*v is then set to INT64_MAX or INT64_MIN by sign). */
int pdt_io_parse_int(const char *tok, size_t len, int64_t *v);

/* 1 if the token is a decimal number ([+-]digits[.digits][e[+-]digits]). */
int pdt_io_is_decimal(const char *tok, size_t len);

/* A decimal number for --scale: value = (neg ? -1 : 1) * m * 10^e with m
 * holding at most 19 significant digits and no trailing zeros (m = 0: e = 0,
 * neg = 0), so equal values compare equal field by field.  `inexact` is 1
 * when digits beyond the 19th were dropped. */
typedef struct pdt_io_dec {
    uint64_t m;
    int32_t e;
    uint8_t neg, inexact;
} pdt_io_dec;

/* Parse a decimal token; returns 0 on success, 1 if it is not a number. */
int pdt_io_parse_dec(const char *tok, size_t len, pdt_io_dec *d);

/* round(d * scale) (halves away from zero) if it fits in int32: returns 0
 * and *v, or 1 if the result is out of range.  Exact when scale is an
 * integer and d is exact; otherwise computed in double precision. */
int pdt_io_scale_round(const pdt_io_dec *d, const char *tok, size_t len, double scale,
                       int32_t *v);

/* Copy a token into buf (size >= 48) for a message: at most 40 bytes,
 * control and non-ASCII bytes as \xNN, "..." when cut. */
const char *pdt_io_show(const char *tok, size_t len, char *buf, size_t cap);

#endif
