/* pdt — SRM's merge messages: the varints (LEB128, signed values
 * zigzagged), packing a rank's message (pdt_srm_pack) and reading one
 * (pdt_srm_msg_decode, the blobs of a relay: pdt_srm_blob_at,
 * pdt_srm_carry).
 *
 * A message is a sequence of blobs (one without relay).  A blob is a header
 * (srm_msg_head, srm.h) and `payload` bytes of LEB128 varints: the point
 * table in increasing key order (x, then y: the order of the merge's border
 * set, which then merges the tables' runs instead of sorting them; each
 * point as x's step from the one before, zigzag y, gid), then the triangles
 * and the hull as positions in that table.  About 8 bytes per point and 5
 * per triangle for coordinates below 2^20, instead of 12 and 12. */
#include "srm.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

size_t pdt_srm_put_varint(unsigned char *b, uint64_t v)
{
    size_t n = 0;
    while (v >= 0x80) {
        b[n++] = (unsigned char)(v | 0x80);
        v >>= 7;
    }
    b[n++] = (unsigned char)v;
    return n;
}

uint64_t pdt_srm_zigzag(int64_t v)
{
    return ((uint64_t)v << 1) ^ (uint64_t)(v >> 63);
}

/* Read one varint at *p (< end); 0 on a truncated or over-long one. */
int pdt_srm_get_varint(const unsigned char **p, const unsigned char *end, uint64_t *v)
{
    uint64_t r = 0;
    for (int shift = 0; shift < 64 && *p < end; shift += 7) {
        unsigned char c = *(*p)++;
        r |= (uint64_t)(c & 0x7f) << shift;
        if (!(c & 0x80)) {
            *v = r;
            return 1;
        }
    }
    return 0;
}

/* ---- packing ---------------------------------------------------------------- */

static pdt_status nomem(pdt_err *err, const char *who, const char *what)
{
    return pdt_err_set(err, PDT_ERR_NOMEM, "%s: %s: out of memory", who, what);
}

/* The merge rank a pending triangle of `level` is shipped to (traced). */
static int64_t ship_to(const srm_rank *s, int level)
{
    int gl, gr, ge;
    if (s->tree && pdt_srm_pair_of(s->tree, s->rank, s->p, level, &gl, &gr, &ge)) return gr;
    return (int64_t)((s->rank >> (level + 1) << (level + 1)) + (1 << level));
}

/* One blob: the pending triangles of `level` (left in s->pend) and, with
 * send_hull, the hull, appended to b[*len ..] (room for blob_bound). */
static size_t blob_bound(size_t nt, size_t nh)
{
    return sizeof(srm_msg_head) + (3 * nt + nh) * 15 + (3 * nt + nh) * 5;
}

/* The point table of a blob: the distinct points of the n slots (a shipped
 * triangle's three corners, then the hull) in increasing key order into tab,
 * and each slot's place in it into pos.  One radix sort of (key, slot)
 * records gives both: equal points are neighbours, and the table grows by
 * one at each new key.  Returns the table's size, or SIZE_MAX without
 * memory. */
static size_t point_table(const srm_pt *slot, size_t n, srm_pt *tab, uint32_t *pos)
{
    if (n == 0) return 0;
    srm_rec *r = malloc(2 * n * sizeof *r);
    if (!r) return SIZE_MAX;
    for (size_t i = 0; i < n; i++) r[i] = (srm_rec){srm_key(slot[i]), (uint32_t)i, 0};
    pdt_srm_radix_sort(r, r + n, n);
    size_t u = 0;
    for (size_t i = 0; i < n; i++) {
        if (u == 0 || r[i].key != r[i - 1].key) tab[u++] = slot[r[i].idx];
        pos[r[i].idx] = (uint32_t)(u - 1);
    }
    free(r);
    return u;
}

/* x as an unsigned number in the keys' order (x's step from the point
 * before is then never negative). */
static uint32_t key_x(int32_t x)
{
    return (uint32_t)x ^ 0x80000000u;
}

