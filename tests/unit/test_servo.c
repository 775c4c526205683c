/* The whole servo core, bytes on the wire in, exact bytes out (or silence):
 * every packet end to end, link changes after the response, persistence,
 * and sync Monitor turn-taking. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "frames.h"
#include "hal_double.h"
#include "protocol/data_table.h"
#include "servo.h"

#define BYTE_US 87u

static struct hal_double hal;
static struct servo servo;

static void poll_n(unsigned n)
{
    for (unsigned i = 0; i < n; i++) {
        servo_poll(&servo);
    }
}

static void feed(const uint8_t *bytes, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        hal.now_us += BYTE_US;
        servo_on_rx_byte(&servo, bytes[i], hal.now_us);
    }
}

static int setup(void **state)
{
    (void)state;
    hal_double_init(&hal);
    hal.now_us = 5000;
    servo_init(&servo, &hal.port);
    return 0;
}

/* Sends a request and collects whatever the servo sends back. */
static void request(uint8_t code, const uint8_t *content, size_t length)
{
    static uint8_t wire[4096];
    size_t n = make_request(wire, code, content, length);
    hal_double_clear_sent(&hal);
    feed(wire, n);
    poll_n(4);
}

#define REQUEST(code, ...)                                  \
    do {                                                    \
        const uint8_t c_[] = {__VA_ARGS__};                 \
        request((code), c_, sizeof c_);                     \
    } while (0)

static void assert_sent(const uint8_t *frame, size_t n)
{
    assert_int_equal(hal.sent_length, n);
    assert_memory_equal(hal.sent, frame, n);
}

/* The response frame for code/content must be exactly what was sent. */
#define EXPECT_RESPONSE(code, ...)                          \
    do {                                                    \
        const uint8_t e_[] = {__VA_ARGS__};                 \
        uint8_t f_[64];                                     \
        size_t n_ = make_response(f_, (code), e_, sizeof e_); \
        assert_sent(f_, n_);                                \
    } while (0)

static void expect_silence(void)
{
    assert_int_equal(hal.sent_length, 0);
}

static void test_ping_exact_bytes(void **state)
{
    (void)state;
    /* 12 4C 01 01 00 60 -> 05 1C 01 01 00 23 (checksums by hand) */
    const uint8_t ping[] = {0x12, 0x4C, 0x01, 0x01, 0x00, 0x60};
    feed(ping, sizeof ping);
    poll_n(2);
    const uint8_t reply[] = {0x05, 0x1C, 0x01, 0x01, 0x00, 0x23};
    assert_sent(reply, sizeof reply);
}

static void test_silence_for_others_broadcast_and_bad_checksum(void **state)
{
    (void)state;
    REQUEST(1, 5);
    expect_silence();
    REQUEST(1, 0xFF);
    expect_silence();
    const uint8_t bad[] = {0x12, 0x4C, 0x01, 0x01, 0x00, 0x61};
    hal_double_clear_sent(&hal);
    feed(bad, sizeof bad);
    poll_n(2);
    expect_silence();
    assert_int_equal(servo.rx.stats.checksum_errors, 1);
    assert_int_equal(servo.regs.status.status & STATUS_COMMAND_ERROR, 0);
}

static void test_read_data_every_item(void **state)
{
    (void)state;
    uint8_t block[USER_AREA_SIZE];
    user_config_encode(&servo.regs.user, block);
    unsigned pos = 0;
    for (uint8_t id = 32; id <= 53; id++) {
        const struct data_item *it = data_table_find(id);
        REQUEST(3, 0, id);
        uint8_t content[8] = {0, id};
        uint8_t n = 2;
        if (id != 35 && id != 45) {
            memcpy(&content[2], &block[pos], it->size);
            n = (uint8_t)(n + it->size);
        }
        uint8_t frame[16];
        size_t fn = make_response(frame, 3, content, n);
        assert_sent(frame, fn);
        pos += it->size;
    }
    /* Status area: model, version, serial from the port. */
    REQUEST(3, 0, 6);
    EXPECT_RESPONSE(3, 0, 6, 0x00, 0x0F);
    REQUEST(3, 0, 7);
    EXPECT_RESPONSE(3, 0, 7, 0x10, 0x00);
    REQUEST(3, 0, 8);
    EXPECT_RESPONSE(3, 0, 8, 0x78, 0x56, 0x34, 0x12);
    REQUEST(3, 0, 200);
    EXPECT_RESPONSE(3, 0, 200);
}

