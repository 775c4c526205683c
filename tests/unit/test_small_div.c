/* The Cortex-M0 image's one-bit-a-step division (hal/runtime/
 * small_div.c) against C's / and % on edge cases and random pairs. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "runtime/small_div.h"
#include "support/xorshift.h"

static uint64_t state = 0x2545F4914F6CDD1Du;
static uint32_t rnd(void)
{
    return (uint32_t)(xorshift64(&state) >> 16);
}

static void check_u(uint32_t n, uint32_t d)
{
    uint64_t qr = small_udivmod(n, d);
    uint32_t q = d != 0u ? n / d : 0u;
    uint32_t r = d != 0u ? n % d : n;
    if ((uint32_t)qr != q || (uint32_t)(qr >> 32) != r) {
        fail_msg("%u / %u: %u rem %u, not %u rem %u", n, d, (uint32_t)qr, (uint32_t)(qr >> 32), q, r);
    }
}

static void check_i(int32_t n, int32_t d)
{
    uint64_t qr = small_idivmod(n, d);
    int32_t q = d == 0 ? 0 : (n == INT32_MIN && d == -1) ? INT32_MIN : n / d;
    int32_t r = d == 0 ? n : (n == INT32_MIN && d == -1) ? 0 : n % d;
    if ((int32_t)(uint32_t)qr != q || (int32_t)(uint32_t)(qr >> 32) != r) {
        fail_msg("%d / %d: %d rem %d, not %d rem %d", n, d, (int32_t)(uint32_t)qr,
                 (int32_t)(uint32_t)(qr >> 32), q, r);
    }
}

static void test_edges(void **state_)
{
    (void)state_;
    const uint32_t values[] = {0, 1, 2, 3, 7, 1000, 0xFFFFu, 0x10000u, 0x7FFFFFFFu, 0x80000000u,
                               0x80000001u, 0xFFFFFFFEu, 0xFFFFFFFFu};
    for (size_t i = 0; i < sizeof values / sizeof values[0]; i++) {
        for (size_t j = 0; j < sizeof values / sizeof values[0]; j++) {
            check_u(values[i], values[j]);
            check_i((int32_t)values[i], (int32_t)values[j]);
        }
    }
}

static void test_random(void **state_)
{
    (void)state_;
    for (int i = 0; i < 1000000; i++) {
        uint32_t n = rnd() >> (rnd() % 32u);
        uint32_t d = rnd() >> (rnd() % 32u);
        check_u(n, d);
        check_i((int32_t)n, (int32_t)d);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_edges),
        cmocka_unit_test(test_random),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
