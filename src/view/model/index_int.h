/* pdt — the kept index of a run folder: the replay model's tables in a file,
 * built at the first opening and memory-mapped at the next ones.
 *
 * File layout (native byte order; a different build's layout is refused):
 *   [0, 4096)        header: magic, version, the run's identity, the sizes
 *                    of the record types, the table sizes, per section its
 *                    offset and length, the place of the chunk checksums
 *                    (a CRC-32C per 16 MiB of every section: verified by
 *                    several threads at each opening); the header's own CRC
 *   sections         the per-event tables (object, kind: written by the
 *                    build's first pass as the events come, completed last);
 *                    the events: the merged order as segments of
 *                    consecutive events of one rank (the events themselves
 *                    stay in the rank files: the table of their encoded
 *                    blocks is a section below; decoded on demand, each
 *                    block's checksum checked: evsrc.c); then the points'
 *                    first lifts, the triangles (in the order of their
 *                    first events) and their histories (as the build
 *                    grouped them: a bucket of triangles after the other,
 *                    each triangle's entries together), streamed here while
 *                    they are built (pdt_replay_build), then every other table of
 *                    the replay (replay_int.h), the points and the reader's
 *                    warnings about the run, each at a 64-byte boundary
 *                    (so that a valid index opens without reading the run),
 *                    and last the checkpoints, one after the other, each
 *                    holding the triangles born before its cursor (their
 *                    places and those counts are in the header)
 *
 * The identity of a run is a hash of the name, size and modification time
 * of every file in the folder (but dot-files) and of the manifest's bytes.
 * An index whose identity, sizes or checksums do not match is rebuilt.
 *
 * Private to src/view/model (index.c, index_load.c, index_verify.c). */
#ifndef PDT_VIEW_INDEX_INT_H
#define PDT_VIEW_INDEX_INT_H

#include <limits.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>

#include "pdt/view/replay.h"
#include "replay_int.h"

#define INDEX_NAME ".pdtview-index"
#define INDEX_VERSION 13u /* raised whenever the layout changes: an index of another
                             * version is rebuilt */
#define ICK_MIN_EVERY 1024u  /* checkpoints in the index: every m/8 events, at least this */
#define ICK_PARTS 8u
/* ... and at most every ICK_MAX_EVERY events while ICK_MAX_PARTS allow: a
 * seek then steps at most half of that, 2^22 events, after restoring a
 * checkpoint, so that a far seek costs about what restoring a checkpoint
 * costs.  That holds up to 4*10^8 events (some 10^8 points); beyond, the
 * steps grow with the run, and each part more costs one more checkpoint's
 * disk.  (docs/benchmarks.md has the seek times.) */
#define ICK_MAX_EVERY ((size_t)1 << 23)
#define ICK_MAX_PARTS 47u
_Static_assert(ICK_MAX_PARTS + 1 <= PDT_ICK_MAX, "the header holds every checkpoint's place");
#define CHUNK_BYTES ((uint64_t)16 << 20) /* sections are checksummed in chunks of this: the
                                          * least a lazily checked frame reads (smaller chunks
                                          * made lazily checked seeks slower) */
#define HDR_BYTES 4096u
#define EST_BYTES_PER_EVENT 100u /* what the replay model holds per event in memory */

enum {
    S_SEGS, S_EVOBJ, S_TRIS, S_HIST, S_EDGES, S_NODES, S_PHASES, S_MERGES,
    S_MSGS, S_HULLS, S_CH, S_SLOTCH, S_SLOTSTART, S_LIFT, S_SORT, S_DEL, S_SORTPOS, S_BOXLO,
    S_BOXHI, S_HASBOX, S_POINTS, S_WARN, S_EVKIND, S_BLKTAB, S_RANKBLK, S_CKPT, NSEC
};

_Static_assert(S_CKPT == NSEC - 1, "the checkpoints are the last section (write_tables)");

typedef struct isec {
    uint64_t off, bytes;
    uint32_t crc, pad;
} isec;

typedef struct ihdr {
    char magic[8];
    uint32_t version, hdr_crc;  /* hdr_crc: over the header with this field 0 */
    uint64_t ident, file_bytes;
    uint32_t layout[12];        /* sizes of the record types */
    uint64_t n, m, skipped, nranks;
    uint64_t count[NSEC];       /* elements per section */
    uint64_t kind_count[64];
    isec sec[NSEC];
    uint64_t ick_every, nick;   /* the checkpoints (S_CKPT): checkpoint c at ick_off[c] */
    uint64_t ick_off[PDT_ICK_MAX + 1], ick_born[PDT_ICK_MAX];  /* of the section, holding
                                 * the triangles born before its cursor: ick_born[c] */
    isec ctab;                  /* CRC-32C of every CHUNK_BYTES of every section,
                                 * in section order; ctab.crc covers the table */
} ihdr;

_Static_assert(sizeof(ihdr) <= HDR_BYTES, "index header fits its page");
_Static_assert(PDT_EV_KIND_COUNT <= 64, "kind counts fit the header");

static const char magic[8] = {'P', 'D', 'T', 'V', 'I', 'D', 'X', '\n'};

static inline uint64_t chunks_of(uint64_t bytes) { return (bytes + CHUNK_BYTES - 1) / CHUNK_BYTES; }

/* ---- chunk checksums of data written in order ------------------------------------ */

