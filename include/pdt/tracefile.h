/* pdt — run folders: the trace writer and the reader library.
 *
 * A run folder holds a manifest (text), the input points (binary) and one
 * binary trace file per rank.  The format is documented in docs/trace-format.md.
 * Writing never involves MPI: the parallel driver gathers what the manifest
 * needs and calls these functions. */
#ifndef PDT_TRACEFILE_H
#define PDT_TRACEFILE_H

#include "pdt/common.h"
#include "pdt/trace.h"

/* ---- manifest ------------------------------------------------------------ */

typedef struct pdt_manifest {
    int format_version;
    char program_version[32];
    char *command_line;      /* malloc'd */
    char *input_name;        /* malloc'd */
    uint64_t input_checksum; /* of the input points as read */
    uint64_t n;              /* points in the input */
    int nranks;
    int level;               /* trace level */
    char command[16];        /* "triangulate" or "hull" */
    int64_t *clock_offset_ns;/* per rank: add to a rank's times to align (malloc'd) */
    uint64_t wall_start_ns;  /* realtime clock at the start (rank 0) */
} pdt_manifest;

void pdt_manifest_free(pdt_manifest *m);

/* ---- writer (one per rank) --------------------------------------------------- */

typedef struct pdt_trace_writer pdt_trace_writer;

/* Create the run folder (rank 0 only: also writes the input points; other
 * ranks call it with pts = NULL after rank 0 did).  Returns a writer for
 * `rank` whose hook (pdt_tw_hook) records events of level <= `level`. */
pdt_status pdt_tw_open(const char *dir, int rank, int level, pdt_trace_writer **w,
                       pdt_err *err);
/* The hook to pass to algorithm code. */
pdt_trace *pdt_tw_hook(pdt_trace_writer *w);
/* Write the last block, close the file and free the writer. */
pdt_status pdt_tw_close(pdt_trace_writer *w, pdt_err *err);

/* Rank 0, after the run: write the input points and the manifest (atomic). */
pdt_status pdt_run_write_meta(const char *dir, const pdt_manifest *m, const pdt_point *pts,
                              size_t n, pdt_err *err);

/* ---- reader ----------------------------------------------------------------- */

typedef struct pdt_run pdt_run;

/* One event with the rank that recorded it. */
typedef struct pdt_rec {
    pdt_event ev;   /* ev.t aligned with the manifest's clock offsets */
    uint32_t rank;
    uint32_t seq;   /* index of the event in its rank's file */
} pdt_rec;

/* Open a run folder: the manifest, the points, every rank file (memory-mapped).
 * Damaged files are read up to their last intact block; what was lost is
 * described by pdt_run_warnings() instead of failing the whole open.  Fails
 * only when nothing usable is there (no manifest, wrong major version, ...). */
pdt_status pdt_run_open(const char *dir, pdt_run **run, pdt_err *err);
void pdt_run_close(pdt_run *run);

const pdt_manifest *pdt_run_manifest(const pdt_run *run);
const pdt_point *pdt_run_points(const pdt_run *run, size_t *n);
/* Text describing damage found while opening ("" if none). */
const char *pdt_run_warnings(const pdt_run *run);

/* All events of one rank, decoded, in recording order (owned by run). */
pdt_status pdt_run_rank_events(pdt_run *run, int rank, const pdt_event **ev, size_t *n,
                               pdt_err *err);

/* All events of all ranks merged in a causally consistent order (a RECV is
 * never before its SEND; each rank's own order is kept; otherwise by aligned
 * time).  Owned by run. */
pdt_status pdt_run_merged(pdt_run *run, const pdt_rec **recs, size_t *n, pdt_err *err);

#endif
