/* pdt — checksums (src/base/crc32c.c): CRC-32C of the trace blocks, of
 * points.bin and of the kept index's chunks; CRC-64/XZ of the points. */
#ifndef PDT_CHECKSUM_H
#define PDT_CHECKSUM_H

#include <stddef.h>
#include <stdint.h>

/* CRC-32C (Castagnoli, reflected 0x82F63B78, init and final xor ~0) of n
 * bytes, continuing from `crc` (start with 0): the checksum of trace blocks
 * and points.bin.  pdt_crc32c(0, "123456789", 9) == 0xE3069283. */
uint32_t pdt_crc32c(uint32_t crc, const void *data, size_t n);
/* CRC-64/XZ (reflected 0xC96C5795D7870F42, init and final xor ~0) of n bytes,
 * continuing from `crc` (start with 0).  pdt_crc64(0, "123456789", 9) ==
 * 0x995DC9BBDF1939FA. */
uint64_t pdt_crc64(uint64_t crc, const void *data, size_t n);
/* The CRC of A followed by B, from crc_a = CRC(A), crc_b = CRC(B) and
 * len_b = |B| in bytes (any length; O(log len_b)). */
uint32_t pdt_crc32c_combine(uint32_t crc_a, uint32_t crc_b, uint64_t len_b);
uint64_t pdt_crc64_combine(uint64_t crc_a, uint64_t crc_b, uint64_t len_b);

#endif
