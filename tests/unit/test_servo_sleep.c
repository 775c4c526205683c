/* When the main loop may sleep until the next interrupt (servo_may_sleep):
 * only when a pass has nothing left to do before one comes. A wrong "yes"
 * is a late answer or a late tick on the board; a wrong "no" is a CPU that
 * never sleeps. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "support/by_name.h"
#include "support/servo_harness.h"

static int setup(void **state)
{
    (void)state;
    harness_init();
    harness_run_ms(5); /* power-up work done, ticks on schedule */
    return 0;
}

/* Just after a tick's pass: nothing until the next tick. */
static void settle(void)
{
    hal.now_us += 10u;
    harness_poll(2);
}

static void test_an_idle_servo_sleeps_until_its_tick_is_due(void **state)
{
    (void)state;
    settle();
    assert_true(servo_may_sleep(&servo));
    hal.now_us = servo.next_tick_us;
    assert_false(servo_may_sleep(&servo));
}

static void test_bytes_not_yet_framed_keep_it_awake(void **state)
{
    (void)state;
    settle();
    servo_on_rx_byte(&servo, 0x12, hal.now_us);
    assert_false(servo_may_sleep(&servo));
}

/* Half a request framed: the loop stays awake to frame the rest as it
 * lands (the DMA would not wake it), and does so while the line is in use;
 * after SERVO_AWAKE_AFTER_LINE_US of quiet it sleeps again, and a request
 * then is framed when the line going idle after it wakes the loop. */
static void test_a_line_in_use_keeps_it_awake(void **state)
{
    (void)state;
    settle();
    const uint8_t half[] = {0x12, 0x4C, 0x01};
    harness_feed(half, sizeof half);
    harness_poll(1);
    assert_true(frame_rx_in_frame(&servo.rx));
    assert_false(servo_may_sleep(&servo));
    uint32_t heard = hal.now_us;
    for (;;) {
        harness_run_ms(1);
        settle(); /* 1010 us on */
        if (hal.now_us - heard >= SERVO_AWAKE_AFTER_LINE_US) {
            break;
        }
        assert_false(servo_may_sleep(&servo));
    }
    assert_true(servo_may_sleep(&servo));
}

static void test_an_answer_that_has_left_unnoticed_keeps_it_awake(void **state)
{
    (void)state;
    settle();
    hal.tx_busy = true;
    REQUEST(PKT_PING, 0); /* Ping (the harness servo holds the factory ID 0) */
    assert_true(servo.tx.sending);
    harness_run_ms(SERVO_AWAKE_AFTER_LINE_US / 1000u); /* the line quiet since */
    settle();
    assert_true(servo.tx.sending);
    assert_true(servo_may_sleep(&servo)); /* the end of the answer is an interrupt */
    hal.tx_busy = false;
    assert_false(servo_may_sleep(&servo));
    harness_poll(1);
    assert_false(servo.tx.sending);
}

static void test_a_sync_monitor_turn_keeps_it_awake(void **state)
{
    (void)state;
    settle();
    const uint8_t sync[] = {22, 1, 2, 5, 0}; /* after servo 5 */
    harness_request(PKT_SYNC_COMMAND, sync, sizeof sync);
    assert_true(servo.tx.waiting);
    assert_false(servo_may_sleep(&servo));
}

static void test_a_new_link_setting_keeps_it_awake_until_applied(void **state)
{
    (void)state;
    settle();
    hal.tx_busy = true;
    WRITE_ITEM(0, ITEM_BAUD_INDEX, 4); /* WriteData: baud index 4, applied once the answer has left */
    assert_true(servo.link_settings_pending);
    assert_false(servo_may_sleep(&servo));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_an_idle_servo_sleeps_until_its_tick_is_due, setup),
        cmocka_unit_test_setup(test_bytes_not_yet_framed_keep_it_awake, setup),
        cmocka_unit_test_setup(test_a_line_in_use_keeps_it_awake, setup),
        cmocka_unit_test_setup(test_an_answer_that_has_left_unnoticed_keeps_it_awake, setup),
        cmocka_unit_test_setup(test_a_sync_monitor_turn_keeps_it_awake, setup),
        cmocka_unit_test_setup(test_a_new_link_setting_keeps_it_awake_until_applied, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
