/* 64-bit division for planning, without the C library's general 64/64
 * routine (about 150 Thumb-2 instructions a call on the Cortex-M3, many
 * more on the M0). The planner's divisors are tick counts and small
 * quantities: when one fits 32 bits, two 32-bit hardware divisions do it
 * (Knuth's algorithm D on 16-bit digits, as in Hacker's Delight, divlu),
 * or on the Cortex-M0, which has no divide instruction, 32 steps of a
 * restoring division in assembly (div64.c); a divisor beyond 32 bits takes
 * one of them and a correction. So no image links the library's 64-bit
 * division (408 bytes on the Cortex-M0). */
#ifndef MOTION_DIV64_H
#define MOTION_DIV64_H

#include <stdint.h>

/* n / d, exactly. */
uint64_t div64_u(uint64_t n, uint64_t d);

/* num / den rounded to nearest, halves away from zero; den > 0. */
int64_t div64_round(int64_t num, int64_t den);

/* The leading zeros of x != 0. On the Cortex-M0, which has no CLZ, a
 * shift a bit (div64.c): planning only, where libgcc's __clzsi2 costs its
 * image 60 B. */
#if defined(__ARM_ARCH_6M__)
unsigned div64_clz(uint32_t x);
#else
#define div64_clz(x) ((unsigned)__builtin_clz(x))
#endif

/* x 2^32 / 1000, rounded down, for x < 59 074 (a speed in 0.1 deg/s to
 * Q32 decideg per 1 ms tick), without a division (test_div64 checks every
 * x). */
uint64_t thousandth_q32(uint32_t x);

/* decideg / 3600 (whole turns), truncated as C divides, for
 * |decideg| <= 2^23 (every angle a Q8 int32 holds, what q8_to_decideg
 * gives), without the M0's software division: 3600 = 16 x 225, and
 * 4661 / 2^20 is 1/225 by a little over, so the product is the quotient or
 * one more (test_div64 checks the whole range). */
static inline int32_t decideg_whole_turns(int32_t decideg)
{
    uint32_t negative = decideg < 0 ? UINT32_MAX : 0u; /* signs by xor: no branch */
    uint32_t size = ((uint32_t)decideg ^ negative) - negative;
    uint32_t turns = ((size >> 4) * 4661u) >> 20;
    turns -= turns * 3600u > size ? 1u : 0u;
    return (int32_t)((turns ^ negative) - negative);
}

#endif
