/* Response frame encoder: 05 1C, packet number, length, content, checksum. */
#ifndef PROTOCOL_FRAME_TX_H
#define PROTOCOL_FRAME_TX_H

#include <stdint.h>

/* Largest response content: ReadStore (0x41), 34 bytes (ReadBatchData's
 * is 1 + 32). */
#define RESPONSE_CONTENT_MAX 34u
#define RESPONSE_FRAME_MAX (RESPONSE_CONTENT_MAX + 5u)

struct response {
    uint8_t code;
    uint8_t length;
    uint8_t content[RESPONSE_CONTENT_MAX];
};

/* Encodes r into out (RESPONSE_FRAME_MAX bytes); returns the frame size. */
uint8_t frame_tx_encode(const struct response *r, uint8_t out[RESPONSE_FRAME_MAX]);

#endif
