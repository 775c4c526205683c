/* The framer against every rule of behaviour.md, "The wire". */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "frames.h"
#include "protocol/frame_rx.h"

#define BYTE_US 87u /* one byte at 115200 baud */
#define IDLE_US 1000u

struct fixture {
    struct frame_rx rx;
    volatile uint8_t id;
    uint32_t now;
};

static int setup(void **state)
{
    static struct fixture f;
    memset(&f, 0, sizeof f);
    f.id = 3;
    frame_rx_init(&f.rx, &f.id, IDLE_US);
    f.now = 1000;
    *state = &f;
    return 0;
}

static void feed(struct fixture *f, const uint8_t *bytes, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        f->now += BYTE_US;
        frame_rx_feed(&f->rx, bytes[i], f->now);
    }
}

static const struct rx_frame *take(struct fixture *f)
{
    static struct rx_frame copy;
    const struct rx_frame *fr = frame_rx_peek(&f->rx);
    if (fr == NULL) {
        return NULL;
    }
    copy = *fr;
    frame_rx_release(&f->rx);
    return &copy;
}

static void test_valid_request_is_delivered(void **state)
{
    struct fixture *f = *state;
    /* ReadData(id 3, data 5): 12 4C 03 02 03 05 sum=0x6B */
    const uint8_t wire[] = {0x12, 0x4C, 0x03, 0x02, 0x03, 0x05, 0x6B};
    feed(f, wire, sizeof wire);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->code, 3);
    assert_int_equal(fr->length, 2);
    assert_int_equal(fr->stored, 2);
    assert_int_equal(fr->flags, 0);
    assert_memory_equal(fr->content, "\x03\x05", 2);
    assert_int_equal(f->rx.stats.frames, 1);
    assert_null(take(f));
}

static void test_empty_request_is_delivered(void **state)
{
    struct fixture *f = *state;
    uint8_t wire[8];
    size_t n = make_request(wire, 18, NULL, 0);
    feed(f, wire, n);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->code, 18);
    assert_int_equal(fr->length, 0);
}

static void test_garbage_is_skipped_until_a_header(void **state)
{
    struct fixture *f = *state;
    uint8_t wire[32];
    const uint8_t junk[] = {0x00, 0x4C, 0x12, 0x12, 0x05, 0x12};
    memcpy(wire, junk, sizeof junk);
    const uint8_t ping[] = {3};
    size_t n = sizeof junk + make_request(wire + sizeof junk, 1, ping, 1);
    feed(f, wire, n);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->code, 1);
    /* Every junk byte: each 12 or 05 is a false start, since the byte after
     * it does not complete a header (the last 12 is followed by the real 12). */
    assert_int_equal(f->rx.stats.garbage_bytes, sizeof junk);
}

static void test_bad_checksum_is_dropped_and_counted(void **state)
{
    struct fixture *f = *state;
    uint8_t wire[16];
    const uint8_t ping[] = {3};
    size_t n = make_request(wire, 1, ping, 1);
    wire[n - 1] ^= 0x01;
    feed(f, wire, n);
    assert_null(take(f));
    assert_int_equal(f->rx.stats.checksum_errors, 1);
    /* The next good frame is not affected. */
    n = make_request(wire, 1, ping, 1);
    feed(f, wire, n);
    assert_non_null(take(f));
}

static void test_response_frames_are_skipped_whole(void **state)
{
    struct fixture *f = *state;
    /* Another servo's ReadData response whose data is itself a valid
     * request frame: it must not be taken for one. */
    uint8_t inner[8];
    const uint8_t ping[] = {3};
    size_t inner_n = make_request(inner, 1, ping, 1);
    uint8_t content[16] = {7, 8};
    memcpy(content + 2, inner, inner_n);
    uint8_t wire[64];
    size_t n = make_response(wire, 3, content, 2 + inner_n);
    /* A request follows immediately, without an idle gap. */
    const uint8_t read_angle[] = {3};
    n += make_request(wire + n, 10, read_angle, 1);
    feed(f, wire, n);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->code, 10);
    assert_null(take(f));
    assert_int_equal(f->rx.stats.responses_skipped, 1);
    assert_int_equal(fr->responses_seen, 1);
}

static void test_response_length_byte_ff_is_not_extended(void **state)
{
    struct fixture *f = *state;
    static uint8_t content[255];
    memset(content, 0x12, sizeof content);
    static uint8_t wire[300];
    size_t n = make_response(wire, 3, content, 255);
    const uint8_t ping[] = {3};
    n += make_request(wire + n, 1, ping, 1);
    feed(f, wire, n);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->code, 1);
}

static void test_partial_frame_dropped_after_idle(void **state)
{
    struct fixture *f = *state;
    uint8_t wire[16];
    const uint8_t ping[] = {3};
    size_t n = make_request(wire, 1, ping, 1);
    feed(f, wire, n - 2); /* truncated: content and checksum missing */
    f->now += IDLE_US + 1;
    feed(f, wire, n);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->code, 1);
    assert_int_equal(f->rx.stats.idle_timeouts, 1);
}

