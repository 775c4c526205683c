#include "ports/host/wire_overlap.h"

/* The level a byte drives at bit `bit` of its frame (0 the start bit, 1-8
 * data, 9 the stop bit); idle (1) outside it. */
static unsigned level(uint8_t byte, int64_t bit)
{
    return bit == 0 ? 0u : (bit >= 1 && bit <= 8) ? (unsigned)(byte >> (bit - 1)) & 1u : 1u;
}

uint8_t wire_overlap(uint8_t heard, uint8_t other, int64_t lag_ns, int64_t byte_ns)
{
    int64_t half = lag_ns >= 0 ? byte_ns : -byte_ns;
    int64_t bits = (lag_ns * 20 + half) / (2 * byte_ns); /* lag_ns / bit time, rounded */
    bits = bits == 0 ? 1 : bits;
    unsigned out = 0;
    for (int64_t i = 0; i < 8; i++) {
        out |= (level(heard, i + 1) & level(other, i + 1 - bits)) << i;
    }
    return (uint8_t)out;
}
