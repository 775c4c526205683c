/* servobus's bus on fake servos: a request's answer, the Sync Monitor with
 * a servo missing, the stream's checks, the robot loop, the UART callbacks. */
#include <errno.h>
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

static void a_call_returns_the_servos_answer(void **state)
{
    fake.present[3] = true;
    sb_read_angle_request r = {3};
    sb_read_angle_answer a;
    assert_int_equal(sb_call_read_angle(&bus, &r, &a).status, SB_OK);
    assert_int_equal(a.id, 3);
    assert_int_equal(a.angle, -123);
    sb_ping_request p = {4};
    sb_ping_answer pa;
    uint64_t before = fake.now_us;
    sb_error e = sb_call_ping(&bus, &p, &pa);
    assert_int_equal(e.status, SB_E_NO_ANSWER);
    assert_int_equal(e.servo, 4);
    assert_int_equal(e.packet, SB_PKT_PING);
    assert_true(fake.now_us - before >= bus.timeout_us); /* on the bus's clock */
    char text[120];
    sb_error_text(&e, text, sizeof text);
    assert_string_equal(text, "servo 4: Ping: no answer in time (is it on the bus, at this baud rate? "
                              "two servos at one ID garble each other)");
}

/* Each error says what was wrong: the list, the field, the value and the range. */
static void an_error_says_what_is_wrong(void **state)
{
    uint8_t ids[SB_MAX_SERVOS + 1], f[32];
    char text[160];
    size_t len = 0;
    sb_stream s;
    for (size_t k = 0; k < sizeof ids; k++)
        ids[k] = (uint8_t)k;
    sb_error e = sb_stream_init(&s, ids, SB_MAX_SERVOS + 1, 10);
    sb_error_text(&e, text, sizeof text);
    assert_string_equal(text, "StreamSetpoint: ids not allowed: 33 servos is beyond 1..32 (SB_MAX_SERVOS)");
    e = sb_stream_init(&s, ids, 0, 10);
    sb_error_text(&e, text, sizeof text);
    assert_string_equal(text, "StreamSetpoint: ids not allowed: 0 servos is beyond 1..32 (SB_MAX_SERVOS)");
    e = sb_sync_frame(SB_PKT_MONITOR, ids, 2, 1, f, sizeof f, &len);
    sb_error_text(&e, text, sizeof text);
    assert_string_equal(text, "SyncCommand: record_len not allowed: 2, not 1");
    e = sb_sync_frame(SB_PKT_PING, ids, 1, 1, f, sizeof f, &len);
    sb_error_text(&e, text, sizeof text);
    assert_string_equal(text, "SyncCommand: cmd not allowed: not a packet SyncCommand carries");
    e = sb_error_of(SB_E_BAD_ANSWER, 3, SB_PKT_READ_FAULTS, "count"); /* as sb_decode_answer fills it */
    e.value = 17;
    e.most = 16;
    sb_error_text(&e, text, sizeof text);
    assert_string_equal(text, "servo 3: ReadFaults: count a bad answer: 17 is beyond 0..16");
    e = sb_error_of(SB_E_BAD_ANSWER, 1, SB_PKT_READ_DATA, "data_id");
    e.value = 8;
    e.least = e.most = 1;
    sb_error_text(&e, text, sizeof text);
    assert_string_equal(text, "servo 1: ReadData: data_id a bad answer: 8, not 1");
    e = sb_error_of(SB_E_LINK, 1, SB_PKT_PING, NULL);
    e.os_error = EIO;
    sb_error_text(&e, text, sizeof text);
    assert_non_null(strstr(text, "servo 1: Ping: the link failed (errno 5: "));
    assert_non_null(strstr(text, strerror(EIO)));
    sb_read_data_request r = {1, 200};
    e = sb_encode_read_data(&r, f, sizeof f, &len);
    sb_error_text(&e, text, sizeof text);
    assert_string_equal(text, "servo 1: ReadData: data_id refused: no data item 200 in the schema");
}

static void a_bad_checksum_is_told(void **state)
{
    fake.present[3] = true;
    fake.garble_next = true;
    sb_ping_request p = {3};
    sb_ping_answer pa;
    sb_error e = sb_call_ping(&bus, &p, &pa);
    assert_int_equal(e.status, SB_E_BAD_CHECKSUM);
    assert_int_equal(e.servo, 3);
}

