/* The servo when its host is not there: the bus watchdog (items 64, 65),
 * what holds the output back (item 67, ReadMotion bits 5-7) and the
 * winding's estimate and derating (item 68), through the whole servo core,
 * request bytes in; what counts as driven (DriveDuty does, damping does
 * not), the fault history's promises on a full page, and the operating
 * time across power cycles. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "registers/byte_order.h"
#include "storage/fault_record.h"
#include "runtime/crc32.h"
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
    assert_int_equal(servo.safety.heat_cap_mw, 0);
    hal.sensors.ntc = 720; /* about 71 degC: 4.4 below 41's 75.4 */
    harness_run_ms(300);
    assert_true(servo.safety.heat_cap_mw > 0u && servo.safety.heat_cap_mw < 10000u);
    assert_int_equal(servo.motion.power_cap_mw, servo.safety.heat_cap_mw);
    assert_int_equal(servo.motion.cap_limiter, LIMITER_HEAT);
    int32_t winding = read_item(ITEM_WINDING_DECIC);
    print_message("# case at NTC 720: cap %u mW, winding %.1f degC\n", servo.safety.heat_cap_mw, winding / 10.0);
    assert_true(winding > 690 && winding < 730);
    WRITE_ITEM(0, ITEM_DERATING_ON, 0); /* the maker's behaviour: full power until 41 trips */
    harness_run_ms(200);
    assert_int_equal(servo.motion.power_cap_mw, 0);
    WRITE_ITEM(0, ITEM_DERATING_ON, 1);
    harness_run_ms(200);
    assert_int_equal(servo.motion.power_cap_mw, servo.safety.heat_cap_mw);
    hal.sensors.ntc = 2048;
    harness_run_ms(300);
    assert_int_equal(servo.safety.heat_cap_mw, 0);
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

#define DUTY(q15, ms)                                                                                      \
    REQUEST(PKT_DRIVE_DUTY, 0, (uint8_t)((q15) & 0xFF), (uint8_t)((uint16_t)(q15) >> 8), (uint8_t)((ms) & 0xFF), \
            (uint8_t)((ms) >> 8))

static uint8_t motion_flags(void)
{
    REQUEST(PKT_READ_MOTION, 0);
    return (uint8_t)ANSWER_FIELD(PKT_READ_MOTION, ANSWER_READ_MOTION_MOTION_FLAGS);
}

static bool command_error(void)
{
    return (servo.regs.status.status & STATUS_COMMAND_ERROR) != 0u;
}

/* DriveDuty drives the bridge: ReadMotion does not call it released, the
 * origin stays put, and the watchdog lets it go within two ticks of its
 * time (a host that died mid-identify had left the motor driven for up
 * to 10 s). */
static void test_an_applied_duty_is_driven_and_watched(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_WATCHDOG_MS, 100);
    WRITE_ITEM(0, ITEM_WATCHDOG_ACTION, 0); /* hold */
    DUTY(9830, 10000);
    harness_run_ms(5);
    assert_int_equal(motion_flags() & DIAG_RELEASED, 0);
    REQUEST(PKT_SET_ORIGIN_POINT, 0, 0);
    assert_true(command_error());
    REQUEST(PKT_RESET_MULTI_TURN_ANGLE, 0);
    assert_true(command_error());
    harness_run_ms(60);
    assert_int_equal(hal.duty, 9830); /* fed: still driven */
    DUTY(9830, 10000); /* the last frame */
    uint32_t ms = 0;
    while (servo.motion.open_ticks != 0u && ms < 300u) {
        harness_run_ms(1);
        ms++;
    }
    print_message("# the duty stopped %u ms after the last frame (watchdog 100 ms)\n", (unsigned)ms);
    assert_true(ms >= 99u && ms <= 102u);
    assert_true(servo.motion.mode == MODE_POSITION); /* hold */
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_WATCHDOG);
    harness_run_ms(30); /* the fault's record */
    REQUEST(PKT_READ_FAULTS, 0, 0);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_WHAT), FAULT_WATCHDOG);
    /* Released by the time's end, it is released again. */
    DUTY(9830, 20);
    harness_run_ms(30);
    assert_true(hal.coasting);
    assert_int_equal(motion_flags() & DIAG_RELEASED, DIAG_RELEASED);
    REQUEST(PKT_SET_ORIGIN_POINT, 0, 0);
    assert_false(command_error());
}

