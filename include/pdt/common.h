/* pdt — common types, status codes and error reporting.
 *
 * Every library function that can fail returns a pdt_status and, when the
 * caller passes a pdt_err, fills in a human-readable message of the form
 * "file:line: what is wrong".  The first error sticks: later calls to
 * pdt_err_set() on an error that is already set do nothing.  Library code
 * never prints and never exits. */
#ifndef PDT_COMMON_H
#define PDT_COMMON_H

#include <stddef.h>
#include <stdint.h>

#define PDT_VERSION "0.1.0"

/* A point of the input: 32-bit signed integer coordinates. */
typedef struct pdt_point {
    int32_t x, y;
} pdt_point;

/* A triangle as three point indices, counter-clockwise. */
typedef struct pdt_tri {
    uint32_t v[3];
} pdt_tri;

typedef enum pdt_status {
    PDT_OK = 0,
    PDT_ERR_NOMEM,   /* allocation failed */
    PDT_ERR_IO,      /* a file could not be opened, read or written */
    PDT_ERR_PARSE,   /* malformed input (message names file and line) */
    PDT_ERR_ARG,     /* bad argument / usage */
    PDT_ERR_FORMAT,  /* wrong file format or version */
    PDT_ERR_CORRUPT, /* damaged data (checksum, truncation) */
    PDT_ERR_MPI,     /* a communication error */
    PDT_ERR_CHECK    /* a verification failed */
} pdt_status;

typedef struct pdt_err {
    pdt_status code;
    char msg[1024];
} pdt_err;

/* Record an error (printf-style message) unless one is already recorded.
 * Returns `code` so that callers can write `return pdt_err_set(...)`.
 * `err` may be NULL.  This is the one place to put a breakpoint on. */
pdt_status pdt_err_set(pdt_err *err, pdt_status code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Clear an error record. */
void pdt_err_clear(pdt_err *err);

/* Short English name of a status code ("out of memory", ...). */
const char *pdt_status_str(pdt_status s);

/* Seconds on the monotonic clock (CLOCK_MONOTONIC): what phase timings,
 * frame times and budgets of time read. */
double pdt_seconds(void);

/* Lexicographic key of a point: unsigned comparison of keys equals (x, then y)
 * comparison of the signed coordinates. */
static inline uint64_t pdt_key(pdt_point p)
{
    return ((uint64_t)((uint32_t)p.x ^ 0x80000000u) << 32) |
           (uint64_t)((uint32_t)p.y ^ 0x80000000u);
}

/* -1, 0, +1 as a is lexicographically before, equal to, after b. */
static inline int pdt_lex_cmp(pdt_point a, pdt_point b)
{
    if (a.x != b.x) return a.x < b.x ? -1 : 1;
    if (a.y != b.y) return a.y < b.y ? -1 : 1;
    return 0;
}

#endif
