/* pdt — point-set generators for tests, benchmarks and lessons. */
#ifndef PDT_GEN_H
#define PDT_GEN_H

#include "pdt/common.h"

/* Generate n points of family `kind` with a deterministic seed.
 * Kinds (at least): "uniform", "grid", "circle" (exact lattice points on a
 * circle), "circle-round" (rounded), "parabola", "clusters", "collinear",
 * "duplicates", "column".  Unknown kind -> PDT_ERR_ARG with the list of
 * kinds in err.  *pts is malloc'd. */
pdt_status pdt_gen(const char *kind, size_t n, uint64_t seed, pdt_point **pts, pdt_err *err);

/* NULL-terminated list of the kind names. */
const char *const *pdt_gen_kinds(void);

#endif
