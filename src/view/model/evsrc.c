/* pdt — the merged events of a kept index, decoded on demand.
 *
 * The index refers to the rank files' encoded blocks (12-13 bytes per
 * event, in the run folder) instead of holding decoded records (40 bytes per
 * event): an event is found by its segment of the merged order (which rank,
 * which event of it), then by that rank's block (binary search), and decoded
 * with its block, from the mapped rank file, into a cache of a few blocks,
 * least recently used first out; a kept index's source checks each block's
 * checksum as it decodes it (the run folder is not the index's to trust).  A forward pass over the
 * events decodes every block once; the event line, a seek, a search decode
 * one or a few blocks (some 50 microseconds each). */
#include "pdt/tracefile.h"
#include "replay_int.h"
#include "pdt/bigmem.h"

#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

typedef struct evslot {
    size_t blk;         /* the block held (SIZE_MAX: none) */
    uint32_t rank;
    uint64_t first;     /* its first event in the rank, and count */
    uint32_t count;
    uint64_t used;      /* the cache's tick when last used */
    pdt_rec *rec;       /* count records */
    size_t cap;
} evslot;

#define RELEASE_STEP ((uint64_t)16 << 20) /* drop_behind: pages given back in steps of this */

/* Where rank q's decoding one event at a time is: in block blk (SIZE_MAX:
 * nowhere), its next event `next` (of the rank) at c. */
typedef struct evcur {
    size_t blk;
    uint64_t next;
    pdt_block_cursor c;
} evcur;

/* What a damaged block gives (never reached on a verified index): an event
 * of no known kind, which every table ignores. */
static const pdt_rec bad_rec = {{.kind = 0xff}, 0, 0};

void pdt_evsrc_clear(pdt_evsrc *s)
{
    for (size_t k = 0; k < s->nslot; k++) free(s->slot[k].rec);
    free(s->slot);
    free(s->released);
    free(s->cur);
    s->slot = NULL;
    s->released = NULL;
    s->cur = NULL;
    s->nslot = 0;
}

/* Block b of rank q lies inside its file. */
static int block_inside(const pdt_evsrc *s, size_t b, uint32_t q)
{
    const pdt_block_ref *bk = &s->blk[b];
    return s->file[q] && bk->off >= PDT_BLOCK_HEADER_BYTES && bk->off <= s->file_len[q] &&
           bk->len <= s->file_len[q] - bk->off;
}

int pdt_evsrc_block_ok(const pdt_evsrc *s, size_t b, uint32_t q)
{
    if (!block_inside(s, b, q)) return 0;
    const pdt_block_ref *bk = &s->blk[b];
    const uint8_t *h = s->file[q] + bk->off - PDT_BLOCK_HEADER_BYTES;
    uint32_t crc = pdt_crc32c(pdt_crc32c(0, h, 28), h + PDT_BLOCK_HEADER_BYTES, bk->len);
    uint32_t want = (uint32_t)h[28] | (uint32_t)h[29] << 8 | (uint32_t)h[30] << 16 | (uint32_t)h[31] << 24;
    return crc == want;
}

/* The segment holding merged event i (i < m). */
static const pdt_evseg *seg_of(pdt_evsrc *s, size_t i)
{
    size_t g = s->last_seg;
    if (g < s->nseg && s->seg[g].start <= i) {
        if (g + 1 == s->nseg || i < s->seg[g + 1].start) return &s->seg[g];
        if (g + 2 == s->nseg || i < s->seg[g + 2].start) return &s->seg[s->last_seg = g + 1];
    }
    size_t lo = 0, hi = s->nseg; /* last segment with start <= i */
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (s->seg[mid].start <= i) lo = mid;
        else hi = mid;
    }
    s->last_seg = lo;
    return &s->seg[lo];
}

uint32_t pdt_evsrc_rank(pdt_evsrc *s, size_t i)
{
    return i < s->m && s->nseg ? seg_of(s, i)->rank : UINT32_MAX;
}

