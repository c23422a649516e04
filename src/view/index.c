/* pdt — the kept index of a run folder: the replay model's tables in a file,
 * built at the first opening and memory-mapped at the next ones.
 *
 * File layout (native byte order; a different build's layout is refused):
 *   [0, 4096)        header: magic, version, the run's identity, the sizes
 *                    of the record types, the table sizes, per section its
 *                    offset and length, the place of the chunk checksums
 *                    (a CRC-32C per 16 MiB of every section: verified by
 *                    several threads at each opening); the header's own CRC
 *   sections         the per-event tables (object, kind: written by the
 *                    build's first pass as the events come, completed last);
 *                    the events: the merged order as segments of
 *                    consecutive events of one rank (the events themselves
 *                    stay in the rank files: the table of their encoded
 *                    blocks is a section below; decoded on demand, each
 *                    block's checksum checked: evsrc.c); then the points'
 *                    first lifts, the triangles and their histories, in the
 *                    triangles' order (streamed here while they are built:
 *                    pdt_replay_build), then every other table of
 *                    the replay (replay_int.h), the points and the reader's
 *                    warnings about the run, each at a 64-byte boundary
 *                    (so that a valid index opens without reading the run),
 *                    and last the checkpoints, one after the other, each
 *                    holding the triangles born before its cursor (their
 *                    places and those counts are in the header)
 *
 * The identity of a run is a hash of the name, size and modification time
 * of every file in the folder (but dot-files) and of the manifest's bytes.
 * An index whose identity, sizes or checksums do not match is rebuilt. */
#include "pdt/safefile.h"
#include "pdt/io.h"
#include "pdt/replay.h"
#include "replay_int.h"
#include "../geom/bigmem.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#define INDEX_NAME ".pdtview-index"
#define INDEX_VERSION 10u /* 8: the histories in the triangles' order; 9: a triangle's state
                             * in 16 bits (an offset from its first entry); 10: up to 48
                             * checkpoints */
#define ICK_MIN_EVERY 1024u  /* checkpoints in the index: every m/8 events, at least this */
#define ICK_PARTS 8u
/* ... and at most every ICK_MAX_EVERY events while ICK_MAX_PARTS allow: a
 * seek steps at most half of it, 2^22 events, 55 ms here on the 4*10^7-point
 * run (12.6 ns an event), after restoring a checkpoint (15 ms for its 191
 * MiB).  So up to 4*10^8 events (some 10^8 points); beyond, the steps grow
 * again (23 parts, the cap before, left a 5*10^8-event run's seeks stepping
 * up to 1.1*10^7 events; 47 keep them to 5.3*10^6, for twice the
 * checkpoints' disk) */
#define ICK_MAX_EVERY ((size_t)1 << 23)
#define ICK_MAX_PARTS 47u
_Static_assert(ICK_MAX_PARTS + 1 <= PDT_ICK_MAX, "the header holds every checkpoint's place");
#define CHUNK_BYTES ((uint64_t)16 << 20) /* sections are checksummed in chunks of this: the
                                          * least a lazily checked frame reads (1 MiB made
                                          * lazily checked seeks 5x slower: not understood) */
#define HDR_BYTES 4096u
#define EST_BYTES_PER_EVENT 100u /* what the replay model holds per event in memory */

enum {
    S_SEGS, S_EVOBJ, S_TRIS, S_HIST, S_EDGES, S_NODES, S_PHASES, S_MERGES,
    S_MSGS, S_HULLS, S_CH, S_SLOTCH, S_SLOTSTART, S_LIFT, S_SORT, S_DEL, S_SORTPOS, S_BOXLO,
    S_BOXHI, S_HASBOX, S_POINTS, S_WARN, S_EVKIND, S_BLKTAB, S_RANKBLK, S_CKPT, NSEC
};

typedef struct isec {
    uint64_t off, bytes;
    uint32_t crc, pad;
} isec;

typedef struct ihdr {
    char magic[8];
    uint32_t version, hdr_crc;  /* hdr_crc: over the header with this field 0 */
    uint64_t ident, file_bytes;
    uint32_t layout[12];        /* sizes of the record types */
    uint64_t n, m, skipped, nranks;
    uint64_t count[NSEC];       /* elements per section */
    uint64_t kind_count[64];
    isec sec[NSEC];
    uint64_t ick_every, nick;   /* the checkpoints (S_CKPT): checkpoint c at ick_off[c] */
    uint64_t ick_off[PDT_ICK_MAX + 1], ick_born[PDT_ICK_MAX];  /* of the section, holding
                                 * the triangles born before its cursor: ick_born[c] */
    isec ctab;                  /* CRC-32C of every CHUNK_BYTES of every section,
                                 * in section order; ctab.crc covers the table */
} ihdr;

_Static_assert(sizeof(ihdr) <= HDR_BYTES, "index header fits its page");
_Static_assert(PDT_EV_KIND_COUNT <= 64, "kind counts fit the header");

static const char magic[8] = {'P', 'D', 'T', 'V', 'I', 'D', 'X', '\n'};

static void layout_of(uint32_t out[12])
{
    const uint32_t l[12] = {sizeof(pdt_block_ref) << 8 | sizeof(pdt_evseg), sizeof(pdt_rtri), sizeof(pdt_rtri_hist),
                            sizeof(pdt_redge), sizeof(pdt_rnode), sizeof(pdt_rphase),
                            sizeof(pdt_rmerge), sizeof(pdt_rmsg), sizeof(pdt_rhull),
                            sizeof(slot_change), sizeof(pdt_point), PDT_SLOT_PER_RANK};
    memcpy(out, l, sizeof l);
}

/* Where each section lives in r (and its event source r->src) and how big
 * its elements are; counts from r. */
static void sections(pdt_replay *r, void **ptr[NSEC], size_t elem[NSEC], uint64_t count[NSEC])
{
    size_t nslot = (size_t)r->nranks * PDT_SLOT_PER_RANK;
#define SEC(i, field, cnt)                \
    ptr[i] = (void **)&r->field;          \
    elem[i] = sizeof *r->field;           \
    count[i] = (cnt)
    SEC(S_SEGS, src->seg, r->src->nseg);
    SEC(S_BLKTAB, src->blk, r->src->nblk);
    SEC(S_RANKBLK, src->rank_blk, (uint64_t)r->nranks + 1);
    SEC(S_EVOBJ, ev_obj, r->m);
    SEC(S_TRIS, tris, r->ntri);
    SEC(S_HIST, hist, r->nhist);
    SEC(S_EDGES, edges, r->nedge);
    SEC(S_NODES, nodes, r->nnode);
    SEC(S_PHASES, phases, r->nphase);
    SEC(S_MERGES, merges, r->nmerge);
    SEC(S_MSGS, msgs, r->nmsg);
    SEC(S_HULLS, hulls, r->nhull);
    SEC(S_CH, ch, r->nch);
    SEC(S_SLOTCH, slot_ch, r->nch);
    SEC(S_SLOTSTART, slot_start, nslot + 1);
    SEC(S_LIFT, lift_ev, r->n);
    SEC(S_SORT, sort_ev, r->sort_ev ? r->n : 0);  /* (none: NULL, see load) */
    SEC(S_DEL, del_ev, r->sort_ev ? r->n : 0);
    SEC(S_SORTPOS, sort_pos, r->sort_ev ? r->n : 0);
    SEC(S_BOXLO, box_lo, (uint64_t)r->nranks);
    SEC(S_BOXHI, box_hi, (uint64_t)r->nranks);
    SEC(S_HASBOX, has_box, (uint64_t)r->nranks);
    ptr[S_POINTS] = (void **)&r->pts;
    elem[S_POINTS] = sizeof(pdt_point);
    count[S_POINTS] = r->n;
    ptr[S_WARN] = (void **)&r->warnings;
    elem[S_WARN] = 1;
    count[S_WARN] = r->warnings ? strlen(r->warnings) + 1 : 0;
    SEC(S_EVKIND, ev_kind, r->m);
    ptr[S_CKPT] = (void **)&r->ick;
    elem[S_CKPT] = 1;
    count[S_CKPT] = r->nick ? r->ick_off[r->nick] : 0;
#undef SEC
}

