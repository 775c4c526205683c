/* The response encoder: every content length, and a length over the
 * largest, against a byte-by-byte reference frame. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "protocol/frame_tx.h"

static uint32_t state = 0x2545F491u;
static uint8_t rnd(void)
{
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    return (uint8_t)state;
}

/* Fills r as a handler would, with stale bytes after the content. */
static void fill(struct response *r, uint8_t code, uint8_t length)
{
    for (size_t i = 0; i < sizeof r->words; i++) {
        ((uint8_t *)r)[i] = rnd();
    }
    r->code = code;
    r->length = length;
}

static void check_frame(const struct response *before, const struct response *after, uint8_t size,
                        uint8_t length)
{
    const uint8_t *f = frame_tx_bytes(after);
    assert_int_equal(size, 5u + length);
    assert_int_equal(f[0], 0x05);
    assert_int_equal(f[1], 0x1C);
    assert_int_equal(f[2], before->code);
    assert_int_equal(f[3], length);
    assert_memory_equal(&f[4], before->content, length);
    uint32_t sum = 0;
    for (uint32_t i = 0; i < 4u + length; i++) {
        sum += f[i];
    }
    assert_int_equal(f[4u + length], (uint8_t)sum);
}

static void test_every_length(void **unused)
{
    (void)unused;
    for (int round = 0; round < 200; round++) {
        for (uint8_t length = 0; length <= RESPONSE_CONTENT_MAX; length++) {
            struct response r;
            fill(&r, rnd(), length);
            struct response before = r;
            uint8_t size = frame_tx_seal(&r);
            check_frame(&before, &r, size, length);
        }
    }
}

/* All 0xFF: the largest sum, each 16-bit lane at its fullest. */
static void test_largest_sum(void **unused)
{
    (void)unused;
    struct response r;
    memset(&r, 0xFF, sizeof r);
    r.length = RESPONSE_CONTENT_MAX;
    struct response before = r;
    check_frame(&before, &r, frame_tx_seal(&r), RESPONSE_CONTENT_MAX);
}

static void test_length_over_the_largest_is_cut(void **unused)
{
    (void)unused;
    const uint8_t lengths[] = {RESPONSE_CONTENT_MAX + 1u, 100, 255};
    for (size_t i = 0; i < sizeof lengths; i++) {
        struct response r;
        fill(&r, 0x41, lengths[i]);
        struct response before = r;
        check_frame(&before, &r, frame_tx_seal(&r), RESPONSE_CONTENT_MAX);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_length),
        cmocka_unit_test(test_largest_sum),
        cmocka_unit_test(test_length_over_the_largest_is_cut),
    };
    return cmocka_run_group_tests_name("frame_tx", tests, NULL, NULL);
}
