/* servobus on fake servos: a frame handed over sooner after the request
 * than its own bytes take on the wire is an earlier request's, not taken. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "tests/fake_servo.h"

static fake_bus fake;
static sb_bus bus;

static int set_up(void **state)
{
    fake_init(&fake, 1000000);
    sb_bus_init(&bus, fake_transport(&fake), 1000000);
    return 0;
}

/* A Monitor answer of id saying angle, appended to the fake's late bytes. */
static void late_monitor(uint8_t id, int32_t angle)
{
    sb_value v[8];
    size_t len = 0;
    memset(v, 0, sizeof v);
    v[0].n = id;
    v[1].n = 7400;
    v[6].n = angle;
    assert_int_equal(sb_encode_answer(SB_PKT_MONITOR, v, 8, fake.late + fake.late_len,
                                      sizeof fake.late - fake.late_len, &len).status, SB_OK);
    fake.late_len += len;
}

static void a_late_round_handed_over_too_early_is_dropped(void **state)
{
    uint8_t ids[3] = {1, 2, 3};
    sb_monitor_answer st[3];
    bool got[3];
    for (int k = 1; k <= 3; k++) {
        fake.present[k] = true;
        fake.setpoint[k] = 10 * k; /* what each servo answers */
    }
    /* the round before's answers, off the wire 20 us after this request's
     * end: sooner than their own bytes take */
    late_monitor(1, -999);
    late_monitor(2, -998);
    late_monitor(3, -997);
    fake.late_us = 20;
    assert_int_equal(sb_sync_monitor(&bus, ids, 3, st, got).status, SB_OK);
    for (int k = 0; k < 3; k++) {
        assert_true(got[k]);
        assert_int_equal(st[k].angle, 10 * (k + 1)); /* this round's */
    }
}

static void a_late_answer_to_the_call_before_is_dropped(void **state)
{
    sb_value v[2] = {{1, NULL, 0}, {111, NULL, 0}};
    size_t len = 0;
    sb_read_angle_request r = {1};
    sb_read_angle_answer a;
    fake.present[1] = true;
    /* the call before's answer, 111, handed over 50 us after the request's
     * end (its 11 bytes take 110 us); the servo's own answer comes after */
    assert_int_equal(sb_encode_answer(SB_PKT_READ_ANGLE, v, 2, fake.late, sizeof fake.late, &len).status, SB_OK);
    fake.late_len = len;
    fake.late_us = 50;
    assert_int_equal(sb_call_read_angle(&bus, &r, &a).status, SB_OK);
    assert_int_equal(a.angle, -123);
    /* one as late as its bytes allow could be this call's: taken */
    fake.late_len = len;
    fake.late_us = len * 10u;
    assert_int_equal(sb_call_read_angle(&bus, &r, &a).status, SB_OK);
    assert_int_equal(a.angle, 111);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(a_late_round_handed_over_too_early_is_dropped, set_up),
        cmocka_unit_test_setup(a_late_answer_to_the_call_before_is_dropped, set_up),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
