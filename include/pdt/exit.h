/* pdt — the exit statuses of both programs (pdt and pdtview). */
#ifndef PDT_EXIT_H
#define PDT_EXIT_H

/* Exit statuses of every pdt command and of pdtview. */
enum {
    PDT_EXIT_OK = 0,    /* success */
    PDT_EXIT_CHECK = 1, /* `pdt check` found a violation */
    PDT_EXIT_USAGE = 2  /* bad usage, unreadable or malformed input, write failure */
};

#endif
