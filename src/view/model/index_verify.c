/* pdt — verifying a kept index: chunk checksums of data written in order,
 * checked in parallel at opening, or lazily, each chunk when first read. */
#include "pdt/io.h"
#include "pdt/view/replay.h"
#include "replay_int.h"
#include "index_int.h"
#include "pdt/bigmem.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

void pdt_ix_crc_feed(crcacc *a, const void *data, size_t len)
{
    const char *p = data;
    while (len) {
        uint64_t room = CHUNK_BYTES - a->pos % CHUNK_BYTES;
        size_t take = len < room ? len : (size_t)room;
        a->cur = pdt_crc32c(a->cur, p, take);
        a->pos += take;
        p += take;
        len -= take;
        if (a->pos % CHUNK_BYTES == 0) {
            if (a->n == a->cap) {
                size_t nc = a->cap ? 2 * a->cap : 64;
                uint32_t *g = realloc(a->crc, nc * sizeof *g);
                if (!g) {
                    a->nomem = 1;
                    return;
                }
                a->crc = g;
                a->cap = nc;
            }
            a->crc[a->n++] = a->cur;
            a->cur = 0;
        }
    }
}

/* Copy the section's chunk checksums (the last chunk's too) to tab.  0 if
 * memory ran out or the bytes fed are not `bytes`. */
int pdt_ix_crc_done(const crcacc *a, uint64_t bytes, uint32_t *tab)
{
    if (a->nomem || a->pos != bytes) return 0;
    if (a->n) memcpy(tab, a->crc, a->n * sizeof *tab);
    if (a->pos % CHUNK_BYTES) tab[a->n] = a->cur;
    return 1;
}

static void *verify_worker(void *arg)
{
    verify_job *j = arg;
    enum { BUF = 1 << 20 };
    unsigned char *buf = malloc(BUF);
    if (!buf) {
        atomic_store(&j->bad, 1);
        return NULL;
    }
    for (;;) {
        uint64_t c = atomic_fetch_add(&j->next, 1);
        if (c >= j->nchunk || atomic_load(&j->bad)) break;
        if (j->todo && !j->todo[c]) continue;
        int i = 0;
        while (i + 1 < NSEC && j->first[i + 1] <= c) i++;
        uint64_t from = (c - j->first[i]) * CHUNK_BYTES, to = from + CHUNK_BYTES;
        if (to > j->h->sec[i].bytes) to = j->h->sec[i].bytes;
        uint32_t crc = 0;
        for (uint64_t o = from; o < to;) {
            size_t want = to - o < BUF ? (size_t)(to - o) : BUF;
            ssize_t got = pread(j->fd, buf, want, (off_t)(j->h->sec[i].off + o));
            if (got <= 0) {
                if (j->compute) atomic_store(&j->bad, 1);  /* (verifying: a mismatch below) */
                break;
            }
            crc = pdt_crc32c(crc, buf, (size_t)got);
            o += (uint64_t)got;
        }
        if (j->compute) j->tab[c] = crc;
        else if (crc != j->tab[c]) atomic_store(&j->bad, 1);
    }
    free(buf);
    return NULL;
}

/* Run job j on up to four threads (this one among them). */
void pdt_ix_run_job(verify_job *j)
{
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    int nt = cpus < 1 ? 1 : cpus > 4 ? 4 : (int)cpus, started = 0;
    pthread_t th[4];
    for (int t = 1; t < nt; t++)
        if (pthread_create(&th[t], NULL, verify_worker, j) == 0) started |= 1 << t;
    verify_worker(j);
    for (int t = 1; t < nt; t++)
        if (started & (1 << t)) pthread_join(th[t], NULL);
}

/* The chunk checksums of the index (its own checksum verified), malloc'd;
 * NULL with a reason in why. */
uint32_t *pdt_ix_read_ctab(int fd, const ihdr *h, char *why, size_t wcap)
{
    uint64_t n = 0;
    for (int i = 0; i < NSEC; i++) n += chunks_of(h->sec[i].bytes);
    if (h->ctab.bytes != n * sizeof(uint32_t)) {
        snprintf(why, wcap, "damaged: chunk table has the wrong size");
        return NULL;
    }
    uint32_t *tab = malloc(n ? n * sizeof *tab : 1);
    if (!tab || pread(fd, tab, (size_t)h->ctab.bytes, (off_t)h->ctab.off) != (ssize_t)h->ctab.bytes ||
        pdt_crc32c(0, tab, (size_t)h->ctab.bytes) != h->ctab.crc) {
        free(tab);
        snprintf(why, wcap, "damaged: chunk table checksum mismatch");
        return NULL;
    }
    return tab;
}