/* Damping (packet 9) only resists motion: it counts as released (the
 * watchdog leaves it be, the origin may move), as before (docs/safety.md). */
static void test_damping_is_released_and_left_alone(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_WATCHDOG_MS, 50);
    WRITE_ITEM(0, ITEM_WATCHDOG_ACTION, 2); /* release */
    REQUEST(PKT_MOVE_DAMPING, 0, 0, 0);
    harness_run_ms(200);
    assert_true(servo.motion.mode == MODE_DAMPING);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_NONE);
    assert_int_equal(motion_flags() & DIAG_RELEASED, DIAG_RELEASED);
    REQUEST(PKT_SET_ORIGIN_POINT, 0, 0);
    assert_false(command_error());
}

/* A command the servo refuses is not a command the host is back with: the
 * watchdog's act stands (item 67 says so) until one is carried out. */
static void test_a_refused_command_leaves_the_watchdogs_act_standing(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_WATCHDOG_MS, 50);
    WRITE_ITEM(0, ITEM_WATCHDOG_ACTION, 2);
    move_to_90();
    harness_run_ms(100);
    assert_true(hal.coasting);
    DUTY(0, 100); /* refused: no duty */
    harness_run_ms(5);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_WATCHDOG);
    hal.sensors.supply = 3500; /* below 39: motion is refused */
    harness_run_ms(60);
    move_to_90();
    harness_run_ms(5);
    assert_true(command_error());
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_WATCHDOG);
    hal.sensors.supply = 7400;
    harness_run_ms(600);
    move_to_90();
    harness_run_ms(20);
    assert_false(hal.coasting);
    assert_true(read_item(ITEM_LIMITER) != LIMITER_WATCHDOG);
}

/* The watchdog drops what a BeginAsync block buffered; moves sent for that
 * block after it acted are refused, not run at once, until the next
 * BeginAsync (or EndAsync). */
static void test_moves_for_a_block_the_watchdog_cut_do_not_run(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_WATCHDOG_MS, 50);
    WRITE_ITEM(0, ITEM_WATCHDOG_ACTION, 2);
    move_to_90();
    harness_run_ms(20);
    REQUEST(PKT_BEGIN_ASYNC);
    REQUEST(PKT_MOVE_ANGLE, 0, 0x2C, 0x01, 0x64, 0x00, 0x00, 0x00); /* 30.0, buffered */
    harness_run_ms(100);
    assert_true(hal.coasting); /* the watchdog */
    REQUEST(PKT_MOVE_ANGLE, 0, 0x58, 0x02, 0x64, 0x00, 0x00, 0x00); /* 60.0, for the cut block */
    assert_true(command_error());
    harness_run_ms(20);
    assert_true(hal.coasting);
    REQUEST(PKT_END_ASYNC, 0);
    harness_run_ms(20);
    assert_true(hal.coasting); /* nothing ran */
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_WATCHDOG);
    REQUEST(PKT_BEGIN_ASYNC); /* a new block works as ever */
    REQUEST(PKT_MOVE_ANGLE, 0, 0x58, 0x02, 0x64, 0x00, 0x00, 0x00);
    harness_run_ms(20);
    assert_true(hal.coasting);
    REQUEST(PKT_END_ASYNC, 0);
    harness_run_ms(20);
    assert_false(hal.coasting);
}

static int32_t read_store(size_t offset, size_t size, int is_signed)
{
    REQUEST(PKT_READ_STORE, 0);
    return ANSWER_FIELD(PKT_READ_STORE, offset, size, is_signed);
}

/* The operating time goes on across power cycles from the latest record
 * the servo wrote (a fault's here: no config save since), so fault times
 * do not go back, and a kind that trips again within 10 s of operation
 * after a power cycle is a repeat, as it would be without one. */