static void a_sync_monitor_names_the_servo_that_did_not_answer(void **state)
{
    uint8_t ids[3] = {1, 2, 3};
    sb_monitor_answer states[3];
    bool got[3];
    fake.present[1] = fake.present[3] = true;
    sb_error e = sb_sync_monitor(&bus, ids, 3, states, got);
    assert_int_equal(e.status, SB_E_NO_ANSWER);
    assert_int_equal(e.servo, 2);
    assert_int_equal(e.packet, SB_PKT_MONITOR);
    assert_true(got[0] && !got[1] && got[2]);
    assert_int_equal(states[2].id, 3);
    fake.present[2] = true;
    assert_int_equal(sb_sync_monitor(&bus, ids, 3, states, got).status, SB_OK);
}

static void the_robot_loop_sends_setpoints_and_reads_every_state(void **state)
{
    uint8_t ids[6] = {1, 2, 3, 4, 5, 6};
    int32_t angles[6] = {0, 10, 20, 30, 40, 50};
    sb_monitor_answer states[6];
    bool got[6];
    sb_loop loop;
    for (int k = 1; k <= 6; k++)
        fake.present[k] = true;
    assert_int_equal(sb_loop_init(&loop, &bus, ids, 6, 20).status, SB_OK);
    uint64_t third_us = 0;
    for (int c = 0; c < 3; c++) {
        for (int k = 0; k < 6; k++)
            angles[k] += 100;
        if (c == 2) {
            assert_true(sb_loop_rate_hz(&loop) > 0.5 * sb_wire_limit_hz(6, 1000000));
            fake.now_us += 37000u; /* the third cycle called late */
        }
        third_us = fake.now_us;
        assert_int_equal(sb_loop_cycle(&loop, angles, NULL, states, got).status, SB_OK);
    }
    assert_int_equal(loop.cycles, 3);
    assert_int_equal(loop.missed, 0);
    assert_int_equal(fake.setpoint_frames, 3);
    assert_int_equal(fake.setpoint[6], 350);
    assert_int_equal(fake.velocity[6], 5000); /* 10 deg in 20 ms */
    /* Stamped with the bus clock when called, not the grid's 40 ms. */
    assert_int_equal(fake.stamp[6], (third_us / 1000u) & 0xFFFFu);
    assert_true(fake.stamp[6] != 40);
    assert_int_equal(states[5].angle, 350);
}

/* The robot loop on six fake servos, all plugged in. */
static sb_loop six;
static int32_t six_angles[6];
static sb_monitor_answer six_states[6];
static bool six_got[6];

static void start_six(void)
{
    static const uint8_t ids[6] = {1, 2, 3, 4, 5, 6};
    for (int k = 1; k <= 6; k++)
        fake.present[k] = true;
    memset(six_angles, 0, sizeof six_angles);
    assert_int_equal(sb_loop_init(&six, &bus, ids, 6, 20).status, SB_OK);
}

/* A cycle of six, on the fake's clock: its status, and the microseconds it took. */
static uint64_t cycle_us(sb_error *e)
{
    uint64_t before = fake.now_us;
    for (int k = 0; k < 6; k++)
        six_angles[k] += 10;
    *e = sb_loop_cycle(&six, six_angles, NULL, six_states, six_got);
    return fake.now_us - before;
}