/* Give back the mapped pages of rank q's file a forward pass left behind. */
static void drop_behind(pdt_evsrc *s, uint32_t q, uint64_t off)
{
    if (!s->released && !(s->released = calloc((size_t)s->nranks, sizeof *s->released))) return;
    uint64_t *rel = &s->released[q];
    if (off < *rel) {
        *rel = off & ~(uint64_t)(pdt_page_size() - 1);
        return;
    }
    if (off - *rel < RELEASE_STEP) return;
    pdt_release_pages(s->file[q] + *rel, off - *rel);
    *rel = off;
}

/* Decode block b (of rank q) into a slot: the least recently used one. */
static evslot *load(pdt_evsrc *s, size_t b, uint32_t q)
{
    if (!s->slot) {
        size_t n = PDT_EVSRC_KEEP + (size_t)(s->nranks < 64 ? s->nranks : 64);
        s->slot = calloc(n, sizeof *s->slot);
        if (!s->slot) return NULL;
        s->nslot = n;
        for (size_t k = 0; k < n; k++) s->slot[k].blk = SIZE_MAX;
    }
    evslot *v = &s->slot[0];
    for (size_t k = 1; k < s->nslot; k++)
        if (s->slot[k].used < v->used) v = &s->slot[k];
    const pdt_block_ref *bk = &s->blk[b];
    if (!block_inside(s, b, q)) return NULL;
    if (s->verify && !pdt_evsrc_block_ok(s, b, q)) {
        if (s->damaged) s->damaged(s->damaged_ctx, q);
        return NULL;
    }
    if (bk->count > v->cap) {
        pdt_rec *g = realloc(v->rec, bk->count * sizeof *g);
        if (!g) return NULL;
        v->rec = g;
        v->cap = bk->count;
    }
    /* decode into the records' room from its end backwards would overlap;
     * decode into the front of the room as events, then spread them out
     * from the last one (a record is an event and 8 bytes more) */
    _Static_assert(sizeof(pdt_rec) >= sizeof(pdt_event), "a record holds its event");
    pdt_event *ev = (pdt_event *)(void *)v->rec;
    v->blk = SIZE_MAX;
    if (pdt_block_decode(s->file[q] + bk->off, bk->len, bk->count, bk->base_t, ev) != 0) return NULL;
    for (size_t j = bk->count; j-- > 0;) {
        pdt_event e = ev[j];
        v->rec[j] = (pdt_rec){e, q, (uint32_t)(bk->first + j)};
    }
    if (s->drop_behind) drop_behind(s, q, bk->off);
    v->blk = b;
    v->rank = q;
    v->first = bk->first;
    v->count = bk->count;
    return v;
}

/* Rank q's cursor (the table made when first needed), or NULL when out of
 * memory. */
static evcur *cur_of(pdt_evsrc *s, uint32_t q)
{
    if (!s->cur) {
        s->cur = malloc((size_t)s->nranks * sizeof *s->cur);
        if (!s->cur) return NULL;
        for (int k = 0; k < s->nranks; k++) s->cur[k].blk = SIZE_MAX;
    }
    return &s->cur[q];
}

/* Start cursor c at the first event of block b of rank q: 1, or 0 (c
 * nowhere) when the block is not in its file or, checked, damaged. */
static int cur_start(pdt_evsrc *s, evcur *c, size_t b, uint32_t q)
{
    c->blk = SIZE_MAX;
    if (!block_inside(s, b, q)) return 0;
    if (s->verify && !pdt_evsrc_block_ok(s, b, q)) {
        if (s->damaged) s->damaged(s->damaged_ctx, q);
        return 0;
    }
    const pdt_block_ref *bk = &s->blk[b];
    pdt_block_cursor_start(&c->c, s->file[q] + bk->off, bk->len, bk->count, bk->base_t);
    if (s->drop_behind) drop_behind(s, q, bk->off);
    c->blk = b;
    c->next = bk->first;
    return 1;
}