/* 1 when every chunk of every section matches its checksum. */
int pdt_ix_verify_chunks(int fd, const ihdr *h, char *why, size_t wcap)
{
    uint64_t first[NSEC + 1], n = 0;
    for (int i = 0; i < NSEC; i++) first[i] = n, n += chunks_of(h->sec[i].bytes);
    first[NSEC] = n;
    uint32_t *tab = pdt_ix_read_ctab(fd, h, why, wcap);
    if (!tab) return 0;
    verify_job j = {fd, h, tab, 0, NULL, n, first, 0, 0};
    pdt_ix_run_job(&j);
    free(tab);
    if (atomic_load(&j.bad)) {
        snprintf(why, wcap, "damaged: checksum mismatch");
        return 0;
    }
    return 1;
}

static _Atomic(lazy *) lazies[LAZY_MAX];
static void (*damage_hook)(const char *msg);
uint64_t pdt_ix_lazy_min_bytes = UINT64_MAX;

void pdt_replay_lazy_verify(void (*on_damage)(const char *msg), uint64_t min_bytes)
{
    damage_hook = on_damage;
    pdt_ix_lazy_min_bytes = on_damage ? min_bytes : UINT64_MAX;
}

/* The file range of chunk c. */
static void lazy_chunk(const lazy *L, uint64_t c, uint64_t *lo, uint64_t *hi)
{
    int i = 0;
    while (i + 1 < NSEC && L->first[i + 1] <= c) i++;
    *lo = L->off[i] + (c - L->first[i]) * CHUNK_BYTES;
    *hi = *lo + CHUNK_BYTES < L->off[i] + L->bytes[i] ? *lo + CHUNK_BYTES : L->off[i] + L->bytes[i];
}

/* Checksum chunk c (once).  0 on a mismatch. */
static int lazy_verify(lazy *L, uint64_t c)
{
    if (atomic_load(&L->done[c])) return 1;
    uint64_t lo, hi;
    lazy_chunk(L, c, &lo, &hi);
    /* read through a small buffer (pread: async-signal-safe, and cheaper
     * than faulting the pages of a second mapping in) */
    unsigned char buf[1 << 16];
    uint32_t crc = 0;
    for (uint64_t o = lo; o < hi;) {
        size_t want = hi - o < sizeof buf ? (size_t)(hi - o) : sizeof buf;
        ssize_t got = pread(L->fd, buf, want, (off_t)o);
        if (got <= 0) return 0;
        crc = pdt_crc32c(crc, buf, (size_t)got);
        o += (uint64_t)got;
    }
    if (crc != L->tab[c]) return 0;
    atomic_store(&L->done[c], 1);
    return 1;
}

/* Verify every chunk overlapping the file range [lo, hi).  0 on a mismatch. */
static int lazy_verify_range(lazy *L, uint64_t lo, uint64_t hi)
{
    for (int i = 0; i < NSEC; i++) {
        uint64_t s = L->off[i], e = L->off[i] + L->bytes[i];
        if (!L->bytes[i] || e <= lo || s >= hi) continue;
        uint64_t from = (lo > s ? lo : s) - s, to = (hi < e ? hi : e) - s;
        for (uint64_t c = from / CHUNK_BYTES; c <= (to - 1) / CHUNK_BYTES; c++)
            if (!lazy_verify(L, L->first[i] + c)) return 0;
    }
    return 1;
}

/* Verify chunk c and open its pages to the replay (the chunks sharing its
 * end pages verified first).  1, 0 on a mismatch, -1 if mprotect failed. */
static int lazy_open_chunk(lazy *L, uint64_t c)
{
    uint64_t lo, hi;
    lazy_chunk(L, c, &lo, &hi);
    uint64_t plo = lo & ~(uint64_t)4095, phi = (hi + 4095) & ~(uint64_t)4095;
    if (phi > L->len) phi = L->len;
    if (!lazy_verify(L, c) || !lazy_verify_range(L, plo, lo) || !lazy_verify_range(L, hi, phi))
        return 0;
    return mprotect(L->base + plo, (size_t)(phi - plo), PROT_READ) == 0 ? 1 : -1;
}

/* Open the page at file offset pos to the replay: the chunks on it are
 * verified, then each of them is opened whole (and the chunks sharing its
 * end pages verified first).  0 on a mismatch or when the pages cannot be
 * opened. */
static int lazy_open_page(lazy *L, uint64_t pos)
{
    uint64_t p = pos & ~(uint64_t)4095, pe = p + 4096 < L->len ? p + 4096 : L->len;
    int any = 0;
    for (int i = 0; i < NSEC; i++) {
        uint64_t s = L->off[i], e = L->off[i] + L->bytes[i];
        if (!L->bytes[i] || e <= p || s >= pe) continue;
        uint64_t from = (p > s ? p : s) - s, to = (pe < e ? pe : e) - s;
        for (uint64_t c = from / CHUNK_BYTES; c <= (to - 1) / CHUNK_BYTES; c++) {
            int ok = lazy_open_chunk(L, L->first[i] + c);
            if (ok != 1) return ok;
            any = 1;
        }
    }
    if (!any && mprotect(L->base + p, (size_t)(pe - p), PROT_READ) != 0) return -1;  /* padding */
    return 1;
}