static void a_silent_servo_costs_one_slot_not_a_time_out(void **state)
{
    sb_error e;
    char text[120];
    /* the wire's cycle: both requests and six answers at 1 Mbaud (10 us a byte) */
    uint64_t wire = sb_cycle_bytes(6) * 10u, all, last_silent, mid_silent;
    start_six();
    assert_int_equal(bus.answer_margin_us, SB_ANSWER_MARGIN_US);
    all = cycle_us(&e);
    assert_int_equal(e.status, SB_OK);
    assert_true(all < wire + 200u);
    fake.present[6] = false; /* the last servo unplugged: every later cycle waits a slot for it, no more */
    for (int c = 0; c < 5; c++) {
        last_silent = cycle_us(&e);
        assert_int_equal(e.status, SB_E_NO_ANSWER);
        assert_int_equal(e.servo, 6);
        assert_int_equal(e.packet, SB_PKT_MONITOR);
        assert_true(six_got[0] && six_got[4] && !six_got[5]);
        assert_int_equal(six_states[4].angle, six_angles[4]);
        assert_true(last_silent <= all + SB_TURNAROUND_US + SB_ANSWER_MARGIN_US + 200u);
    }
    sb_error_text(&e, text, sizeof text);
    assert_string_equal(text, "servo 6: Monitor: no answer in time (is it on the bus, at this baud rate? "
                              "two servos at one ID garble each other)");
    fake.present[6] = true;
    fake.present[3] = false; /* one in the middle: the servos' own silence, then the rest answer */
    mid_silent = cycle_us(&e);
    assert_int_equal(e.servo, 3);
    assert_true(six_got[3] && six_got[5] && !six_got[2]);
    assert_int_equal(six_states[5].angle, six_angles[5]);
    assert_true(mid_silent <= all + SB_SYNC_SILENCE_US + 200u);
    bus.answer_margin_us = 300; /* the user's margin */
    fake.present[3] = true;
    fake.present[6] = false;
    last_silent = cycle_us(&e);
    assert_int_equal(e.servo, 6);
    assert_true(last_silent <= all + SB_TURNAROUND_US + 300u + 200u);
    assert_int_equal(six.missed, 7);
}

static void a_late_answer_to_the_round_before_is_dropped(void **state)
{
    sb_error e;
    sb_value v[8];
    size_t len = 0;
    start_six();
    cycle_us(&e);
    assert_int_equal(e.status, SB_OK);
    /* servo 6's answer to the last round, off the wire after the bus drained its input */
    memset(v, 0, sizeof v);
    v[0].n = 6;
    v[1].n = 7400;
    v[6].n = -999;
    assert_int_equal(sb_encode_answer(SB_PKT_MONITOR, v, 8, fake.late, sizeof fake.late, &len).status, SB_OK);
    fake.late_len = len;
    cycle_us(&e);
    assert_int_equal(e.status, SB_OK);
    assert_true(six_got[5]);
    assert_int_equal(six_states[5].angle, six_angles[5]); /* this round's, not -999 */
    assert_int_equal(six_states[0].angle, six_angles[0]);
}

static void a_failed_write_leaves_the_stream_where_the_servos_are(void **state)
{
    uint8_t ids[1] = {1};
    int32_t a = 0;
    sb_monitor_answer st[1];
    bool got[1];
    sb_loop l;
    fake.present[1] = true;
    assert_int_equal(sb_loop_init(&l, &bus, ids, 1, 10).status, SB_OK); /* 7.5 deg a step at most */
    assert_int_equal(sb_loop_cycle(&l, &a, NULL, st, got).status, SB_OK);
    a = 75;
    for (int k = 0; k < 3; k++) { /* 7.5 deg, each write failing: the servo stays at 0 */
        fake.fail_writes = 1;
        assert_int_equal(sb_loop_cycle(&l, &a, NULL, st, got).status, SB_E_LINK);
    }
    assert_int_equal(l.stream.sent, 1);
    assert_int_equal(l.stream.last[0], 0);
    a = 150; /* 15 deg from the 0 the servo got: refused, nothing sent */
    sb_error e = sb_loop_cycle(&l, &a, NULL, st, got);
    assert_int_equal(e.status, SB_E_RANGE);
    assert_string_equal(e.field, "angle step");
    assert_int_equal(fake.setpoint[1], 0);
    a = 75;
    assert_int_equal(sb_loop_cycle(&l, &a, NULL, st, got).status, SB_OK);
    assert_int_equal(fake.setpoint[1], 75);
    assert_int_equal(fake.velocity[1], 7500); /* from the 0 it got */
}

