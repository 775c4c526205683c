/* The tests' random numbers: Marsaglia's xorshift64 (shifts 13, 7, 17),
 * reproducible from the seed each test keeps in its own state. */
#ifndef TEST_XORSHIFT_H
#define TEST_XORSHIFT_H

#include <stdint.h>

static inline uint64_t xorshift64(uint64_t *state)
{
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    return *state;
}

#endif
