/* pdt — the replay's containers: a growable array, a hash map from a 128-bit
 * key to an int32, and the build's tables (in memory, or paged beyond a
 * limit). */
#include "pdt/view/replay.h"
#include "replay_int.h"
#include "build_int.h"
#include "pdt/bigmem.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <pthread.h>
#include <stdatomic.h>
#include <sys/mman.h>
#include <unistd.h>

/* pdt — the replay model: index the events once, then answer "state at k". */
#include "pdt/view/replay.h"
#include "replay_int.h"
#include "pdt/bigmem.h"

/* ---- a small growable array ----------------------------------------------- */

int pdt_rp_grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap) return 1;
    size_t c = *cap ? *cap : 64;
    while (c < need) c *= 2;
    void *q = realloc(*p, c * elem);
    if (!q) return 0;
    *p = q;
    *cap = c;
    return 1;
}

/* Room for at least `n` keys at load <= 3/4: in a temporary file's mapping
 * beyond `limit` bytes (0: no limit), else in memory (big tables 2 MiB-
 * aligned, for huge pages if asked for: pdt_big_advise). */
int pdt_rp_km_alloc(keymap *km, size_t n, uint64_t limit)
{
    size_t cap = 1024;
    while (cap / 4 * 3 < n) cap *= 2;
    size_t bytes = cap * sizeof *km->e;
    km->paged = limit && bytes > limit;
    if (km->paged) {
        km->e = pdt_temp_zeros(bytes);
    } else if (bytes >= ((size_t)4 << 20)) {
        km->e = aligned_alloc((size_t)2 << 20, bytes);
        if (km->e) pdt_big_advise(km->e, bytes);
        if (km->e) memset(km->e, 0, bytes);
    } else {
        km->e = calloc(cap, sizeof *km->e);
    }
    if (!km->e) return 0;
    km->cap = cap;
    km->used = 0;
    return 1;
}

void pdt_rp_km_free(keymap *km)
{
    if (km->paged && km->e) munmap(km->e, km->cap * sizeof *km->e);
    else free(km->e);
    memset(km, 0, sizeof *km);
}

/* A paged map's resident pages given back (the file keeps them). */
void pdt_rp_km_give_back(const keymap *km)
{
    if (km->paged) pdt_release_pages(km->e, km->cap * sizeof *km->e);
}

/* Slot of key (found, or the empty slot where it would go). */
static size_t km_slot(const keymap *km, uint64_t hi, uint64_t lo)
{
    size_t mask = km->cap - 1, i = (size_t)pdt_rp_mix(hi, lo) & mask;
    while (km->e[i].enc != 0 && (km->e[i].hi != hi || km->e[i].lo != lo)) i = (i + 1) & mask;
    return i;
}

int pdt_rp_km_get(const keymap *km, uint64_t hi, uint64_t lo, int32_t *v)
{
    if (!km->cap) return 0;
    size_t i = km_slot(km, hi, lo);
    if (km->e[i].enc == 0) return 0;
    *v = (int32_t)(km->e[i].enc ^ 0x80000000u);
    return 1;
}

/* (v != INT32_MIN) */
int pdt_rp_km_put(keymap *km, uint64_t hi, uint64_t lo, int32_t v, uint64_t limit)
{
    if (km->used + 1 > km->cap / 4 * 3) {
        keymap big;
        if (!pdt_rp_km_alloc(&big, km->cap ? km->cap : 512, limit)) return 0;
        for (size_t i = 0; i < km->cap; i++) {
            if (km->e[i].enc == 0) continue;
            big.e[km_slot(&big, km->e[i].hi, km->e[i].lo)] = km->e[i];
            if (++big.used % 65536 == 0) { /* (paged: the pages go back as it goes) */
                pdt_rp_km_give_back(&big);
                pdt_rp_km_give_back(km);
            }
        }
        pdt_rp_km_free(km);
        *km = big;
    }
    size_t i = km_slot(km, hi, lo);
    if (km->e[i].enc == 0) km->used++;
    km->e[i] = (km_slot_t){hi, lo, (uint32_t)v ^ 0x80000000u, 0};
    return 1;
}

static int tab_paged(const pdt_replay *r, const void *p)
{
    for (int i = 0; p && i < r->nptab; i++)
        if (r->ptab[i].p == p) return i;
    return -1;
}

void pdt_rp_tab_free(pdt_replay *r, void *p)
{
    int i = tab_paged(r, p);
    if (i < 0) {
        free(p);
        return;
    }
    pdt_temp_map_free(&r->ptab[i]);
    r->ptab[i] = r->ptab[--r->nptab];
}

/* A new table of `bytes` (zero-filled when paged; else malloc's, huge
 * pages if asked for), or NULL. */
void *pdt_rp_tab_new(pdt_replay *r, size_t bytes)
{
    if (!r->tab_limit || bytes <= r->tab_limit || r->nptab == PDT_PTAB_MAX) {
        void *p = malloc(bytes ? bytes : 1);
        if (p) pdt_big_advise(p, bytes);
        return p;
    }
    pdt_temp_map m = {0};
    if (pdt_temp_map_new(&m, bytes) != 0) return NULL;
    r->ptab[r->nptab++] = m;
    return m.p;
}

/* pdt_rp_grow() for a table of r: room for `need` entries of `elem` bytes, its
 * entries [0, *cap) kept. */
int pdt_rp_tab_grow(pdt_replay *r, void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap) return 1;
    size_t c = *cap ? *cap : 64;
    while (c < need) c *= 2;
    int i = tab_paged(r, *p);
    if (!r->tab_limit || (c * elem <= r->tab_limit && i < 0)) return pdt_rp_grow(p, cap, need, elem);
    if (i >= 0) { /* (paged: the file lengthened, its mapping moved if need be) */
        if (pdt_temp_map_grow(&r->ptab[i], c * elem) != 0) return 0;
        *p = r->ptab[i].p;
        *cap = c;
        return 1;
    }
    void *q = pdt_rp_tab_new(r, c * elem); /* (a table in memory outgrowing the limit: paged) */
    if (!q) return 0;
    memcpy(q, *p, *cap * elem); /* (at most tab_limit bytes) */
    pdt_replay_tab_release(r, q, *cap * elem);
    pdt_rp_tab_free(r, *p);
    *p = q;
    *cap = c;
    return 1;
}

void pdt_rp_tabs_give_back(const pdt_replay *r)
{
    for (int i = 0; i < r->nptab; i++) pdt_release_pages(r->ptab[i].p, r->ptab[i].bytes);
}

void pdt_replay_tab_release(const pdt_replay *r, const void *p, size_t len)
{
    for (int i = 0; i < r->nptab; i++) {
        const char *b = r->ptab[i].p;
        if ((const char *)p >= b && (const char *)p + len <= b + r->ptab[i].bytes) {
            pdt_release_pages(p, len);
            return;
        }
    }
}
