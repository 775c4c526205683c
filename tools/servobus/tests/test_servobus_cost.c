/* The frame finder's cost a byte, counted without a clock: the bytes it
 * moves (memmove) and sums (sb_checksum) for each byte fed, one a call as
 * a microcontroller's UART hands them over. Before, a false header held
 * made every later byte move and rescan the bytes held: quadratic. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "servobus/servobus.h"

static size_t moved, summed;

static void *counted_memmove(void *to, const void *from, size_t n)
{
    moved += n;
    return memmove(to, from, n);
}

static uint8_t counted_checksum(const uint8_t *data, size_t n)
{
    summed += n;
    return sb_checksum(data, n);
}

#define memmove counted_memmove
#define sb_checksum counted_checksum
#include "src/sb_parse.c"
#undef memmove
#undef sb_checksum

static uint8_t stream[4096];
static size_t streamed;

static void monitor(uint8_t id)
{
    sb_value v[8] = {{id, NULL, 0},    {7400, NULL, 0}, {300, NULL, 0}, {2000, NULL, 0},
                     {1800, NULL, 0}, {1, NULL, 0},    {900, NULL, 0}, {0, NULL, 0}};
    size_t n = 0;
    assert_int_equal(sb_encode_answer(SB_PKT_MONITOR, v, 8, stream + streamed, sizeof stream - streamed, &n).status,
                     SB_OK);
    streamed += n;
}

/* The frames found, fed a byte a call; the bytes moved and summed counted. */
static size_t feed(void)
{
    static sb_parser p;
    size_t frames = 0, used = 0, clen = 0;
    uint8_t code = 0;
    const uint8_t *content = NULL;
    sb_parser_init(&p, false);
    moved = summed = 0;
    for (size_t k = 0; k < streamed; k++)
        if (sb_parse(&p, stream + k, 1, &used, &code, &content, &clen))
            for (frames++; sb_parse(&p, NULL, 0, &used, &code, &content, &clen);)
                frames++;
    return frames;
}

static void a_false_header_held_costs_no_pass_over_the_bytes_held(void **state)
{
    (void)state;
    streamed = 0;
    stream[streamed++] = SB_RESPONSE_HEADER_0; /* a frame of 255 bytes, never ending */
    stream[streamed++] = SB_RESPONSE_HEADER_1;
    stream[streamed++] = SB_PKT_MONITOR;
    stream[streamed++] = 250;
    for (uint8_t id = 1; id <= 40; id++)
        monitor(id);
    assert_int_equal(feed(), 40);
    assert_true(moved + summed <= 4 * streamed);
}

static void a_flipped_length_byte_costs_no_pass_over_the_bytes_held(void **state)
{
    (void)state;
    streamed = 0;
    for (uint8_t id = 1; id <= 12; id++)
        monitor(id);
    stream[3] |= 0x80; /* the first answer's length: 0x90, not 0x10 */
    assert_int_equal(feed(), 11);
    assert_true(moved + summed <= 4 * streamed);
}

static void headers_every_four_bytes_cost_no_pass_over_the_bytes_held(void **state)
{
    (void)state;
    for (streamed = 0; streamed + 4 <= 3000; streamed += 4)
        memcpy(stream + streamed, "\x05\x1c\x00\xf6", 4);
    assert_int_equal(feed(), 0);
    assert_true(moved + summed <= 4 * streamed);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_false_header_held_costs_no_pass_over_the_bytes_held),
        cmocka_unit_test(a_flipped_length_byte_costs_no_pass_over_the_bytes_held),
        cmocka_unit_test(headers_every_four_bytes_cost_no_pass_over_the_bytes_held),
    };
    (void)counted_memmove; /* the finder's, if it calls them */
    (void)counted_checksum;
    return cmocka_run_group_tests(tests, NULL, NULL);
}
