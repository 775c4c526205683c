/* 64-bit division for planning, without the C library's general 64/64
 * routine (about 150 Thumb-2 instructions a call on the Cortex-M3, many
 * more on the M0). The planner's divisors are tick counts and small
 * quantities: when one fits 32 bits, two 32-bit hardware divisions do it
 * (Knuth's algorithm D on 16-bit digits, as in Hacker's Delight, divlu);
 * only a divisor beyond 32 bits takes the general routine. */
#ifndef MOTION_DIV64_H
#define MOTION_DIV64_H

#include <stdint.h>

/* (u1:u0) / v for u1 < v, v != 0: the quotient fits 32 bits. */
static inline uint32_t div64_long(uint32_t u1, uint32_t u0, uint32_t v)
{
    const uint32_t b = 65536u;
    unsigned s = (unsigned)__builtin_clz(v);
    v <<= s;
    uint32_t vn1 = v >> 16;
    uint32_t vn0 = v & 0xFFFFu;
    uint32_t un32 = s != 0u ? (u1 << s) | (u0 >> (32u - s)) : u1;
    uint32_t un10 = u0 << s;
    uint32_t un1 = un10 >> 16;
    uint32_t un0 = un10 & 0xFFFFu;
    uint32_t q1 = un32 / vn1;
    uint32_t rhat = un32 - q1 * vn1;
    while (q1 >= b || q1 * vn0 > ((rhat << 16) | un1)) {
        q1--;
        rhat += vn1;
        if (rhat >= b) {
            break;
        }
    }
    uint32_t un21 = (un32 << 16) + un1 - q1 * v;
    uint32_t q0 = un21 / vn1;
    rhat = un21 - q0 * vn1;
    while (q0 >= b || q0 * vn0 > ((rhat << 16) | un0)) {
        q0--;
        rhat += vn1;
        if (rhat >= b) {
            break;
        }
    }
    return (q1 << 16) | q0;
}

static inline uint64_t div64_u(uint64_t n, uint64_t d)
{
    if ((d >> 32) != 0u) {
        return n / d;
    }
    uint32_t v = (uint32_t)d;
    uint32_t hi = (uint32_t)(n >> 32);
    if (hi == 0u) {
        return (uint32_t)n / v;
    }
    uint32_t q_hi = hi / v;
    return ((uint64_t)q_hi << 32) | div64_long(hi - q_hi * v, (uint32_t)n, v);
}

/* num / den rounded to nearest, halves away from zero; den > 0. */
static inline int64_t div64_round(int64_t num, int64_t den)
{
    uint64_t d = (uint64_t)den;
    if (num >= 0) {
        return (int64_t)div64_u((uint64_t)num + d / 2u, d);
    }
    return -(int64_t)div64_u((uint64_t)-num + d / 2u, d);
}

#endif