static uint32_t hdr_crc(const ihdr *h)
{
    ihdr c = *h;
    c.hdr_crc = 0;
    return pdt_crc32c(0, &c, sizeof c);
}

static uint64_t chunks_of(uint64_t bytes) { return (bytes + CHUNK_BYTES - 1) / CHUNK_BYTES; }

/* ---- chunk checksums of data written in order ------------------------------------ */

/* The CRC-32C of every CHUNK_BYTES of a section, made as the section is
 * written from its start to its end (so that the build does not read it
 * back): crc[k] for chunk k, grown as needed. */
typedef struct crcacc {
    uint32_t *crc;
    size_t n, cap;
    uint64_t pos;   /* bytes fed */
    uint32_t cur;   /* of the chunk being fed */
    int nomem;
} crcacc;

static void crc_feed(crcacc *a, const void *data, size_t len)
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
static int crc_done(const crcacc *a, uint64_t bytes, uint32_t *tab)
{
    if (a->nomem || a->pos != bytes) return 0;
    if (a->n) memcpy(tab, a->crc, a->n * sizeof *tab);
    if (a->pos % CHUNK_BYTES) tab[a->n] = a->cur;
    return 1;
}

/* ---- verifying the chunks, in parallel ----------------------------------------- */

typedef struct verify_job {
    int fd;
    const ihdr *h;
    uint32_t *tab;              /* chunk checksums */
    int compute;                /* 1: fill tab in (building), 0: compare with it */
    const uint8_t *todo;        /* compute: NULL, or per chunk 1 if it is to be read */
    uint64_t nchunk;
    uint64_t *first;            /* per section: index of its first chunk in tab */
    atomic_uint_fast64_t next;  /* next chunk to check */
    atomic_int bad;
} verify_job;

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
static void run_job(verify_job *j)
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
static uint32_t *read_ctab(int fd, const ihdr *h, char *why, size_t wcap)
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
static int verify_chunks(int fd, const ihdr *h, char *why, size_t wcap)
{
    uint64_t first[NSEC + 1], n = 0;
    for (int i = 0; i < NSEC; i++) first[i] = n, n += chunks_of(h->sec[i].bytes);
    first[NSEC] = n;
    uint32_t *tab = read_ctab(fd, h, why, wcap);
    if (!tab) return 0;
    verify_job j = {fd, h, tab, 0, NULL, n, first, 0, 0};
    run_job(&j);
    free(tab);
    if (atomic_load(&j.bad)) {
        snprintf(why, wcap, "damaged: checksum mismatch");
        return 0;
    }
    return 1;
}

/* ---- verifying a big index lazily: each chunk when it is first read -------------
 *
 * Checksumming a whole index of gigabytes at every opening costs seconds; a
 * frame reads a small part of it.  So a big index (pdt_replay_lazy_verify)
 * is mapped with no access but its header page: the first read of a page
 * faults, and the handler (SIGSEGV) checksums the chunks the page belongs
 * to, reading the file (pread), before it opens their
 * pages to the replay.  Nothing of the index is used unverified.  A mismatch
 * removes the index and calls the program's damage hook (which must not
 * return: the replay cannot go on with a damaged table). */

#define LAZY_MAX 8  /* indexes open at once with lazy verification */

typedef struct lazy {
    char *base;                  /* the replay's mapping */
    int fd;                      /* the file, read (pread) for the checksums */
    size_t len;
    uint64_t off[NSEC], bytes[NSEC], first[NSEC + 1];
    uint32_t *tab;               /* the chunk checksums */
    atomic_uchar *done;          /* per chunk: verified */
    char path[PATH_MAX];
    char msg[PATH_MAX + 256];
} lazy;

static _Atomic(lazy *) lazies[LAZY_MAX];
static void (*damage_hook)(const char *msg);
static uint64_t lazy_min_bytes = UINT64_MAX;
static struct sigaction old_segv;
static pthread_once_t segv_once = PTHREAD_ONCE_INIT;

void pdt_replay_lazy_verify(void (*on_damage)(const char *msg), uint64_t min_bytes)
{
    damage_hook = on_damage;
    lazy_min_bytes = on_damage ? min_bytes : UINT64_MAX;
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
 * index, tell the program, stop (async-signal-safe). */
static _Noreturn void lazy_fail(lazy *L, int ok)
{
    char *m = L->msg, *end = L->msg + sizeof L->msg - 1;
    m = cat(m, end, "the kept index ");
    m = cat(m, end, L->path);
    m = cat(m, end, ok == 0 ? " is damaged (a checksum mismatch, found when a part of it was "
                              "first read); it was removed: open the run again to rebuild it"
                            : " cannot be opened to the replay (mprotect failed)");
    *m = 0;
    if (ok == 0) unlink(L->path);
    if (damage_hook) damage_hook(L->msg);
    abort();
}

static void segv_handler(int sig, siginfo_t *si, void *uc)
{
    const char *a = si->si_addr;
    for (int k = 0; k < LAZY_MAX; k++) {
        lazy *L = atomic_load(&lazies[k]);
        if (!L || a < L->base || a >= L->base + L->len) continue;
        int ok = lazy_open_page(L, (uint64_t)(a - L->base));
        if (ok == 1) return;
        lazy_fail(L, ok);
    }
    /* not ours: what was there before */
    if ((old_segv.sa_flags & SA_SIGINFO) && old_segv.sa_sigaction) {
        old_segv.sa_sigaction(sig, si, uc);
    } else if (old_segv.sa_handler != SIG_DFL && old_segv.sa_handler != SIG_IGN) {
        old_segv.sa_handler(sig);
    } else {
        signal(SIGSEGV, SIG_DFL);  /* the fault repeats and ends the process as usual */
    }
}

static void segv_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_sigaction = segv_handler;
    sa.sa_flags = SA_SIGINFO | SA_NODEFER;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGSEGV, &sa, &old_segv);
}

/* Make r's mapping (map, len, header h, chunk table tab) lazily verified:
 * every page but the header's closed until read.  0 if it cannot be
 * (then the caller verifies the whole index). */
static lazy *lazy_start(char *map, size_t len, const ihdr *h, uint32_t *tab, int fd,
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
    pthread_once(&segv_once, segv_install);
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
static void lazy_stop(lazy *L)
{
    for (int k = 0; k < LAZY_MAX; k++)
        if (atomic_load(&lazies[k]) == L) atomic_store(&lazies[k], NULL);
    close(L->fd);
    munmap(L->base, L->len);
    free(L->tab);
    free(L->done);
    free(L);
}

static void unmap_ranks(pdt_replay *r);

void pdt_index_unmap(pdt_replay *r)
{
    unmap_ranks(r);
    if (r->lazy) lazy_stop(r->lazy);
    else munmap(r->map, r->map_len);
    r->lazy = NULL;
    r->map = NULL;
}

void pdt_index_release(const pdt_replay *r, const void *p, size_t len)
{
    if (!r->map || !len) return;
    uintptr_t base = (uintptr_t)r->map, lo = (uintptr_t)p, hi = lo + len;
    if (hi <= base || lo >= base + r->map_len) return;
    if (lo < base) lo = base;
    if (hi > base + r->map_len) hi = base + r->map_len;
    pdt_release_pages((const void *)lo, hi - lo);
}

/* ---- the run's identity and the index's place ---------------------------------- */

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) h = (h ^ b[i]) * 0x100000001B3ull;
    return h;
}

typedef struct fent {
    char name[256];
    uint64_t size, mtime_ns;
} fent;

