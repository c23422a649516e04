/* pdt — event encoding of a block payload (docs/trace-format.md, "Events").
 *
 * Each event: kind byte, mask byte (which of sub, a, b, c, v are non-zero),
 * zigzag varint of the time delta, then the present fields: sub as one byte,
 * a/b/c as zigzag varints of the 32-bit wrapped difference from the previous
 * present value of the same field, v as a zigzag varint of the 64-bit wrapped
 * difference.  All "previous" values start at 0 (time: the block's base time)
 * at the beginning of every block, so a block decodes on its own. */
#include "tf_internal.h"

static inline uint8_t *put_varint(uint8_t *p, uint64_t v)
{
    while (v >= 0x80) {
        *p++ = (uint8_t)(v | 0x80);
        v >>= 7;
    }
    *p++ = (uint8_t)v;
    return p;
}

static inline uint64_t zz64(uint64_t d)  /* d: two's complement difference */
{
    return (d << 1) ^ (uint64_t)-(int64_t)(d >> 63);
}

static inline uint32_t zz32(uint32_t d)
{
    return (d << 1) ^ (uint32_t)-(int32_t)(d >> 31);
}

static inline uint64_t unzz(uint64_t z)
{
    return (z >> 1) ^ (uint64_t)-(int64_t)(z & 1);
}

size_t pdt_tf_encode(const pdt_event *ev, size_t n, uint64_t base_t, uint8_t *out)
{
    uint8_t *p = out;
    uint64_t pt = base_t, pv = 0;
    uint32_t pa = 0, pb = 0, pc = 0;
    for (size_t i = 0; i < n; i++) {
        const pdt_event *e = &ev[i];
        uint8_t mask = (uint8_t)((e->sub ? TF_SUB : 0) | (e->a ? TF_A : 0) | (e->b ? TF_B : 0) |
                                 (e->c ? TF_C : 0) | (e->v ? TF_V : 0));
        *p++ = e->kind;
        *p++ = mask;
        p = put_varint(p, zz64(e->t - pt));
        pt = e->t;
        if (mask & TF_SUB) *p++ = e->sub;
        if (mask & TF_A) {
            p = put_varint(p, zz32(e->a - pa));
            pa = e->a;
        }
        if (mask & TF_B) {
            p = put_varint(p, zz32(e->b - pb));
            pb = e->b;
        }
        if (mask & TF_C) {
            p = put_varint(p, zz32(e->c - pc));
            pc = e->c;
        }
        if (mask & TF_V) {
            p = put_varint(p, zz64((uint64_t)e->v - pv));
            pv = (uint64_t)e->v;
        }
    }
    return (size_t)(p - out);
}

/* Read a varint of at most `maxbytes` bytes; NULL on overrun or overlong. */
static inline const uint8_t *get_varint(const uint8_t *p, const uint8_t *end, int maxbytes,
                                        uint64_t *v)
{
    uint64_t r = 0;
    for (int i = 0; i < maxbytes; i++) {
        if (p == end) return NULL;
        uint8_t b = *p++;
        r |= (uint64_t)(b & 0x7f) << (7 * i);
        if (!(b & 0x80)) {
            *v = r;
            return p;
        }
    }
    return NULL;
}

/* Decode the next event at c->p into *e (the fields' previous values in c);
 * 0, or -1 when the payload is malformed there. */
static inline int decode_one(pdt_block_cursor *c, pdt_event *e)
{
    const uint8_t *p = c->p, *end = c->end;
    uint64_t z;
    if (end - p < 2) return -1;
    e->kind = p[0];
    uint8_t mask = p[1];
    p += 2;
    if (mask & ~(TF_SUB | TF_A | TF_B | TF_C | TF_V)) return -1;
    if (!(p = get_varint(p, end, 10, &z))) return -1;
    c->t += unzz(z);
    e->t = c->t;
    e->sub = 0;
    e->reserved = 0;
    e->a = e->b = e->c = 0;
    e->v = 0;
    if (mask & TF_SUB) {
        if (p == end) return -1;
        e->sub = *p++;
    }
    if (mask & TF_A) {
        if (!(p = get_varint(p, end, 5, &z)) || z > UINT32_MAX) return -1;
        c->a += (uint32_t)unzz(z);
        e->a = c->a;
    }
    if (mask & TF_B) {
        if (!(p = get_varint(p, end, 5, &z)) || z > UINT32_MAX) return -1;
        c->b += (uint32_t)unzz(z);
        e->b = c->b;
    }
    if (mask & TF_C) {
        if (!(p = get_varint(p, end, 5, &z)) || z > UINT32_MAX) return -1;
        c->c += (uint32_t)unzz(z);
        e->c = c->c;
    }
    if (mask & TF_V) {
        if (!(p = get_varint(p, end, 10, &z))) return -1;
        c->v += unzz(z);
        e->v = (int64_t)c->v;
    }
    c->p = p;
    return 0;
}

