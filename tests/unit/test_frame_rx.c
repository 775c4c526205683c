/* The framer against every rule of docs/protocol.md, "The shared wire". */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "support/frames.h"
#include "protocol/frame_rx.h"
#include "protocol/packet_codes.h"

struct fixture {
    struct frame_rx rx;
    volatile uint8_t id;
};

static int setup(void **state)
{
    static struct fixture f;
    memset(&f, 0, sizeof f);
    f.id = 3;
    frame_rx_init(&f.rx, &f.id);
    *state = &f;
    return 0;
}

/* As the main loop does: a burst at a time. */
static void feed(struct fixture *f, const uint8_t *bytes, size_t n)
{
    frame_rx_feed_bytes(&f->rx, bytes, (uint32_t)n);
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
    assert_true(frame_rx_in_frame(&f->rx));
    frame_rx_line_idle(&f->rx);
    assert_false(frame_rx_in_frame(&f->rx));
    feed(f, wire, n);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->code, 1);
    assert_int_equal(f->rx.stats.idle_timeouts, 1);
    frame_rx_line_idle(&f->rx); /* between frames: nothing to drop */
    assert_int_equal(f->rx.stats.idle_timeouts, 1);
}

static void test_requests_to_other_ids_are_passed_over(void **state)
{
    struct fixture *f = *state;
    /* A WriteData to servo 4 whose data holds a valid request to servo 3:
     * it must not be taken for one; a request to 3 follows at once. */
    uint8_t inner[8];
    size_t inner_n = make_request(inner, 1, (const uint8_t[]){3}, 1);
    uint8_t content[16] = {4};
    memcpy(content + 1, inner, inner_n);
    uint8_t wire[64];
    size_t n = make_request(wire, 4, content, 1 + inner_n);
    n += make_request(wire + n, 10, (const uint8_t[]){3}, 1);
    n += make_request(wire + n, 1, (const uint8_t[]){0xFF}, 1); /* broadcast: kept */
    n += make_request(wire + n, 20, (const uint8_t[]){9}, 1);   /* not addressed: kept */
    feed(f, wire, n);
    const struct rx_frame *fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->code, 10);
    fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->content[0], 0xFF);
    fr = take(f);
    assert_non_null(fr);
    assert_int_equal(fr->code, 20);
    assert_null(take(f));
    assert_int_equal(f->rx.stats.requests_seen, 4);
    assert_int_equal(f->rx.stats.frames, 3);
}

/* A stream of every kind of frame, and garbage. */
static size_t mixed_stream(uint8_t *wire)
{
    size_t n = 0;
    uint8_t content[40];
    for (unsigned i = 0; i < sizeof content; i++) {
        content[i] = (uint8_t)(0x12 + i * 7u);
    }
    content[0] = 3;
    n += make_request(wire + n, 4, content, 4);
    n += make_response(wire + n, 3, content, 6);
    content[0] = 5;
    n += make_request(wire + n, 11, content, 11);
    wire[n++] = 0x12;
    wire[n++] = 0x05;
    content[0] = 3;
    n += make_request(wire + n, 6, content, 33);
    n += make_request(wire + n, 4, content, 40); /* truncated */
    n += make_request(wire + n, 1, content, 1);
    wire[n - 1] ^= 0x10u; /* bad checksum */
    const uint8_t ids[] = {7, 3, 9};
    content[0] = 12;
    content[1] = 7;
    content[2] = 3;
    for (unsigned k = 0; k < 3; k++) {
        content[3 + 7 * k] = ids[k];
    }
    n += make_request(wire + n, 25, content, 3 + 21);
    n += make_request(wire + n, 22, (const uint8_t[]){3}, 1);
    return n;
}

/* What the framer makes of a stream, as one string of facts. */
static size_t outcome(struct fixture *f, uint8_t *out)
{
    size_t n = 0;
    for (const struct rx_frame *fr; (fr = take(f)) != NULL;) {
        memcpy(out + n, fr, sizeof *fr);
        n += sizeof *fr;
    }
    memcpy(out + n, &f->rx.stats, sizeof f->rx.stats);
    return n + sizeof f->rx.stats;
}

/* As the main loop does with its ring: a burst fed; what the framer did
 * not take (its queue full) is fed again once the waiting frames are
 * taken, each appended to out. Returns out's new length. */
static size_t feed_draining(struct fixture *f, const uint8_t *bytes, size_t n, uint8_t *out,
                            size_t out_n)
{
    for (;;) {
        uint32_t took = frame_rx_feed_until_full(&f->rx, bytes, (uint32_t)n);
        bytes += took;
        n -= took;
        if (n == 0u) {
            return out_n;
        }
        for (const struct rx_frame *fr; (fr = take(f)) != NULL;) {
            memcpy(out + out_n, fr, sizeof *fr);
            out_n += sizeof *fr;
        }
    }
}