static int fent_cmp(const void *a, const void *b)
{
    return strcmp(((const fent *)a)->name, ((const fent *)b)->name);
}

/* Identity of the run folder: its files' names, sizes, modification times
 * and the manifest's bytes.  0 and err set when the folder cannot be listed. */
static pdt_status run_ident(const char *dir, uint64_t *id, pdt_err *err)
{
    DIR *d = opendir(dir);
    if (!d) return pdt_err_set(err, PDT_ERR_IO, "%s: %s", dir, strerror(errno));
    fent *f = NULL;
    size_t nf = 0, cap = 0;
    struct dirent *de;
    pdt_status st = PDT_OK;
    while ((de = readdir(d))) {
        if (de->d_name[0] == '.' || strlen(de->d_name) >= sizeof f->name) continue;
        char path[PATH_MAX];
        struct stat sb;
        snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
        if (stat(path, &sb) != 0 || !S_ISREG(sb.st_mode)) continue;
        if (nf == cap) {
            fent *g = realloc(f, (cap = cap ? 2 * cap : 16) * sizeof *f);
            if (!g) {
                st = pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
                break;
            }
            f = g;
        }
        memset(&f[nf], 0, sizeof *f);
        strcpy(f[nf].name, de->d_name);
        f[nf].size = (uint64_t)sb.st_size;
        f[nf].mtime_ns = (uint64_t)sb.st_mtim.tv_sec * 1000000000ull + (uint64_t)sb.st_mtim.tv_nsec;
        nf++;
    }
    closedir(d);
    if (st == PDT_OK) {
        qsort(f, nf, sizeof *f, fent_cmp);
        uint64_t h = fnv(0xCBF29CE484222325ull, magic, sizeof magic);
        for (size_t i = 0; i < nf; i++) h = fnv(h, &f[i], sizeof f[i]);
        char path[PATH_MAX];
        snprintf(path, sizeof path, "%s/manifest", dir);
        FILE *mf = fopen(path, "rb");
        if (mf) {
            char buf[4096];
            size_t got;
            while ((got = fread(buf, 1, sizeof buf, mf)) > 0) h = fnv(h, buf, got);
            fclose(mf);
        }
        *id = h;
    }
    free(f);
    return st;
}

/* The cache folder ($XDG_CACHE_HOME/pdt, else ~/.cache/pdt) into buf; 0 if
 * there is none (no HOME). */
static int cache_dir(char *buf, size_t cap)
{
    const char *x = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    if (x && *x == '/') snprintf(buf, cap, "%s/pdt", x);
    else if (home && *home) snprintf(buf, cap, "%s/.cache/pdt", home);
    else return 0;
    return 1;
}

/* mkdir -p of a folder we own (0700 like other cache folders). */
static int make_dirs(const char *path)
{
    char tmp[PATH_MAX];
    snprintf(tmp, sizeof tmp, "%s", path);
    for (char *p = tmp + 1; *p; p++) {
        if (*p != '/') continue;
        *p = 0;
        if (mkdir(tmp, 0700) != 0 && errno != EEXIST) return 0;
        *p = '/';
    }
    return mkdir(tmp, 0700) == 0 || errno == EEXIST;
}

/* The index beside the run (where = 0) or in the cache (where = 1), keyed
 * by the folder's real path.  0 if there is no such place. */
static int index_path(const char *dir, int where, char *buf, size_t cap)
{
    if (where == 0) {
        return snprintf(buf, cap, "%s/" INDEX_NAME, dir) < (int)cap;
    }
    char cdir[PATH_MAX], real[PATH_MAX];
    if (!cache_dir(cdir, sizeof cdir) || !realpath(dir, real)) return 0;
    uint64_t h = fnv(0xCBF29CE484222325ull, real, strlen(real));
    return snprintf(buf, cap, "%s/run-%016llx" INDEX_NAME, cdir, (unsigned long long)h) < (int)cap;
}

/* ---- loading ------------------------------------------------------------------ */

/* Map the index at `path` onto a new replay over pts.  Returns NULL with a
 * reason in why when it is missing, stale or damaged.  verify: check every
 * section's checksum (reading the file through a small buffer), or, for an
 * index of at least lazy_min_bytes, each chunk when it is first read. */
/* A rank file's block did not match its checksum when it was decoded (a
 * lazily verified index's source): the run folder changed behind the index
 * (its files' sizes and times are the same).  Remove the index, tell the
 * program, stop: the replay cannot go on without its events. */
static void run_damaged(void *ctx, uint32_t rank)
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
    abort();
}

/* Map the rank files of run folder `dir` that the index's block table
 * refers to (into r->src), and unless the index is verified lazily (L),
 * check every block's checksum now.  0 with a reason in why. */
static int map_ranks(pdt_replay *r, const char *dir, lazy *L, char *why, size_t wcap)
{
    pdt_evsrc *src = r->src;
    size_t q1 = (size_t)r->nranks;
    src->file = calloc(q1, sizeof *src->file);
    src->file_len = calloc(q1, sizeof *src->file_len);
    if (!src->file || !src->file_len) {
        snprintf(why, wcap, "out of memory");
        return 0;
    }
    for (size_t q = 0; q < q1; q++) {
        if (src->rank_blk[q] > src->rank_blk[q + 1] || src->rank_blk[q + 1] > src->nblk) {
            snprintf(why, wcap, "damaged: block table of rank %zu", q);
            return 0;
        }
        if (src->rank_blk[q] == src->rank_blk[q + 1]) continue;
        char p[PATH_MAX + 32];
        snprintf(p, sizeof p, "%s/rank-%04zu.trace", dir, q);
        int fd = open(p, O_RDONLY | O_CLOEXEC);
        struct stat sb;
        void *m = MAP_FAILED;
        if (fd >= 0 && fstat(fd, &sb) == 0 && sb.st_size > 0)
            m = mmap(NULL, (size_t)sb.st_size, PROT_READ, MAP_SHARED, fd, 0);
        if (fd >= 0) close(fd);
        if (m == MAP_FAILED) {
            snprintf(why, wcap, "stale: rank-%04zu.trace cannot be read", q);
            return 0;
        }
        src->file[q] = m;
        src->file_len[q] = (uint64_t)sb.st_size;
        size_t released = 0;  /* (checked whole: its pages let go behind, 16 MiB at a time) */
        for (size_t b = src->rank_blk[q]; !L && b < src->rank_blk[q + 1]; b++) {
            if (!pdt_evsrc_block_ok(src, b, (uint32_t)q)) {
                snprintf(why, wcap, "stale: rank-%04zu.trace does not match it (a block's checksum)", q);
                return 0;
            }
            size_t upto = (size_t)src->blk[b].off;
            if (upto - released >= ((size_t)16 << 20) || b + 1 == src->rank_blk[q + 1]) {
                if (b + 1 == src->rank_blk[q + 1]) upto = (size_t)sb.st_size;
                pdt_release_pages((char *)m + released, upto - released);
                released = upto & ~(pdt_page_size() - 1);
            }
        }
    }
    if (L) {
        src->verify = 1;
        src->damaged = run_damaged;
        src->damaged_ctx = L;
    }
    return 1;
}

/* Unmap the rank files and free r->src (a kept index's). */
static void unmap_ranks(pdt_replay *r)
{
    pdt_evsrc *src = r->src;
    if (!src) return;
    for (size_t q = 0; src->file && q < (size_t)r->nranks; q++)
        if (src->file[q]) munmap((void *)src->file[q], (size_t)src->file_len[q]);
    pdt_evsrc_clear(src);
    free(src->file);
    free(src->file_len);
    free(src);
    r->src = NULL;
}

