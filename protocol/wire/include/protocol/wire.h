/* Little-endian field access and the constants of the wire format.
 * Every multi-byte field of the protocol is little-endian. */
#ifndef PROTOCOL_WIRE_H
#define PROTOCOL_WIRE_H

#include <stdint.h>

enum {
    WIRE_REQUEST_HDR0 = 0x12,
    WIRE_REQUEST_HDR1 = 0x4C,
    WIRE_RESPONSE_HDR0 = 0x05,
    WIRE_RESPONSE_HDR1 = 0x1C,
    WIRE_EXTENDED_LENGTH = 0xFF, /* length byte announcing a u16 length */
    WIRE_BROADCAST_ID = 0xFF,
    WIRE_HEADER_SIZE = 4,        /* two header bytes, packet number, length */
};

static inline uint16_t wire_get_u16(const uint8_t *p)
{
    return (uint16_t)((uint16_t)p[0] | (uint16_t)((uint16_t)p[1] << 8));
}

static inline int16_t wire_get_i16(const uint8_t *p)
{
    return (int16_t)wire_get_u16(p);
}

static inline uint32_t wire_get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
           ((uint32_t)p[3] << 24);
}

static inline int32_t wire_get_i32(const uint8_t *p)
{
    return (int32_t)wire_get_u32(p);
}

static inline void wire_put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)(v >> 8);
}

static inline void wire_put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)((v >> 8) & 0xFFu);
    p[2] = (uint8_t)((v >> 16) & 0xFFu);
    p[3] = (uint8_t)(v >> 24);
}

#endif
