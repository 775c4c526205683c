#include "runtime/crc32.h"

#ifdef CRC32_BITWISE
/* The bootloaders' and the Cortex-M0 application's: no table, where flash
 * is tightest. */
static uint32_t crc32_byte(uint32_t crc)
{
    for (int bit = 0; bit < 8; bit++) {
        crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return crc;
}
#else
/* The application's: a nibble a step from 64 bytes of table, a quarter of
 * the bitwise instructions; a config save checksums its record before the
 * write is answered. */
static const uint32_t NIBBLE[16] = {
    0x00000000u, 0x1DB71064u, 0x3B6E20C8u, 0x26D930ACu, 0x76DC4190u, 0x6B6B51F4u,
    0x4DB26158u, 0x5005713Cu, 0xEDB88320u, 0xF00F9344u, 0xD6D6A3E8u, 0xCB61B38Cu,
    0x9B64C2B0u, 0x86D3D2D4u, 0xA00AE278u, 0xBDBDF21Cu,
};

static uint32_t crc32_byte(uint32_t crc)
{
    crc = (crc >> 4) ^ NIBBLE[crc & 0xFu];
    return (crc >> 4) ^ NIBBLE[crc & 0xFu];
}
#endif

uint32_t crc32_update(uint32_t state, const uint8_t *data, size_t len)
{
    uint32_t crc = state;
    for (size_t i = 0; i < len; i++) {
        crc = crc32_byte(crc ^ data[i]);
    }
    return crc;
}

uint32_t crc32(const uint8_t *data, size_t len)
{
    return ~crc32_update(CRC32_START, data, len);
}
