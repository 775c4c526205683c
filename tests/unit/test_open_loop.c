/* Open loop (DriveDuty, 0x46) on the servo core closed around the plant:
 * the bridge holds the duty it was given, the horn reaches the speed the
 * plant's physics give that duty, the output is released when the time is
 * up, the current limit clips the duty (and ReadMotion says by how much),
 * and any other motion command takes over. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#include "support/by_name.h"
#include "support/plant_harness.h"

#define DUTY(q15, ms) \
    REQUEST(PKT_DRIVE_DUTY, 0, (uint8_t)((q15) & 0xFF), (uint8_t)((uint16_t)(q15) >> 8), (uint8_t)((ms) & 0xFF), \
            (uint8_t)((ms) >> 8))

static int32_t motion_field(size_t offset, size_t size, int is_signed)
{
    REQUEST(PKT_READ_MOTION, 0);
    return ANSWER_FIELD(PKT_READ_MOTION, offset, size, is_signed);
}

/* The output's steady speed (rad/s) at duty d, from the plant's equations:
 * K V d / R = (K^2 / R + B) w + C at the output (K = kt n). */
static double steady_speed(double d)
{
    const struct plant_params *p = &plant.p;
    double k = p->kt * p->gear_ratio;
    double drag_b = p->drag_viscous * p->gear_ratio * p->gear_ratio;
    double drag_c = p->drag_coulomb * p->gear_ratio;
    return (k * p->supply_v * d / p->resistance_ohm - drag_c) / (k * k / p->resistance_ohm + drag_b);
}

static void test_the_duty_drives_the_horn_open_loop_then_lets_go(void **state)
{
    (void)state;
    DUTY(9830, 300); /* 0.3 of the supply */
    harness_run_ms(250);
    double w = plant.velocity;
    printf("# duty 0.3: %.1f deg/s, the plant's steady speed %.1f deg/s\n", w * 180 / M_PI,
           steady_speed(9830 / 32767.0) * 180 / M_PI);
    assert_true(fabs(w / steady_speed(9830 / 32767.0) - 1.0) < 0.02);
    assert_int_equal(motion_field(ANSWER_READ_MOTION_DUTY), 9830);
    assert_int_equal(servo.motion.mode, MODE_OPEN_LOOP); /* driven */
    harness_run_ms(44); /* 300 ms, to within the request's own time on the wire */
    assert_int_equal(servo.motion.mode, MODE_OPEN_LOOP);
    harness_run_ms(10);
    assert_int_equal(servo.motion.mode, MODE_RELEASED);
    assert_int_equal(motion_field(ANSWER_READ_MOTION_DUTY), 0);
}

/* From rest, full duty asks more current than item 42's 10 W allows at
 * 7.4 V: the bridge gets the current limit's duty, P R / V^2 = 0.50, and
 * ReadMotion reports that one, so a host fits what the motor saw. */
static void test_the_current_limit_clips_the_duty_and_says_so(void **state)
{
    (void)state;
    DUTY(-32767, 100);
    harness_run_ms(2);
    int32_t given = motion_field(ANSWER_READ_MOTION_DUTY);
    printf("# full duty from rest: %d given\n", given);
    assert_true(given < -15000 && given > -18000);
    assert_true(plant.velocity < 0.0);
}

static void test_another_command_takes_over(void **state)
{
    (void)state;
    DUTY(9830, 5000);
    harness_run_ms(100);
    REQUEST(PKT_MOVE_ANGLE_BY_INTERVAL, 0, 0x00, 0x00, 0xF4, 0x01, 0x64, 0x00, 0x64, 0x00, 0x00, 0x00);
    harness_run_ms(1500);
    assert_int_equal(servo.motion.mode, MODE_POSITION);
    assert_int_equal(servo.motion.open_ticks, 0);
    assert_true(fabs(plant_angle_deg(&plant)) < 0.2);
    /* Damping (packet 9) after open loop brakes again: no duty is left over. */
    DUTY(9830, 5000);
    harness_run_ms(100);
    REQUEST(PKT_MOVE_DAMPING, 0, 0x00, 0x00);
    harness_run_ms(300);
    assert_true(fabs(plant.velocity) < 0.01);
    assert_int_equal(servo.motion.open_duty_q15, 0);
}

static void test_out_of_range_is_refused(void **state)
{
    (void)state;
    DUTY(9830, 0);
    DUTY(9830, 10001);
    DUTY(0, 100);
    harness_run_ms(50);
    assert_int_equal(servo.motion.mode, MODE_RELEASED);
    assert_true(fabs(plant.velocity) < 1e-9);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_the_duty_drives_the_horn_open_loop_then_lets_go, plant_harness_setup),
        cmocka_unit_test_setup(test_the_current_limit_clips_the_duty_and_says_so, plant_harness_setup),
        cmocka_unit_test_setup(test_another_command_takes_over, plant_harness_setup),
        cmocka_unit_test_setup(test_out_of_range_is_refused, plant_harness_setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
