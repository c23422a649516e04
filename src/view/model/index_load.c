/* pdt — loading a kept index: the run's identity, the index's place, and
 * mapping a valid index onto a replay. */
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

void pdt_ix_layout_of(uint32_t out[12])
{
    const uint32_t l[12] = {sizeof(pdt_block_ref) << 8 | sizeof(pdt_evseg), sizeof(pdt_rtri), sizeof(pdt_rtri_hist),
                            sizeof(pdt_redge), sizeof(pdt_rnode), sizeof(pdt_rphase),
                            sizeof(pdt_rmerge), sizeof(pdt_rmsg), sizeof(pdt_rhull),
                            sizeof(slot_change), sizeof(pdt_point), PDT_SLOT_PER_RANK};
    memcpy(out, l, sizeof l);
}

/* Where each section lives in r (and its event source r->src) and how big
 * its elements are; counts from r. */
void pdt_ix_sections(pdt_replay *r, void **ptr[NSEC], size_t elem[NSEC], uint64_t count[NSEC])
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
    SEC(S_SORT, sort_ev, r->sort_ev ? r->n : 0);  /* (none: NULL, see pdt_ix_load) */
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

static void unmap_ranks(pdt_replay *r);

void pdt_index_unmap(pdt_replay *r)
{
    unmap_ranks(r);
    if (r->lazy) pdt_ix_lazy_stop(r->lazy);
    munmap(r->map, r->map_len);
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
pdt_status pdt_ix_run_ident(const char *dir, uint64_t *id, pdt_err *err)
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
        char why[160];
        int mfd = pdt_open_input(path, why, sizeof why); /* (not a file: the run's open says so) */
        if (mfd >= 0) {
            char buf[4096];
            ssize_t got;
            while ((got = read(mfd, buf, sizeof buf)) > 0) h = fnv(h, buf, (size_t)got);
            close(mfd);
        }
        *id = h;
    }
    free(f);
    return st;
}

/* The cache folder ($XDG_CACHE_HOME/pdt, else ~/.cache/pdt) into buf; 0 if
 * there is none (no HOME). */
int pdt_ix_cache_dir(char *buf, size_t cap)
{
    const char *x = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    if (x && *x == '/') snprintf(buf, cap, "%s/pdt", x);
    else if (home && *home) snprintf(buf, cap, "%s/.cache/pdt", home);
    else return 0;
    return 1;
}