/* Append src to dst (async-signal-safe). */
static char *cat(char *dst, const char *end, const char *src)
{
    while (*src && dst < end) *dst++ = *src++;
    return dst;
}

/* A chunk did not match (ok 0) or could not be opened (-1): remove the
 * index and say so in L->msg (async-signal-safe). */
static const char *lazy_fail(lazy *L, int ok)
{
    char *m = L->msg, *end = L->msg + sizeof L->msg - 1;
    m = cat(m, end, "the kept index ");
    m = cat(m, end, L->path);
    m = cat(m, end, ok == 0 ? " is damaged (a checksum mismatch, found when a part of it was "
                              "first read); it was removed: open the run again to rebuild it"
                            : " cannot be opened to the replay (mprotect failed)");
    *m = 0;
    if (ok == 0) unlink(L->path);
    return L->msg;
}

int pdt_replay_lazy_fault(const void *addr, const char **msg)
{
    const char *a = addr;
    for (int k = 0; k < LAZY_MAX; k++) {
        lazy *L = atomic_load(&lazies[k]);
        if (!L || a < L->base || a >= L->base + L->len) continue;
        int ok = lazy_open_page(L, (uint64_t)(a - L->base));
        if (ok == 1) return 1;
        *msg = lazy_fail(L, ok);
        return 0;
    }
    return -1;
}

/* Make r's mapping (map, len, header h, chunk table tab) lazily verified:
 * every page but the header's closed until read.  0 if it cannot be
 * (then the caller verifies the whole index). */
lazy *pdt_ix_lazy_start(char *map, size_t len, const ihdr *h, uint32_t *tab, int fd,
                        const char *path)
{
    lazy *L = calloc(1, sizeof *L);
    if (!L) return NULL;
    uint64_t n = 0;
    for (int i = 0; i < NSEC; i++) L->first[i] = n, n += chunks_of(h->sec[i].bytes);
    L->first[NSEC] = n;
    L->done = calloc(n ? n : 1, 1);
    L->fd = fcntl(fd, F_DUPFD_CLOEXEC, 0);
    if (!L->done || L->fd < 0 || strlen(path) >= sizeof L->path) {
        if (L->fd >= 0) close(L->fd);
        free(L->done);
        free(L);
        return NULL;
    }
    L->base = map;

    L->len = len;
    L->tab = tab;
    for (int i = 0; i < NSEC; i++) L->off[i] = h->sec[i].off, L->bytes[i] = h->sec[i].bytes;
    strcpy(L->path, path);
    int slot = -1;
    for (int k = 0; k < LAZY_MAX && slot < 0; k++) {
        lazy *none = NULL;
        if (atomic_compare_exchange_strong(&lazies[k], &none, L)) slot = k;
    }
    if (slot < 0 || mprotect(map + HDR_BYTES, len - HDR_BYTES, PROT_NONE) != 0) {
        if (slot >= 0) atomic_store(&lazies[slot], NULL);
        close(L->fd);
        free(L->done);
        free(L);
        return NULL;
    }
    return L;
}

/* Forget a lazily verified mapping and unmap it. */
void pdt_ix_lazy_stop(lazy *L)
{
    for (int k = 0; k < LAZY_MAX; k++)
        if (atomic_load(&lazies[k]) == L) atomic_store(&lazies[k], NULL);
    close(L->fd);
    munmap(L->base, L->len);
    free(L->tab);
    free(L->done);
    free(L);
}

/* A rank file's block did not match its checksum when it was decoded (a
 * lazily verified index's source): the run folder changed behind the index
 * (its files' sizes and times are the same).  Remove the index and tell the
 * program, which should stop; if it goes on, the block's events read as
 * events of no known kind, which every table ignores (evsrc.c). */
void pdt_ix_run_damaged(void *ctx, uint32_t rank)
{
    lazy *L = ctx;
    char *m = L->msg, *end = L->msg + sizeof L->msg - 1, num[16];
    snprintf(num, sizeof num, "%04u", rank);
    m = cat(m, end, "the kept index ");
    m = cat(m, end, L->path);
    m = cat(m, end, " refers to rank-");
    m = cat(m, end, num);
    m = cat(m, end, ".trace, which no longer matches it (a block's checksum); the index was removed: "
                    "open the run again to rebuild it");
    *m = 0;
    unlink(L->path);
    if (damage_hook) damage_hook(L->msg);
}
