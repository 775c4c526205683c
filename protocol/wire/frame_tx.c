#include "protocol/frame_tx.h"

#include "protocol/wire.h"

/* Two bytes of a word into each 16-bit lane: 20 bytes a lane at most, so
 * no lane carries into the other. */
static uint32_t byte_pairs(uint32_t word)
{
    return (word & 0x00FF00FFu) + ((word >> 8) & 0x00FF00FFu);
}

uint8_t frame_tx_seal(struct response *r)
{
    uint32_t length = r->length <= RESPONSE_CONTENT_MAX ? r->length : RESPONSE_CONTENT_MAX;
    r->header[0] = WIRE_RESPONSE_HDR0;
    r->header[1] = WIRE_RESPONSE_HDR1;
    r->length = (uint8_t)length;
    /* The checksum is the low byte of the sum of every byte before it;
     * the bytes after the content are zeroed so that whole words sum. */
    r->content[length] = 0;
    r->content[length + 1u] = 0;
    r->content[length + 2u] = 0;
    const uint32_t *word = r->words;
    const uint32_t *end = &r->words[(WIRE_HEADER_SIZE + length + 3u) / 4u];
    uint32_t lanes = 0;
    do { /* the header is a word at least */
        lanes += byte_pairs(*word++);
    } while (word != end);
    r->content[length] = (uint8_t)(lanes + (lanes >> 16));
    return (uint8_t)(WIRE_HEADER_SIZE + length + 1u);
}
