/* The Cortex-M0's 64-bit multiplication (firmware/runtime/small_mul.c)
 * against C's, on edge values, a million random pairs and short factors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "runtime/small_mul.h"
#include "support/xorshift.h"

static uint64_t state = 0x9E3779B97F4A7C15u;
static uint64_t rnd(void)
{
    return xorshift64(&state);
}

static void check(uint64_t a, uint64_t b)
{
    if (small_lmul(a, b) != a * b) {
        fail_msg("%llx x %llx: %llx, not %llx", (unsigned long long)a, (unsigned long long)b,
                 (unsigned long long)small_lmul(a, b), (unsigned long long)(a * b));
    }
}

static void test_edges(void **unused)
{
    (void)unused;
    const uint64_t edges[] = {0, 1, 2, 0xFFFFu, 0x10000u, 0xFFFFFFFFu, 0x100000000u,
                              0x8000000000000000u, 0xFFFFFFFFFFFFFFFFu, 0xFFFF0000FFFF0000u,
                              (uint64_t)-7};
    for (size_t i = 0; i < sizeof edges / sizeof edges[0]; i++) {
        for (size_t j = 0; j < sizeof edges / sizeof edges[0]; j++) {
            check(edges[i], edges[j]);
        }
    }
}

/* Random pairs, and random pairs of small signed values (the planner's). */
static void test_random(void **unused)
{
    (void)unused;
    for (int i = 0; i < 1000000; i++) {
        uint64_t a = rnd();
        uint64_t b = rnd();
        check(a, b);
        check(a >> (rnd() % 64u), (uint64_t)(-(int64_t)(b >> (rnd() % 64u))));
    }
}

/* A factor below 2^16 on either side (three products instead of six),
 * and the values either side of 2^16. */
static void test_short_factor(void **unused)
{
    (void)unused;
    for (int i = 0; i < 200000; i++) {
        uint64_t a = rnd() >> (rnd() % 64u);
        uint64_t s = rnd() & 0xFFFFu;
        check(a, s);
        check(s, a);
        check(a, (uint64_t)-(int64_t)s);
        check(a, 0x10000u + s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_edges),
        cmocka_unit_test(test_random),
        cmocka_unit_test(test_short_factor),
    };
    return cmocka_run_group_tests_name("small_mul", tests, NULL, NULL);
}
