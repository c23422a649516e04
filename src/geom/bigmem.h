/* pdt — large scratch arrays of the sequential pipeline (internal to src/geom).
 *
 * Arrays of 1 MiB or more are mapped directly (mmap) and unmapped when freed,
 * so the memory goes back to the system at once (glibc keeps freed heap
 * memory resident when its adaptive mmap threshold has grown, which made the
 * sort's scratch count twice in the peak), and they ask for transparent huge
 * pages: the kernel's random accesses then miss the TLB far less.  Smaller
 * ones use malloc. */
#ifndef PDT_GEOM_BIGMEM_H
#define PDT_GEOM_BIGMEM_H

#include <stddef.h>

/* An uninitialised array of `bytes` bytes, or NULL.  Free it with
 * pdt_big_free(p, bytes), the same size. */
void *pdt_big_alloc(size_t bytes);
void pdt_big_free(void *p, size_t bytes);

/* Ask for transparent huge pages on the whole pages inside [p, p + bytes)
 * (of any allocation, e.g. a large malloc'd block).  Only a hint. */
void pdt_big_advise(void *p, size_t bytes);

#endif
