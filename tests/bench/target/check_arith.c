/* The planner's arithmetic as the target CPU runs it, under QEMU: div64_u
 * (on the Cortex-M0 its assembly loops, motion/div64.c), and the 32-bit
 * division and 64-bit multiplication the compiler calls (on the M0 the
 * small run-time's), each against a product from 16-bit pieces: a
 * quotient q of n / d must have q d <= n < q d + d. The host tests check
 * the C; only this runs the Thumb code. Exits 1 at the first error. */
#include <stdint.h>
#include <stdio.h>

#include "motion/div64.h"
#include "support/xorshift.h"

static uint64_t state = 0x9E3779B97F4A7C15u;
static uint64_t rnd(void)
{
    return xorshift64(&state);
}

static unsigned checked;

/* The run-time's printf (newlib nano) has no long long. */
static void print_hex64(const char *label, uint64_t x)
{
    printf(" %s 0x%08lx%08lx", label, (unsigned long)(x >> 32), (unsigned long)x);
}

/* a x b in full, from 16-bit digits (no 64-bit multiply, no division):
 * the low 64 bits, and whether any bit is beyond them. */
static uint64_t product(uint64_t a, uint64_t b, int *beyond)
{
    uint32_t digits[8] = {0};
    for (unsigned i = 0; i < 4; i++) {
        uint32_t carry = 0;
        uint32_t ai = (uint32_t)(a >> (16 * i)) & 0xFFFFu;
        for (unsigned j = 0; j < 4; j++) {
            uint32_t t = ai * ((uint32_t)(b >> (16 * j)) & 0xFFFFu); /* < 2^32 - 2^17 + 2 */
            uint32_t sum = (t & 0xFFFFu) + digits[i + j] + carry;
            digits[i + j] = sum & 0xFFFFu;
            carry = (t >> 16) + (sum >> 16);
        }
        digits[i + 4] = carry;
    }
    *beyond = (digits[4] | digits[5] | digits[6] | digits[7]) != 0u;
    return (uint64_t)digits[0] | (uint64_t)digits[1] << 16 | (uint64_t)digits[2] << 32 |
           (uint64_t)digits[3] << 48;
}

/* q is n / d when q d <= n < q d + d. */
static int quotient_ok(uint64_t n, uint64_t d, uint64_t q)
{
    int beyond;
    uint64_t qd = product(q, d, &beyond);
    return !beyond && qd <= n && n - qd < d;
}

static int check_div(uint64_t n, uint64_t d)
{
    checked++;
    uint64_t q = div64_u(n, d);
    if (quotient_ok(n, d, q)) {
        return 0;
    }
    printf("check_arith: div64_u:");
    print_hex64("n", n);
    print_hex64("d", d);
    print_hex64("gave", q);
    printf("\n");
    return 1;
}

static int check_div32(uint32_t n, uint32_t d)
{
    checked++;
    volatile uint32_t vn = n, vd = d;
    uint32_t q = vn / vd; /* __aeabi_uidiv */
    uint32_t r = vn % vd; /* __aeabi_uidivmod */
    if (quotient_ok(n, d, q) && r == n - q * d) {
        return 0;
    }
    printf("check_arith: %#lx / %#lx = %#lx rem %#lx\n", (unsigned long)n, (unsigned long)d,
           (unsigned long)q, (unsigned long)r);
    return 1;
}

static int check_mul(uint64_t a, uint64_t b)
{
    checked++;
    volatile uint64_t va = a, vb = b;
    uint64_t p = va * vb; /* __aeabi_lmul */
    int beyond;
    uint64_t reference = product(a, b, &beyond);
    if (p == reference) {
        return 0;
    }
    printf("check_arith: multiply:");
    print_hex64("a", a);
    print_hex64("b", b);
    print_hex64("gave", p);
    print_hex64("not", reference);
    printf("\n");
    return 1;
}

int main(void)
{
    static const uint64_t edges[] = {0, 1, 2, 3, 0xFFFFu, 0x10000u, 0x7FFFFFFFu, 0x80000000u,
                                     0x80000001u, 0xFFFFFFFEu, 0xFFFFFFFFu, 0x100000000u,
                                     0x100000001u, 0x7FFFFFFF00000000u, 0xFFFFFFFF00000000u,
                                     0x7FFFFFFFFFFFFFFFu, UINT64_MAX};
    const unsigned count = sizeof edges / sizeof edges[0];
    int bad = 0;
    for (unsigned i = 0; i < count && !bad; i++) {
        for (unsigned j = 0; j < count && !bad; j++) {
            bad |= check_mul(edges[i], edges[j]);
            if (edges[j] != 0u) {
                bad |= check_div(edges[i], edges[j]);
                bad |= check_div(edges[i] - (edges[i] != 0u), edges[j]);
            }
        }
    }
    /* The largest quotients: the high word one below the divisor, on both
     * sides of 2^31 (the M0's two loops). */
    for (uint64_t step = 1; step <= 0xFFFFFFFFu && !bad; step += step / 7u + 1u) {
        uint32_t v = (uint32_t)step;
        bad |= check_div(((uint64_t)(v - 1u) << 32) | 0xFFFFFFFFu, v);
        bad |= check_div(((uint64_t)v << 32) - 1u, v);
        bad |= check_div32(0xFFFFFFFFu - v, v);
    }
    for (int i = 0; i < 200000 && !bad; i++) {
        uint64_t n = rnd() >> (rnd() % 64u);
        uint64_t d = rnd() >> (rnd() % 64u);
        bad |= check_mul(n, d);
        if (d != 0u) {
            bad |= check_div(n, d);
            bad |= check_div32((uint32_t)n, (uint32_t)d | 1u);
        }
    }
    printf("check_arith: %u cases, %s\n", checked, bad ? "FAILED" : "all agree");
    return bad;
}
