#include "crc32.h"

uint32_t crc32_update(uint32_t state, const uint8_t *data, size_t len)
{
    uint32_t crc = state;
    for (size_t i = 0; i < len; i++) {
        crc ^= data[i];
        for (int bit = 0; bit < 8; bit++) {
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
        }
    }
    return crc;
}

uint32_t crc32(const uint8_t *data, size_t len)
{
    return ~crc32_update(CRC32_START, data, len);
}