static void test_write_data_and_failures(void **state)
{
    (void)state;
    REQUEST(4, 0, 50, 0xE8, 0x03);
    EXPECT_RESPONSE(4, 0, 50, 1);
    REQUEST(3, 0, 50);
    EXPECT_RESPONSE(3, 0, 50, 0xE8, 0x03);
    REQUEST(4, 0, 1, 0, 0); /* read-only */
    EXPECT_RESPONSE(4, 0, 1, 0);
    REQUEST(4, 0, 50, 0xE8); /* wrong size */
    EXPECT_RESPONSE(4, 0, 50, 0);
    REQUEST(4, 0, 53, 0x09, 0x07); /* 1801: out of range */
    EXPECT_RESPONSE(4, 0, 53, 0);
    assert_true(servo.regs.status.status & STATUS_COMMAND_ERROR);
    REQUEST(3, 0, 5);
    EXPECT_RESPONSE(3, 0, 5, STATUS_COMMAND_ERROR);
}

static void test_batch_read_write_and_reset(void **state)
{
    (void)state;
    uint8_t block[1 + USER_AREA_SIZE] = {0};
    user_config_encode(&servo.regs.user, &block[1]);
    REQUEST(5, 0);
    uint8_t frame[64];
    size_t n = make_response(frame, 5, block, sizeof block);
    assert_sent(frame, n);

    block[1 + 1] = 1;    /* control response */
    block[1 + 3] = 0x42; /* reserved 35 kept as given */
    block[1 + 28] = 0x10; /* 52 = -1520 (0xFA10) */
    request(6, block, sizeof block);
    EXPECT_RESPONSE(6, 0, 1);
    REQUEST(5, 0);
    n = make_response(frame, 5, block, sizeof block);
    assert_sent(frame, n);

    block[1 + 4] = 0; /* invalid baud index: all or nothing */
    block[1 + 1] = 0;
    request(6, block, sizeof block);
    EXPECT_RESPONSE(6, 0, 0);
    assert_int_equal(servo.regs.user.control_response, 1);

    REQUEST(2, 0);
    EXPECT_RESPONSE(2, 0, 1);
    assert_int_equal(servo.regs.user.control_response, 0);
    assert_int_equal(servo.regs.user.reserved_35, 0);
}

static void test_new_id_takes_effect_after_the_response(void **state)
{
    (void)state;
    hal.tx_busy = true; /* the response is still on the wire */
    REQUEST(4, 0, 34, 7);
    EXPECT_RESPONSE(4, 0, 34, 1); /* answered with the old ID */
    REQUEST(1, 7); /* waits in the queue while the response is on the wire */
    assert_int_equal(servo.active_id, 0);
    hal_double_clear_sent(&hal);
    hal.tx_busy = false;
    poll_n(2);
    assert_int_equal(servo.active_id, 7);
    EXPECT_RESPONSE(1, 7); /* dispatched after the change took effect */
    REQUEST(1, 7);
    EXPECT_RESPONSE(1, 7);
    REQUEST(1, 0);
    expect_silence();
}

static void test_new_baud_takes_effect_after_the_response(void **state)
{
    (void)state;
    assert_int_equal(hal.baud, 115200);
    hal.tx_busy = true;
    REQUEST(4, 0, 36, 8);
    EXPECT_RESPONSE(4, 0, 36, 1);
    assert_int_equal(hal.baud, 115200);
    hal.tx_busy = false;
    poll_n(2);
    assert_int_equal(hal.baud, 1000000);
    assert_int_equal(servo.rx.idle_timeout_us, 1000);
}

