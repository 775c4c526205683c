/* A Sync Monitor round's first answer within two byte times of the
 * request's end (docs/sleep.md, "The first answer"): listed first, the
 * servo hands the answer's header and ID to the UART in the pass that
 * frames the checksum byte and builds the rest behind them (the double
 * reads the buffer at the pass's end, as the DMA reads it while it goes);
 * a request whose checksum fails, or that is cut, is never answered; a
 * tick that falls due as a request for this servo ends waits for its
 * answer. At 1 Mbaud, with the M0's tick and pass (46 us). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "support/by_name.h"
#include "support/servo_harness.h"

/* Servo 0 listed first of six, as a robot loop's host asks. */
static const uint8_t round_of_six[] = {22, 1, 6, 0, 9, 10, 11, 12, 13};
static uint8_t request[32];
static size_t request_length;

static void feed_at_1mbaud(const uint8_t *bytes, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        hal.now_us += 10u;
        servo_on_rx_byte(&servo, bytes[i], hal.now_us);
        harness_poll(1); /* the loop, awake, frames each byte as it lands */
    }
}

static int setup(void **state)
{
    (void)state;
    harness_init();
    hal.port.tick_and_pass_us = 46;
    servo.regs.user.baud_index = 8; /* 1 Mbaud */
    servo.link_settings_pending = 1;
    harness_poll(1);
    request_length = make_request(request, PKT_SYNC_COMMAND, round_of_six, sizeof round_of_six);
    /* Just after a tick: none falls due in the request's 150 us. */
    hal.now_us = servo.next_tick_us;
    harness_poll(1);
    hal_double_clear_sent(&hal);
    return 0;
}

/* Dispatched once, in the pass that frames the checksum, which sends it:
 * the bytes on the wire are the whole answer. */
static void test_the_first_answer_leaves_with_the_checksum(void **state)
{
    (void)state;
    uint32_t heard = servo.dispatcher.heard;
    feed_at_1mbaud(request, request_length - 1u);
    assert_int_equal(servo.dispatcher.heard, heard); /* nothing before the end */
    EXPECT_SILENCE();
    feed_at_1mbaud(&request[request_length - 1u], 1);
    assert_int_equal(servo.dispatcher.heard, heard + 1u);
    assert_true(servo.tx.sending);
    const uint8_t *sent = hal.sent;
    assert_int_equal(hal.sends, 1u);
    assert_int_equal(hal.sent_length, 4u + 16u + 1u); /* Monitor's 16 bytes */
    assert_int_equal(sent[0], 0x05);
    assert_int_equal(sent[1], 0x1C);
    assert_int_equal(sent[2], PKT_MONITOR);
    assert_int_equal(sent[3], 16);
    assert_int_equal(sent[4], 0); /* this servo's ID */
    assert_int_equal(sent[5] | sent[6] << 8, servo.regs.status.voltage_mv);
    /* Header and ID were in place when the UART took the frame. */
    assert_memory_equal(hal.head_at_send, sent, sizeof hal.head_at_send);
    uint8_t sum = 0;
    for (size_t i = 0; i + 1u < hal.sent_length; i++) {
        sum = (uint8_t)(sum + sent[i]);
    }
    assert_int_equal(sent[hal.sent_length - 1u], sum);
}

/* A request whose checksum fails is never answered, and the next one is. */
static void test_a_request_with_a_bad_checksum_is_not_answered(void **state)
{
    (void)state;
    feed_at_1mbaud(request, request_length - 1u);
    uint8_t bad = (uint8_t)(request[request_length - 1u] + 1u);
    feed_at_1mbaud(&bad, 1);
    harness_poll(2);
    EXPECT_SILENCE();
    REQUEST(PKT_PING, 0);
    EXPECT_RESPONSE(PKT_PING, 0);
}

/* Nor that of a request the line's quiet cut short. */
static void test_a_cut_request_is_not_answered(void **state)
{
    (void)state;
    feed_at_1mbaud(request, request_length - 1u);
    hal.now_us += 2000u; /* the idle timeout (1 ms at least) */
    harness_poll(2);
    EXPECT_SILENCE();
    REQUEST(PKT_PING, 0);
    EXPECT_RESPONSE(PKT_PING, 0);
}

/* A tick that falls due 3 byte times before the request ends waits: the
 * answer leaves as the checksum is framed, the tick in the next pass, on
 * its schedule. */
static void test_a_tick_waits_for_a_request_about_to_end(void **state)
{
    (void)state;
    hal.now_us = servo.next_tick_us - 10u * (request_length - 3u) - 1u;
    feed_at_1mbaud(request, request_length - 3u);
    uint32_t due = servo.next_tick_us;
    assert_true((int32_t)(hal.now_us - due) < 0);
    hal.now_us = due;
    harness_poll(1);
    assert_int_equal(servo.next_tick_us, due); /* held */
    feed_at_1mbaud(&request[request_length - 3u], 2);
    assert_int_equal(servo.next_tick_us, due);
    EXPECT_SILENCE();
    hal.now_us += 10u;
    servo_on_rx_byte(&servo, request[request_length - 1u], hal.now_us);
    harness_poll(1);
    assert_int_equal(hal.sent_length, 21);
    assert_int_equal(servo.next_tick_us, due);
    harness_poll(1);
    assert_int_equal(servo.next_tick_us, due + CONTROL_TICK_US);
}

/* The cases around the send ahead: listed twice, it answers once, as
 * listed first; a Monitor record of another length, or a round that does
 * not list it, sends nothing (the send ahead takes only what the full
 * dispatch answers). */
static void feed_round(const uint8_t *content, size_t n)
{
    request_length = make_request(request, PKT_SYNC_COMMAND, content, n);
    feed_at_1mbaud(request, request_length);
    harness_run_ms(20); /* every turn passes */
}

static void test_the_send_ahead_answers_only_what_a_dispatch_does(void **state)
{
    (void)state;
    static const uint8_t twice[] = {22, 1, 3, 0, 5, 0};
    feed_round(twice, sizeof twice);
    assert_int_equal(hal.sends, 1u);
    assert_int_equal(hal.sent_length, 4u + 16u + 1u);
    assert_memory_equal(hal.head_at_send, hal.sent, sizeof hal.head_at_send);
    hal_double_clear_sent(&hal);
    static const uint8_t longer[] = {22, 2, 2, 0, 0, 5, 0};
    feed_round(longer, sizeof longer);
    assert_int_equal(hal.sends, 0u);
    assert_true(servo.regs.status.status & STATUS_COMMAND_ERROR);
    static const uint8_t others[] = {22, 1, 2, 5, 6};
    feed_round(others, sizeof others);
    assert_int_equal(hal.sends, 0u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_the_first_answer_leaves_with_the_checksum, setup),
        cmocka_unit_test_setup(test_a_request_with_a_bad_checksum_is_not_answered, setup),
        cmocka_unit_test_setup(test_a_cut_request_is_not_answered, setup),
        cmocka_unit_test_setup(test_a_tick_waits_for_a_request_about_to_end, setup),
        cmocka_unit_test_setup(test_the_send_ahead_answers_only_what_a_dispatch_does, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
