#include "motion/div64.h"

/* (u1:u0) / v for u1 < v, v != 0: the quotient fits 32 bits. */
static uint32_t div64_long(uint32_t u1, uint32_t u0, uint32_t v)
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

/* n / d for d beyond 32 bits (the quotient fits 32): d normalised to its
 * top 32 bits, one long division of n / 2, then at most one correction
 * (Hacker's Delight 9-5, divdu). */
static uint64_t div64_wide(uint64_t n, uint64_t d)
{
    unsigned s = (unsigned)__builtin_clz((uint32_t)(d >> 32));
    uint32_t top = (uint32_t)((d << s) >> 32);
    uint64_t half = n >> 1;
    uint64_t q = ((uint64_t)div64_long((uint32_t)(half >> 32), (uint32_t)half, top) << s) >> 31;
    if (q != 0u) {
        q--;
    }
    if (n - q * d >= d) {
        q++;
    }
    return q;
}

uint64_t div64_u(uint64_t n, uint64_t d)
{
    if ((d >> 32) != 0u) {
        return div64_wide(n, d);
    }
    uint32_t v = (uint32_t)d;
    uint32_t hi = (uint32_t)(n >> 32);
    if (hi == 0u) {
        return (uint32_t)n / v;
    }
    uint32_t q_hi = hi / v;
    return ((uint64_t)q_hi << 32) | div64_long(hi - q_hi * v, (uint32_t)n, v);
}

int64_t div64_round(int64_t num, int64_t den)
{
    uint64_t d = (uint64_t)den;
    if (num >= 0) {
        return (int64_t)div64_u((uint64_t)num + d / 2u, d);
    }
    return -(int64_t)div64_u((uint64_t)-num + d / 2u, d);
}


/* x = 125 a + b; each / 125 is a multiply by 33 555 / 2^22, exact for
 * what it divides here (x < 59 074, and 37 b < 9 250 with a one short). */
uint64_t thousandth_q32(uint32_t x)
{
    uint32_t a = (x * 33555u) >> 22;
    uint32_t b = x - 125u * a;
    /* 2^29 / 125 = 4 294 967 + 37 / 125 */
    return ((uint64_t)a << 29) + b * 4294967u + ((b * 37u * 33555u) >> 22);
}
