/* a x b mod 2^64 for the Cortex-M0, which multiplies 32 x 32 -> 32 only:
 * the low words' full product from four 16 x 16 products, the high words
 * times the low ones from two more (their high halves fall off); three in
 * all when a factor is below 2^16, as the planner's tick counts are. The
 * planner calls it a dozen times a move: 138 bytes against libgcc's
 * __aeabi_lmul's 90, and about 25 instructions a call where that takes 41
 * (docs/benchmark.md). */
#include "runtime/small_mul.h"

/* a x s for s below 2^16 (the planner's tick counts): three products. */
static uint64_t times_short(uint64_t a, uint32_t s)
{
    uint32_t al = (uint32_t)a;
    uint32_t low = (al & 0xFFFFu) * s;
    uint32_t cross = (al >> 16) * s;
    uint32_t sum = low + (cross << 16);
    uint32_t high = (uint32_t)(a >> 32) * s + (cross >> 16) + (sum < low ? 1u : 0u);
    return ((uint64_t)high << 32) | sum;
}

uint64_t small_lmul(uint64_t a, uint64_t b)
{
    if (b >> 16 == 0u) {
        return times_short(a, (uint32_t)b);
    }
    if (a >> 16 == 0u) {
        return times_short(b, (uint32_t)a);
    }
    uint32_t al = (uint32_t)a;
    uint32_t bl = (uint32_t)b;
    uint32_t a0 = al & 0xFFFFu;
    uint32_t a1 = al >> 16;
    uint32_t b0 = bl & 0xFFFFu;
    uint32_t b1 = bl >> 16;
    uint32_t cross = a1 * b0;
    uint32_t middle = cross + a0 * b1; /* it may carry: 2^32 here is 2^48 */
    uint32_t high = a1 * b1 + (uint32_t)(a >> 32) * bl + al * (uint32_t)(b >> 32) +
                    (middle >> 16) + (middle < cross ? 0x10000u : 0u);
    uint32_t low = a0 * b0;
    uint32_t sum = low + (middle << 16);
    high += sum < low ? 1u : 0u;
    return ((uint64_t)high << 32) | sum;
}

#ifdef SMALL_MUL_AEABI
/* The run-time ABI's name (ARM IHI 0043, 4.2): the same function. */
uint64_t __aeabi_lmul(uint64_t a, uint64_t b) __attribute__((alias("small_lmul")));
#endif
