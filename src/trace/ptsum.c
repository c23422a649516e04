/* pdt — the manifest's points checksums (CRC-64/XZ of points.bin's data, or
 * FNV-1a 64 in format 1 manifests) and points.bin's encoding of the points. */
#include "tf_internal.h"

void pdt_points_encode(uint8_t *out, const pdt_point *pts, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        tf_put32(out + 8 * i, (uint32_t)pts[i].x);
        tf_put32(out + 8 * i + 4, (uint32_t)pts[i].y);
    }
}

uint64_t pdt_points_checksum(const pdt_point *pts, size_t n)
{
    uint8_t buf[8 * 1024];
    uint64_t crc = 0;
    for (size_t i = 0; i < n;) {
        size_t k = n - i < sizeof buf / 8 ? n - i : sizeof buf / 8;
        pdt_points_encode(buf, pts + i, k);
        crc = pdt_crc64(crc, buf, 8 * k);
        i += k;
    }
    return crc;
}

uint64_t pdt_points_fnv1a64(const pdt_point *pts, size_t n)
{
    uint64_t h = 0xcbf29ce484222325u; /* FNV-1a 64 offset basis */
    for (size_t i = 0; i < n; i++) {
        uint32_t xy[2] = {(uint32_t)pts[i].x, (uint32_t)pts[i].y};
        for (int k = 0; k < 2; k++)
            for (int s = 0; s < 32; s += 8) {
                h ^= (xy[k] >> s) & 0xffu;
                h *= 0x100000001b3u; /* FNV-1a 64 prime */
            }
    }
    return h;
}
