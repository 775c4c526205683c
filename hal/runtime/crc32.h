#ifndef RUNTIME_CRC32_H
#define RUNTIME_CRC32_H

#include <stddef.h>
#include <stdint.h>

/* CRC-32/ISO-HDLC (the zlib CRC). A nibble a step from a 64-byte table; the
 * bootloader builds it bitwise (CRC32_BITWISE), for size. */
uint32_t crc32(const uint8_t *data, size_t len);

/* The same in pieces: state starts at CRC32_START, crc32 = ~state at the end. */
#define CRC32_START 0xFFFFFFFFu
uint32_t crc32_update(uint32_t state, const uint8_t *data, size_t len);

#endif
