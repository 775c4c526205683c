#include "protocol/frame_tx.h"

#include "protocol/wire.h"

uint8_t frame_tx_encode(const struct response *r, uint8_t out[RESPONSE_FRAME_MAX])
{
    uint8_t length = r->length <= RESPONSE_CONTENT_MAX ? r->length : RESPONSE_CONTENT_MAX;
    out[0] = WIRE_RESPONSE_HDR0;
    out[1] = WIRE_RESPONSE_HDR1;
    out[2] = r->code;
    out[3] = length;
    uint8_t sum = (uint8_t)(out[0] + out[1] + out[2] + out[3]);
    for (uint8_t i = 0; i < length; i++) {
        out[WIRE_HEADER_SIZE + i] = r->content[i];
        sum = (uint8_t)(sum + r->content[i]);
    }
    out[WIRE_HEADER_SIZE + length] = sum;
    return (uint8_t)(WIRE_HEADER_SIZE + length + 1u);
}
