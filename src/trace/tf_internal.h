/* pdt — trace file layout shared by the writer and the reader (private).
 * docs/trace-format.md is the description of record; keep them in step. */
#ifndef PDT_TF_INTERNAL_H
#define PDT_TF_INTERNAL_H

#include <stdlib.h>
#include <string.h>

#include "pdt/tracefile.h"

#define TF_MAGIC "PDTTRACE"          /* 8 bytes at offset 0 of a rank file */
#define TF_HEADER_SIZE 32u           /* file header */
#define TF_BLOCK_HEADER_SIZE 32u     /* block header */
#define TF_BLOCK_MAGIC 0x42544450u   /* "PDTB" read as little-endian u32 */
#define TF_END_MAGIC 0x45544450u     /* "PDTE": end-of-trace block */
#define TF_END_PAYLOAD 16u           /* u64 total events, u64 reserved */
#define TF_BLOCK_EVENTS 4096u        /* events per block written by pdt_tw */
#define TF_MAX_EVENT_BYTES 38u       /* 2 + 10 (time) + 1 + 3 * 5 + 10 */

/* Presence bits of an event's mask byte. */
enum { TF_SUB = 1, TF_A = 2, TF_B = 4, TF_C = 8, TF_V = 16 };

#define PTS_MAGIC "PDTPNTS1"         /* points.bin */
#define PTS_HEADER_SIZE 24u

static inline void tf_put32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (uint8_t)(v >> (8 * i));
}

static inline void tf_put64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++) p[i] = (uint8_t)(v >> (8 * i));
}

static inline uint16_t tf_get16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

static inline uint32_t tf_get32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static inline uint64_t tf_get64(const uint8_t *p)
{
    return (uint64_t)tf_get32(p) | (uint64_t)tf_get32(p + 4) << 32;
}

/* Encode events ev[0..n) as one block payload into out (which must hold
 * n * TF_MAX_EVENT_BYTES bytes); deltas start from base_t and zero.
 * Returns the payload length. */
size_t pdt_tf_encode(const pdt_event *ev, size_t n, uint64_t base_t, uint8_t *out);

/* Decode a block payload of `len` bytes holding exactly `count` events into
 * out[0..count) (out may be NULL to validate only).  Returns 0 on success,
 * -1 if the payload is malformed. */
int pdt_tf_decode(const uint8_t *p, size_t len, uint32_t count, uint64_t base_t,
                  pdt_event *out);

/* Whether a block payload of `len` bytes holds exactly `count` events that
 * pdt_tf_decode accepts (0), or not (-1), without decoding them: each
 * field's length and range checked, no value computed (opening a run
 * checks every block this way). */
int pdt_tf_validate(const uint8_t *p, size_t len, uint32_t count);

/* Fill a block header at h (TF_BLOCK_HEADER_SIZE bytes) for the payload that
 * follows it in memory; computes the checksum. */
void pdt_tf_block_header(uint8_t *h, uint32_t magic, const uint8_t *payload, uint32_t len,
                         uint64_t first, uint64_t base_t, uint32_t count);

/* "DIR/NAME" in a malloc'd string (caller frees), or NULL when out of memory. */
char *pdt_tf_path_join(const char *dir, const char *name);

/* Parse the manifest text (NUL-terminated, modified in place) of file
 * `path` into *m (zeroed first).  Unknown keys are ignored; a different major
 * format version is PDT_ERR_FORMAT naming both versions. */
pdt_status pdt_tf_manifest_parse(const char *path, char *text, pdt_manifest *m, pdt_err *err);

/* Verify points.bin (len bytes at p) and decode it.  *pts malloc'd. */
pdt_status pdt_tf_points_parse(const char *path, const uint8_t *p, size_t len, pdt_point **pts,
                               size_t *n, pdt_err *err);

/* A growable array of 32-bit values (the check's index lists, the OTF2
 * export's stack of open regions).  Zero-initialise; free(v) when done. */
typedef struct u32vec {
    uint32_t *v;
    size_t n, cap;
} u32vec;

/* Append x; 0, or -1 when out of memory (the vector is unchanged). */
static inline int u32_push(u32vec *s, uint32_t x)
{
    if (s->n == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 16;
        uint32_t *v = realloc(s->v, cap * sizeof *v);
        if (!v) return -1;
        s->v = v;
        s->cap = cap;
    }
    s->v[s->n++] = x;
    return 0;
}

#endif
