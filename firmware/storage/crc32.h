#ifndef STORAGE_CRC32_H
#define STORAGE_CRC32_H

#include <stddef.h>
#include <stdint.h>

/* CRC-32/ISO-HDLC (the zlib CRC). Bitwise: it runs once per config save or
 * slot scanned, so 1 KB of table would buy nothing. */
uint32_t crc32(const uint8_t *data, size_t len);

#endif