static void a_refused_loop_sends_nothing(void **state)
{
    uint8_t ids[2] = {1, 2};
    int32_t a[2] = {900, -900};
    sb_monitor_answer st[2];
    bool got[2] = {true, true};
    sb_loop l;
    sb_bus_init(&bus, fake_transport(&fake), 115200);
    assert_int_equal(sb_loop_init(&l, &bus, ids, 2, 1).status, SB_E_USAGE); /* 1 ms: shorter than its wire */
    sb_error e = sb_loop_cycle(&l, a, NULL, st, got);
    assert_int_equal(e.status, SB_E_USAGE);
    assert_int_equal(fake.frames, 0);
    assert_int_equal(fake.now_us, 0);
    char text[120];
    sb_error_text(&e, text, sizeof text);
    assert_string_equal(text, "StreamSetpoint: loop not allowed: sb_loop_init refused it; nothing was sent");
    sb_bus_init(&bus, fake_transport(&fake), 0);
    assert_int_equal(sb_loop_init(&l, &bus, ids, 2, 10).status, SB_E_USAGE);
    assert_int_equal(sb_loop_cycle(&l, a, NULL, st, got).status, SB_E_USAGE);
    assert_int_equal(fake.frames, 0);
}

static void the_stream_counts_on_past_its_counter(void **state)
{
    uint8_t ids[1] = {1};
    int32_t a = 0;
    uint8_t f[64];
    size_t len = 0;
    sb_stream s;
    assert_int_equal(sb_stream_init(&s, ids, 1, 10).status, SB_OK);
    s.sent = UINT32_MAX;
    assert_int_equal(sb_stream_frame(&s, &a, NULL, f, sizeof f, &len).status, SB_OK);
    assert_true(s.sent != 0);
    a = 760; /* 76 deg in 10 ms: still checked after the counter's wrap */
    assert_int_equal(sb_stream_frame(&s, &a, NULL, f, sizeof f, &len).status, SB_E_RANGE);
}

static void the_stream_refuses_what_the_servo_would_not_follow(void **state)
{
    uint8_t ids[2] = {1, 2};
    int32_t angles[2] = {0, 0};
    uint8_t f[64];
    size_t len = 0;
    sb_stream s;
    assert_int_equal(sb_stream_init(&s, ids, 2, 10).status, SB_OK);
    assert_int_equal(sb_stream_frame(&s, angles, NULL, f, sizeof f, &len).status, SB_OK);
    angles[1] = 76; /* 7.6 deg in 10 ms: 760 deg/s */
    sb_error e = sb_stream_frame(&s, angles, NULL, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_RANGE);
    assert_int_equal(e.servo, 2);
    assert_string_equal(e.field, "angle step");
    assert_int_equal(s.sent, 1);
    s.angle_max[0] = 50;
    angles[0] = 51;
    angles[1] = 0;
    e = sb_stream_frame(&s, angles, NULL, f, sizeof f, &len);
    assert_int_equal(e.servo, 1);
    assert_string_equal(e.field, "angle");
    int16_t speeds[2] = {0, 7501};
    angles[0] = 0;
    e = sb_stream_frame(&s, angles, speeds, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_RANGE);
    assert_string_equal(e.field, "velocity");
    uint8_t twice[2] = {1, 1};
    assert_int_equal(sb_stream_init(&s, twice, 2, 10).status, SB_E_DUPLICATE_ID);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(a_call_returns_the_servos_answer, set_up),
        cmocka_unit_test_setup(a_bad_checksum_is_told, set_up),
        cmocka_unit_test_setup(a_sync_monitor_names_the_servo_that_did_not_answer, set_up),
        cmocka_unit_test_setup(the_robot_loop_sends_setpoints_and_reads_every_state, set_up),
        cmocka_unit_test_setup(a_silent_servo_costs_one_slot_not_a_time_out, set_up),
        cmocka_unit_test_setup(a_late_answer_to_the_round_before_is_dropped, set_up),
        cmocka_unit_test_setup(an_error_says_what_is_wrong, set_up),
        cmocka_unit_test_setup(the_stream_refuses_what_the_servo_would_not_follow, set_up),
        cmocka_unit_test_setup(a_failed_write_leaves_the_stream_where_the_servos_are, set_up),
        cmocka_unit_test_setup(a_refused_loop_sends_nothing, set_up),
        cmocka_unit_test_setup(the_stream_counts_on_past_its_counter, set_up),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