static pdt_replay *load(const char *path, const char *dir, uint64_t ident, const pdt_point *pts,
                        size_t n, int verify, char *why, size_t wcap)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        snprintf(why, wcap, "%s", errno == ENOENT ? "no index yet" : strerror(errno));
        return NULL;
    }
    struct stat sb;
    ihdr h;
    uint32_t lay[12];
    layout_of(lay);
    pdt_replay *r = NULL;
    void *map = MAP_FAILED;
    lazy *L = NULL;
    if (fstat(fd, &sb) != 0 || (uint64_t)sb.st_size < HDR_BYTES ||
        pread(fd, &h, sizeof h, 0) != (ssize_t)sizeof h) {
        snprintf(why, wcap, "damaged: shorter than its header");
        goto fail;
    }
    if (memcmp(h.magic, magic, sizeof magic) || h.version != INDEX_VERSION ||
        memcmp(h.layout, lay, sizeof lay)) {
        snprintf(why, wcap, "made by another version of pdtview");
        goto fail;
    }
    if (hdr_crc(&h) != h.hdr_crc) {
        snprintf(why, wcap, "damaged: header checksum mismatch");
        goto fail;
    }
    if (h.ident != ident) {
        snprintf(why, wcap, "stale: the run folder changed since it was made");
        goto fail;
    }
    if (h.file_bytes != (uint64_t)sb.st_size) {
        snprintf(why, wcap, "damaged: %llu bytes, want %llu", (unsigned long long)sb.st_size,
                 (unsigned long long)h.file_bytes);
        goto fail;
    }
    if ((pts && h.n != n) || h.nranks == 0 || h.nranks > INT32_MAX) {
        snprintf(why, wcap, "stale: made for %llu points, the run has %zu", (unsigned long long)h.n, n);
        goto fail;
    }
    for (int i = 0; i < NSEC; i++)
        if (h.sec[i].off < HDR_BYTES || h.sec[i].off > h.file_bytes ||
            h.sec[i].bytes > h.file_bytes - h.sec[i].off) {
            snprintf(why, wcap, "damaged: section %d outside the file", i);
            goto fail;
        }
    if (h.ctab.off < HDR_BYTES || h.ctab.off > h.file_bytes ||
        h.ctab.bytes > h.file_bytes - h.ctab.off) {
        snprintf(why, wcap, "damaged: chunk table outside the file");
        goto fail;
    }
    int lazily = verify && h.file_bytes >= lazy_min_bytes;
    if (verify && !lazily && !verify_chunks(fd, &h, why, wcap)) goto fail;
    map = mmap(NULL, h.file_bytes, PROT_READ, MAP_SHARED, fd, 0);
    if (map == MAP_FAILED) {
        snprintf(why, wcap, "cannot map it: %s", strerror(errno));
        goto fail;
    }
    if (lazily) { /* only the chunk table now; each chunk when first read */
        uint32_t *tab = read_ctab(fd, &h, why, wcap);
        if (!tab) goto fail;
        L = lazy_start(map, h.file_bytes, &h, tab, fd, path);
        if (!L) {
            free(tab);
            if (!verify_chunks(fd, &h, why, wcap)) goto fail;
        }
    }
    r = calloc(1, sizeof *r);
    if (r) r->src = calloc(1, sizeof *r->src);
    if (!r || !r->src) {
        free(r);
        r = NULL;
        snprintf(why, wcap, "out of memory");
        goto fail;
    }
    r->src->nseg = h.count[S_SEGS];
    r->src->nblk = h.count[S_BLKTAB];
    r->src->m = h.m;
    r->src->nranks = (int)h.nranks;
    r->n = h.n;
    r->m = h.m;
    r->skipped = h.skipped;
    r->nranks = (int)h.nranks;
    for (int k = 0; k < PDT_EV_KIND_COUNT; k++) r->kind_count[k] = h.kind_count[k];
    r->ntri = h.count[S_TRIS];
    r->nhist = h.count[S_HIST];
    r->nedge = h.count[S_EDGES];
    r->nnode = h.count[S_NODES];
    r->nphase = h.count[S_PHASES];
    r->nmerge = h.count[S_MERGES];
    r->nmsg = h.count[S_MSGS];
    r->nhull = h.count[S_HULLS];
    r->nch = h.count[S_CH];
    r->warnings = h.count[S_WARN] ? "" : NULL;  /* so that sections() sizes it */
    r->ick_every = h.ick_every;
    r->nick = h.nick;
    int ck_ok = r->nick <= PDT_ICK_MAX &&
                (!r->nick || (r->ick_every && (r->nick - 1) * r->ick_every <= r->m));
    for (size_t c = 0; ck_ok && c <= r->nick; c++) {
        r->ick_off[c] = h.ick_off[c];
        if (c == 0) {
            ck_ok = h.ick_off[0] == 0;
            continue;
        }
        r->ick_born[c - 1] = h.ick_born[c - 1];
        ck_ok = h.ick_born[c - 1] <= r->ntri &&
                h.ick_off[c] == h.ick_off[c - 1] + pdt_rstate_blob_bytes(r, h.ick_born[c - 1]);
    }
    if (!ck_ok) {
        snprintf(why, wcap, "damaged: checkpoints do not fit the tables");
        free(r->src);
        free(r);
        r = NULL;
        goto fail;
    }
    void **ptr[NSEC];
    size_t elem[NSEC];
    uint64_t count[NSEC];
    sections(r, ptr, elem, count);
    count[S_WARN] = h.count[S_WARN];
    if (h.count[S_SORT]) count[S_SORT] = count[S_DEL] = count[S_SORTPOS] = r->n;  /* Graham's */
    for (int i = 0; i < NSEC; i++) {
        if (count[i] != h.count[i] || count[i] * elem[i] != h.sec[i].bytes) {
            snprintf(why, wcap, "damaged: section %d has the wrong size", i);
            free(r->src);
            free(r);
            r = NULL;
            goto fail;
        }
        *ptr[i] = (char *)map + h.sec[i].off;
    }
    if (!h.count[S_SORT]) { /* a run without Graham's sort */
        r->sort_ev = r->del_ev = NULL;
        r->sort_pos = NULL;
    }
    if (h.count[S_WARN] && ((const char *)map)[h.sec[S_WARN].off + h.count[S_WARN] - 1]) {
        snprintf(why, wcap, "damaged: warnings not terminated");
        free(r->src);
        free(r);
        r = NULL;
        goto fail;
    }
    if (!map_ranks(r, dir, L, why, wcap)) {
        unmap_ranks(r);
        free(r);
        r = NULL;
        goto fail;
    }
    if (pts) r->pts = pts;  /* the run's own copy (the same points) */
    r->map = map;
    r->map_len = h.file_bytes;
    r->lazy = L;
    close(fd);
    return r;
fail:
    if (L) lazy_stop(L);
    else if (map != MAP_FAILED) munmap(map, h.file_bytes);
    close(fd);
    return NULL;
}

/* ---- building ------------------------------------------------------------------ */

static int write_all(int fd, const void *p, size_t len, uint64_t off)
{
    const char *b = p;
    while (len) {
        ssize_t w = pwrite(fd, b, len > ((size_t)1 << 30) ? (size_t)1 << 30 : len, (off_t)off);
        if (w <= 0) return 0;
        b += w;
        len -= (size_t)w;
        off += (uint64_t)w;
    }
    return 1;
}

/* The events of a build: the merged order as segments (S_SEGS), and the
 * tables that find a block of a rank file (held here until write_tables
 * writes them). */
typedef struct evcopy {
    pdt_evsrc src;           /* over the reader's mappings and S_SEGS, once written */
    pdt_block_ref *blk;      /* src.blk */
    uint64_t *rank_blk;      /* src.rank_blk */
    crcacc segs_crc;
} evcopy;

/* The table of every rank's intact blocks (where each payload is in its
 * file, its aligned time base), and the source decoding them from the
 * reader's mappings of the rank files. */