static void test_config_survives_restart(void **state)
{
    (void)state;
    REQUEST(4, 0, 34, 9);
    REQUEST(4, 9, 43, 0xD0, 0x07);
    EXPECT_RESPONSE(4, 9, 43, 1);
    poll_n(2);
    flash_double_power_on(&hal.flash);
    servo_init(&servo, &hal.port);
    REQUEST(3, 9, 43);
    EXPECT_RESPONSE(3, 9, 43, 0xD0, 0x07);
    /* Writing the same value again writes no flash. */
    long steps = hal.flash.steps;
    REQUEST(4, 9, 43, 0xD0, 0x07);
    EXPECT_RESPONSE(4, 9, 43, 1);
    poll_n(2);
    assert_int_equal(hal.flash.steps, steps);
}

static void test_reset_keeps_link(void **state)
{
    (void)state;
    REQUEST(4, 0, 34, 4);
    poll_n(2);
    REQUEST(2, 4);
    EXPECT_RESPONSE(2, 4, 1);
    REQUEST(1, 4);
    EXPECT_RESPONSE(1, 4);
}

static void test_motion_packets_and_reads(void **state)
{
    (void)state;
    REQUEST(8, 0, 0x84, 0x03, 0xF4, 0x01, 0, 0); /* 90.0 degrees */
    expect_silence();
    REQUEST(10, 0);
    EXPECT_RESPONSE(10, 0, 0x84, 0x03);
    REQUEST(13, 0, 0x10, 0x1F, 0, 0, 0xE8, 0x03, 0, 0, 0, 0); /* 7952 = 2 turns + 20.8 */
    REQUEST(16, 0);
    EXPECT_RESPONSE(16, 0, 0x10, 0x1F, 0, 0, 2, 0);
    REQUEST(10, 0);
    EXPECT_RESPONSE(10, 0, 0xF0, 0x02); /* 75.2 */
    /* Under control: reset of turns and origin fail. */
    REQUEST(4, 0, 33, 1);
    REQUEST(17, 0);
    EXPECT_RESPONSE(17, 0, 0);
    REQUEST(24, 0, 0x10, 0, 0); /* stop and release */
    expect_silence();
    REQUEST(17, 0);
    EXPECT_RESPONSE(17, 0, 1);
    REQUEST(16, 0);
    EXPECT_RESPONSE(16, 0, 0xF0, 0x02, 0, 0, 0, 0);
    REQUEST(23, 0, 0);
    expect_silence();
    REQUEST(10, 0);
    EXPECT_RESPONSE(10, 0, 0, 0);
}

static void test_move_answered_when_finished(void **state)
{
    (void)state;
    REQUEST(4, 0, 33, 1);
    REQUEST(11, 0, 0xE8, 0x03, 0xE8, 0x03, 0x64, 0, 0xC8, 0, 0, 0);
    EXPECT_RESPONSE(11, 0, 1);
    REQUEST(7, 0, 0x01, 10, 0, 0, 0); /* wheel run */
    EXPECT_RESPONSE(7, 0, 1);
    REQUEST(9, 0, 0x10, 0x27);
    EXPECT_RESPONSE(9, 0, 1);
}

static void test_monitor(void **state)
{
    (void)state;
    servo.regs.status.voltage_mv = 7400;
    REQUEST(12, 0, 0x2C, 0x01, 0xB8, 0x0B, 0x64, 0, 0xC8, 0, 0, 0); /* 30.0 deg */
    REQUEST(22, 0);
    EXPECT_RESPONSE(22, 0, 0xE8, 0x1C, 0, 0, 0, 0, 0, 0, 0, 0x2C, 0x01, 0, 0, 0, 0);
}

static void test_async_moves_start_together(void **state)
{
    (void)state;
    request(18, NULL, 0);
    REQUEST(8, 0, 0x84, 0x03, 0xF4, 0x01, 0, 0);
    REQUEST(10, 0);
    EXPECT_RESPONSE(10, 0, 0, 0); /* buffered, not started */
    REQUEST(19, 0);
    REQUEST(10, 0);
    EXPECT_RESPONSE(10, 0, 0x84, 0x03);
    request(18, NULL, 0);
    REQUEST(8, 0, 0x10, 0x00, 0xF4, 0x01, 0, 0);
    REQUEST(19, 1); /* cancelled */
    REQUEST(10, 0);
    EXPECT_RESPONSE(10, 0, 0x84, 0x03);
}