/* The length of the varint at p (within end, at most maxbytes long), or 0
 * where get_varint would fail; for a 32-bit field (maxbytes 5) also 0 when
 * its value is over UINT32_MAX (a fifth byte above 0x0f).  Eight bytes at
 * a time where they are there. */
static inline size_t varint_len(const uint8_t *p, const uint8_t *end, int maxbytes)
{
    size_t n = 0;
    if (end - p >= 8) {
        uint64_t w;
        memcpy(&w, p, 8);
        uint64_t stop = ~w & UINT64_C(0x8080808080808080);
        if (stop) {  /* (the host is little-endian: the first byte is the lowest) */
            const uint16_t one = 1;
            if (*(const uint8_t *)&one) n = (size_t)__builtin_ctzll(stop) / 8 + 1;
        }
    }
    if (!n) {
        while (p + n < end && n < (size_t)maxbytes && (p[n] & 0x80)) n++;
        if (p + n == end || n == (size_t)maxbytes) return 0;
        n++;
    }
    if (n > (size_t)maxbytes) return 0;
    if (maxbytes == 5 && n == 5 && p[4] > 0x0f) return 0;
    return n;
}

int pdt_tf_validate(const uint8_t *p, size_t len, uint32_t count)
{
    const uint8_t *end = p + len;
    for (uint32_t i = 0; i < count; i++) {
        if (end - p < 2) return -1;
        uint8_t mask = p[1];
        p += 2;
        if (mask & ~(TF_SUB | TF_A | TF_B | TF_C | TF_V)) return -1;
        size_t k = varint_len(p, end, 10);
        if (!k) return -1;
        p += k;
        if (mask & TF_SUB) {
            if (p == end) return -1;
            p++;
        }
        for (int f = TF_A; f <= TF_C; f <<= 1)
            if (mask & f) {
                if (!(k = varint_len(p, end, 5))) return -1;
                p += k;
            }
        if (mask & TF_V) {
            if (!(k = varint_len(p, end, 10))) return -1;
            p += k;
        }
    }
    return p == end ? 0 : -1;
}

void pdt_block_cursor_start(pdt_block_cursor *c, const uint8_t *payload, uint32_t len,
                            uint32_t count, uint64_t base_t)
{
    *c = (pdt_block_cursor){payload, payload + len, base_t, 0, 0, 0, 0, count};
}

int pdt_block_cursor_next(pdt_block_cursor *c, pdt_event *out)
{
    if (!c->left) return c->p == c->end ? 0 : -1;
    pdt_event e;
    if (decode_one(c, &e) != 0) return -1;
    c->left--;
    if (!c->left && c->p != c->end) return -1;
    if (out) *out = e;
    return 1;
}

int pdt_tf_decode(const uint8_t *p, size_t len, uint32_t count, uint64_t base_t,
                  pdt_event *out)
{
    pdt_block_cursor c = {p, p + len, base_t, 0, 0, 0, 0, count};
    for (uint32_t i = 0; i < count; i++) {
        pdt_event e;
        if (decode_one(&c, &e) != 0) return -1;
        if (out) out[i] = e;
    }
    return c.p == c.end ? 0 : -1;
}

void pdt_tf_block_header(uint8_t *h, uint32_t magic, const uint8_t *payload, uint32_t len,
                         uint64_t first, uint64_t base_t, uint32_t count)
{
    tf_put32(h, magic);
    tf_put32(h + 4, len);
    tf_put64(h + 8, first);
    tf_put64(h + 16, base_t);
    tf_put32(h + 24, count);
    uint32_t crc = pdt_crc32c(0, h, 28);
    crc = pdt_crc32c(crc, payload, len);
    tf_put32(h + 28, crc);
}
