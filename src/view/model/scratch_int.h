/* pdt — the scratch files of a streamed build (the kept index's), private
 * to src/view/model: where the build's spill and its other scratch tables
 * (PDT_SCR_*, replay_int.h) live between being written and read back.
 *
 * Each scratch file has a memory part, its first bytes, and a file part,
 * the rest: bytes [0, split) are held in an anonymous mapping, bytes from
 * split on in an unnamed file beside the index.  All memory parts together
 * hold at most `pool` bytes (a share of the build's --mem budget, counted in
 * whole 2 MiB pages): a part grows as the build writes further into its
 * file while the pool has room, and the first write the pool cannot take
 * fixes its split for good.  A scratch file the pool holds whole never
 * reaches the page cache or the disk: writing a gigabyte there costs the
 * system a second or two of copying, its memory a fraction of that.  Safe
 * for the build's threads to use at once (a file's writes and reads of
 * disjoint parts). */
#ifndef PDT_VIEW_SCRATCH_INT_H
#define PDT_VIEW_SCRATCH_INT_H

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>

#include "replay_int.h"

typedef struct scr_file {
    int fd;          /* the file part (-1: none yet) */
    char *mem;       /* the memory part's mapping, `pool` bytes of address space (NULL: none) */
    uint64_t split;  /* bytes [0, split) are the memory part's (whole pages of the pool) */
    int fixed;       /* split is final: the pool could not take a write beyond it */
} scr_file;

typedef struct scr_set {
    pthread_mutex_t mu;
    const char *near;   /* the file parts are made in this path's folder */
    uint64_t pool;      /* the most all memory parts hold at once */
    uint64_t left;      /* what the pool still has */
    uint64_t peak;      /* the most held at once */
    scr_file f[PDT_SCR_COUNT];
} scr_set;

/* An empty set whose memory parts share `pool` bytes (0: every byte goes
 * to the files) and whose file parts are made beside path `near`. */
void pdt_scr_init(scr_set *s, const char *near, uint64_t pool);

/* Make file's file part now (so that a folder that cannot hold one is
 * found before the build starts): 1, or 0 with errno set. */
int pdt_scr_make_file(scr_set *s, int file);

/* Write `bytes` at offset `at` of scratch file `file`; read them back.  1
 * on success, 0 with errno set. */
int pdt_scr_put(scr_set *s, int file, uint64_t at, const void *p, size_t bytes);
int pdt_scr_get(scr_set *s, int file, uint64_t at, void *p, size_t bytes);

/* The build is done with `file`: its memory goes back to the pool (and to
 * the system), its file part is closed (unnamed: its pages go with it). */
void pdt_scr_drop(scr_set *s, int file);

/* Every file dropped. */
void pdt_scr_free(scr_set *s);

#endif
