/* Response frame: 05 1C, packet number, length, content, checksum. */
#ifndef PROTOCOL_FRAME_TX_H
#define PROTOCOL_FRAME_TX_H

#include <stddef.h>
#include <stdint.h>

#include "protocol/packet_codes.h" /* RESPONSE_CONTENT_MAX: the largest answer's content */

#define RESPONSE_FRAME_MAX (RESPONSE_CONTENT_MAX + 5u)
#define RESPONSE_FRAME_WORDS ((RESPONSE_FRAME_MAX + 5u) / 4u) /* + 2 zeros */

/* A response is built where it is sent from: the handlers write its code,
 * length and content in place, frame_tx_seal() adds the header and the
 * checksum, and its first bytes are the frame (no copy on the way out).
 * The words let the checksum be summed four bytes a load. */
struct response {
    union {
        struct {
            uint8_t header[2];
            uint8_t code;
            uint8_t length;
            uint8_t content[RESPONSE_CONTENT_MAX + 3u]; /* + checksum, zeros */
        };
        uint32_t words[RESPONSE_FRAME_WORDS];
    };
};
_Static_assert(offsetof(struct response, content) == 4u, "content follows the 4-byte header");

/* Completes r's frame (a length over RESPONSE_CONTENT_MAX is cut to it);
 * returns its size. */
uint8_t frame_tx_seal(struct response *r);

/* A sealed frame's size, as frame_tx_seal() returned it. */
static inline uint8_t frame_tx_size(const struct response *r)
{
    return (uint8_t)(4u + r->length + 1u); /* header, content, checksum */
}

/* The frame's bytes, frame_tx_seal()'s size of them. */
static inline const uint8_t *frame_tx_bytes(const struct response *r)
{
    return (const uint8_t *)r;
}

#endif
