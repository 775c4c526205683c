/* What servobus refuses and how it says so: a stream's and a loop's
 * period (item 69's range, the wire's cycle), and errors that name the
 * item, the count, the lengths, the sizes, the speed and the serial. */
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
    assert_string_equal(words(e), "StreamSetpoint: period_ms not allowed: 1 ms is shorter than the wire's cycle at "
                                  "this baud rate (sb_cycle_bytes): at least 4 ms");
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

/* As many servos as the structs hold: the Sync Monitor's frame fits. */
static void a_loop_takes_sb_max_servos(void **state)
{
    uint8_t ids[SB_MAX_SERVOS];
    int32_t angles[SB_MAX_SERVOS];
    sb_monitor_answer st[SB_MAX_SERVOS];
    bool got[SB_MAX_SERVOS];
    sb_loop loop;
    for (size_t k = 0; k < SB_MAX_SERVOS; k++) {
        ids[k] = (uint8_t)(k + 1);
        angles[k] = 0;
        fake.present[k + 1] = true;
    }
    for (size_t n = SB_MAX_SERVOS - 2; n <= SB_MAX_SERVOS; n++)
        assert_int_equal(sb_loop_init(&loop, &bus, ids, n, 1000).status, SB_OK);
    assert_int_equal(sb_loop_cycle(&loop, angles, NULL, st, got).status, SB_OK);
    assert_true(got[SB_MAX_SERVOS - 1]);
}

/* An item the schema lacks, and one the packet may not write, apart. */
static void an_item_refused_says_why(void **state)
{
    uint8_t f[32];
    size_t len = 0;
    sb_read_data_request r = {1, 200};
    sb_write_data_request w = {1, SB_ITEM_VOLTAGE_MV, 7400, 0};
    assert_string_equal(words(sb_encode_read_data(&r, f, sizeof f, &len)),
                        "servo 1: ReadData: data_id refused: no data item 200 in the schema");
    assert_string_equal(words(sb_encode_write_data(&w, f, sizeof f, &len)),
                        "servo 1: WriteData: data_id refused: item 1 (voltage) is read-only");
}

/* The fields' count, as sb_encode_request says it. */
static void a_wrong_count_of_fields_is_told(void **state)
{
    sb_value v[3];
    uint8_t content[2] = {1, 0};
    memset(v, 0, sizeof v);
    v[0].n = 1;
    assert_string_equal(words(sb_check_request(SB_PKT_PING, v, 2)), "Ping: fields not allowed: 2, not 1");
    assert_string_equal(words(sb_decode_answer(SB_PKT_PING, content, 1, v, 3)),
                        "servo 1: Ping: fields not allowed: 3, not 1");
}

/* A transport that answers every request with one frame, at once. */
static uint8_t canned[64];
static size_t canned_len, canned_at;
static uint64_t canned_now;

static int canned_write(void *ctx, const uint8_t *data, size_t len)
{
    canned_at = 0;
    return 0;
}

static int canned_read(void *ctx, uint8_t *buf, size_t cap, size_t want, uint32_t wait_us)
{
    size_t n = canned_len - canned_at < cap ? canned_len - canned_at : cap;
    if (n == 0) {
        canned_now += wait_us;
        return 0;
    }
    memcpy(buf, canned + canned_at, n);
    canned_at += n;
    return (int)n;
}

static uint64_t canned_clock(void *ctx)
{
    return canned_now;
}

/* A bad answer's length: got and expected. */
static void a_bad_answer_says_its_length(void **state)
{
    const uint8_t serial3[5] = {1, SB_ITEM_SERIAL_NUMBER, 0x11, 0x22, 0x33}; /* item 8 is 4 bytes */
    const uint8_t ping6[6] = {1, 0, 0, 0, 0, 0};
    sb_value v[3];
    sb_read_data_request r = {1, SB_ITEM_SERIAL_NUMBER};
    sb_read_data_answer a;
    sb_bus b;
    canned_at = 0;
    assert_int_equal(sb_frame(false, SB_PKT_READ_DATA, serial3, 5, canned, sizeof canned, &canned_len).status, SB_OK);
    sb_bus_init(&b, sb_transport_make(NULL, canned_write, canned_read, canned_clock), 115200);
    assert_string_equal(words(sb_call_read_data(&b, &r, &a)), "servo 1: ReadData: data a bad answer: 3 bytes, not 4");
    assert_string_equal(words(sb_decode_answer(SB_PKT_PING, ping6, 6, v, sb_packet(SB_PKT_PING)->answer_count)),
                        "servo 1: Ping: length a bad answer: 6 bytes, not 1");
}

