/* pdt — run folders: the trace writer and the reader library.
 *
 * A run folder holds a manifest (text, "manifest"), the input points (binary,
 * "points.bin") and one binary trace file per rank ("rank-NNNN.trace", four
 * or more digits).  The format is documented in docs/trace-format.md.
 * Writing never involves MPI: the parallel driver writes points.bin with its
 * own parallel file API (every rank its block; the checksums combined) and
 * calls these functions for the rest.
 *
 * What a driver calls (sequential: nranks = 1, rank = 0, offsets {0}):
 *
 *   1. every rank:  pdt_tw_open(dir, rank, level, &w, &err)   (creates dir;
 *                   rank 0 also removes a stale manifest/points.bin)
 *   2. measure clock offsets (MPI driver): after a barrier every rank reads
 *                   pdt_tw_now(w); rank 0 gathers them and sets
 *                   offset[r] = now[0] - now[r] (or better, a ping-pong
 *                   estimate); adding offset[r] to rank r's times puts them
 *                   on rank 0's time line.
 *   3. rank 0:      fill a pdt_manifest (format_version = PDT_TRACE_FORMAT_MAJOR,
 *                   program_version = PDT_VERSION, command, command_line,
 *                   input_name, input_checksum = pdt_points_checksum(pts, n)
 *                   (or combined from the ranks' blocks: pdt_crc64_combine),
 *                   n, nranks, level, clock_offset_ns, wall_start_ns =
 *                   pdt_wall_ns()) and call pdt_run_write_meta(dir, &m, pts, n).
 *                   Doing this before the run means a killed run still
 *                   leaves a complete folder.  Writing it again later is fine.
 *   4. pass pdt_tw_hook(w) to the algorithm (set hook->gid if local indices
 *                   must be translated to global input indices).
 *   5. every rank:  pdt_tw_close(w, &err) — writes the last block and the end
 *                   marker; its status reports any write error that happened
 *                   during the run (the hook cannot return errors; after the
 *                   first write error the writer stops recording).
 *
 * Events carry global input indices (duplicates: the smallest index), so
 * that every rank's events refer to the same points.bin. */
#ifndef PDT_TRACEFILE_H
#define PDT_TRACEFILE_H

#include "pdt/common.h"
#include "pdt/checksum.h"
#include "pdt/trace.h"

/* Version of the run-folder format written by this code.  A reader accepts
 * every minor version of the major versions it knows (unknown manifest keys
 * and unknown event kinds are skipped); another major version is refused.
 * Format 2 differs from 1 only in the manifest's input_checksum (CRC-64/XZ,
 * which ranks can compute in parallel, instead of FNV-1a 64); this reader
 * reads both (PDT_TRACE_FORMAT_OLDEST). */
#define PDT_TRACE_FORMAT_MAJOR 2
#define PDT_TRACE_FORMAT_MINOR 0
#define PDT_TRACE_FORMAT_OLDEST 1

/* ---- manifest ------------------------------------------------------------ */

typedef struct pdt_manifest {
    int format_version;
    char program_version[32];
    char *command_line;      /* malloc'd */
    char *input_name;        /* malloc'd */
    uint64_t input_checksum; /* of the input points as read (input_checksum_kind) */
    uint64_t n;              /* points in the input */
    int nranks;
    int level;               /* trace level */
    char command[16];        /* "triangulate" or "hull" */
    int64_t *clock_offset_ns;/* per rank: add to a rank's times to align (malloc'd) */
    uint64_t wall_start_ns;  /* realtime clock at the start (rank 0) */
    int format_minor;        /* minor version (reader: as found in the file) */
    int input_checksum_kind; /* PDT_CHECKSUM_CRC64 (0: what writers write) or
                              * PDT_CHECKSUM_FNV1A64 (format 1 runs) */
    int partition;           /* a triangulate run's regions: 0 strips (no
                              * 'partition' line), 1 bisect (pdt_par_partition) */
} pdt_manifest;

enum { PDT_CHECKSUM_CRC64 = 0, PDT_CHECKSUM_FNV1A64 = 1 };

