#ifndef STORAGE_CRC32_H
#define STORAGE_CRC32_H

#include <stddef.h>
#include <stdint.h>

/* CRC-32/ISO-HDLC (the zlib CRC). Bitwise: it runs once per config save or
 * slot scanned, or over an application image before it boots, so 1 KB of
 * table would buy nothing. */
uint32_t crc32(const uint8_t *data, size_t len);

/* The same in pieces: state starts at CRC32_START, crc32 = ~state at the end. */
#define CRC32_START 0xFFFFFFFFu
uint32_t crc32_update(uint32_t state, const uint8_t *data, size_t len);

#endif