/* SB_E_SPACE: the bytes needed and given. */
static void a_small_buffer_says_how_small(void **state)
{
    uint8_t f[64], ids[4] = {1, 2, 3, 4};
    size_t len = 0;
    sb_ping_request p = {1};
    assert_string_equal(words(sb_encode_ping(&p, f, 4, &len)),
                        "servo 1: Ping: the buffer is too small: 6 bytes needed, 4 given");
    assert_string_equal(words(sb_encode_ping(&p, f, 5, &len)),
                        "servo 1: Ping: the buffer is too small: 6 bytes needed, 5 given");
    assert_string_equal(words(sb_sync_frame(SB_PKT_MONITOR, ids, 1, 4, f, 8, &len)),
                        "SyncCommand: the buffer is too small: 14 bytes needed, 8 given");
}

/* The step's limit in deg/s at the stream's period, and the way out. */
static void a_step_too_fast_says_the_speed_and_the_fix(void **state)
{
    uint8_t ids[1] = {1}, f[32];
    int32_t angles[1] = {0};
    size_t len = 0;
    sb_stream s;
    assert_int_equal(sb_stream_init(&s, ids, 1, 20).status, SB_OK);
    assert_int_equal(sb_stream_frame(&s, angles, NULL, f, sizeof f, &len).status, SB_OK);
    angles[0] = 200; /* 20 deg in 20 ms: 1000 deg/s */
    assert_string_equal(words(sb_stream_frame(&s, angles, NULL, f, sizeof f, &len)),
                        "servo 1: StreamSetpoint: angle step out of range: 200 is beyond -150..150: over 750 "
                        "deg/s at this period: use a longer period or a smaller step; nothing was sent");
}

/* AssignId at 255 that no servo answers: its serial, not a shared ID. */
static void an_unknown_serial_is_named(void **state)
{
    sb_assign_id_request r = {SB_BROADCAST_ID, 12345, 7};
    sb_assign_id_answer a;
    sb_error e = sb_call_assign_id(&bus, &r, &a);
    assert_int_equal(e.status, SB_E_NO_ANSWER);
    assert_string_equal(words(e), "AssignId: no servo has serial 12345 (item 8): none answered (is the servo on "
                                  "the bus, at this baud rate?)");
}

/* A Sync Monitor of no servo is the Monitor's error, not its SyncCommand's. */
static void an_empty_sync_monitor_says_monitor(void **state)
{
    uint8_t ids[1] = {1};
    sb_monitor_answer st[1];
    bool got[1];
    assert_string_equal(words(sb_sync_monitor(&bus, ids, 0, st, got)),
                        "Monitor: ids not allowed: 0 servos is beyond 1..255");
}

/* An ID out of range names no servo of that number. */
static void an_id_out_of_range_names_no_servo(void **state)
{
    uint8_t f[32];
    size_t len = 0;
    sb_value v[4] = {{256, NULL, 0}, {900, NULL, 0}, {500, NULL, 0}, {0, NULL, 0}};
    sb_error e = sb_encode_request(SB_PKT_MOVE_ANGLE, v, 4, f, sizeof f, &len);
    assert_int_not_equal(e.status, SB_OK);
    assert_int_equal(e.servo, -1);
    assert_null(strstr(words(e), "servo 256"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(a_stream_s_period_is_item_69_s, set_up),
        cmocka_unit_test_setup(a_loop_s_period_holds_its_cycle_on_the_wire, set_up),
        cmocka_unit_test_setup(a_loop_takes_sb_max_servos, set_up),
        cmocka_unit_test_setup(an_item_refused_says_why, set_up),
        cmocka_unit_test_setup(a_wrong_count_of_fields_is_told, set_up),
        cmocka_unit_test_setup(a_bad_answer_says_its_length, set_up),
        cmocka_unit_test_setup(a_small_buffer_says_how_small, set_up),
        cmocka_unit_test_setup(a_step_too_fast_says_the_speed_and_the_fix, set_up),
        cmocka_unit_test_setup(an_unknown_serial_is_named, set_up),
        cmocka_unit_test_setup(an_empty_sync_monitor_says_monitor, set_up),
        cmocka_unit_test_setup(an_id_out_of_range_names_no_servo, set_up),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