/* Free the malloc'd members (not m itself); m may be NULL. */
void pdt_manifest_free(pdt_manifest *m);

/* CRC-64/XZ of the points as little-endian int32 pairs (x, y), i.e. of the
 * data part of points.bin: the manifest's input_checksum (format 2). */
uint64_t pdt_points_checksum(const pdt_point *pts, size_t n);
/* FNV-1a 64 of the same bytes: the input_checksum of format 1 manifests. */
uint64_t pdt_points_fnv1a64(const pdt_point *pts, size_t n);
/* The 8n bytes of pts[0..n) as points.bin stores them (i32 x, i32 y,
 * little-endian) into out. */
void pdt_points_encode(uint8_t *out, const pdt_point *pts, size_t n);
/* points.bin's header (PDT_POINTS_HEADER_BYTES) for n points whose 8n data
 * bytes have CRC-32C data_crc. */
#define PDT_POINTS_HEADER_BYTES 24
void pdt_points_header(uint8_t *h, uint64_t n, uint32_t data_crc);
/* Realtime clock in nanoseconds since the epoch (for wall_start_ns). */
uint64_t pdt_wall_ns(void);

/* ---- writer (one per rank) --------------------------------------------------- */

typedef struct pdt_trace_writer pdt_trace_writer;

/* Create the run folder `dir` if needed (every rank may call this at the same
 * time) and the file dir/rank-NNNN.trace (truncated if present).  Rank 0 also
 * removes a stale dir/manifest and dir/points.bin.  Returns in *w a writer for
 * `rank` whose hook (pdt_tw_hook) records events of level <= `level`
 * (1 or 2); its clock starts at 0 now.  The caller owns *w (pdt_tw_close). */
pdt_status pdt_tw_open(const char *dir, int rank, int level, pdt_trace_writer **w,
                       pdt_err *err);
/* The hook to pass to algorithm code (owned by w; valid until pdt_tw_close).
 * The sink stamps each event with the writer's clock and appends it to a
 * buffer; full buffers are encoded and written as one block.  The clock is
 * read for phase, merge, message and hull events and at least every 16
 * events; events in between reuse the latest reading (docs/trace-format.md,
 * "Time"). */
pdt_trace *pdt_tw_hook(pdt_trace_writer *w);
/* Current time on the writer's clock (CLOCK_MONOTONIC ns since pdt_tw_open):
 * the value event times are measured in; for clock-offset measurement. */
uint64_t pdt_tw_now(const pdt_trace_writer *w);
/* Read the writer's clock from clock_ns(user) (nanoseconds) instead of
 * CLOCK_MONOTONIC, from now on; its origin becomes that clock's reading now.
 * For runs whose time is not this machine's (simulated ranks: the simulated
 * clock).  Call before the first event. */
void pdt_tw_set_clock(pdt_trace_writer *w, uint64_t (*clock_ns)(void *user), void *user);
/* Events recorded so far (written or buffered). */
uint64_t pdt_tw_events(const pdt_trace_writer *w);
/* Write the buffered events, the end marker, close the file and free the
 * writer (w may be NULL).  Returns the first error of the whole recording
 * (a failed write during the run is reported here). */
pdt_status pdt_tw_close(pdt_trace_writer *w, pdt_err *err);
/* Abandon a writer without the end marker (error paths): closes and frees;
 * what was written stays readable. */
void pdt_tw_abort(pdt_trace_writer *w);

/* Rank 0: write the input points (points.bin) and the manifest, each
 * atomically (temporary file + rename).  Creates dir if needed.  (A parallel
 * driver writes points.bin itself, every rank its block at byte
 * PDT_POINTS_HEADER_BYTES + 8 * first, and then calls pdt_run_write_manifest.) */
pdt_status pdt_run_write_meta(const char *dir, const pdt_manifest *m, const pdt_point *pts,
                              size_t n, pdt_err *err);
/* Write dir/manifest only, atomically (dir must exist). */
pdt_status pdt_run_write_manifest(const char *dir, const pdt_manifest *m, pdt_err *err);

