/* The constants of the wire format. Every multi-byte field is little-endian
 * (registers/byte_order.h). */
#ifndef PROTOCOL_WIRE_H
#define PROTOCOL_WIRE_H

#include <stdint.h>

#include "registers/byte_order.h"

enum {
    WIRE_REQUEST_HDR0 = 0x12,
    WIRE_REQUEST_HDR1 = 0x4C,
    WIRE_RESPONSE_HDR0 = 0x05,
    WIRE_RESPONSE_HDR1 = 0x1C,
    WIRE_EXTENDED_LENGTH = 0xFF, /* length byte announcing a u16 length */
    WIRE_BROADCAST_ID = 0xFF,
    WIRE_HEADER_SIZE = 4,        /* two header bytes, packet number, length */
};

#endif
