#include "motion/div64.h"

/* (u1:u0) / v for u1 < v, v != 0: the quotient fits 32 bits. */
#if defined(__ARM_ARCH_6M__)
/* The ARMv6-M has no divide instruction and no count of leading zeros, so
 * Knuth's digits below would cost four software divisions: restoring
 * division a bit a step instead, the dividend shifted through the carry
 * into the remainder and the quotient's bits in where it leaves (about 6
 * instructions a bit; tests/bench/target/check_arith.c runs it). */
/* One quotient bit, the remainder below 2^31 (its double fits): label is
 * the step's end. */
#define DIV_STEP(label)                                                                      \
    "adds %[lo], %[lo], %[lo]\n\t"                                                         \
    "adcs %[hi], %[hi], %[hi]\n\t"                                                         \
    "cmp %[hi], %[v]\n\t"                                                                  \
    "bcc " label "f\n\t"                                                                   \
    "subs %[hi], %[hi], %[v]\n\t"                                                          \
    "adds %[lo], %[lo], #1\n" label ":\n\t"

unsigned div64_clz(uint32_t x)
{
    unsigned n = 0;
    while ((int32_t)x > 0) {
        x <<= 1;
        n++;
    }
    return n;
}

static uint32_t div64_long(uint32_t u1, uint32_t u0, uint32_t v)
{
    uint32_t i;
    if (v >> 31 != 0u) {
        /* The doubled remainder may pass 2^32: its carry out subtracts. */
        i = 32;
        __asm__(".syntax unified\n"
                "1:\n\t"
                "adds %[lo], %[lo], %[lo]\n\t"
                "adcs %[hi], %[hi], %[hi]\n\t"
                "bcs 2f\n\t"
                "cmp %[hi], %[v]\n\t"
                "bcc 3f\n"
                "2:\n\t"
                "subs %[hi], %[hi], %[v]\n\t"
                "adds %[lo], %[lo], #1\n"
                "3:\n\t"
                "subs %[i], %[i], #1\n\t"
                "bne 1b"
                : [hi] "+l"(u1), [lo] "+l"(u0), [i] "+l"(i)
                : [v] "l"(v)
                : "cc");
    } else {
        i = 16; /* two bits a pass */
        __asm__(".syntax unified\n"
                "1:\n\t" DIV_STEP("2") DIV_STEP("3") "subs %[i], %[i], #1\n\t"
                "bne 1b"
                : [hi] "+l"(u1), [lo] "+l"(u0), [i] "+l"(i)
                : [v] "l"(v)
                : "cc");
    }
    return u0;
}
#else
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
#endif

/* n / d for d beyond 32 bits (the quotient fits 32): d normalised to its
 * top 32 bits, one long division of n / 2, then at most one correction
 * (Hacker's Delight 9-5, divdu). */
static uint64_t div64_wide(uint64_t n, uint64_t d)
{
    /* 32-bit shifts only: a 64-bit one by a variable is a libgcc call on
     * the Cortex-M0 (24 B). s < 32, as d >> 32 != 0. */
    unsigned s = div64_clz((uint32_t)(d >> 32));
    uint32_t hi = (uint32_t)(d >> 32);
    uint32_t top = s != 0u ? hi << s | (uint32_t)d >> (32u - s) : hi;
    uint64_t half = n >> 1;
    uint64_t q = div64_long((uint32_t)(half >> 32), (uint32_t)half, top) >> (31u - s);
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
