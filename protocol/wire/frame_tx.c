#include "protocol/frame_tx.h"

#include <string.h>

#include "protocol/wire.h"

#ifndef SERVO_SIZE_FIRST
/* The byte sum, four bytes a pass: a response is up to 40 bytes, and its
 * encoding is on the path from request to answer. */
static uint8_t byte_sum(const uint8_t *p, uint32_t n)
{
    uint32_t sum = 0;
    uint32_t i = 0;
    for (; i + 4u <= n; i += 4u) {
        sum += (uint32_t)p[i] + p[i + 1u] + p[i + 2u] + p[i + 3u];
    }
    for (; i < n; i++) {
        sum += p[i];
    }
    return (uint8_t)sum;
}
#endif

uint8_t frame_tx_encode(const struct response *r, uint8_t out[RESPONSE_FRAME_MAX])
{
    uint8_t length = r->length <= RESPONSE_CONTENT_MAX ? r->length : RESPONSE_CONTENT_MAX;
    out[0] = WIRE_RESPONSE_HDR0;
    out[1] = WIRE_RESPONSE_HDR1;
    out[2] = r->code;
    out[3] = length;
#ifdef SERVO_SIZE_FIRST
    /* Copied and summed in one pass: the size-first image (SERVO_SIZE_FIRST,
     * the Cortex-M0) copies a byte at a time anyway. */
    uint32_t sum = (uint32_t)WIRE_RESPONSE_HDR0 + WIRE_RESPONSE_HDR1 + r->code + length;
    for (uint32_t i = 0; i < length; i++) {
        uint8_t byte = r->content[i];
        out[WIRE_HEADER_SIZE + i] = byte;
        sum += byte;
    }
    out[WIRE_HEADER_SIZE + length] = (uint8_t)sum;
#else
    memcpy(&out[WIRE_HEADER_SIZE], r->content, length);
    out[WIRE_HEADER_SIZE + length] = byte_sum(out, WIRE_HEADER_SIZE + (uint32_t)length);
#endif
    return (uint8_t)(WIRE_HEADER_SIZE + length + 1u);
}
