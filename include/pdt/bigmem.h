/* pdt — large scratch arrays of the sequential pipeline (internal to src/geom).
 *
 * Arrays of 1 MiB or more are mapped directly (mmap) and unmapped when freed,
 * so the memory goes back to the system at once (glibc keeps freed heap
 * memory resident when its adaptive mmap threshold has grown, which made the
 * sort's scratch count twice in the peak).  Smaller ones use malloc. */
#ifndef PDT_GEOM_BIGMEM_H
#define PDT_GEOM_BIGMEM_H

#include <pthread.h>
#include <stddef.h>

/* An uninitialised array of `bytes` bytes, or NULL.  Free it with
 * pdt_big_free(p, bytes), the same size. */
void *pdt_big_alloc(size_t bytes);
void pdt_big_free(void *p, size_t bytes);

/* With PDT_HUGEPAGES=1 in the environment, ask for transparent huge pages on
 * the whole 2 MiB pages inside [p, p + bytes) of any allocation of 1 MiB or
 * more (a large malloc'd block too); otherwise nothing.  Only a hint.  Off by
 * default: measured on the development machines (docs/geometry.md, "Fresh
 * memory"), huge pages saved no user time and their first touch cost system
 * time several times over, the free 2 MiB blocks being the ones the virtual
 * machine hands back to its host. */
void pdt_big_advise(void *p, size_t bytes);

/* `bytes` of zeros in a shared mapping of an anonymous temporary file in
 * $TMPDIR (else /tmp): memory the kernel pages to that file, whose resident
 * pages pdt_release_pages gives back without losing them.  NULL with errno
 * set.  Unmap it with munmap(p, bytes). */
void *pdt_temp_zeros(size_t bytes);

/* A pdt_temp_zeros that can grow: `bytes` of zeros in a shared mapping of an
 * anonymous temporary file, which stays open (one descriptor) so that
 * pdt_temp_map_grow can lengthen it (ftruncate, then mremap: the mapping may
 * move, the contents stay, the new part reads zeros).  The file costs disk
 * only where it is written; pdt_release_pages gives its resident pages back
 * without losing them.  m->p is NULL while nothing is mapped (a zeroed
 * struct, or after pdt_temp_map_free).  new and grow return 0, or -1 with
 * errno set (grow leaves m as it was). */
typedef struct pdt_temp_map {
    void *p;
    size_t bytes;
    int fd;
} pdt_temp_map;
int pdt_temp_map_new(pdt_temp_map *m, size_t bytes);
int pdt_temp_map_grow(pdt_temp_map *m, size_t bytes);
/* Unmap and close (nothing if m->p is NULL). */
void pdt_temp_map_free(pdt_temp_map *m);

/* The system's page size (sysconf), for code that gives pages back. */
size_t pdt_page_size(void);

/* Give back to the system the whole pages inside [p, p + len) of a mapping
 * whose contents there are not needed now (an anonymous mapping then reads
 * zeros there, a file's mapping reads the file again); a page that the range
 * only shares with something else is kept. */
void pdt_release_pages(const void *p, size_t len);

/* An array used front to back, whose front [0, to) is no longer needed
 * (its contents there read as zeros if touched again): give back to the
 * system the whole 2 MiB pages of it not given back yet, `from` being the
 * `to` of the previous call (0 at first).  Whole huge pages only: giving back
 * part of one splits it and frees nothing until the kernel gets round to it;
 * the page that holds `to` goes with a later call.  The memory can serve the
 * next allocation (e.g. the page cache of a file being written) at once,
 * which on a virtual machine is far cheaper than memory the host has taken
 * back (see below). */
void pdt_big_release_front(void *base, size_t from, size_t to);

/* Fault in memory ahead of use, on an idle core.  On a virtual machine
 * whose host backs each page on demand, the first touch of memory new to a
 * process can be a pipeline's dearest cost (the host backs the page, the
 * guest zeroes it; docs/benchmarks.md has figures).  pdt_prefault_start starts one thread
 * that asks the kernel to populate the pages of the given ranges, in order,
 * 2 MiB at a time (madvise MADV_POPULATE_WRITE: the pages are made present
 * and writable, their contents are left alone, so the caller may already be
 * writing to them), while the calling thread does something else.  Worth it
 * only when a core would otherwise be idle: the faults then cost that core's
 * time instead of the caller's (the same CPU seconds in total, or a little
 * more).  Returns NULL (and nothing runs) if the thread cannot be started or
 * nr == 0; ranges are copied.  pdt_prefault_stop(pf) (NULL allowed) stops
 * the thread at its next 2 MiB step and waits for it; call it before any of
 * the ranges is unmapped or resized. */
typedef struct pdt_prefault pdt_prefault;
typedef struct pdt_range {
    void *p;
    size_t bytes;
} pdt_range;
pdt_prefault *pdt_prefault_start(const pdt_range *r, int nr);
void pdt_prefault_stop(pdt_prefault *pf);

/* pthread_create for a helper thread: when the caller is bound to one CPU
 * (mpirun binds each rank to a core), the thread is created on the other
 * CPUs online, so that it does not take turns with the caller.  Returns 0,
 * or pthread_attr_init's or pthread_create's error code. */
int pdt_helper_start(pthread_t *th, void *(*fn)(void *), void *arg);

#endif
