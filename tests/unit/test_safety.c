/* The servo when its host is not there: the bus watchdog (items 64, 65),
 * what holds the output back (item 67, ReadMotion bits 5-7) and the
 * winding's estimate and derating (item 68), through the whole servo core,
 * request bytes in. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "registers/faults.h"
#include "support/by_name.h"
#include "support/servo_harness.h"

static int setup(void **state)
{
    (void)state;
    harness_init();
    harness_ideal_tracking();
    WRITE_ITEM(0, ITEM_SOFT_START_ON, 0);
    harness_run_ms(20);
    return 0;
}

static void move_to_90(void)
{
    REQUEST(PKT_MOVE_ANGLE, 0, 0x84, 0x03, 0x64, 0x00, 0x00, 0x00); /* 90.0 in 100 ms */
}

static int32_t read_item(enum data_item_id item)
{
    REQUEST(PKT_READ_DATA, 0, (uint8_t)item);
    assert_true(hal.sent_length >= 8u);
    return ANSWER_FIELD(PKT_READ_DATA, 2, hal.sent_length - 7u, item == ITEM_WINDING_DECIC);
}

/* Silent ticks until the output is let go, from the last frame. */
static uint32_t ms_until_released(uint32_t most)
{
    for (uint32_t ms = 0; ms <= most; ms++) {
        if (hal.coasting) {
            return ms;
        }
        harness_run_ms(1);
    }
    return most + 1u;
}

static void test_off_by_default_the_servo_holds_whatever_the_silence(void **state)
{
    (void)state;
    assert_int_equal(read_item(ITEM_WATCHDOG_MS), 0);
    move_to_90();
    harness_run_ms(3000);
    assert_false(hal.coasting);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_NONE);
}

static void test_release_within_two_ticks_of_the_timeout(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_WATCHDOG_MS, 100);
    WRITE_ITEM(0, ITEM_WATCHDOG_ACTION, 2);
    move_to_90(); /* the last frame */
    harness_run_ms(10);
    assert_false(hal.coasting);
    uint32_t ms = 10u + ms_until_released(200);
    print_message("# released %u ms after the last frame (watchdog 100 ms)\n", (unsigned)ms);
    assert_true(ms >= 99u && ms <= 102u);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_WATCHDOG);
    /* Reads feed it but do not clear it; the next motion command does. */
    move_to_90();
    harness_run_ms(50);
    assert_false(hal.coasting);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_NONE);
}

static void test_frames_for_other_servos_do_not_feed_it(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_WATCHDOG_MS, 100);
    WRITE_ITEM(0, ITEM_WATCHDOG_ACTION, 2);
    move_to_90();
    for (int i = 0; i < 6; i++) { /* a ping to servo 5 every 30 ms */
        harness_run_ms(30);
        REQUEST(PKT_PING, 5);
    }
    assert_true(hal.coasting);
    /* A broadcast and a SyncCommand record for this servo do feed it. */
    move_to_90();
    for (int i = 0; i < 3; i++) {
        harness_run_ms(60);
        REQUEST(PKT_STOP_ON_CONTROL_MODE, 0xFF, 0x11, 0, 0); /* broadcast hold */
    }
    for (int i = 0; i < 3; i++) {
        harness_run_ms(60);
        const uint8_t sync[] = {8, 7, 2, 5, 0, 0, 0, 0, 0, 0, 0, 0x84, 0x03, 0x00, 0x00, 0x00, 0x00};
        harness_request(PKT_SYNC_COMMAND, sync, sizeof sync);
    }
    assert_false(hal.coasting);
    /* One naming only servo 5 does not. */
    const uint8_t other[] = {8, 7, 1, 5, 0, 0, 0, 0, 0, 0};
    for (int i = 0; i < 3; i++) {
        harness_run_ms(40);
        harness_request(PKT_SYNC_COMMAND, other, sizeof other);
    }
    assert_true(hal.coasting);
}

static void test_hold_and_damp_keep_the_output_driven(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_WATCHDOG_MS, 50);
    WRITE_ITEM(0, ITEM_WATCHDOG_ACTION, 0); /* hold */
    move_to_90();
    harness_run_ms(20); /* mid-move */
    harness_run_ms(100);
    assert_false(hal.coasting);
    assert_true(servo.motion.mode == MODE_POSITION);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_WATCHDOG);
    REQUEST(PKT_READ_MOTION, 0);
    assert_int_equal(ANSWER_FIELD(PKT_READ_MOTION, ANSWER_READ_MOTION_MOTION_FLAGS) >> LIMITER_SHIFT,
                     LIMITER_WATCHDOG);
    WRITE_ITEM(0, ITEM_WATCHDOG_ACTION, 1); /* damp */
    move_to_90();
    harness_run_ms(100);
    assert_true(servo.motion.mode == MODE_DAMPING);
    assert_false(hal.coasting);
}