static pdt_status block_table(pdt_run *run, evcopy *ec, pdt_err *err)
{
    int nranks = pdt_run_nranks(run);
    size_t nblk = 0;
    for (int q = 0; q < nranks; q++) {
        const pdt_block_ref *b;
        const uint8_t *file;
        int64_t shift;
        nblk += pdt_run_rank_blocks(run, q, &b, &file, &shift);
    }
    ec->blk = malloc((nblk ? nblk : 1) * sizeof *ec->blk);
    ec->rank_blk = malloc(((size_t)nranks + 1) * sizeof *ec->rank_blk);
    ec->src.file = calloc((size_t)nranks + 1, sizeof *ec->src.file);
    ec->src.file_len = calloc((size_t)nranks + 1, sizeof *ec->src.file_len);
    if (!ec->blk || !ec->rank_blk || !ec->src.file || !ec->src.file_len)
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    size_t k = 0;
    for (int q = 0; q < nranks; q++) {
        const pdt_block_ref *b;
        const uint8_t *file;
        int64_t shift;
        size_t nb = pdt_run_rank_blocks(run, q, &b, &file, &shift);
        pdt_rank_info ri;
        pdt_run_rank_info(run, q, &ri);
        ec->rank_blk[q] = k;
        ec->src.file[q] = file;
        ec->src.file_len[q] = file ? ri.bytes : 0;
        for (size_t j = 0; j < nb; j++, k++)
            ec->blk[k] = (pdt_block_ref){b[j].off + PDT_BLOCK_HEADER_BYTES, b[j].first,
                                         b[j].base_t + (uint64_t)shift, b[j].len, b[j].count};
    }
    ec->rank_blk[nranks] = k;
    ec->src.nblk = nblk;
    ec->src.nranks = nranks;
    return PDT_OK;
}

/* The merged order of run, streamed to the build (pass 1) by the reader's
 * merge (one decoded block per rank in memory), and written as it goes
 * into fd after the blocks as segments (S_SEGS).  At its end the blocks and
 * segments are mapped, and ec->src decodes the events from there. */
typedef struct evstream {
    pdt_merge *mg;
    int fd;
    ihdr *h;
    evcopy *ec;
    uint64_t at, off;     /* S_SEGS: where it starts, where the next batch goes */
    pdt_evseg cur, *buf;  /* the segment being made; a batch of finished ones */
    size_t nb, count, nseg;
    void *map;            /* at the end: [0, the end of S_SEGS) of the file */
    size_t map_len;
    uint64_t *place_off;  /* the placer's start: after S_SEGS */
    int done;
} evstream;

enum { SEG_BATCH = 8192 };

static int seg_flush(evstream *es, pdt_err *err)
{
    if (!es->nb) return 1;
    if (!write_all(es->fd, es->buf, es->nb * sizeof *es->buf, es->off)) {
        pdt_err_set(err, PDT_ERR_IO, "writing the index: %s", strerror(errno));
        return 0;
    }
    crc_feed(&es->ec->segs_crc, es->buf, es->nb * sizeof *es->buf);
    es->off += es->nb * sizeof *es->buf;
    es->nseg += es->nb;
    es->nb = 0;
    return 1;
}

/* The last segment out, the section's place, the mapping for ec->src. */
static int stream_finish(evstream *es, pdt_err *err)
{
    if (es->cur.rank != UINT32_MAX) es->buf[es->nb++] = es->cur;
    if (!seg_flush(es, err)) return 0;
    es->h->sec[S_SEGS] = (isec){es->at, (uint64_t)es->nseg * sizeof(pdt_evseg), 0, 0};
    es->h->count[S_SEGS] = es->nseg;
    es->map_len = (size_t)es->off;
    es->map = mmap(NULL, es->map_len, PROT_READ, MAP_SHARED, es->fd, 0);
    if (es->map == MAP_FAILED) {
        es->map = NULL;
        pdt_err_set(err, PDT_ERR_IO, "mapping the index: %s", strerror(errno));
        return 0;
    }
    pdt_evsrc *src = &es->ec->src;
    src->blk = es->ec->blk;
    src->rank_blk = es->ec->rank_blk;
    src->seg = (const pdt_evseg *)(void *)((const char *)es->map + es->at);
    src->nseg = es->nseg;
    src->m = es->count;
    src->drop_behind = 1;
    *es->place_off = es->off;
    return 1;
}

static int stream_fill(evstream *es, pdt_rec *out, size_t max, pdt_err *err)
{
    size_t j = 0;
    while (!es->done && j < max) {
        int got = pdt_merge_next(es->mg, &out[j], err);
        if (got < 0) return -1;
        if (got == 0) {
            es->done = 1;
            if (!stream_finish(es, err)) return -1;
            break;
        }
        const pdt_rec *rec = &out[j++];
        if (rec->rank != es->cur.rank || rec->seq - es->cur.seq0 != es->count - es->cur.start) {
            if (es->cur.rank != UINT32_MAX) {
                es->buf[es->nb++] = es->cur;
                if (es->nb == SEG_BATCH && !seg_flush(es, err)) return -1;
            }
            es->cur = (pdt_evseg){(uint32_t)es->count, rec->rank, rec->seq};
        }
        es->count++;
    }
    return (int)j;
}


/* The merge (decoding the rank files, the busier half of the build's first
 * pass) runs in a thread of its own, a batch of events ahead of the build:
 * two batches, one filled while the other is read. */
enum { PIPE_BATCH = 8192 };

typedef struct evpipe {
    evstream *es;
    pthread_t th;
    int started;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    pdt_rec *buf[2];
    size_t n[2];
    int full[2];      /* filled, not yet read */
    int last[2];      /* the stream ends after this batch (n may be 0) */
    int failed[2];    /* the stream failed filling it (perr) */
    int stop;         /* the reader is gone: stop filling */
    pdt_err perr;
    size_t slot, at;  /* the reader's batch and place in it */
    int ended;
} evpipe;

static void *pipe_worker(void *arg)
{
    evpipe *p = arg;
    for (size_t k = 0;; k ^= 1) {
        pthread_mutex_lock(&p->mu);
        while (p->full[k] && !p->stop) pthread_cond_wait(&p->cv, &p->mu);
        int stop = p->stop;
        pthread_mutex_unlock(&p->mu);
        if (stop) return NULL;
        int got = stream_fill(p->es, p->buf[k], PIPE_BATCH, &p->perr);
        pthread_mutex_lock(&p->mu);
        p->n[k] = got > 0 ? (size_t)got : 0;
        p->failed[k] = got < 0;
        p->last[k] = got <= 0 || p->es->done;
        p->full[k] = 1;
        int end = p->last[k];
        pthread_cond_broadcast(&p->cv);
        pthread_mutex_unlock(&p->mu);
        if (end) return NULL;
    }
}

static int stream_next(void *ctx, pdt_rec *out, size_t max, pdt_err *err)
{
    evpipe *p = *(evpipe **)ctx;
    size_t j = 0;
    while (j < max && !p->ended) {
        size_t k = p->slot;
        pthread_mutex_lock(&p->mu);
        while (!p->full[k]) pthread_cond_wait(&p->cv, &p->mu);
        pthread_mutex_unlock(&p->mu);
        if (p->failed[k]) {
            *err = p->perr;
            return -1;
        }
        size_t take = p->n[k] - p->at < max - j ? p->n[k] - p->at : max - j;
        memcpy(out + j, p->buf[k] + p->at, take * sizeof *out);
        j += take;
        p->at += take;
        if (p->at == p->n[k]) { /* give the batch back */
            if (p->last[k]) p->ended = 1;
            pthread_mutex_lock(&p->mu);
            p->full[k] = 0;
            pthread_cond_broadcast(&p->cv);
            pthread_mutex_unlock(&p->mu);
            p->slot ^= 1;
            p->at = 0;
        }
    }
    return (int)j;
}