/* ---- reader ----------------------------------------------------------------- */

typedef struct pdt_run pdt_run;

/* One event with the rank that recorded it.  Reader times are aligned:
 * t + clock_offset_ns[rank] - min(0, smallest offset) (never negative). */
typedef struct pdt_rec {
    pdt_event ev;   /* ev.t aligned with the manifest's clock offsets */
    uint32_t rank;
    uint32_t seq;   /* index of the event in its rank's file */
} pdt_rec;

/* Open a run folder: the manifest, the points, every rank file (memory-mapped).
 * Damaged files are read up to their last intact block; what was lost is
 * described by pdt_run_warnings() instead of failing the whole open.  Fails
 * only when nothing usable is there (neither manifest nor rank-0000.trace,
 * another major version, out of memory); without a manifest the rank files
 * found are read with a warning.  The caller owns *run (pdt_run_close).
 * A pdt_run is not thread-safe (decoding is lazy); a writer is not either. */
pdt_status pdt_run_open(const char *dir, pdt_run **run, pdt_err *err);
void pdt_run_close(pdt_run *run);

const pdt_manifest *pdt_run_manifest(const pdt_run *run);
/* The run's points (read in place from points.bin's mapping where the
 * host's layout allows: then only the pages read are resident). */
const pdt_point *pdt_run_points(const pdt_run *run, size_t *n);
/* Give back the resident pages of the points (they are read again from the
 * page cache when used); nothing when they are a copy. */
void pdt_run_release_points(const pdt_run *run);
/* Text describing damage found while opening ("" if none). */
const char *pdt_run_warnings(const pdt_run *run);

/* All events of one rank, decoded (aligned times), in recording order; owned
 * by run, valid until pdt_run_close.  Memory: 40 bytes per event (use a
 * cursor for very large ranks). */
pdt_status pdt_run_rank_events(pdt_run *run, int rank, const pdt_event **ev, size_t *n,
                               pdt_err *err);

/* All events of all ranks merged in a causally consistent order (a RECV is
 * never before its SEND; each rank's own order is kept; otherwise by aligned
 * time, ties by rank).  SEND and RECV are matched by (source, destination,
 * tag, sequence number); a RECV whose SEND is missing is placed by its time
 * and noted in the warnings.  Owned by run. */
pdt_status pdt_run_merged(pdt_run *run, const pdt_rec **recs, size_t *n, pdt_err *err);

/* The same merged order, streamed: memory one decoded block per rank plus
 * the messages' index, whatever the number of events (pdt_run_merged keeps
 * 40 bytes per event).  Opening reads every rank once to index the SENDs.
 * The caller owns *m (pdt_merge_close); run must outlive it. */
typedef struct pdt_merge pdt_merge;
pdt_status pdt_merge_open(pdt_run *run, pdt_merge **m, pdt_err *err);
/* The next record of the merged order into *rec: 1, 0 at the end, -1 on an
 * error (out of memory; err set). */
int pdt_merge_next(pdt_merge *m, pdt_rec *rec, pdt_err *err);
/* The next records of the merged order, up to max (at least 1) of them,
 * into out: how many, 0 at the end, -1 on an error (err set).  What pdt_merge_next gives
 * one at a time; a run of one rank is copied from its decoded blocks. */
int pdt_merge_fill(pdt_merge *m, pdt_rec *out, size_t max, pdt_err *err);
void pdt_merge_close(pdt_merge *m);

/* Facts about one rank's file, known after pdt_run_open without decoding. */
typedef struct pdt_rank_info {
    uint64_t events;     /* intact events */
    uint64_t bytes;      /* file size */
    uint64_t blocks;     /* intact blocks */
    int complete;        /* 1 if the end marker was found (the run closed it) */
    int present;         /* 0 if the file is missing or unreadable */
    int level;           /* trace level in the file header */
} pdt_rank_info;

/* Number of ranks (the manifest's nranks). */
int pdt_run_nranks(const pdt_run *run);
/* Fill *info for `rank` (0 <= rank < nranks). */
void pdt_run_rank_info(const pdt_run *run, int rank, pdt_rank_info *info);

