/* Little-endian fields: every multi-byte value of the protocol, the data
 * table's wire image and the config store's records. */
#ifndef REGISTERS_BYTE_ORDER_H
#define REGISTERS_BYTE_ORDER_H

#include <stdint.h>

static inline uint16_t le_get_u16(const uint8_t *p)
{
    return (uint16_t)((uint16_t)p[0] | (uint16_t)((uint16_t)p[1] << 8));
}

static inline int16_t le_get_i16(const uint8_t *p)
{
    return (int16_t)le_get_u16(p);
}

/* A call in the Cortex-M0's application, where size comes first and no
 * answer's time hangs on it (byte_order.c); inline elsewhere. */
static inline uint32_t le_get_u32_inline(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
           ((uint32_t)p[3] << 24);
}
#if defined(SERVO_SIZE_FIRST) && !defined(STARTUP_BOOTLOADER)
uint32_t le_get_u32(const uint8_t *p);
#else
#define le_get_u32 le_get_u32_inline
#endif

static inline int32_t le_get_i32(const uint8_t *p)
{
    return (int32_t)le_get_u32(p);
}

static inline void le_put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)(v >> 8);
}

static inline void le_put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)((v >> 8) & 0xFFu);
    p[2] = (uint8_t)((v >> 16) & 0xFFu);
    p[3] = (uint8_t)(v >> 24);
}

#endif
