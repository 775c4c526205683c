/* Protection through the whole servo core, request bytes in, exact bytes
 * out: live status readings, faults releasing or limiting the output,
 * motion refused while a fault lasts, recovery. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "motion/controller.h"
#include "support/by_name.h"
#include "support/servo_harness.h"

static int setup(void **state)
{
    (void)state;
    harness_init();
    harness_ideal_tracking();
    WRITE_ITEM(0, ITEM_SOFT_START_ON, 0); /* no soft start */
    harness_run_ms(20);
    return 0;
}

static void test_status_area_is_live(void **state)
{
    (void)state;
    hal.sensors = (struct sensor_raw){.supply = 7800, .current = 650, .ntc = 1700};
    harness_run_ms(200); /* the low-passes settle (the supply's in 115 ms) */
    REQUEST(PKT_READ_DATA, 0, ITEM_VOLTAGE_MV);
    EXPECT_ITEM(0, ITEM_VOLTAGE_MV, 7800); /* 7800 mV */
    REQUEST(PKT_READ_DATA, 0, ITEM_CURRENT_MA);
    EXPECT_ITEM(0, ITEM_CURRENT_MA, 650); /* 650 mA */
    REQUEST(PKT_READ_DATA, 0, ITEM_POWER_MW);
    EXPECT_ITEM(0, ITEM_POWER_MW, 5070); /* 5070 mW */
    REQUEST(PKT_READ_DATA, 0, ITEM_TEMPERATURE_ADC);
    EXPECT_ITEM(0, ITEM_TEMPERATURE_ADC, 1700); /* NTC 1700 */
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_ITEM(0, ITEM_STATUS, 0);
}

static void test_low_voltage_releases_and_refuses_motion(void **state)
{
    (void)state;
    REQUEST(PKT_MOVE_ANGLE, 0, 0x84, 0x03, 0xC8, 0x00, 0x00, 0x00); /* 90.0 */
    harness_run_ms(300);
    assert_false(hal.coasting);
    hal.sensors.supply = 3500; /* below 39 = 4000 mV */
    harness_run_ms(60);
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_RESPONSE(PKT_READ_DATA, 0, ITEM_STATUS, STATUS_LOW_VOLTAGE);
    assert_true(hal.coasting);
    REQUEST(PKT_MOVE_ANGLE, 0, 0x00, 0x00, 0xC8, 0x00, 0x00, 0x00); /* refused */
    harness_run_ms(300);
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_RESPONSE(PKT_READ_DATA, 0, ITEM_STATUS, STATUS_LOW_VOLTAGE | STATUS_COMMAND_ERROR);
    REQUEST(PKT_READ_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_ANGLE, 0, 0x84, 0x03); /* it did not move */
    hal.sensors.supply = 7400;          /* recovered */
    harness_run_ms(200);
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_RESPONSE(PKT_READ_DATA, 0, ITEM_STATUS, STATUS_COMMAND_ERROR); /* until a command succeeds */
    assert_true(hal.coasting);                      /* and released until commanded */
    REQUEST(PKT_MOVE_ANGLE, 0, 0x00, 0x00, 0xC8, 0x00, 0x00, 0x00);
    harness_run_ms(300);
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_ITEM(0, ITEM_STATUS, 0);
    REQUEST(PKT_READ_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_ANGLE, 0, 0x00, 0x00);
}

static void test_high_voltage_and_heat_release(void **state)
{
    (void)state;
    hal.sensors.supply = 9000;
    harness_run_ms(60);
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_RESPONSE(PKT_READ_DATA, 0, ITEM_STATUS, STATUS_HIGH_VOLTAGE);
    hal.sensors.supply = 7400;
    hal.sensors.ntc = 600; /* hotter than 41 = 651 */
    harness_run_ms(200);
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_RESPONSE(PKT_READ_DATA, 0, ITEM_STATUS, STATUS_OVER_TEMPERATURE);
    REQUEST(PKT_MOVE_ANGLE, 0, 0x84, 0x03, 0xC8, 0x00, 0x00, 0x00);
    assert_true(hal.coasting);
    hal.sensors.ntc = 2048;
    harness_run_ms(300);
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_RESPONSE(PKT_READ_DATA, 0, ITEM_STATUS, STATUS_COMMAND_ERROR);
}

static void test_over_current_halves_the_output_while_moving(void **state)
{
    (void)state;
    REQUEST(PKT_MOVE_ANGLE, 0, 0x10, 0x27, 0xE8, 0x03, 0x00, 0x00); /* a long move */
    harness_run_ms(50);
    /* Factory: 42's 10 W binds before 43's 4 A (4 A x 2 ohm > the supply). */
    assert_int_equal(servo.motion.drive.duty_limit, duty_limit_for_power(10000, 7400, ITEM_RESISTANCE_MOHM_FACTORY));
    WRITE_ITEM(0, ITEM_CURRENT_LIMIT_MA, 1000); /* 43 = 1000 mA: now it binds */
    REQUEST(PKT_MOVE_ANGLE, 0, 0x10, 0x27, 0xE8, 0x03, 0x00, 0x00);
    int16_t normal = servo.motion.drive.duty_limit;
    assert_int_equal(normal, duty_limit_for_current(1000, 7400, ITEM_RESISTANCE_MOHM_FACTORY));
    assert_true(normal < duty_limit_for_power(10000, 7400, ITEM_RESISTANCE_MOHM_FACTORY));
    hal.sensors.current = 1200;
    harness_run_ms(60);
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_RESPONSE(PKT_READ_DATA, 0, ITEM_STATUS, STATUS_EXECUTING | STATUS_OVER_CURRENT);
    assert_int_equal(servo.motion.drive.duty_limit, normal / 2);
    assert_false(hal.coasting); /* limited, not released */
    hal.sensors.current = 300;
    harness_run_ms(200);
    assert_int_equal(servo.motion.drive.duty_limit, normal);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_status_area_is_live, setup),
        cmocka_unit_test_setup(test_low_voltage_releases_and_refuses_motion, setup),
        cmocka_unit_test_setup(test_high_voltage_and_heat_release, setup),
        cmocka_unit_test_setup(test_over_current_halves_the_output_while_moving, setup),
    };
    return cmocka_run_group_tests_name("protection_servo", tests, NULL, NULL);
}