/* A cursor over one rank's events that decodes one block at a time: memory
 * O(block), seek O(log blocks) (binary search over the block index). */
typedef struct pdt_cursor pdt_cursor;

/* Open a cursor positioned at event 0 of `rank`.  Caller owns *c. */
pdt_status pdt_cursor_open(pdt_run *run, int rank, pdt_cursor **c, pdt_err *err);
/* Position at event k (k == event count positions at the end).  Returns
 * PDT_ERR_ARG if k is beyond the end. */
pdt_status pdt_cursor_seek(pdt_cursor *c, uint64_t k, pdt_err *err);
/* Next event (aligned time) into *ev and its index into *seq (may be NULL).
 * Returns 1, or 0 at the end. */
int pdt_cursor_next(pdt_cursor *c, pdt_event *ev, uint64_t *seq);
/* The next events, as pdt_cursor_next gives them, up to max of them and to
 * the end of the block that holds the first: *evs points at them in the
 * cursor's decoded block (valid until its next call), *seq at the first's
 * index; the cursor moves past them.  Their count; 0 at the end. */
size_t pdt_cursor_span(pdt_cursor *c, const pdt_event **evs, size_t max, uint64_t *seq);
void pdt_cursor_close(pdt_cursor *c);

/* One readable line for an event, without rank or time, e.g.
 * "pop graham pt=17 depth=3 cause=12"; a triangle starts at its smallest
 * index ("ra-defer 9 30 28 rank=0").  Writes at most cap bytes
 * (NUL-terminated); returns buf. */
char *pdt_event_format(const pdt_event *ev, char *buf, size_t cap);
/* Kind by name ("push", "tri-final", ...); -1 if unknown. */
int pdt_event_kind_by_name(const char *name);

/* ---- the encoded blocks, for random access (pdtview's kept index) ----------- */

/* One intact block of a rank's file, as pdt_run_open indexed it: its
 * header at byte `off` of the file (PDT_BLOCK_HEADER_BYTES), then `len`
 * bytes of payload holding events first .. first + count - 1 of the rank,
 * their times deltas from base_t (the rank's own clock).  A rank's blocks
 * follow each other: the first starts at event 0, each at the end of the
 * one before. */
typedef struct pdt_block_ref {
    uint64_t off, first, base_t;
    uint32_t len, count;
} pdt_block_ref;
#define PDT_BLOCK_HEADER_BYTES 32

/* The intact blocks of `rank` (owned by run), the rank file's bytes as
 * mapped (*file; a payload is at file + off + PDT_BLOCK_HEADER_BYTES) and
 * the shift that aligns its times (added to every decoded time).  Returns
 * the number of blocks (0 for a rank out of range or without events). */
size_t pdt_run_rank_blocks(const pdt_run *run, int rank, const pdt_block_ref **blk,
                           const uint8_t **file, int64_t *shift);
/* Decode one block payload (`len` bytes, `count` events, times from
 * base_t: pass base_t + shift for aligned times) into out[0 .. count).
 * Returns 0, or -1 when the payload is malformed (out then partly
 * written). */
int pdt_block_decode(const uint8_t *payload, uint32_t len, uint32_t count, uint64_t base_t,
                     pdt_event *out);

/* A block payload decoded one event at a time (what pdt_block_decode
 * decodes, without a room for the whole block): started on a payload as
 * pdt_block_decode is called; each pdt_block_cursor_next decodes the next
 * event into *out (out may be NULL: skipped) and returns 1, or 0 once the
 * block's count events are out, or -1 when the payload is malformed there
 * (the last event is refused when bytes are left after it).  The payload
 * stays the caller's; the cursor is a value (copied freely). */
typedef struct pdt_block_cursor {
    const uint8_t *p, *end;
    uint64_t t, v;        /* the previous time and v (time: from base_t) */
    uint32_t a, b, c;     /* the previous a, b, c */
    uint32_t left;        /* events not decoded yet */
} pdt_block_cursor;
void pdt_block_cursor_start(pdt_block_cursor *c, const uint8_t *payload, uint32_t len,
                            uint32_t count, uint64_t base_t);