static pdt_status pack_blob(srm_rank *s, int level, int send_hull, unsigned char *b, size_t *len,
                            pdt_err *err)
{
    size_t nt = 0;
    for (size_t i = 0; i < s->npend; i++) nt += s->pend[i].level == level;
    size_t nh = send_hull ? s->nhull : 0, ns = 3 * nt + nh;
    /* the slots: the shipped triangles' corners, then the hull */
    srm_pt *slot = srm_big((2 * ns + 1) * sizeof *slot), *tab = slot + ns;
    uint32_t *pos = malloc((ns + 1) * sizeof *pos);
    size_t np = 0;
    if (slot && pos) {
        for (size_t i = 0; i < s->npend; i++)
            if (s->pend[i].level == level)
                for (int k = 0; k < 3; k++) slot[np++] = s->pend[i].p[k];
        for (size_t i = 0; i < nh; i++) slot[np++] = s->hull[i];
        np = point_table(slot, ns, tab, pos);
    }
    if (!slot || !pos || np == SIZE_MAX) {
        free(slot);
        free(pos);
        return nomem(err, s->who, "pack");
    }
    unsigned char *b0 = b + *len, *w = b0 + sizeof(srm_msg_head);
    uint32_t prev = 0;
    for (size_t i = 0; i < np; i++) {
        w += pdt_srm_put_varint(w, key_x(tab[i].x) - prev);
        prev = key_x(tab[i].x);
        w += pdt_srm_put_varint(w, pdt_srm_zigzag(tab[i].y));
        w += pdt_srm_put_varint(w, tab[i].gid);
    }
    const uint32_t *at = pos;
    for (size_t i = 0; i < s->npend; i++) {
        srm_tri *t = &s->pend[i];
        if (t->level != level) continue;
        for (int j = 0; j < 3; j++) w += pdt_srm_put_varint(w, *at++);
        PDT_TRACE(s->tr, 1, PDT_EV_SHIP, 0, t->p[0].gid, t->p[1].gid, t->p[2].gid,
                  ship_to(s, level));
    }
    s->cnt.shipped += nt;
    for (size_t i = 0; i < nh; i++) w += pdt_srm_put_varint(w, *at++);
    srm_msg_head hd = {SRM_MSG_MAGIC,
                   (uint32_t)level,
                   (send_hull ? SRM_MSG_HAS_HULL : 0u) |
                       (send_hull && s->hull_degenerate ? SRM_MSG_HULL_DEGENERATE : 0u),
                   0,
                   (uint64_t)np,
                   (uint64_t)nt,
                   (uint64_t)nh,
                   (uint64_t)(w - b0 - sizeof(srm_msg_head)),
                   s->cnt.critical_path,
                   s->cnt.critical_cpu};
    memcpy(b0, &hd, sizeof hd);
    free(slot);
    free(pos);
    *len = (size_t)(w - b);
    return PDT_OK;
}

/* The pending triangles of the levels in `sent` (a bit per level) leave. */
static void drop_sent(srm_rank *s, uint64_t sent)
{
    size_t keep = 0;
    for (size_t i = 0; i < s->npend; i++)
        if (!(sent >> s->pend[i].level & 1)) s->pend[keep++] = s->pend[i];
    s->npend = keep;
}

pdt_status pdt_srm_pack(srm_rank *s, int level, void **buf, size_t *len, pdt_err *err)
{
    *buf = NULL;
    *len = 0;
    int holder = pdt_srm_holder_of(s->tree, s->rank, s->p, level) == s->rank;
    if (s->relay && !holder) {
        if (s->npend || s->nfwd)
            return pdt_err_set(err, PDT_ERR_CHECK, "%s: holds pending triangles at level %d "
                               "without holding its group", s->who, level);
        return PDT_OK;
    }
    int send_hull = s->holds_hull && holder;
    /* the levels whose triangles go: this one; with relay every later one */
    uint64_t sent = (uint64_t)1 << level;
    size_t bound = blob_bound(0, send_hull ? s->nhull : 0) + s->nfwd;
    for (size_t i = 0; i < s->npend; i++) {
        int lv = s->pend[i].level;
        if (lv != level && !s->relay) continue;
        if (!(sent >> lv & 1)) bound += sizeof(srm_msg_head);
        sent |= (uint64_t)1 << lv;
        bound += blob_bound(1, 0) - sizeof(srm_msg_head);
    }
    unsigned char *b = malloc(bound);
    if (!b) return nomem(err, s->who, "pack");
    size_t n = 0;
    pdt_status st = PDT_OK;
    for (int lv = level; lv < 64 && st == PDT_OK; lv++)
        if (sent >> lv & 1) st = pack_blob(s, lv, send_hull && lv == level, b, &n, err);
    if (st != PDT_OK) {
        free(b);
        return st;
    }
    if (s->nfwd) memcpy(b + n, s->fwd, s->nfwd);
    n += s->nfwd;
    s->nfwd = 0;
    drop_sent(s, sent);
    if (send_hull) {
        s->holds_hull = 0;
        s->nhull = 0;
    }
    *buf = b;
    *len = n;
    return PDT_OK;
}