/* The CRC-32C of every CHUNK_BYTES of a section, made as the section is
 * written from its start to its end (so that the build does not read it
 * back): crc[k] for chunk k, grown as needed. */
typedef struct crcacc {
    uint32_t *crc;
    size_t n, cap;
    uint64_t pos;   /* bytes fed */
    uint32_t cur;   /* of the chunk being fed */
    int nomem;
} crcacc;

/* ---- verifying the chunks, in parallel ----------------------------------------- */

typedef struct verify_job {
    int fd;
    const ihdr *h;
    uint32_t *tab;              /* chunk checksums */
    int compute;                /* 1: fill tab in (building), 0: compare with it */
    const uint8_t *todo;        /* compute: NULL, or per chunk 1 if it is to be read */
    uint64_t nchunk;
    uint64_t *first;            /* per section: index of its first chunk in tab */
    atomic_uint_fast64_t next;  /* next chunk to check */
    atomic_int bad;
} verify_job;

/* ---- verifying a big index lazily: each chunk when it is first asked for ------
 *
 * Checksumming a whole index of gigabytes at every opening costs seconds; a
 * frame reads a small part of it.  So a big index (pdt_replay_lazy_verify)
 * is checked in two steps.  At the opening: its header, its chunk table and
 * every chunk of its small sections.  The big tables (the per-event ones,
 * the triangles and their histories, the points and their per-point tables,
 * the checkpoints) are checked a chunk at a time by the replay itself,
 * before it reads them: every place of the model that reads such a table
 * asks for the range it is about to read (pdt_ix_need and the helpers in
 * replay_int.h), and the chunks there not checked yet are read (pread) and
 * checksummed then, by the verifying threads.  A flag per chunk remembers
 * what is checked.  The tables the renderer is handed (triangles, their
 * histories, points) are asked for whole (points) or up to the triangles
 * born by the state's cursor (pdt_ix_need_born), which is all a frame of
 * that state reads.  A mismatch removes the index and tells the program,
 * which stops (the replay cannot go on with a damaged table).  No page of
 * the index is closed and no fault is trapped. */

typedef struct lazy {
    int fd;                      /* the file, read (pread) for the checksums */
    ihdr h;                      /* its header */
    uint64_t first[NSEC + 1];    /* per section: index of its first chunk in tab */
    uint64_t nchunk;
    uint32_t *tab;               /* the chunk checksums */
    uint8_t *done;               /* per chunk: verified */
    size_t tris_upto;            /* triangles 0 .. tris_upto-1 and their entries checked */
    int bad;                     /* a mismatch was found (reported once) */
    char path[PATH_MAX];
    char msg[PATH_MAX + 256];
} lazy;

/* ---- shared between the index's files (each defined in the file named) ----- */

/* index_load.c */
void pdt_ix_layout_of(uint32_t out[12]);
void pdt_ix_sections(pdt_replay *r, void **ptr[NSEC], size_t elem[NSEC], uint64_t count[NSEC]);
pdt_status pdt_ix_run_ident(const char *dir, uint64_t *id, pdt_err *err);
int pdt_ix_cache_dir(char *buf, size_t cap);
int pdt_ix_make_dirs(const char *path);
int pdt_ix_index_path(const char *dir, int where, char *buf, size_t cap);
pdt_replay *pdt_ix_load(const char *path, const char *dir, uint64_t ident, const pdt_point *pts,
                        size_t n, int verify, char *why, size_t wcap);

/* index.c */
uint32_t pdt_ix_ihdr_crc(const ihdr *h);

/* index_verify.c */
/* Indexes from this size on are verified lazily (pdt_replay_lazy_verify). */
extern uint64_t pdt_ix_lazy_min_bytes;
void pdt_ix_crc_feed(crcacc *a, const void *data, size_t len);
int pdt_ix_crc_done(const crcacc *a, uint64_t bytes, uint32_t *tab);
void pdt_ix_run_job(verify_job *j);
uint32_t *pdt_ix_read_ctab(int fd, const ihdr *h, char *why, size_t wcap);
int pdt_ix_verify_chunks(int fd, const ihdr *h, char *why, size_t wcap);
/* The lazy checks of the index open on fd (header h, chunk table tab, taken
 * over), the small sections checked now: NULL when out of memory, or with
 * a reason in why when a small section does not match. */
lazy *pdt_ix_lazy_start(const ihdr *h, uint32_t *tab, int fd, const char *path, char *why,
                        size_t wcap);
void pdt_ix_lazy_stop(lazy *L);
void pdt_ix_run_damaged(void *ctx, uint32_t rank);

/* ---- the checkpoints (index_ck.c) ----------------------------------------------- */

/* Start stepping through r's events (read back from the index fd) on a
 * thread of its own, the checkpoints going to fd at off; NULL when out of
 * memory.  pdt_ix_ck_finish (on the thread that started it, once its own
 * tables are written) writes what the stepping thread handed over, waits
 * for it and frees j: 1, or 0 with errno set; *crc takes the section's
 * chunk checksums, *copy_bytes what the copies of states held. */
typedef struct ck_job ck_job;
ck_job *pdt_ix_ck_start(pdt_replay *r, int fd, uint64_t off);
int pdt_ix_ck_finish(ck_job *j, crcacc *crc, uint64_t *copy_bytes);

#endif