/* mkdir -p of a folder we own (0700 like other cache folders). */
int pdt_ix_make_dirs(const char *path)
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
int pdt_ix_index_path(const char *dir, int where, char *buf, size_t cap)
{
    if (where == 0) {
        return snprintf(buf, cap, "%s/" INDEX_NAME, dir) < (int)cap;
    }
    char cdir[PATH_MAX], real[PATH_MAX];
    if (!pdt_ix_cache_dir(cdir, sizeof cdir) || !realpath(dir, real)) return 0;
    uint64_t h = fnv(0xCBF29CE484222325ull, real, strlen(real));
    return snprintf(buf, cap, "%s/run-%016llx" INDEX_NAME, cdir, (unsigned long long)h) < (int)cap;
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
        char whyopen[160];
        int fd = pdt_open_input(p, whyopen, sizeof whyopen);
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
        src->damaged = pdt_ix_run_damaged;
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

/* Read and check the header of the index open on fd against the run
 * (ident, n when pts): 1, or 0 with a reason in why. */
static int read_header(int fd, ihdr *h, uint64_t ident, const pdt_point *pts, size_t n, char *why,
                       size_t wcap)
{
    struct stat sb;
    uint32_t lay[12];
    pdt_ix_layout_of(lay);
    if (fstat(fd, &sb) != 0 || (uint64_t)sb.st_size < HDR_BYTES ||
        pread(fd, h, sizeof *h, 0) != (ssize_t)sizeof *h)
        return snprintf(why, wcap, "damaged: shorter than its header"), 0;
    if (memcmp(h->magic, magic, sizeof magic) || h->version != INDEX_VERSION ||
        memcmp(h->layout, lay, sizeof lay))
        return snprintf(why, wcap, "made by another version of pdtview"), 0;
    if (pdt_ix_ihdr_crc(h) != h->hdr_crc)
        return snprintf(why, wcap, "damaged: header checksum mismatch"), 0;
    if (h->ident != ident)
        return snprintf(why, wcap, "stale: the run folder changed since it was made"), 0;
    if (h->file_bytes != (uint64_t)sb.st_size)
        return snprintf(why, wcap, "damaged: %llu bytes, want %llu", (unsigned long long)sb.st_size,
                        (unsigned long long)h->file_bytes), 0;
    if ((pts && h->n != n) || h->nranks == 0 || h->nranks > INT32_MAX)
        return snprintf(why, wcap, "stale: made for %llu points, the run has %zu",
                        (unsigned long long)h->n, n), 0;
    for (int i = 0; i < NSEC; i++)
        if (h->sec[i].off < HDR_BYTES || h->sec[i].off > h->file_bytes ||
            h->sec[i].bytes > h->file_bytes - h->sec[i].off)
            return snprintf(why, wcap, "damaged: section %d outside the file", i), 0;
    if (h->ctab.off < HDR_BYTES || h->ctab.off > h->file_bytes ||
        h->ctab.bytes > h->file_bytes - h->ctab.off)
        return snprintf(why, wcap, "damaged: chunk table outside the file"), 0;
    return 1;
}

/* Map the index (checked whole now, or lazily when verify and big: then
 * *L): the mapping, or MAP_FAILED with a reason in why. */
static void *map_index(int fd, const ihdr *h, const char *path, int verify, lazy **L, char *why,
                       size_t wcap)
{
    int lazily = verify && h->file_bytes >= pdt_ix_lazy_min_bytes;
    if (lazily) { /* the chunk table and the small sections now; the big ones when asked for */
        uint32_t *tab = pdt_ix_read_ctab(fd, h, why, wcap);
        if (!tab) return MAP_FAILED;
        why[0] = 0;
        *L = pdt_ix_lazy_start(h, tab, fd, path, why, wcap);
        if (!*L) free(tab);
        if (!*L && why[0]) return MAP_FAILED;
        lazily = *L != NULL;
    }
    if (verify && !lazily && !pdt_ix_verify_chunks(fd, h, why, wcap)) return MAP_FAILED;
    void *map = mmap(NULL, h->file_bytes, PROT_READ, MAP_SHARED, fd, 0);
    if (map == MAP_FAILED) {
        snprintf(why, wcap, "cannot map it: %s", strerror(errno));
        if (*L) pdt_ix_lazy_stop(*L);
        *L = NULL;
    }
    return map;
}

/* A new replay with the header's counts and checkpoints (its tables not
 * set yet), or NULL with a reason in why. */
static pdt_replay *replay_of_header(const ihdr *h, char *why, size_t wcap)
{
    pdt_replay *r = calloc(1, sizeof *r);
    if (r) r->src = calloc(1, sizeof *r->src);
    if (!r || !r->src) {
        free(r);
        snprintf(why, wcap, "out of memory");
        return NULL;
    }
    r->src->nseg = h->count[S_SEGS];
    r->src->nblk = h->count[S_BLKTAB];
    r->src->m = h->m;
    r->src->nranks = (int)h->nranks;
    r->n = h->n;
    r->m = h->m;
    r->skipped = h->skipped;
    r->nranks = (int)h->nranks;
    for (int k = 0; k < PDT_EV_KIND_COUNT; k++) r->kind_count[k] = h->kind_count[k];
    r->ntri = h->count[S_TRIS];
    r->nhist = h->count[S_HIST];
    r->nedge = h->count[S_EDGES];
    r->nnode = h->count[S_NODES];
    r->nphase = h->count[S_PHASES];
    r->nmerge = h->count[S_MERGES];
    r->nmsg = h->count[S_MSGS];
    r->nhull = h->count[S_HULLS];
    r->nch = h->count[S_CH];
    r->warnings = h->count[S_WARN] ? "" : NULL;  /* so that pdt_ix_sections() sizes it */
    r->ick_every = h->ick_every;
    r->nick = h->nick;
    int ck_ok = r->nick <= PDT_ICK_MAX &&
                (!r->nick || (r->ick_every && (r->nick - 1) * r->ick_every <= r->m));
    for (size_t c = 0; ck_ok && c <= r->nick; c++) {
        r->ick_off[c] = h->ick_off[c];
        if (c == 0) {
            ck_ok = h->ick_off[0] == 0;
            continue;
        }
        r->ick_born[c - 1] = h->ick_born[c - 1];
        ck_ok = h->ick_born[c - 1] <= r->ntri &&
                h->ick_off[c] == h->ick_off[c - 1] + pdt_rstate_blob_bytes(r, h->ick_born[c - 1]);
    }
    if (!ck_ok) {
        snprintf(why, wcap, "damaged: checkpoints do not fit the tables");
        free(r->src);
        free(r);
        return NULL;
    }
    return r;
}

/* Point r's tables into the mapping: 1, or 0 with a reason in why. */
static int set_tables(pdt_replay *r, const ihdr *h, void *map, char *why, size_t wcap)
{
    void **ptr[NSEC];
    size_t elem[NSEC];
    uint64_t count[NSEC];
    pdt_ix_sections(r, ptr, elem, count);
    count[S_WARN] = h->count[S_WARN];
    if (h->count[S_SORT]) count[S_SORT] = count[S_DEL] = count[S_SORTPOS] = r->n;  /* Graham's */
    for (int i = 0; i < NSEC; i++) {
        if (count[i] != h->count[i] || count[i] * elem[i] != h->sec[i].bytes)
            return snprintf(why, wcap, "damaged: section %d has the wrong size", i), 0;
        *ptr[i] = (char *)map + h->sec[i].off;
    }
    if (!h->count[S_SORT]) { /* a run without Graham's sort */
        r->sort_ev = r->del_ev = NULL;
        r->sort_pos = NULL;
    }
    if (h->count[S_WARN] && ((const char *)map)[h->sec[S_WARN].off + h->count[S_WARN] - 1])
        return snprintf(why, wcap, "damaged: warnings not terminated"), 0;
    return 1;
}

pdt_replay *pdt_ix_load(const char *path, const char *dir, uint64_t ident, const pdt_point *pts,
                        size_t n, int verify, char *why, size_t wcap)
{
    char whyopen[160];
    int fd = pdt_open_input(path, whyopen, sizeof whyopen);
    if (fd < 0) {
        snprintf(why, wcap, "%s", errno == ENOENT ? "no index yet" : whyopen);
        return NULL;
    }
    ihdr h;
    pdt_replay *r = NULL;
    void *map = MAP_FAILED;
    lazy *L = NULL;
    if (!read_header(fd, &h, ident, pts, n, why, wcap)) goto fail;
    map = map_index(fd, &h, path, verify, &L, why, wcap);
    if (map == MAP_FAILED || !(r = replay_of_header(&h, why, wcap))) goto fail;
    if (!set_tables(r, &h, map, why, wcap)) {
        free(r->src);
        free(r);
        goto fail;
    }
    if (!map_ranks(r, dir, L, why, wcap)) {
        unmap_ranks(r);
        free(r);
        goto fail;
    }
    if (pts) r->pts = pts;  /* the run's own copy (the same points) */
    r->map = map;
    r->map_len = h.file_bytes;
    r->lazy = L;
    close(fd);
    return r;
fail:
    if (L) pdt_ix_lazy_stop(L);
    if (map != MAP_FAILED) munmap(map, h.file_bytes);
    close(fd);
    return NULL;
}