static void test_gap_at_the_idle_limit_keeps_the_frame(void **state)
{
    struct fixture *f = *state;
    uint8_t wire[16];
    const uint8_t ping[] = {3};
    size_t n = make_request(wire, 1, ping, 1);
    feed(f, wire, 3);
    f->now += IDLE_US - BYTE_US; /* the next byte arrives exactly IDLE_US later */
    feed(f, wire + 3, n - 3);
    assert_non_null(take(f));
    assert_int_equal(f->rx.stats.idle_timeouts, 0);
}

static void test_idle_timeout_survives_clock_wrap(void **state)
{
    struct fixture *f = *state;
    uint8_t wire[16];
    const uint8_t ping[] = {3};
    size_t n = make_request(wire, 1, ping, 1);
    f->now = 0xFFFFFFFFu - 2u * BYTE_US;
    feed(f, wire, n);
    assert_non_null(take(f));
    assert_int_equal(f->rx.stats.idle_timeouts, 0);
}

static void test_clock_stepping_back_is_not_an_idle_gap(void **state)
{
    struct fixture *f = *state;
    uint8_t wire[16];
    const uint8_t ping[] = {3};
    size_t n = make_request(wire, 1, ping, 1);
    feed(f, wire, 3);
    f->now -= 1000; /* the clock reads 1 ms earlier than the last byte */
    feed(f, wire + 3, n - 3);
    assert_non_null(take(f));
    assert_int_equal(f->rx.stats.idle_timeouts, 0);
}

static void test_without_idle_gap_truncated_frame_swallows_next(void **state)
{
    /* Documents why the idle timeout exists: with no gap, a truncated frame
     * takes the next frame's bytes as its own and fails its checksum. */
    struct fixture *f = *state;
    uint8_t wire[32];
    const uint8_t ping[] = {3};
    size_t n = make_request(wire, 3, (const uint8_t[]){3, 5}, 2);
    size_t m = make_request(wire + n - 2, 1, ping, 1);
    feed(f, wire, n - 2 + m);
    assert_null(take(f));
}

static void test_extended_length(void **state)
{
    struct fixture *f = *state;
    uint8_t content[300];
    memset(content, 0xAB, sizeof content);
    content[0] = 3;
    static uint8_t wire[320];
    size_t n = make_request(wire, 4, content, sizeof content);
    assert_int_equal(wire[3], 0xFF);
    feed(f, wire, n);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->length, 300);
    assert_int_equal(fr->stored, FRAME_CONTENT_MAX);
    assert_true(fr->flags & FRAME_TRUNCATED);
}

static void test_extended_length_short_frame(void **state)
{
    struct fixture *f = *state;
    /* 12 4C 01 FF 01 00 03 + checksum: a Ping in extended form. */
    uint8_t wire[] = {0x12, 0x4C, 0x01, 0xFF, 0x01, 0x00, 0x03, 0};
    unsigned sum = 0;
    for (size_t i = 0; i < sizeof wire - 1; i++) {
        sum += wire[i];
    }
    wire[sizeof wire - 1] = (uint8_t)sum;
    feed(f, wire, sizeof wire);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->length, 1);
    assert_int_equal(fr->content[0], 3);
    assert_int_equal(fr->flags, 0);
}

static void test_queue_overflow_is_counted(void **state)
{
    struct fixture *f = *state;
    uint8_t wire[16];
    for (uint8_t i = 0; i < FRAME_QUEUE_SLOTS; i++) {
        const uint8_t ping[] = {i};
        size_t n = make_request(wire, 1, ping, 1);
        feed(f, wire, n);
    }
    assert_int_equal(f->rx.stats.queue_overflows, 1);
    for (uint8_t i = 0; i + 1u < FRAME_QUEUE_SLOTS; i++) {
        const struct rx_frame *fr = take(f);
        assert_non_null(fr);
        assert_int_equal(fr->content[0], i); /* oldest first */
    }
    assert_null(take(f));
}

/* A sync frame of count records of record_len bytes, the servo ID of
 * record k being ids[k]; record bytes are k-dependent so they can be told
 * apart. */
static size_t make_sync(uint8_t *wire, uint8_t cmd, uint8_t record_len, uint8_t count,
                        const uint8_t *ids)
{
    static uint8_t content[3 + 255 * 15];
    size_t n = 0;
    content[n++] = cmd;
    content[n++] = record_len;
    content[n++] = count;
    for (unsigned k = 0; k < count; k++) {
        content[n++] = ids[k];
        for (unsigned b = 1; b < record_len; b++) {
            content[n++] = (uint8_t)(k + b);
        }
    }
    return make_request(wire, 25, content, n);
}

