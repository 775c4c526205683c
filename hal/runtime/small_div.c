/* 32-bit division for the size-first Cortex-M0 image, which has no divide
 * instruction: the run-time ABI's entry points (ARM IHI 0043, "The
 * Run-time ABI", 4.3.1) one quotient bit a step, about 100 bytes where
 * libgcc's unrolled ones take 726, and slower (a few instructions for each
 * bit of the quotient): the M0 divides when it plans a move and scales a
 * reading, never in the control tick (docs/benchmark.md has the M0's
 * figures with it). Divided by zero, the quotient is 0 and the
 * remainder the dividend, as the Cortex-M3's UDIV/SDIV give (without the
 * divide-by-zero trap). */
#include <stdint.h>

#include "runtime/small_div.h"

uint64_t small_udivmod(uint32_t n, uint32_t d)
{
    if (d == 0u || d > n) {
        return (uint64_t)n << 32;
    }
    /* Only the quotient's own bits: d doubled up to below n's top bit,
     * then one compare and subtract a bit. No overflow: a step is doubled
     * only while it is at most half of n. (No count of leading zeros: the
     * M0 has no CLZ, and libgcc's takes 60 bytes.) */
    uint32_t step = d;
    uint32_t bit = 1u;
    uint32_t half = n >> 1;
    while (step <= half >> 4) { /* four bits a step, then one */
        step <<= 4;
        bit <<= 4;
    }
    while (step <= half) {
        step <<= 1;
        bit <<= 1;
    }
    uint32_t q = 0;
    do {
        if (n >= step) {
            n -= step;
            q |= bit;
        }
        step >>= 1;
        bit >>= 1;
    } while (bit != 0u);
    return ((uint64_t)n << 32) | q;
}

uint64_t small_idivmod(int32_t n, int32_t d)
{
    uint32_t un = n < 0 ? 0u - (uint32_t)n : (uint32_t)n;
    uint32_t ud = d < 0 ? 0u - (uint32_t)d : (uint32_t)d;
    uint64_t qr = small_udivmod(un, ud);
    uint32_t q = (uint32_t)qr;
    uint32_t r = (uint32_t)(qr >> 32);
    if ((n < 0) != (d < 0) && d != 0) {
        q = 0u - q; /* toward zero, as C's / */
    }
    if (n < 0) {
        r = 0u - r; /* the remainder takes the dividend's sign, as C's % */
    }
    return ((uint64_t)r << 32) | q;
}

#ifdef SMALL_DIV_AEABI
/* The quotient in r0 and the remainder in r1: small_udivmod's own result,
 * so the unsigned entry points are small_udivmod itself (__aeabi_uidiv's
 * callers read r0 only). The signed ones take the signs off first. */
uint64_t __aeabi_uidivmod(uint32_t n, uint32_t d) __attribute__((alias("small_udivmod")));
uint64_t __aeabi_uidiv(uint32_t n, uint32_t d) __attribute__((alias("small_udivmod")));
uint64_t __aeabi_idivmod(int32_t n, int32_t d);
int32_t __aeabi_idiv(int32_t n, int32_t d);

uint64_t __aeabi_idivmod(int32_t n, int32_t d)
{
    return small_idivmod(n, d);
}

int32_t __aeabi_idiv(int32_t n, int32_t d)
{
    return (int32_t)(uint32_t)small_idivmod(n, d);
}
#endif