static void test_bursts_split_anywhere_give_the_same_frames(void **state)
{
    struct fixture *f = *state;
    static uint8_t wire[512];
    size_t n = mixed_stream(wire);
    static uint8_t expected[4096], got[4096];
    size_t expected_n = 0;
    for (size_t i = 0; i < n; i++) { /* a byte a pass */
        expected_n = feed_draining(f, &wire[i], 1, expected, expected_n);
    }
    expected_n += outcome(f, expected + expected_n);
    assert_int_equal(f->rx.stats.frames, 5); /* more than the queue holds: none lost */
    assert_int_equal(f->rx.stats.queue_overflows, 0);
    for (size_t cut = 0; cut <= n; cut++) {
        for (size_t cut2 = cut; cut2 <= n; cut2 += 5) {
            frame_rx_init(&f->rx, &f->id);
            size_t got_n = feed_draining(f, wire, cut, got, 0);
            got_n = feed_draining(f, wire + cut, cut2 - cut, got, got_n);
            got_n = feed_draining(f, wire + cut2, n - cut2, got, got_n);
            got_n += outcome(f, got + got_n);
            assert_int_equal(got_n, expected_n);
            assert_memory_equal(got, expected, expected_n);
        }
    }
}

/* A burst of more frames than the queue holds: the framer stops at the
 * end of the frame that fills it, and the rest waits in the ring. */
static void test_a_full_queue_leaves_the_rest_of_a_burst_unread(void **state)
{
    struct fixture *f = *state;
    uint8_t wire[64];
    size_t n = 0, ends[FRAME_QUEUE_SLOTS];
    for (uint8_t i = 0; i < FRAME_QUEUE_SLOTS; i++) {
        const uint8_t read[] = {3, i};
        n += make_request(wire + n, 3, read, 2);
        ends[i] = n;
    }
    uint32_t took = frame_rx_feed_until_full(&f->rx, wire, (uint32_t)n);
    assert_int_equal(took, ends[FRAME_QUEUE_SLOTS - 2u]);
    assert_int_equal(frame_rx_feed_until_full(&f->rx, wire + took, (uint32_t)(n - took)), 0);
    assert_non_null(take(f));
    assert_int_equal(frame_rx_feed_until_full(&f->rx, wire + took, (uint32_t)(n - took)), n - took);
    for (uint8_t i = 1; i < FRAME_QUEUE_SLOTS; i++) {
        const struct rx_frame *fr = take(f);
        assert_non_null(fr);
        assert_int_equal(fr->content[1], i);
    }
    assert_int_equal(f->rx.stats.queue_overflows, 0);
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

/* frame_rx_feed_bytes takes every byte: a frame that starts with the
 * queue full is dropped, and counted. */
static void test_queue_overflow_is_counted(void **state)
{
    struct fixture *f = *state;
    uint8_t wire[16];
    for (uint8_t i = 0; i < FRAME_QUEUE_SLOTS; i++) {
        const uint8_t read[] = {3, i};
        size_t n = make_request(wire, 3, read, 2);
        feed(f, wire, n);
    }
    assert_int_equal(f->rx.stats.queue_overflows, 1);
    for (uint8_t i = 0; i + 1u < FRAME_QUEUE_SLOTS; i++) {
        const struct rx_frame *fr = take(f);
        assert_non_null(fr);
        assert_int_equal(fr->content[1], i); /* oldest first */
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
        cmocka_unit_test_setup(test_requests_to_other_ids_are_passed_over, setup),
        cmocka_unit_test_setup(test_bursts_split_anywhere_give_the_same_frames, setup),
        cmocka_unit_test_setup(test_without_idle_gap_truncated_frame_swallows_next, setup),
        cmocka_unit_test_setup(test_extended_length, setup),
        cmocka_unit_test_setup(test_extended_length_short_frame, setup),
        cmocka_unit_test_setup(test_queue_overflow_is_counted, setup),
        cmocka_unit_test_setup(test_a_full_queue_leaves_the_rest_of_a_burst_unread, setup),
        cmocka_unit_test_setup(test_sync_keeps_only_own_record, setup),
        cmocka_unit_test_setup(test_sync_record_data_matching_id_is_not_a_record_start, setup),
        cmocka_unit_test_setup(test_sync_without_own_record, setup),
        cmocka_unit_test_setup(test_sync_with_inconsistent_length_is_flagged, setup),
        cmocka_unit_test_setup(test_sync_record_too_long_is_flagged, setup),
        cmocka_unit_test_setup(test_idle_time_per_baud, setup),
    };
    return cmocka_run_group_tests_name("frame_rx", tests, NULL, NULL);
}