static void test_operating_time_and_repeats_go_on_across_power_cycles(void **state)
{
    (void)state;
    harness_run_ms(4000);
    hal.sensors.supply = 3500; /* below 39 */
    harness_run_ms(100);
    hal.sensors.supply = 7400;
    harness_run_ms(500);
    REQUEST(PKT_READ_FAULTS, 0, 0);
    int32_t first = ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_OPERATING_TIME);
    assert_true(first >= 4);
    harness_restart();
    harness_run_ms(5);
    assert_true(read_store(ANSWER_READ_STORE_OPERATING_TIME) >= first);
    hal.sensors.supply = 3500; /* again, within 10 s of operation */
    harness_run_ms(100);
    hal.sensors.supply = 7400;
    harness_run_ms(500);
    REQUEST(PKT_READ_FAULTS, 0, 0);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_COUNT), 1);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_NOT_LOGGED), 1);
    harness_run_ms(11000);
    hal.sensors.supply = 3500;
    harness_run_ms(100);
    hal.sensors.supply = 7400;
    harness_run_ms(500);
    REQUEST(PKT_READ_FAULTS, 0, 0);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_COUNT), 2);
    assert_true(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_OPERATING_TIME) >= first + 11);
}

/* One record of the history in the fault pages, as fault_log.c writes it. */
static void put_record(uint8_t page, uint8_t slot, uint32_t number, uint8_t what)
{
    uint8_t *rec = &hal.fault_flash.mem[page][slot * 32u];
    memset(rec, 0xFF, 32);
    le_put_u16(&rec[0], 0xFA17);
    rec[2] = 1;
    struct fault_entry e = {.number = number, .op_seconds = number, .voltage_mv = 7400, .what = what};
    memcpy(&rec[4], &e, FAULT_ENTRY_BYTES);
    le_put_u32(&rec[28], crc32(rec, 28));
}

/* Page 1 full of shown faults 1-32; page 0 in use, its slots but the last
 * spent (failed programs) and fault 40 in slot 30: one slot left, and the
 * spare still shows faults, so no erase is due at power-up. */
static void fill_the_history_but_a_slot(void)
{
    for (uint8_t i = 0; i < 32u; i++) {
        put_record(1, i, 1u + i, FAULT_STALL);
    }
    memset(hal.fault_flash.mem[0], 0x00, 30u * 32u);
    put_record(0, 30, 40, FAULT_OVER_POWER);
    harness_restart();
    WRITE_ITEM(0, ITEM_SOFT_START_ON, 0);
    harness_run_ms(5);
}

/* A page that fills while the output is driven waits for the erase (the
 * output released, the bus quiet): a ClearFaults then would wait with it,
 * so it is refused, and taken once the erase is done (it was
 * answered "done" and neither applied nor kept). A fault that comes while
 * it waits is kept and written after the erase. */
static void test_a_clear_on_a_full_page_while_driven_is_refused_then_taken(void **state)
{
    (void)state;
    fill_the_history_but_a_slot();
    REQUEST(PKT_READ_FAULTS, 0, 0);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_COUNT), 16);
    WRITE_ITEM(0, ITEM_WATCHDOG_MS, 20);
    WRITE_ITEM(0, ITEM_WATCHDOG_ACTION, 0); /* hold: driven all along */
    move_to_90();
    harness_run_ms(100); /* the watchdog: its fault fills the page */
    REQUEST(PKT_READ_FAULTS, 0, 0);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_WHAT), FAULT_WATCHDOG);
    REQUEST(PKT_CLEAR_FAULTS, 0);
    EXPECT_RESPONSE(PKT_CLEAR_FAULTS, 0, 0);
    hal.sensors.supply = 9000; /* high voltage: released, waits for the erase */
    harness_run_ms(60);
    hal.sensors.supply = 7400;
    harness_run_ms(20);
    REQUEST(PKT_CLEAR_FAULTS, 0);
    EXPECT_RESPONSE(PKT_CLEAR_FAULTS, 0, 0); /* the erase waits for a quiet bus */
    assert_true(servo.faults.pending_count == 1u);
    harness_run_ms(300); /* quiet: the spare is erased, the fault written */
    REQUEST(PKT_READ_FAULTS, 0, 0);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_WHAT), FAULT_HIGH_VOLTAGE);
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
        cmocka_unit_test_setup(test_an_applied_duty_is_driven_and_watched, setup),
        cmocka_unit_test_setup(test_damping_is_released_and_left_alone, setup),
        cmocka_unit_test_setup(test_a_refused_command_leaves_the_watchdogs_act_standing, setup),
        cmocka_unit_test_setup(test_moves_for_a_block_the_watchdog_cut_do_not_run, setup),
        cmocka_unit_test_setup(test_operating_time_and_repeats_go_on_across_power_cycles, setup),
        cmocka_unit_test_setup(test_a_clear_on_a_full_page_while_driven_is_refused_then_taken, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