static void test_the_watchdog_items_live_in_ram(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_WATCHDOG_MS, 250);
    REQUEST(PKT_READ_BATCH_DATA, 0);
    assert_int_equal(hal.sent_length, 5u + 1u + USER_AREA_SIZE); /* the batch is the maker's */
    harness_restart();
    harness_run_ms(5);
    assert_int_equal(read_item(ITEM_WATCHDOG_MS), 0);
    assert_int_equal(read_item(ITEM_WATCHDOG_ACTION), 1);
    REQUEST(PKT_WRITE_DATA, 0, ITEM_WATCHDOG_ACTION, 3); /* out of range */
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_WATCHDOG_ACTION, 0);
    REQUEST(PKT_WRITE_DATA, 0, ITEM_LIMITER, 0); /* read-only */
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_LIMITER, 0);
}

static void test_the_limiter_names_a_clamped_angle_the_supply_and_heat(void **state)
{
    (void)state;
    REQUEST(PKT_MOVE_ANGLE, 0, 0x08, 0x07, 0x64, 0x00, 0x00, 0x00); /* 180.0, past 51 = 135 */
    harness_run_ms(200);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_ANGLE);
    hal.sensors.supply = 3500;
    harness_run_ms(60);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_SUPPLY);
    hal.sensors.supply = 7400;
    hal.sensors.ntc = 600;
    harness_run_ms(200);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_HEAT);
}

static void test_a_hot_case_derates_the_power_limit(void **state)
{
    (void)state;
    move_to_90();
    harness_run_ms(200);
    assert_int_equal(servo.heat_cap_mw, 0);
    hal.sensors.ntc = 720; /* about 71 degC: 4.4 below 41's 75.4 */
    harness_run_ms(300);
    assert_true(servo.heat_cap_mw > 0u && servo.heat_cap_mw < 10000u);
    assert_int_equal(servo.motion.power_cap_mw, servo.heat_cap_mw);
    assert_int_equal(servo.motion.cap_limiter, LIMITER_HEAT);
    int32_t winding = read_item(ITEM_WINDING_DECIC);
    print_message("# case at NTC 720: cap %u mW, winding %.1f degC\n", servo.heat_cap_mw, winding / 10.0);
    assert_true(winding > 690 && winding < 730);
    WRITE_ITEM(0, ITEM_DERATING_ON, 0); /* the maker's behaviour: full power until 41 trips */
    harness_run_ms(200);
    assert_int_equal(servo.motion.power_cap_mw, 0);
    WRITE_ITEM(0, ITEM_DERATING_ON, 1);
    harness_run_ms(200);
    assert_int_equal(servo.motion.power_cap_mw, servo.heat_cap_mw);
    hal.sensors.ntc = 2048;
    harness_run_ms(300);
    assert_int_equal(servo.heat_cap_mw, 0);
    assert_int_equal(servo.motion.power_cap_mw, 0);
}

/* The fault history through the servo: a trip is logged with its
 * readings, kept across a power cycle, and cleared. */
static void test_faults_are_logged_kept_and_cleared(void **state)
{
    (void)state;
    move_to_90();
    harness_run_ms(200);
    hal.sensors.supply = 3500; /* below 39 */
    harness_run_ms(100);
    hal.sensors.supply = 7400;
    harness_run_ms(400);
    WRITE_ITEM(0, ITEM_WATCHDOG_MS, 20);
    WRITE_ITEM(0, ITEM_WATCHDOG_ACTION, 2);
    move_to_90();
    harness_run_ms(200); /* the watchdog */
    REQUEST(PKT_READ_FAULTS, 0, 0);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_COUNT), 2);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_WHAT), FAULT_WATCHDOG);
    harness_restart();
    harness_run_ms(5);
    REQUEST(PKT_READ_FAULTS, 0, 1);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_COUNT), 2);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_WHAT), FAULT_LOW_VOLTAGE);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_NUMBER), 1);
    int32_t mv = ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_VOLTAGE);
    assert_true(mv < 4000);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_ANGLE), 900);
    REQUEST(PKT_READ_FAULTS, 0, 2); /* beyond the count */
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_WHAT), 0);
    REQUEST(PKT_CLEAR_FAULTS, 0);
    EXPECT_RESPONSE(PKT_CLEAR_FAULTS, 0, 1);
    harness_run_ms(50);
    harness_restart();
    harness_run_ms(5);
    REQUEST(PKT_READ_FAULTS, 0, 0);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_COUNT), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_off_by_default_the_servo_holds_whatever_the_silence, setup),
        cmocka_unit_test_setup(test_release_within_two_ticks_of_the_timeout, setup),
        cmocka_unit_test_setup(test_frames_for_other_servos_do_not_feed_it, setup),
        cmocka_unit_test_setup(test_hold_and_damp_keep_the_output_driven, setup),
        cmocka_unit_test_setup(test_the_watchdog_items_live_in_ram, setup),
        cmocka_unit_test_setup(test_the_limiter_names_a_clamped_angle_the_supply_and_heat, setup),
        cmocka_unit_test_setup(test_a_hot_case_derates_the_power_limit, setup),
        cmocka_unit_test_setup(test_faults_are_logged_kept_and_cleared, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
