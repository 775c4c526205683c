/* The planner's 64-bit division (motion/div64.h) against the compiler's,
 * on edge cases and a million random pairs; the whole turns of an angle
 * against C's division. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "motion/div64.h"
#include "support/xorshift.h"

static uint64_t state = 0x9E3779B97F4A7C15u;
static uint64_t rnd(void)
{
    return xorshift64(&state);
}

static void check(uint64_t n, uint64_t d)
{
    if (div64_u(n, d) != n / d) {
        fail_msg("%llu / %llu: %llu, not %llu", (unsigned long long)n, (unsigned long long)d,
                 (unsigned long long)div64_u(n, d), (unsigned long long)(n / d));
    }
}

static void test_edges(void **state_)
{
    (void)state_;
    const uint64_t values[] = {0, 1, 2, 3, 0xFFFFu, 0x10000u, 0x10001u, 0x7FFFFFFFu, 0x80000000u,
                               0xFFFFFFFEu, 0xFFFFFFFFu, 0x100000000u, 0x100000001u,
                               0xFFFFFFFF00000000u, 0x7FFFFFFFFFFFFFFFu, UINT64_MAX};
    for (size_t i = 0; i < sizeof values / sizeof values[0]; i++) {
        for (size_t j = 0; j < sizeof values / sizeof values[0]; j++) {
            if (values[j] != 0u) {
                check(values[i], values[j]);
                check(values[i] - (values[i] != 0u), values[j]);
            }
        }
    }
    /* The high word one below the divisor: the largest quotient digits. */
    for (uint32_t v = 1; v < 200000u; v += 97u) {
        check(((uint64_t)(v - 1u) << 32) | 0xFFFFFFFFu, v);
        check(((uint64_t)v << 32) - 1u, v);
    }
}

static void test_random(void **state_)
{
    (void)state_;
    for (int i = 0; i < 1000000; i++) {
        uint64_t n = rnd() >> (rnd() % 64u);
        uint64_t d = rnd() >> (rnd() % 64u);
        if (d != 0u) {
            check(n, d);
        }
    }
}

static void test_rounding(void **state_)
{
    (void)state_;
    assert_int_equal(div64_round(7, 2), 4);
    assert_int_equal(div64_round(-7, 2), -4);
    assert_int_equal(div64_round(5, 3), 2);
    assert_int_equal(div64_round(-5, 3), -2);
    for (int i = 0; i < 100000; i++) {
        int64_t num = (int64_t)(rnd() >> 2) * ((rnd() & 1u) ? 1 : -1);
        int64_t den = (int64_t)(rnd() >> (33u + rnd() % 30u)) + 1;
        int64_t ref = num >= 0 ? (num + den / 2) / den : -((-num + den / 2) / den);
        assert_int_equal(div64_round(num, den), ref);
    }
}

/* Every angle in its range, both signs, against C's division. */
static void test_whole_turns(void **state_)
{
    (void)state_;
    for (int32_t a = -(1 << 23); a <= (1 << 23); a++) {
        if (decideg_whole_turns(a) != a / 3600) {
            fail_msg("%ld / 3600: %ld, not %ld", (long)a, (long)decideg_whole_turns(a),
                     (long)(a / 3600));
        }
    }
}

static void test_thousandths(void **state_)
{
    (void)state_;
    for (uint32_t x = 0; x < 59074u; x++) {
        if (thousandth_q32(x) != ((uint64_t)x << 32) / 1000u) {
            fail_msg("%lu x 2^32 / 1000: %llu", (unsigned long)x,
                     (unsigned long long)thousandth_q32(x));
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_edges),
        cmocka_unit_test(test_random),
        cmocka_unit_test(test_rounding),
        cmocka_unit_test(test_whole_turns),
        cmocka_unit_test(test_thousandths),
    };
    return cmocka_run_group_tests_name("div64", tests, NULL, NULL);
}