/* ---- reading ---------------------------------------------------------------- */

/* A decoded message (arrays owned: srm_msg_view_free). */

void pdt_srm_msg_free(srm_msg_view *v)
{
    free(v->pts);
    free(v->tri);
    v->pts = NULL;
    v->tri = v->hull = NULL;
}

pdt_status pdt_srm_msg_decode(const void *buf, size_t len, int level, const char *from, srm_msg_view *v,
                         pdt_err *err)
{
    if (len < sizeof(srm_msg_head))
        return pdt_err_set(err, PDT_ERR_CORRUPT, "merge message from %s: too short", from);
    memcpy(&v->h, buf, sizeof v->h);
    const srm_msg_head *h = &v->h;
    if (h->magic != SRM_MSG_MAGIC || h->level != (uint32_t)level ||
        h->payload != (uint64_t)(len - sizeof(srm_msg_head)))
        return pdt_err_set(err, PDT_ERR_CORRUPT, "merge message from %s: bad header", from);
    /* every count is at most the payload (a varint takes a byte at least) */
    if (h->npts > h->payload || h->ntri > h->payload / 3 ||
        h->nhull > h->payload - 3 * h->ntri)
        return pdt_err_set(err, PDT_ERR_CORRUPT, "merge message from %s: bad counts", from);
    size_t ni = 3 * (size_t)h->ntri + (size_t)h->nhull;
    v->pts = malloc(((size_t)h->npts + 1) * sizeof *v->pts);
    v->tri = malloc((ni + 1) * sizeof *v->tri);
    if (!v->pts || !v->tri) {
        pdt_srm_msg_free(v);
        return pdt_err_set(err, PDT_ERR_NOMEM, "merge message from %s: out of memory",
                           from);
    }
    v->hull = v->tri + 3 * (size_t)h->ntri;
    const unsigned char *p = (const unsigned char *)buf + sizeof(srm_msg_head), *end = p + h->payload;
    uint64_t ux = 0, a, y, gid, prev = 0;
    for (size_t i = 0; i < h->npts; i++) {
        if (!pdt_srm_get_varint(&p, end, &a) || !pdt_srm_get_varint(&p, end, &y) || !pdt_srm_get_varint(&p, end, &gid))
            goto bad;
        if (a > UINT32_MAX - ux) goto bad; /* (checked before the sum, which could wrap) */
        ux += a;
        int64_t sy = (int64_t)(y >> 1) ^ -(int64_t)(y & 1);
        if (gid > UINT32_MAX || sy < INT32_MIN || sy > INT32_MAX) goto bad;
        srm_pt q = {(int32_t)((uint32_t)ux ^ 0x80000000u), (int32_t)sy, (uint32_t)gid};
        if (i > 0 && srm_key(q) <= prev) goto bad; /* (the merge relies on the order) */
        prev = srm_key(q);
        v->pts[i] = q;
    }
    for (size_t i = 0; i < ni; i++) {
        if (!pdt_srm_get_varint(&p, end, &a) || a >= h->npts) goto bad;
        v->tri[i] = (uint32_t)a;
    }
    if (p != end) goto bad;
    return PDT_OK;
bad:
    pdt_srm_msg_free(v);
    return pdt_err_set(err, PDT_ERR_CORRUPT, "merge message from %s: damaged payload", from);
}

int pdt_srm_blob_at(const unsigned char *b, size_t left, srm_msg_head *h)
{
    if (left < sizeof *h) return 0;
    memcpy(h, b, sizeof *h);
    return h->magic == SRM_MSG_MAGIC && h->payload <= left - sizeof *h;
}

pdt_status pdt_srm_carry(srm_rank *s, const unsigned char *b, size_t n)
{
    if (s->nfwd + n > s->capfwd) {
        size_t cap = s->capfwd ? s->capfwd : 4096;
        while (cap < s->nfwd + n) cap *= 2;
        unsigned char *f = realloc(s->fwd, cap);
        if (!f) return PDT_ERR_NOMEM;
        s->fwd = f;
        s->capfwd = cap;
    }
    memcpy(s->fwd + s->nfwd, b, n);
    s->nfwd += n;
    return PDT_OK;
}