int pdt_block_cursor_next(pdt_block_cursor *c, pdt_event *out);

/* ---- export ------------------------------------------------------------------ */

/* What pdt_run_export_otf2 wrote (over all ranks). */
typedef struct pdt_otf2_counts {
    uint64_t enters, leaves;  /* phases and merge steps (regions) */
    uint64_t sends, recvs;    /* MPI point-to-point records */
    uint64_t skipped;         /* unbalanced ends, messages naming no rank */
} pdt_otf2_counts;

/* Write the run as an OTF2 archive in folder `dir` (absent or empty; the
 * anchor file is dir/run.otf2): one location per rank, a region per phase id
 * and per merge level (Enter/Leave), MpiSend/MpiRecv records for SEND/RECV
 * on one communicator of all ranks, clock properties from the manifest (1 ns
 * resolution, wall_start_ns).  Other events are left out.  Memory O(one
 * OTF2 chunk), independent of the run's size.  Written into a temporary
 * folder and renamed: on error nothing is left.  counts may be NULL. */
pdt_status pdt_run_export_otf2(pdt_run *run, const char *dir, pdt_otf2_counts *counts,
                               pdt_err *err);

/* ---- verification (pdt trace check) ------------------------------------------ */

/* Check the invariants a correct run satisfies (docs/trace-format.md,
 * "Invariants"): intact files; per stack instance every pop removes the top
 * and depths agree; Graham's final stack is the hull of the points; lift-ups
 * cover the distinct points once (local) and |B| at each merge, with
 * z = x*x + y*y; every TRI_FINAL once across ranks and the set equals
 * T*(points) (recomputed with pdt_triangulate, or see pdt_run_check_tstar;
 * certified on disk over the budget: pdt_run_check_mem);
 * merge steps begin and end on one rank and do not overlap within a level;
 * every SEND has its RECV.
 * Returns PDT_OK and a one-line summary in `summary` (cap bytes), or
 * PDT_ERR_CHECK with the first violation in err. */
pdt_status pdt_run_check(pdt_run *run, char *summary, size_t cap, pdt_err *err);

/* Default memory budget of the trace tools (pdt trace check|dump|info|export). */
#define PDT_TRACE_MEM_DEFAULT ((uint64_t)1 << 30)

/* pdt_run_check with a memory budget in bytes for what grows with the run:
 * the final triangles are sorted in memory up to half the budget, beyond it
 * in sorted runs spilled to temporary files (in $TMPDIR, else /tmp; removed
 * at once, so never left behind) and merged; the distinct points are found
 * by a sort on disk and T* is certified side by side on disk instead of
 * recomputed when doing them in memory would not fit the budget, and the
 * marks (a byte per point) go to a temporary file's mapping beyond a
 * quarter of it, as do a level-2 kernel run's edges (docs/trace-format.md,
 * "Memory").  Not part of the budget: the stacks of one stack instance, the
 * messages and merge steps, and a hull run's hull recomputed. */
pdt_status pdt_run_check_mem(pdt_run *run, uint64_t budget, char *summary, size_t cap,
                             pdt_err *err);

/* How the check recomputes T* of the run's n points: its canonical triangles
 * (pdt_tri_canonical order, malloc'd) into *tris, *ntri, and in *strips the
 * strips it worked on one after the other (0: the whole kernel at once). */
typedef pdt_status (*pdt_tstar_fn)(const pdt_point *pts, size_t n, pdt_tri **tris, size_t *ntri,
                                   int *strips);

/* pdt_run_check_mem, T* recomputed by `tstar` (NULL: pdt_triangulate).  The
 * cli passes pdt_par_tstar (pdt/par.h), which needs less memory on big runs;
 * the summary then says on how many strips. */
pdt_status pdt_run_check_tstar(pdt_run *run, uint64_t budget, pdt_tstar_fn tstar, char *summary,
                               size_t cap, pdt_err *err);

#endif
