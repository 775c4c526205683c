/* servobus's rules across a request's fields, and of single fields the
 * schema's ranges do not say: what the servo would stretch, clamp or not
 * carry out is refused before anything is sent (sb_rules.c). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "servobus/servobus.h"

static void a_profile_the_servo_would_stretch_is_refused(void **state)
{
    uint8_t f[32];
    size_t len = 0;
    sb_move_angle_by_interval_request a = {1, 900, 199, 100, 100, 0};
    sb_error e = sb_encode_move_angle_by_interval(&a, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_RANGE);
    assert_string_equal(e.field, "interval");
    assert_int_equal(e.value, 199);
    assert_int_equal(e.least, 200); /* acc + dec */
    a.interval = 200;
    assert_int_equal(sb_encode_move_angle_by_interval(&a, f, sizeof f, &len).status, SB_OK);
    sb_move_multi_turn_by_interval_request m = {1, 36000, 39, 20, 20, 0};
    assert_int_equal(sb_encode_move_multi_turn_by_interval(&m, f, sizeof f, &len).status, SB_E_RANGE);
    m.interval = 40;
    assert_int_equal(sb_encode_move_multi_turn_by_interval(&m, f, sizeof f, &len).status, SB_OK);
    /* The plain moves ramp 20 ms each way: 40 ms at least. */
    sb_move_angle_request p = {1, 900, 39, 0};
    assert_int_equal(sb_encode_move_angle(&p, f, sizeof f, &len).status, SB_E_RANGE);
    sb_move_multi_turn_request pm = {1, 900, 39, 0};
    assert_int_equal(sb_encode_move_multi_turn(&pm, f, sizeof f, &len).status, SB_E_RANGE);
    /* A wheel run for a time shorter than its two 20 ms ramps. */
    sb_move_wheel_request w = {1, 3, 100, 39};
    e = sb_encode_move_wheel(&w, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_RANGE);
    assert_string_equal(e.field, "value");
    w.value = 40;
    assert_int_equal(sb_encode_move_wheel(&w, f, sizeof f, &len).status, SB_OK);
    w.method = 2; /* turns: any number */
    w.value = 1;
    assert_int_equal(sb_encode_move_wheel(&w, f, sizeof f, &len).status, SB_OK);
}

/* Values within their fields that the servo would clamp or not carry out:
 * a DriveDuty of 0 (refused) or -32768 (clamped), a wheel action the servo
 * takes as a stop, an UpdateWrite the bootloader drops unanswered. */

static void what_the_servo_would_change_or_drop_is_refused(void **state)
{
    uint8_t f[300];
    size_t len = 0;
    sb_drive_duty_request d = {1, 0, 100};
    sb_error e = sb_encode_drive_duty(&d, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_RANGE);
    assert_string_equal(e.field, "duty");
    d.duty = -32768;
    assert_int_equal(sb_encode_drive_duty(&d, f, sizeof f, &len).status, SB_E_RANGE);
    d.duty = -32767;
    assert_int_equal(sb_encode_drive_duty(&d, f, sizeof f, &len).status, SB_OK);
    sb_move_wheel_request w = {1, 0x84, 100, 1000};
    e = sb_encode_move_wheel(&w, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_RANGE);
    assert_string_equal(e.field, "method");
    assert_int_equal(e.value, 4);
    w.method = 0x81; /* run, clockwise */
    assert_int_equal(sb_encode_move_wheel(&w, f, sizeof f, &len).status, SB_OK);
    uint8_t data[260] = {0};
    sb_update_write_request u = {1, 0, data, 0, 0};
    assert_int_equal(sb_encode_update_write(&u, f, sizeof f, &len).status, SB_E_USAGE);
    u.data_len = 25;
    e = sb_encode_update_write(&u, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_USAGE);
    assert_int_equal(e.value, 25);
    assert_int_equal(e.most, 24);
    u.data_len = 24;
    assert_int_equal(sb_encode_update_write(&u, f, sizeof f, &len).status, SB_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(a_profile_the_servo_would_stretch_is_refused),
        cmocka_unit_test(what_the_servo_would_change_or_drop_is_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
