/* pdt — large scratch arrays: mmap'd, huge pages on request (see bigmem.h). */
#include "pdt/bigmem.h"
#include "pdt/tmpfile.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

enum { BIG = 1 << 20, HUGE_PAGE = 1 << 21 };

/* PDT_HUGEPAGES=1, read once (bigmem.h). */
static bool huge_wanted(void)
{
    static atomic_int wanted = -1;
    int w = atomic_load_explicit(&wanted, memory_order_relaxed);
    if (w < 0) {
        const char *e = getenv("PDT_HUGEPAGES");
        w = e && strcmp(e, "1") == 0;
        atomic_store_explicit(&wanted, w, memory_order_relaxed);
    }
    return w;
}

void pdt_big_advise(void *p, size_t bytes)
{
#ifdef MADV_HUGEPAGE
    uintptr_t a = ((uintptr_t)p + HUGE_PAGE - 1) & ~(uintptr_t)(HUGE_PAGE - 1);
    uintptr_t b = ((uintptr_t)p + bytes) & ~(uintptr_t)(HUGE_PAGE - 1);
    if (bytes >= BIG && b > a && huge_wanted()) madvise((void *)a, b - a, MADV_HUGEPAGE);
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

size_t pdt_page_size(void)
{
    long pg = sysconf(_SC_PAGESIZE);
    return pg > 0 ? (size_t)pg : 4096;
}

void pdt_release_pages(const void *p, size_t len)
{
    uintptr_t m = pdt_page_size() - 1;
    uintptr_t lo = ((uintptr_t)p + m) & ~m, hi = ((uintptr_t)p + len) & ~m;
    if (hi > lo) (void)madvise((void *)lo, hi - lo, MADV_DONTNEED);
}

void pdt_big_release_front(void *base, size_t from, size_t to)
{
    uintptr_t b0 = (uintptr_t)base;
    uintptr_t a = (b0 + from) & ~(uintptr_t)(HUGE_PAGE - 1); /* the page `from` is in ... */
    if (a < b0) a = (b0 + HUGE_PAGE - 1) & ~(uintptr_t)(HUGE_PAGE - 1); /* ... if all ours */
    uintptr_t b = (b0 + to) & ~(uintptr_t)(HUGE_PAGE - 1);
    if (b > a) (void)madvise((void *)a, b - a, MADV_DONTNEED);
}

/* ---- faulting in ahead of use (bigmem.h) ---- */

enum { PF_MAX = 8, PF_STEP = 1 << 21 };

struct pdt_prefault {
    pthread_t th;
    atomic_int stop;
    int nr;
    pdt_range r[PF_MAX];
};

static void *prefault_run(void *arg)
{
    pdt_prefault *pf = arg;
#ifdef MADV_POPULATE_WRITE
    long pg = (long)pdt_page_size();
    for (int k = 0; k < pf->nr; k++) {
        /* whole pages inside the range only: a page it shares with another
         * allocation is left to that allocation's owner */
        uintptr_t a = ((uintptr_t)pf->r[k].p + (uintptr_t)pg - 1) & ~(uintptr_t)(pg - 1);
        uintptr_t b = ((uintptr_t)pf->r[k].p + pf->r[k].bytes) & ~(uintptr_t)(pg - 1);
        while (a < b && !atomic_load_explicit(&pf->stop, memory_order_relaxed)) {
            uintptr_t e = (a & ~(uintptr_t)(PF_STEP - 1)) + PF_STEP; /* the next 2 MiB boundary */
            if (e > b) e = b;
            if (madvise((void *)a, e - a, MADV_POPULATE_WRITE) != 0) return NULL; /* old kernel */
            a = e;
        }
    }
#endif
    return NULL;
}

/* (bigmem.h) A process bound to one CPU would run the helper on that CPU,
 * taking turns with the main thread.  The helper's CPUs are an attribute of
 * its creation, not set afterwards: a thread that has already ended has no
 * kernel id left in its handle, and setting the CPUs of such a handle sets
 * the caller's own (a quick helper then moved the main thread onto the other
 * rank's CPU). */
int pdt_helper_start(pthread_t *th, void *(*fn)(void *), void *arg)
{
    cpu_set_t mine, other;
    pthread_attr_t at;
    int rc = pthread_attr_init(&at);
    if (rc != 0) return rc;
    if (sched_getaffinity(0, sizeof mine, &mine) == 0 && CPU_COUNT(&mine) == 1) {
        long online = sysconf(_SC_NPROCESSORS_ONLN);
        CPU_ZERO(&other);
        for (long c = 0; c < online && c < CPU_SETSIZE; c++)
            if (!CPU_ISSET((size_t)c, &mine)) CPU_SET((size_t)c, &other);
        if (CPU_COUNT(&other) > 0) (void)pthread_attr_setaffinity_np(&at, sizeof other, &other);
    }
    rc = pthread_create(th, &at, fn, arg);
    pthread_attr_destroy(&at);
    return rc;
}

pdt_prefault *pdt_prefault_start(const pdt_range *r, int nr)
{
    if (nr <= 0 || nr > PF_MAX) return NULL;
    pdt_prefault *pf = malloc(sizeof *pf);
    if (!pf) return NULL;
    atomic_init(&pf->stop, 0);
    pf->nr = nr;
    memcpy(pf->r, r, (size_t)nr * sizeof *r);
    if (pdt_helper_start(&pf->th, prefault_run, pf) != 0) {
        free(pf);
        return NULL;
    }
    return pf;
}

void pdt_prefault_stop(pdt_prefault *pf)
{
    if (!pf) return;
    atomic_store(&pf->stop, 1);
    pthread_join(pf->th, NULL);
    free(pf);
}

void *pdt_temp_zeros(size_t bytes)
{
    int fd = pdt_tmp_fd("pdt-scratch");
    if (fd < 0) return NULL;
    void *p = MAP_FAILED;
    if (ftruncate(fd, (off_t)(bytes ? bytes : 1)) == 0)
        p = mmap(NULL, bytes ? bytes : 1, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    int e = errno;
    close(fd);  /* the mapping keeps the file */
    errno = e;
    return p == MAP_FAILED ? NULL : p;
}

/* ---- a growable temporary file's mapping (bigmem.h) ---- */

int pdt_temp_map_new(pdt_temp_map *m, size_t bytes)
{
    m->p = NULL;
    m->bytes = 0;
    if (!bytes) bytes = 1;
    if ((m->fd = pdt_tmp_fd("pdt-scratch")) < 0) return -1;
    void *p = MAP_FAILED;
    if (ftruncate(m->fd, (off_t)bytes) == 0)
        p = mmap(NULL, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, m->fd, 0);
    if (p == MAP_FAILED) {
        int e = errno;
        close(m->fd);
        m->fd = -1;
        errno = e;
        return -1;
    }
    m->p = p;
    m->bytes = bytes;
    return 0;
}

int pdt_temp_map_grow(pdt_temp_map *m, size_t bytes)
{
    if (bytes <= m->bytes) return 0;
    if (ftruncate(m->fd, (off_t)bytes) != 0) return -1;
    void *p = mremap(m->p, m->bytes, bytes, MREMAP_MAYMOVE);
    if (p == MAP_FAILED) {
        int e = errno;
        (void)ftruncate(m->fd, (off_t)m->bytes);  /* as it was */
        errno = e;
        return -1;
    }
    m->p = p;
    m->bytes = bytes;
    return 0;
}

void pdt_temp_map_free(pdt_temp_map *m)
{
    if (!m->p) return;
    munmap(m->p, m->bytes);
    close(m->fd);
    m->p = NULL;
    m->bytes = 0;
    m->fd = -1;
}
