/* pdt — large scratch arrays: mmap'd, huge pages asked for (see bigmem.h). */
#include "bigmem.h"

#include <stdint.h>
#include <stdlib.h>
#include <sys/mman.h>

enum { BIG = 1 << 20, HUGE_PAGE = 1 << 21 };

void pdt_big_advise(void *p, size_t bytes)
{
#ifdef MADV_HUGEPAGE
    uintptr_t a = ((uintptr_t)p + HUGE_PAGE - 1) & ~(uintptr_t)(HUGE_PAGE - 1);
    uintptr_t b = ((uintptr_t)p + bytes) & ~(uintptr_t)(HUGE_PAGE - 1);
    if (bytes >= BIG && b > a) madvise((void *)a, b - a, MADV_HUGEPAGE);
#else
    (void)p;
    (void)bytes;
#endif
}

void *pdt_big_alloc(size_t bytes)
{
    if (bytes < BIG) return malloc(bytes ? bytes : 1);
    void *p = mmap(NULL, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) return NULL;
    pdt_big_advise(p, bytes);
    return p;
}

void pdt_big_free(void *p, size_t bytes)
{
    if (!p) return;
    if (bytes < BIG) free(p);
    else munmap(p, bytes);
}
