/* pdt — verifying a kept index: chunk checksums of data written in order,
 * checked in parallel at opening, or lazily: each chunk of the big tables
 * the first time the replay asks for it (pdt_ix_need). */
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

static void (*damage_hook)(const char *msg);
uint64_t pdt_ix_lazy_min_bytes = UINT64_MAX;

void pdt_replay_lazy_verify(void (*on_damage)(const char *msg), uint64_t min_bytes)
{
    damage_hook = on_damage;
    pdt_ix_lazy_min_bytes = on_damage ? min_bytes : UINT64_MAX;
}

/* The sections checked as they are first read: the big ones, sized by the
 * events, the points or the triangles.  Every other section is small and
 * checked whole at the opening. */
static int lazy_section(int i)
{
    switch (i) {
    case S_EVOBJ: case S_EVKIND: case S_TRIS: case S_HIST: case S_LIFT: case S_SORT:
    case S_DEL: case S_SORTPOS: case S_POINTS: case S_CKPT: return 1;
    default: return 0;
    }
}

/* A chunk did not match: remove the index, say so in L->msg and tell the
 * program (which should stop).  Always 0. */
static int lazy_fail(lazy *L)
{
    if (!L->bad) {
        L->bad = 1;
        snprintf(L->msg, sizeof L->msg,
                 "the kept index %s is damaged (a checksum mismatch, found when a part of it was "
                 "first read); it was removed: open the run again to rebuild it", L->path);
        unlink(L->path);
        if (damage_hook) damage_hook(L->msg);
    }
    return 0;
}

/* Check the chunks c0 .. c1-1 (of the whole table) not checked yet: one
 * here, several by the verifying threads.  1, or 0 on a mismatch. */
static int lazy_check(lazy *L, uint64_t c0, uint64_t c1)
{
    uint64_t todo_n = 0;
    for (uint64_t c = c0; c < c1; c++) todo_n += !L->done[c];
    if (!todo_n) return 1;
    if (L->bad) return 0;
    uint8_t *todo = calloc(L->nchunk ? L->nchunk : 1, 1);
    if (!todo) return lazy_fail(L);  /* (cannot check: treated as damaged) */
    for (uint64_t c = c0; c < c1; c++) todo[c] = !L->done[c];
    verify_job j = {L->fd, &L->h, L->tab, 0, todo, L->nchunk, L->first, 0, 0};
    j.next = c0;
    pdt_ix_run_job(&j);
    free(todo);
    if (atomic_load(&j.bad)) return lazy_fail(L);
    for (uint64_t c = c0; c < c1; c++) L->done[c] = 1;
    return 1;
}

int pdt_ix_need(const pdt_replay *r, int sec, uint64_t lo, uint64_t hi)
{
    lazy *L = r->lazy;
    if (!L || !lazy_section(sec)) return 1;
    if (L->bad) return 0;
    if (hi > L->h.sec[sec].bytes) hi = L->h.sec[sec].bytes;
    if (lo >= hi) return 1;
    uint64_t c0 = L->first[sec] + lo / CHUNK_BYTES, c1 = L->first[sec] + (hi - 1) / CHUNK_BYTES + 1;
    if (c1 == c0 + 1 && L->done[c0]) return 1;  /* the usual case */
    return lazy_check(L, c0, c1);
}

int pdt_ix_need_events(const pdt_replay *r, size_t lo, size_t hi)
{
    return pdt_ix_need(r, S_EVOBJ, lo * sizeof *r->ev_obj, hi * sizeof *r->ev_obj) &&
           pdt_ix_need(r, S_EVKIND, lo, hi);
}

int pdt_ix_need_born(const pdt_replay *r, size_t k)
{
    lazy *L = r->lazy;
    size_t born = pdt_replay_born_at_most(r, k);
    if (born <= L->tris_upto) return !L->bad;  /* (none born: tris_upto 0) */
    /* (their entries are where the build grouped them: anywhere in the table) */
    if (!pdt_ix_need(r, S_TRIS, 0, born * sizeof *r->tris) ||
        !pdt_ix_need(r, S_HIST, 0, r->nhist * sizeof *r->hist))
        return 0;
    L->tris_upto = born;
    return 1;
}

int pdt_ix_need_ckpt(const pdt_replay *r, size_t c)
{
    return pdt_ix_need(r, S_CKPT, r->ick_off[c], r->ick_off[c + 1]);
}

int pdt_ix_need_point(const pdt_replay *r, size_t p)
{
    return pdt_ix_need(r, S_LIFT, p * 4, p * 4 + 4) && pdt_ix_need(r, S_SORT, p * 4, p * 4 + 4) &&
           pdt_ix_need(r, S_DEL, p * 4, p * 4 + 4) &&
           pdt_ix_need(r, S_SORTPOS, p * sizeof *r->sort_pos, (p + 1) * sizeof *r->sort_pos);
}

int pdt_ix_need_points(const pdt_replay *r)
{
    return pdt_ix_need(r, S_POINTS, 0, UINT64_MAX);
}

int pdt_ix_need_all(const pdt_replay *r)
{
    for (int i = 0; i < NSEC; i++)
        if (!pdt_ix_need(r, i, 0, UINT64_MAX)) return 0;
    return 1;
}

/* Check every chunk of the sections that are not checked lazily (at the
 * opening).  1, or 0 with a reason in why. */
static int check_small_sections(lazy *L, char *why, size_t wcap)
{
    uint8_t *todo = calloc(L->nchunk ? L->nchunk : 1, 1);
    if (!todo) return snprintf(why, wcap, "out of memory"), 0;
    for (int i = 0; i < NSEC; i++)
        if (!lazy_section(i))
            for (uint64_t c = L->first[i]; c < L->first[i + 1]; c++) todo[c] = 1, L->done[c] = 1;
    verify_job j = {L->fd, &L->h, L->tab, 0, todo, L->nchunk, L->first, 0, 0};
    pdt_ix_run_job(&j);
    free(todo);
    if (atomic_load(&j.bad)) return snprintf(why, wcap, "damaged: checksum mismatch"), 0;
    return 1;
}

lazy *pdt_ix_lazy_start(const ihdr *h, uint32_t *tab, int fd, const char *path, char *why,
                        size_t wcap)
{
    lazy *L = calloc(1, sizeof *L);
    if (!L) return NULL;
    uint64_t n = 0;
    for (int i = 0; i < NSEC; i++) L->first[i] = n, n += chunks_of(h->sec[i].bytes);
    L->first[NSEC] = n;
    L->nchunk = n;
    L->h = *h;
    L->done = calloc(n ? n : 1, 1);
    L->fd = fcntl(fd, F_DUPFD_CLOEXEC, 0);
    if (!L->done || L->fd < 0 || strlen(path) >= sizeof L->path) {
        if (L->fd >= 0) close(L->fd);
        free(L->done);
        free(L);
        return NULL;
    }
    L->tab = tab;
    strcpy(L->path, path);
    if (!check_small_sections(L, why, wcap)) {
        L->tab = NULL;  /* (the caller's) */
        pdt_ix_lazy_stop(L);
        return NULL;
    }
    return L;
}

void pdt_ix_lazy_stop(lazy *L)
{
    close(L->fd);
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
    snprintf(L->msg, sizeof L->msg,
             "the kept index %s refers to rank-%04u.trace, which no longer matches it (a block's "
             "checksum); the index was removed: open the run again to rebuild it", L->path, rank);
    unlink(L->path);
    if (damage_hook) damage_hook(L->msg);
}
