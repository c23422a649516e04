/* pdt — every fuzz target, by name (for fuzz_main.c and the replay test).
 * Adding a target: write static int fuzz_NAME(const uint8_t *, size_t) in a
 * tests/fuzz/fuzz_*.c file included here, list it in FZ_TARGETS below and
 * in the Makefile's FUZZ_TARGETS, and give it a seed corpus in
 * tests/fuzz/corpus/NAME/. */
#ifndef PDT_FUZZ_TARGETS_H
#define PDT_FUZZ_TARGETS_H

#include "fuzz_points.c"
#include "fuzz_tris.c"
#include "fuzz_trace.c"

typedef struct fz_target {
    const char *name;
    int (*fn)(const uint8_t *data, size_t size);
} fz_target;

static const fz_target FZ_TARGETS[] = {
    {"points_text", fuzz_points_text},
    {"points_node", fuzz_points_node},
    {"tris", fuzz_tris},
    {"manifest", fuzz_manifest},
    {"trace_rank", fuzz_trace_rank},
    {"trace_run", fuzz_trace_run},
};

#endif