/* Start the merge's thread: 1, or 0 and err set. */
static int pipe_start(evpipe *p, evstream *es, pdt_err *err)
{
    memset(p, 0, sizeof *p);
    p->es = es;
    p->buf[0] = malloc(PIPE_BATCH * sizeof *p->buf[0]);
    p->buf[1] = malloc(PIPE_BATCH * sizeof *p->buf[1]);
    if (!p->buf[0] || !p->buf[1]) {
        pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
        return 0;
    }
    pthread_mutex_init(&p->mu, NULL);
    pthread_cond_init(&p->cv, NULL);
    if (pthread_create(&p->th, NULL, pipe_worker, p) != 0) {
        pdt_err_set(err, PDT_ERR_NOMEM, "cannot start a thread: %s", strerror(errno));
        return 0;
    }
    p->started = 1;
    return 1;
}

/* Stop the merge's thread (wherever it is) and free the batches. */
static void pipe_stop(evpipe *p)
{
    if (p->started) {
        pthread_mutex_lock(&p->mu);
        p->stop = 1;
        pthread_cond_broadcast(&p->cv);
        pthread_mutex_unlock(&p->mu);
        pthread_join(p->th, NULL);
        pthread_mutex_destroy(&p->mu);
        pthread_cond_destroy(&p->cv);
    }
    free(p->buf[0]);
    free(p->buf[1]);
    p->started = 0;
}

static int read_all(int fd, uint64_t at, void *p, size_t bytes);

static int fd_get(void *ctx, uint64_t at, void *p, size_t bytes)
{
    return read_all(*(const int *)ctx, at, p, bytes);
}

/* The state at every r->ick_every-th cursor, stepped forwards from 0 (the
 * streamed replay's tables read back from fd), written at off one after
 * the other (r->nick of them), each holding the triangles born before its
 * cursor; sets r->ick_off and r->ick_born.  Memory: one state. */
static int write_checkpoints(pdt_replay *r, int fd, uint64_t off, crcacc *crc)
{
    static const uint8_t zeros[8];
    r->ick_off[0] = 0;
    if (!r->nick) return 1;
    pdt_rstate *s = pdt_rstate_new(r);
    pdt_fwd *fw = pdt_fwd_new(r, fd_get, &fd);
    int ok = s && fw;
    for (size_t c = 0; ok && c < r->nick; c++) {
        ok = pdt_fwd_to(fw, s, c * r->ick_every);
        size_t born = pdt_rstate_born(r, s), bytes = pdt_rstate_blob_bytes(r, born);
        const void *part[5];
        size_t len[5], pad[5];
        uint64_t at = off + r->ick_off[c];
        pdt_rstate_blob_parts(r, s, born, part, len, pad);
        for (int j = 0; ok && j < 5; j++) {
            for (size_t o = 0; ok && o < len[j]; o += CHUNK_BYTES) { /* (a paged state's
                                                                       * pages go back) */
                size_t k = len[j] - o < CHUNK_BYTES ? len[j] - o : CHUNK_BYTES;
                ok = write_all(fd, (const char *)part[j] + o, k, at + o);
                crc_feed(crc, (const char *)part[j] + o, k);
                pdt_replay_give_back(r, s);
            }
            ok = ok && write_all(fd, zeros, pad[j], at + len[j]);
            crc_feed(crc, zeros, pad[j]);
            at += len[j] + pad[j];
        }
        r->ick_born[c] = born;
        r->ick_off[c + 1] = r->ick_off[c] + bytes;
    }
    pdt_fwd_free(fw);
    pdt_rstate_free(s);
    return ok;
}

/* The triangles and histories of a replay being built, streamed to the index
 * file itself (pdt_replay_place): written once, in place, by pwrite (not
 * through a shared mapping: on this file system page faults on a file being
 * written back wait for the disk), and never held in memory.  The triangle
 * events the build groups go to a spill of their own, an unnamed file
 * beside the index (O_TMPFILE), dropped (closed) once they are grouped: its
 * pages leave the page cache with it, mostly before they were written back. */
typedef struct placer {
    struct evpipe *pipe; /* (first: the stream's context is the placer's) */
    int fd;
    uint64_t off;  /* where the next table goes */
    int sfd[PDT_SCR_COUNT];  /* the scratch files (-1: not made yet, or dropped) */
    const char *near;        /* made in the folder of this path */
    pdt_run *run;
    pthread_mutex_t mu;      /* (the grouping's threads make them) */
} placer;

static uint64_t place_reserve(void *ctx, uint64_t bytes)
{
    placer *pc = ctx;
    uint64_t at = (pc->off + 63) & ~(uint64_t)63;
    pc->off = at + bytes;
    return at;
}

static int place_put(void *ctx, uint64_t at, const void *p, size_t bytes)
{
    return write_all(((placer *)ctx)->fd, p, bytes, at);
}

static int read_all(int fd, uint64_t at, void *p, size_t bytes)
{
    char *b = p;
    while (bytes) {
        ssize_t got = pread(fd, b, bytes, (off_t)at);
        if (got <= 0) return 0;
        b += got;
        bytes -= (size_t)got;
        at += (uint64_t)got;
    }
    return 1;
}

static int place_get(void *ctx, uint64_t at, void *p, size_t bytes)
{
    return read_all(((placer *)ctx)->fd, at, p, bytes);
}

static int open_spill(const char *path);

static int scratch_put(void *ctx, int file, uint64_t at, const void *p, size_t bytes)
{
    placer *pc = ctx;
    if (file < 0 || file >= PDT_SCR_COUNT) return 0;
    pthread_mutex_lock(&pc->mu);
    if (pc->sfd[file] < 0) pc->sfd[file] = open_spill(pc->near);
    int fd = pc->sfd[file];
    pthread_mutex_unlock(&pc->mu);
    return fd >= 0 && write_all(fd, p, bytes, at);
}

static int scratch_get(void *ctx, int file, uint64_t at, void *p, size_t bytes)
{
    placer *pc = ctx;
    if (file < 0 || file >= PDT_SCR_COUNT || pc->sfd[file] < 0) return 0;
    return read_all(pc->sfd[file], at, p, bytes);
}

static void points_read(void *ctx) { pdt_run_release_points(((placer *)ctx)->run); }

/* A scratch file done with: closed (unnamed: its pages go with it, mostly
 * before they were written back). */
static void scratch_drop(void *ctx, int file)
{
    placer *pc = ctx;
    if (file < 0 || file >= PDT_SCR_COUNT || pc->sfd[file] < 0) return;
    close(pc->sfd[file]);
    pc->sfd[file] = -1;
}

/* An unnamed scratch file in the folder of `path` (O_TMPFILE; where the file
 * system has none, a named one removed at once), or -1. */
static int open_spill(const char *path)
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

/* Write the tables of r after the records and the streamed ones (at pc->off),
 * then the header. */
/* write_checkpoints in a thread of its own (stepping through the run takes
 * a core while the tables are written). */
typedef struct ck_job {
    pdt_replay *r;
    int fd, ok;
    uint64_t off;
    crcacc crc;
} ck_job;

static void *ck_worker(void *arg)
{
    ck_job *j = arg;
    j->ok = write_checkpoints(j->r, j->fd, j->off, &j->crc);
    return NULL;
}

/* 1 if section i of a streamed replay was written by the build (at *at). */
static int streamed_sec(const pdt_replay *r, int i, uint64_t *at)
{
    if (!r->streamed) return 0;
    switch (i) {
    case S_TRIS: *at = r->tris_at; return 1;
    case S_HIST: *at = r->hist_at; return 1;
    case S_EVOBJ: *at = r->evobj_at; return 1;
    case S_EVKIND: *at = r->evkind_at; return 1;
    case S_LIFT: *at = r->lift_at; return 1;
    default: return 0;
    }
}

