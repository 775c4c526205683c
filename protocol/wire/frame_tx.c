#include "protocol/frame_tx.h"

#include "protocol/wire.h"

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
    /* Two sums a word: of the words, and of their bytes 0 and 2 (a 16-bit
     * lane each, 10 words at most: no lane carries into the other). Their
     * difference is the bytes 1 and 3 a lane up: bytes 1 in bits 8-23,
     * bytes 3 (mod 256) in bits 24-31. */
    uint32_t all = 0;
    uint32_t even = 0;
    do { /* the header is a word at least */
        uint32_t w = *word++;
        all += w;
        even += w & 0x00FF00FFu;
    } while (word != end);
    uint32_t odd = (all - even) >> 8;
    r->content[length] = (uint8_t)(even + (even >> 16) + odd + (odd >> 16));
    return (uint8_t)(WIRE_HEADER_SIZE + length + 1u);
}
