/* What servobus refuses and how it says so: a stream's and a loop's
 * period (item 69's range, the wire's cycle). */
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
    fake_init(&fake, 115200);
    sb_bus_init(&bus, fake_transport(&fake), 115200);
    return 0;
}

static const char *words(sb_error e)
{
    static char text[240];
    sb_error_text(&e, text, sizeof text);
    return text;
}

/* 1..1000 ms: item 69's range but for its 0 (off), as servoctl's Stream. */
static void a_stream_s_period_is_item_69_s(void **state)
{
    uint8_t ids[1] = {1};
    sb_stream s;
    sb_error e = sb_stream_init(&s, ids, 1, 1001);
    assert_int_equal(e.status, SB_E_USAGE);
    assert_string_equal(words(e), "StreamSetpoint: period_ms not allowed: 1001 is beyond 1..1000");
    assert_int_equal(sb_stream_init(&s, ids, 1, 65535).status, SB_E_USAGE);
    assert_string_equal(words(sb_stream_init(&s, ids, 1, 0)),
                        "StreamSetpoint: period_ms not allowed: 0 is beyond 1..1000");
    assert_int_equal(sb_stream_init(&s, ids, 1, 1000).status, SB_OK);
    assert_int_equal(sb_stream_init(&s, ids, 1, 1).status, SB_OK);
}

/* A loop's period shorter than its cycle's bytes at the bus's baud rate. */
static void a_loop_s_period_holds_its_cycle_on_the_wire(void **state)
{
    uint8_t ids[6] = {1, 2, 3, 4, 5, 6};
    sb_loop loop;
    /* as servoctl's check_wire: 1000 / wire_limit_hz ms, rounded up to a ms */
    int64_t least = (int64_t)((sb_cycle_bytes(1) * 10u * 1000u + 115199u) / 115200u);
    sb_error e = sb_loop_init(&loop, &bus, ids, 1, 1);
    assert_int_equal(e.status, SB_E_USAGE);
    assert_int_equal(e.least, least);
    assert_true(least > 1);
    assert_non_null(strstr(words(e), "StreamSetpoint: period_ms not allowed: 1 ms is shorter than the wire's cycle"));
    assert_int_equal(sb_loop_init(&loop, &bus, ids, 1, (uint16_t)(least - 1)).status, SB_E_USAGE);
    assert_int_equal(sb_loop_init(&loop, &bus, ids, 1, (uint16_t)least).status, SB_OK);
    /* six servos at 115200: 202 bytes, 17.5 ms (docs/streaming.md's 57.0 Hz) */
    assert_int_equal(sb_loop_init(&loop, &bus, ids, 6, 17).status, SB_E_USAGE);
    assert_int_equal(sb_loop_init(&loop, &bus, ids, 6, 18).status, SB_OK);
    bus.baud = 0; /* no wire to pace by */
    e = sb_loop_init(&loop, &bus, ids, 1, 20);
    assert_int_equal(e.status, SB_E_USAGE);
    assert_string_equal(e.field, "baud");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(a_stream_s_period_is_item_69_s, set_up),
        cmocka_unit_test_setup(a_loop_s_period_holds_its_cycle_on_the_wire, set_up),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