/* Event seq of rank q (in c's block, not before c->next) decoded by c,
 * into the ring. */
static const pdt_rec *cur_get(pdt_evsrc *s, evcur *c, uint32_t q, uint64_t seq)
{
    pdt_event e;
    for (; c->next < seq; c->next++)
        if (pdt_block_cursor_next(&c->c, NULL) != 1) break;
    if (c->next != seq || pdt_block_cursor_next(&c->c, &e) != 1) {
        c->blk = SIZE_MAX;  /* (malformed: as a block that does not decode) */
        return &bad_rec;
    }
    c->next++;
    pdt_rec *out = &s->ring[s->ring_at++ % PDT_EVSRC_KEEP];
    *out = (pdt_rec){e, q, (uint32_t)seq};
    return out;
}

/* Event seq of rank q from its cursor when that is just before it (in its
 * block, or at the end of it with seq the next block's first), else NULL. */
static const pdt_rec *cur_next(pdt_evsrc *s, evcur *c, uint32_t q, uint64_t seq)
{
    if (!c || c->blk == SIZE_MAX || c->next != seq) return NULL;
    if (seq - s->blk[c->blk].first < s->blk[c->blk].count) return cur_get(s, c, q, seq);
    size_t b = c->blk + 1;
    if (b < s->rank_blk[q + 1] && s->blk[b].first == seq && cur_start(s, c, b, q))
        return cur_get(s, c, q, seq);
    return NULL;
}

/* The slot holding event seq of rank q, or NULL. */
static evslot *slot_hit(pdt_evsrc *s, uint32_t q, uint64_t seq)
{
    for (size_t j = 0; j < s->nslot; j++) { /* the slot used last first */
        size_t k = (s->hot + j) % s->nslot;
        evslot *v = &s->slot[k];
        if (v->blk != SIZE_MAX && v->rank == q && seq - v->first < v->count) {
            s->hot = k;
            return v;
        }
    }
    return NULL;
}

const pdt_rec *pdt_evsrc_get(pdt_evsrc *s, size_t i)
{
    if (i >= s->m || !s->nseg) return NULL;
    const pdt_evseg *g = seg_of(s, i);
    uint32_t q = g->rank;
    uint64_t seq = (uint64_t)g->seq0 + (i - g->start);
    s->tick++;
    if (q >= (uint32_t)s->nranks) return &bad_rec;
    evcur *c = cur_of(s, q);
    const pdt_rec *got = cur_next(s, c, q, seq);  /* a forward pass: one event decoded */
    if (got) return got;
    evslot *v = slot_hit(s, q, seq);
    if (v) {
        v->used = s->tick;
        return &v->rec[seq - v->first];
    }
    size_t lo = (size_t)s->rank_blk[q], hi = (size_t)s->rank_blk[q + 1];
    if (lo >= hi || hi > s->nblk || seq < s->blk[lo].first) return &bad_rec;
    while (hi - lo > 1) { /* the last block with first <= seq */
        size_t mid = lo + (hi - lo) / 2;
        if (s->blk[mid].first <= seq) lo = mid;
        else hi = mid;
    }
    if (seq - s->blk[lo].first >= s->blk[lo].count) return &bad_rec;
    /* ahead in the cursor's block, or in another block: the cursor decodes
     * up to it (no more than the block would, and without its room); back
     * in the cursor's block: the block into the cache */
    if (c && (c->blk != lo || c->next <= seq))
        return c->blk == lo || cur_start(s, c, lo, q) ? cur_get(s, c, q, seq) : &bad_rec;
    v = load(s, lo, q);
    if (!v) return &bad_rec;
    v->used = s->tick;
    s->hot = (size_t)(v - s->slot);
    return &v->rec[seq - v->first];
}