/* Servo `id` sends its Monitor response on the shared wire. */
static void other_servo_answers(uint8_t id)
{
    uint8_t frame[32];
    uint8_t content[16] = {id};
    size_t n = make_response(frame, 22, content, sizeof content);
    feed(frame, n);
    poll_n(3);
}

/* Sync Monitor: servo 0 is third in the list, so it lets two responses go
 * by first. */
static void test_sync_monitor_waits_its_turn(void **state)
{
    (void)state;
    const uint8_t sync[] = {22, 1, 4, 5, 6, 0, 9};
    request(25, sync, sizeof sync);
    expect_silence();
    other_servo_answers(5);
    expect_silence();
    other_servo_answers(6);
    assert_int_equal(hal.sent_length, 21);
    assert_int_equal(hal.sent[2], 22);
    assert_int_equal(hal.sent[4], 0);
}

static void test_sync_monitor_passes_a_silent_servo(void **state)
{
    (void)state;
    const uint8_t sync[] = {22, 1, 3, 5, 6, 0};
    request(25, sync, sizeof sync);
    other_servo_answers(5);
    expect_silence();
    /* Servo 6 never answers: after the documented silence, servo 0 goes. */
    hal.now_us += SYNC_SLOT_SILENCE_US - 1;
    poll_n(3);
    expect_silence();
    hal.now_us += 2;
    poll_n(3);
    assert_int_equal(hal.sent_length, 21);
}

static void test_sync_move_record(void **state)
{
    (void)state;
    const uint8_t sync[] = {8, 7, 2, 4, 0x10, 0, 0, 0, 0, 0, 0, 0x84, 0x03, 0xF4, 0x01, 0, 0};
    request(25, sync, sizeof sync);
    expect_silence();
    REQUEST(10, 0);
    EXPECT_RESPONSE(10, 0, 0x84, 0x03);
}

static void test_garbage_between_frames_and_responses_of_others(void **state)
{
    (void)state;
    uint8_t wire[128];
    size_t n = 0;
    const uint8_t junk[] = {0x00, 0x12, 0x99, 0x05, 0x4C};
    memcpy(wire, junk, sizeof junk);
    n += sizeof junk;
    const uint8_t inner[] = {0x12, 0x4C, 0x01, 0x01, 0x00, 0x60}; /* a ping to 0 */
    n += make_response(wire + n, 3, inner, sizeof inner);
    const uint8_t ping[] = {0};
    n += make_request(wire + n, 1, ping, 1);
    hal_double_clear_sent(&hal);
    feed(wire, n);
    poll_n(4);
    EXPECT_RESPONSE(1, 0); /* exactly one answer: the inner ping was skipped */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_ping_exact_bytes, setup),
        cmocka_unit_test_setup(test_silence_for_others_broadcast_and_bad_checksum, setup),
        cmocka_unit_test_setup(test_read_data_every_item, setup),
        cmocka_unit_test_setup(test_write_data_and_failures, setup),
        cmocka_unit_test_setup(test_batch_read_write_and_reset, setup),
        cmocka_unit_test_setup(test_new_id_takes_effect_after_the_response, setup),
        cmocka_unit_test_setup(test_new_baud_takes_effect_after_the_response, setup),
        cmocka_unit_test_setup(test_config_survives_restart, setup),
        cmocka_unit_test_setup(test_reset_keeps_link, setup),
        cmocka_unit_test_setup(test_motion_packets_and_reads, setup),
        cmocka_unit_test_setup(test_move_answered_when_finished, setup),
        cmocka_unit_test_setup(test_monitor, setup),
        cmocka_unit_test_setup(test_async_moves_start_together, setup),
        cmocka_unit_test_setup(test_sync_monitor_waits_its_turn, setup),
        cmocka_unit_test_setup(test_sync_monitor_passes_a_silent_servo, setup),
        cmocka_unit_test_setup(test_sync_move_record, setup),
        cmocka_unit_test_setup(test_garbage_between_frames_and_responses_of_others, setup),
    };
    return cmocka_run_group_tests_name("servo", tests, NULL, NULL);
}