static pdt_status write_tables(pdt_replay *r, int fd, ihdr *h, uint64_t ident, const placer *pc,
                               evcopy *ec, pdt_err *err)
{
    void **ptr[NSEC];
    size_t elem[NSEC];
    uint64_t count[NSEC];
    sections(r, ptr, elem, count);
    /* the places of the tables (the checkpoints last: their sizes are known
     * once they are made) */
    uint64_t off = pc->off;
    for (int i = 0; i < NSEC; i++) {
        h->count[i] = count[i];
        if (i == S_SEGS || i == S_CKPT) continue; /* (S_SEGS: written first, stream_next) */
        uint64_t at;
        if (streamed_sec(r, i, &at)) {
            h->sec[i] = (isec){at, count[i] * elem[i], 0, 0};
            continue;
        }
        off = (off + 63) & ~(uint64_t)63;
        h->sec[i] = (isec){off, count[i] * elem[i], 0, 0};
        off += h->sec[i].bytes;
    }
    off = (off + 63) & ~(uint64_t)63;
    ck_job ck = {r, fd, 0, off, {0}};
    pthread_t th;
    int threaded = pthread_create(&th, NULL, ck_worker, &ck) == 0;
    int wrote = 1;
    for (int i = 0; wrote && i < NSEC; i++) {
        uint64_t at;
        if (i == S_SEGS || i == S_CKPT || streamed_sec(r, i, &at)) continue;
        /* (the points, read in place from the run: a chunk at a time, their
         * pages given back behind, while the checkpoints' state is held) */
        for (uint64_t o = 0; wrote && o < h->sec[i].bytes; o += CHUNK_BYTES) {
            uint64_t k = h->sec[i].bytes - o < CHUNK_BYTES ? h->sec[i].bytes - o : CHUNK_BYTES;
            wrote = write_all(fd, (const char *)*ptr[i] + o, (size_t)k, h->sec[i].off + o);
            if (i == S_POINTS) pdt_run_release_points(pc->run);
            pdt_replay_tab_release(r, (const char *)*ptr[i] + o, (size_t)k);  /* (paged) */
        }
    }
    if (threaded) pthread_join(th, NULL);
    else ck_worker(&ck);
    crcacc ck_crc = ck.crc;
    if (!wrote || !ck.ok) {
        free(ck_crc.crc);
        return pdt_err_set(err, PDT_ERR_IO, "writing the index: %s", strerror(errno));
    }
    h->count[S_CKPT] = r->nick ? r->ick_off[r->nick] : 0;
    h->sec[S_CKPT] = (isec){off, h->count[S_CKPT], 0, 0};
    off += h->count[S_CKPT];
    /* the chunk checksums: of the tables in memory from memory, of the
     * records and checkpoints as they were written, of the streamed
     * triangles and histories read back (pread, by up to four threads) */
    uint64_t first[NSEC + 1], n = 0;
    for (int i = 0; i < NSEC; i++) first[i] = n, n += chunks_of(h->sec[i].bytes);
    first[NSEC] = n;
    uint32_t *tab = malloc(n ? n * sizeof *tab : 1);
    uint8_t *todo = calloc(n ? n : 1, 1);
    int have = tab && todo;
    for (int i = 0; have && i < NSEC; i++) {
        uint64_t nc = chunks_of(h->sec[i].bytes), at;
        if (i == S_SEGS) {
            have = crc_done(&ec->segs_crc, h->sec[i].bytes, tab + first[i]);
        } else if (i == S_CKPT) {
            have = crc_done(&ck_crc, h->sec[i].bytes, tab + first[i]);
        } else if (streamed_sec(r, i, &at)) {
            memset(todo + first[i], 1, nc);
        } else {
            const char *p = *ptr[i];
            for (uint64_t c = 0; c < nc; c++) {
                uint64_t lo = c * CHUNK_BYTES, hi = lo + CHUNK_BYTES;
                if (hi > h->sec[i].bytes) hi = h->sec[i].bytes;
                tab[first[i] + c] = pdt_crc32c(0, p + lo, (size_t)(hi - lo));
                if (i == S_POINTS) pdt_run_release_points(pc->run);
                pdt_replay_tab_release(r, p + lo, (size_t)(hi - lo));
            }
        }
    }
    free(ck_crc.crc);
    if (!have) {
        free(tab);
        free(todo);
        return pdt_err_set(err, PDT_ERR_NOMEM, "out of memory for the index's checksums");
    }
    verify_job j = {fd, h, tab, 1, todo, n, first, 0, 0};
    run_job(&j);
    free(todo);
    if (atomic_load(&j.bad)) {
        free(tab);
        return pdt_err_set(err, PDT_ERR_IO, "reading the index back for its checksums failed");
    }
    off = (off + 63) & ~(uint64_t)63;
    h->ctab = (isec){off, n * sizeof *tab, pdt_crc32c(0, tab, (size_t)(n * sizeof *tab)), 0};
    wrote = write_all(fd, tab, (size_t)(n * sizeof *tab), off);
    free(tab);
    if (!wrote) return pdt_err_set(err, PDT_ERR_IO, "writing the index: %s", strerror(errno));
    off += h->ctab.bytes;
    memcpy(h->magic, magic, sizeof magic);
    h->version = INDEX_VERSION;
    h->ident = ident;
    h->file_bytes = off;
    layout_of(h->layout);
    h->n = r->n;
    h->m = r->m;
    h->skipped = r->skipped;
    h->nranks = (uint64_t)r->nranks;
    h->ick_every = r->ick_every;
    h->nick = r->nick;
    memcpy(h->ick_off, r->ick_off, sizeof h->ick_off);
    memcpy(h->ick_born, r->ick_born, sizeof h->ick_born);
    for (int k = 0; k < PDT_EV_KIND_COUNT; k++) h->kind_count[k] = r->kind_count[k];
    h->hdr_crc = hdr_crc(h);
    unsigned char page[HDR_BYTES];
    memset(page, 0, sizeof page);
    memcpy(page, h, sizeof *h);
    if (ftruncate(fd, (off_t)off) != 0 || !write_all(fd, page, sizeof page, 0))
        return pdt_err_set(err, PDT_ERR_IO, "writing the index: %s", strerror(errno));
    return PDT_OK;
}

