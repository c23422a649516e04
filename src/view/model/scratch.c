/* pdt — the scratch files of a streamed build: a memory part while the
 * pool has room, a file part beyond (scratch_int.h). */
#include "scratch_int.h"
#include "pdt/bigmem.h"
#include "pdt/tmpfile.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#define SCR_PAGE ((uint64_t)2 << 20) /* the pool counts whole huge pages */

void pdt_scr_init(scr_set *s, const char *near, uint64_t pool)
{
    memset(s, 0, sizeof *s);
    pthread_mutex_init(&s->mu, NULL);
    s->near = near;
    s->pool = s->left = pool / SCR_PAGE * SCR_PAGE;
    for (int k = 0; k < PDT_SCR_COUNT; k++) s->f[k].fd = -1;
}

/* An unnamed file in the folder of `path` (O_TMPFILE; where the file
 * system has none, a named one removed at once), or -1. */
static int open_unnamed(const char *path)
{
    char dir[PATH_MAX + 128];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (slash) *slash = 0;
    else snprintf(dir, sizeof dir, ".");
    int fd = open(dir, O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
    if (fd >= 0) return fd;
    char name[PATH_MAX + 160];
    snprintf(name, sizeof name, "%s.spill", path);
    fd = open(name, O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd >= 0) unlink(name);
    return fd;
}

/* (s->mu held) f's file part, made if it has none: its descriptor or -1. */
static int file_part(scr_set *s, scr_file *f)
{
    if (f->fd < 0) f->fd = open_unnamed(s->near);
    return f->fd;
}

int pdt_scr_make_file(scr_set *s, int file)
{
    if (file < 0 || file >= PDT_SCR_COUNT) return errno = EINVAL, 0;
    pthread_mutex_lock(&s->mu);
    int fd = file_part(s, &s->f[file]);
    pthread_mutex_unlock(&s->mu);
    return fd >= 0;
}

/* (s->mu held) f's memory part grown to hold bytes up to `end`, if the pool
 * has room; if not, its split is fixed where it is. */
static void grow(scr_set *s, scr_file *f, uint64_t end)
{
    uint64_t want = (end + SCR_PAGE - 1) / SCR_PAGE * SCR_PAGE;
    if (f->fixed || want <= f->split) return;
    if (!f->mem && s->left) { /* address space for the whole pool, pages made as written */
        void *m = mmap(NULL, s->pool, PROT_READ | PROT_WRITE,
                       MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
        if (m != MAP_FAILED) {
            f->mem = m;
            pdt_big_advise(m, s->pool);
        }
    }
    if (!f->mem || want - f->split > s->left) {
        f->fixed = 1;
        return;
    }
    s->left -= want - f->split;
    f->split = want;
    if (s->pool - s->left > s->peak) s->peak = s->pool - s->left;
}

int pdt_scr_put(scr_set *s, int file, uint64_t at, const void *p, size_t bytes)
{
    if (file < 0 || file >= PDT_SCR_COUNT) return errno = EINVAL, 0;
    scr_file *f = &s->f[file];
    uint64_t end = at + bytes;
    pthread_mutex_lock(&s->mu);
    grow(s, f, end);
    uint64_t split = f->split; /* (only grows while this write is made: [0, split) stays memory) */
    int fd = end > split ? file_part(s, f) : f->fd;
    pthread_mutex_unlock(&s->mu);
    size_t in_mem = at >= split ? 0 : end <= split ? bytes : (size_t)(split - at);
    if (in_mem) memcpy(f->mem + at, p, in_mem);
    if (in_mem == bytes) return 1;
    return fd >= 0 && pdt_pwrite_all(fd, (const char *)p + in_mem, bytes - in_mem, at + in_mem);
}

int pdt_scr_get(scr_set *s, int file, uint64_t at, void *p, size_t bytes)
{
    if (file < 0 || file >= PDT_SCR_COUNT) return errno = EINVAL, 0;
    scr_file *f = &s->f[file];
    pthread_mutex_lock(&s->mu);
    uint64_t split = f->split;
    int fd = f->fd;
    pthread_mutex_unlock(&s->mu);
    uint64_t end = at + bytes;
    size_t in_mem = at >= split ? 0 : end <= split ? bytes : (size_t)(split - at);
    if (in_mem) memcpy(p, f->mem + at, in_mem);
    if (in_mem == bytes) return 1;
    if (fd < 0) return errno = EINVAL, 0;
    return pdt_pread_all(fd, at + in_mem, (char *)p + in_mem, bytes - in_mem);
}

void pdt_scr_drop(scr_set *s, int file)
{
    if (file < 0 || file >= PDT_SCR_COUNT) return;
    scr_file *f = &s->f[file];
    pthread_mutex_lock(&s->mu);
    if (f->mem) munmap(f->mem, s->pool);
    if (f->fd >= 0) close(f->fd);
    s->left += f->split;
    *f = (scr_file){.fd = -1};
    pthread_mutex_unlock(&s->mu);
}

void pdt_scr_free(scr_set *s)
{
    for (int k = 0; k < PDT_SCR_COUNT; k++) pdt_scr_drop(s, k);
    pthread_mutex_destroy(&s->mu);
}