static void test_sync_keeps_only_own_record(void **state)
{
    struct fixture *f = *state;
    uint8_t ids[254];
    for (unsigned k = 0; k < 254; k++) {
        ids[k] = (uint8_t)(k + 10); /* IDs 10..263 wrap; 3 is at k = 249 */
    }
    static uint8_t wire[7 + 3 + 254 * 15]; /* header, ext. length, checksum */
    size_t n = make_sync(wire, 14, 15, 254, ids);
    assert_true(n > 3000);
    feed(f, wire, n);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->code, 25);
    assert_int_equal(fr->length, 3 + 254 * 15);
    assert_int_equal(fr->flags, 0);
    assert_int_equal(fr->sync_index, 249);
    assert_int_equal(fr->stored, 3 + 15);
    assert_int_equal(fr->content[0], 14);
    assert_int_equal(fr->content[1], 15);
    assert_int_equal(fr->content[2], 254);
    assert_int_equal(fr->content[3], 3);
    for (unsigned b = 1; b < 15; b++) {
        assert_int_equal(fr->content[3 + b], (uint8_t)(249 + b));
    }
}

static void test_sync_record_data_matching_id_is_not_a_record_start(void **state)
{
    struct fixture *f = *state;
    /* Record 0 is for servo 9 and its data bytes include 3; record 1 is ours. */
    const uint8_t content[] = {22, 2, 2, 9, 3, 3, 0x55};
    uint8_t wire[16];
    size_t n = make_request(wire, 25, content, sizeof content);
    feed(f, wire, n);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->sync_index, 1);
    assert_memory_equal(&fr->content[3], "\x03\x55", 2);
}

static void test_sync_without_own_record(void **state)
{
    struct fixture *f = *state;
    const uint8_t ids[] = {1, 2, 4};
    uint8_t wire[64];
    size_t n = make_sync(wire, 8, 7, 3, ids);
    feed(f, wire, n);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->sync_index, FRAME_SYNC_NO_RECORD);
    assert_int_equal(fr->stored, 3);
}

static void test_sync_with_inconsistent_length_is_flagged(void **state)
{
    struct fixture *f = *state;
    const uint8_t content[] = {22, 1, 3, 3, 4}; /* says 3 records, carries 2 */
    uint8_t wire[16];
    size_t n = make_request(wire, 25, content, sizeof content);
    feed(f, wire, n);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_true(fr->flags & FRAME_BAD_SYNC);
}

static void test_sync_record_too_long_is_flagged(void **state)
{
    struct fixture *f = *state;
    uint8_t content[3 + 16] = {8, 16, 1, 3};
    uint8_t wire[32];
    size_t n = make_request(wire, 25, content, sizeof content);
    feed(f, wire, n);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_true(fr->flags & FRAME_BAD_SYNC);
}

static void test_idle_time_per_baud(void **state)
{
    (void)state;
    assert_int_equal(frame_rx_idle_us(9600), 10417);   /* 10 bytes */
    assert_int_equal(frame_rx_idle_us(57600), 1737);
    assert_int_equal(frame_rx_idle_us(115200), 1000);  /* floor */
    assert_int_equal(frame_rx_idle_us(1000000), 1000); /* floor */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_valid_request_is_delivered, setup),
        cmocka_unit_test_setup(test_empty_request_is_delivered, setup),
        cmocka_unit_test_setup(test_garbage_is_skipped_until_a_header, setup),
        cmocka_unit_test_setup(test_bad_checksum_is_dropped_and_counted, setup),
        cmocka_unit_test_setup(test_response_frames_are_skipped_whole, setup),
        cmocka_unit_test_setup(test_response_length_byte_ff_is_not_extended, setup),
        cmocka_unit_test_setup(test_partial_frame_dropped_after_idle, setup),
        cmocka_unit_test_setup(test_gap_at_the_idle_limit_keeps_the_frame, setup),
        cmocka_unit_test_setup(test_idle_timeout_survives_clock_wrap, setup),
        cmocka_unit_test_setup(test_clock_stepping_back_is_not_an_idle_gap, setup),
        cmocka_unit_test_setup(test_without_idle_gap_truncated_frame_swallows_next, setup),
        cmocka_unit_test_setup(test_extended_length, setup),
        cmocka_unit_test_setup(test_extended_length_short_frame, setup),
        cmocka_unit_test_setup(test_queue_overflow_is_counted, setup),
        cmocka_unit_test_setup(test_sync_keeps_only_own_record, setup),
        cmocka_unit_test_setup(test_sync_record_data_matching_id_is_not_a_record_start, setup),
        cmocka_unit_test_setup(test_sync_without_own_record, setup),
        cmocka_unit_test_setup(test_sync_with_inconsistent_length_is_flagged, setup),
        cmocka_unit_test_setup(test_sync_record_too_long_is_flagged, setup),
        cmocka_unit_test_setup(test_idle_time_per_baud, setup),
    };
    return cmocka_run_group_tests_name("frame_rx", tests, NULL, NULL);
}