/* Build the index of run at `path` (temporary file + rename). */
static pdt_status build(pdt_run *run, const pdt_point *pts, size_t n, int nranks, uint64_t ident,
                        const char *path, uint64_t budget, uint64_t *work, uint32_t *buckets,
                        pdt_err *err)
{
    /* the index's name is ours: a link planted there is replaced, not
     * followed; leftovers of killed builds are removed (pdt/safefile.h) */
    pdt_safe_file sf;
    pdt_status st0 = pdt_safe_open(&sf, path, PDT_SAFE_NOFOLLOW, err);
    if (st0 != PDT_OK) return st0;
    char tmp[PATH_MAX + 256];
    snprintf(tmp, sizeof tmp, "%s", sf.tmp);
    int fd = sf.fd;
    ihdr *h = calloc(1, sizeof *h);
    evcopy ec;
    memset(&ec, 0, sizeof ec);
    pdt_replay *r = NULL;
    uint64_t events = 0;
    for (int q = 0; q < nranks; q++) {
        pdt_rank_info ri;
        pdt_run_rank_info(run, q, &ri);
        events += ri.events;
    }
    size_t m = (size_t)events;
    evstream es;
    memset(&es, 0, sizeof es);
    es.cur.rank = UINT32_MAX;
    es.buf = malloc(SEG_BATCH * sizeof *es.buf);
    evpipe pipe;
    memset(&pipe, 0, sizeof pipe);
    placer pc = {&pipe, fd, 0, {0}, tmp, run, PTHREAD_MUTEX_INITIALIZER};
    for (int k = 0; k < PDT_SCR_COUNT; k++) pc.sfd[k] = -1;
    pdt_replay_place pl = {place_reserve, place_put,   place_get, scratch_put, scratch_get,
                           scratch_drop,  points_read, &pc,       budget,      stream_next,
                           &ec.src,       0,           0};
    pdt_status st = h && es.buf ? block_table(run, &ec, err)
                                : pdt_err_set(err, PDT_ERR_NOMEM, "out of memory");
    if (st == PDT_OK) st = pdt_merge_open(run, &es.mg, err);
    if (st == PDT_OK) {
        es.fd = fd;
        es.h = h;
        es.ec = &ec;
        /* the per-event tables first (their sizes are known: pass 1 writes
         * them as it goes), then the segments */
        pc.off = HDR_BYTES;
        pl.evobj_at = place_reserve(&pc, (uint64_t)m * sizeof(int32_t));
        pl.evkind_at = place_reserve(&pc, m);
        es.at = es.off = (pc.off + 63) & ~(uint64_t)63;
        es.place_off = &pc.off;
        if ((pc.sfd[PDT_SCR_SPILL] = open_spill(tmp)) < 0)
            st = pdt_err_set(err, PDT_ERR_IO, "%s: a scratch file beside it: %s", tmp, strerror(errno));
    }
    if (st == PDT_OK && !pipe_start(&pipe, &es, err)) st = err->code;
    if (st == PDT_OK) st = pdt_replay_build(pts, n, NULL, m, nranks, &pl, &r, err);
    pipe_stop(&pipe);
    for (int k = 0; k < PDT_SCR_COUNT; k++) scratch_drop(&pc, k);  /* the scratch: gone */
    if (st == PDT_OK) {
        r->warnings = pdt_run_warnings(run);
        size_t parts = (r->m + ICK_MAX_EVERY - 1) / ICK_MAX_EVERY;
        parts = parts < ICK_PARTS ? ICK_PARTS : parts > ICK_MAX_PARTS ? ICK_MAX_PARTS : parts;
        size_t every = r->m / parts;
        r->ick_every = every < ICK_MIN_EVERY ? ICK_MIN_EVERY : every;
        r->nick = r->m / r->ick_every + 1;
        /* the checkpoints' state: paged beyond a quarter of the budget, as a
         * replay's is (pdt_replay_set_mem) */
        r->mem_budget = budget;
        r->state_paged = budget && pdt_replay_state_bytes(r) > budget / 4;
        st = write_tables(r, fd, h, ident, &pc, &ec, err);
        pdt_run_release_points(run);  /* (written from them) */
        *work = r->build_peak + (r->state_paged ? 0 : pdt_replay_state_bytes(r)); /* (the
                                                            * checkpoints' state, when held) */
        *buckets = r->build_buckets;
        r->nick = 0;  /* r's own tables are freed below; it has no mapped checkpoints */
    }
    pdt_replay_free(r);
    pdt_evsrc_clear(&ec.src);
    pdt_merge_close(es.mg);
    free(es.buf);
    if (es.map) munmap(es.map, es.map_len);
    /* into place over a stale index by an exchange of names, without ext4
     * writing the new one back inside the call (gigabytes for a big run) */
    if (st == PDT_OK) st = pdt_safe_commit(&sf, err);
    else pdt_safe_abort(&sf);
    free(h);
    free(ec.blk);
    free(ec.rank_blk);
    free(ec.src.file);
    free(ec.src.file_len);
    free(ec.segs_crc.crc);
    return st;
}

/* ---- opening a run ---------------------------------------------------------------- */

pdt_status pdt_replay_open_kept(const char *dir, uint64_t budget, pdt_replay **out,
                                pdt_replay_open_info *info, pdt_err *err)
{
    pdt_replay_open_info dummy;
    if (!info) info = &dummy;
    memset(info, 0, sizeof *info);
    *out = NULL;
    uint64_t ident = 0;
    pdt_status st = run_ident(dir, &ident, err);
    if (st != PDT_OK) return st;
    char path[PATH_MAX];
    for (int where = 0; where < 2; where++) {
        char why[160];
        if (!index_path(dir, where, path, sizeof path)) continue;
        pdt_replay *r = load(path, dir, ident, NULL, 0, 1, why, sizeof why);
        if (!r) {
            if (where == 0 || strcmp(why, "no index yet"))
                snprintf(info->why, sizeof info->why, "%s", why);
            continue;
        }
        info->indexed = 1;
        info->events = r->m;
        snprintf(info->path, sizeof info->path, "%s", path);
        pdt_replay_set_mem(r, budget);
        *out = r;
        return PDT_OK;
    }
    return PDT_OK;
}

/* The replay of run in memory, as before the kept index. */
static pdt_status in_memory(pdt_run *run, const pdt_point *pts, size_t n, int nranks,
                            pdt_replay **out, pdt_err *err)
{
    const pdt_rec *recs;
    size_t m;
    pdt_status st = pdt_run_merged(run, &recs, &m, err);
    if (st != PDT_OK) return st;
    return pdt_replay_new(pts, n, recs, m, nranks, out, err);
}

static void release_run_points(const void *run)
{
    pdt_run_release_points(run);
}

pdt_status pdt_replay_open_run(pdt_run *run, const char *dir, uint64_t budget, int use_index,
                               pdt_replay **out, pdt_replay_open_info *info, pdt_err *err)
{
    pdt_replay_open_info dummy;
    if (!info) info = &dummy;
    memset(info, 0, sizeof *info);
    *out = NULL;
    size_t n;
    const pdt_point *pts = pdt_run_points(run, &n);
    int nranks = pdt_run_nranks(run);
    uint64_t events = 0;
    for (int q = 0; q < nranks; q++) {
        pdt_rank_info ri;
        pdt_run_rank_info(run, q, &ri);
        events += ri.events;
    }
    info->events = events;
    if (use_index < 0) use_index = events * EST_BYTES_PER_EVENT > budget / 4;
    pdt_status st;
    if (!use_index) {
        st = in_memory(run, pts, n, nranks, out, err);
        if (st == PDT_OK) pdt_replay_set_mem(*out, budget);
        return st;
    }
    uint64_t ident = 0;
    st = run_ident(dir, &ident, err);
    if (st != PDT_OK) return st;
    char path[PATH_MAX];
    pdt_replay *r = NULL;
    /* a kept index beside the run, else in the cache */
    for (int where = 0; where < 2 && !r; where++) {
        char why[160];
        if (!index_path(dir, where, path, sizeof path)) continue;
        r = load(path, dir, ident, pts, n, 1, why, sizeof why);
        if (!r && where == 0) snprintf(info->why, sizeof info->why, "%s", why);
        if (!r && where == 1 && strcmp(why, "no index yet"))
            snprintf(info->why, sizeof info->why, "%s", why);
    }
    if (!r) { /* (re)build it: beside the run if the folder takes it, else in the cache */
        double t0 = pdt_seconds();
        for (int where = 0; where < 2 && !r; where++) {
            if (!index_path(dir, where, path, sizeof path)) continue;
            if (where == 1) {
                char cdir[PATH_MAX];
                if (!cache_dir(cdir, sizeof cdir) || !make_dirs(cdir)) continue;
            }
            pdt_err e2 = {0};
            if (build(run, pts, n, nranks, ident, path, budget, &info->build_bytes,
                      &info->build_buckets, &e2) != PDT_OK) {
                snprintf(info->write_error, sizeof info->write_error, "%s", e2.msg);
                pdt_err_clear(&e2);
                continue;
            }
            char why[160];
            r = load(path, dir, ident, pts, n, 0, why, sizeof why);
        }
        info->built = r != NULL;
        info->build_s = pdt_seconds() - t0;
    }
    if (!r) { /* no place to keep an index: the whole run in memory */
        st = in_memory(run, pts, n, nranks, out, err);
        if (st == PDT_OK) pdt_replay_set_mem(*out, budget);
        return st;
    }
    info->indexed = 1;
    snprintf(info->path, sizeof info->path, "%s", path);
    r->release_points = release_run_points;  /* read in place: given back after frames */
    r->release_ctx = run;
    pdt_replay_set_mem(r, budget);
    *out = r;
    return PDT_OK;
}
