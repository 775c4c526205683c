/* servobus's codec: frames, every field's range, answers checked, the
 * frame finder, errors in words. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "servobus/servobus.h"

static void ping_frame_is_the_protocols(void **state)
{
    uint8_t f[16];
    size_t len = 0;
    sb_ping_request r = {7};
    assert_int_equal(sb_encode_ping(&r, f, sizeof f, &len).status, SB_OK);
    assert_int_equal(len, 6);
    uint8_t want[] = {0x12, 0x4C, 0x01, 0x01, 0x07, (uint8_t)(0x12 + 0x4C + 1 + 1 + 7)};
    assert_memory_equal(f, want, sizeof want);
}

static void a_field_beyond_its_range_is_refused_naming_servo_packet_field(void **state)
{
    uint8_t f[32];
    size_t len = 99;
    char text[160];
    sb_move_angle_request r = {3, 1801, 100, 0};
    sb_error e = sb_encode_move_angle(&r, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_RANGE);
    assert_int_equal(e.servo, 3);
    assert_int_equal(e.packet, SB_PKT_MOVE_ANGLE);
    assert_string_equal(e.field, "angle");
    assert_int_equal(e.least, -1800);
    assert_int_equal(e.most, 1800);
    assert_int_equal(len, 99); /* nothing written */
    sb_error_text(&e, text, sizeof text);
    assert_string_equal(text, "servo 3: MoveOnAngleMode: angle out of range: 1801 is beyond -1800..1800; nothing was sent");
    r.angle = 1800;
    assert_int_equal(sb_encode_move_angle(&r, f, sizeof f, &len).status, SB_OK);
    /* A ramp below the schema's 20 ms, an EndAsync other than 0 or 1. */
    sb_move_angle_by_interval_request ri = {1, 0, 100, 19, 20, 0};
    e = sb_encode_move_angle_by_interval(&ri, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_RANGE);
    assert_string_equal(e.field, "acc_interval");
    sb_end_async_request ea = {2};
    e = sb_encode_end_async(&ea, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_RANGE);
    assert_int_equal(e.servo, -1); /* EndAsync names no servo */
}

static void write_data_takes_the_items_size_and_range(void **state)
{
    uint8_t f[32];
    size_t len = 0;
    sb_write_data_request r = {1, SB_ITEM_ANGLE_MAX_DECIDEG, -1800, 0};
    assert_int_equal(sb_encode_write_data(&r, f, sizeof f, &len).status, SB_OK);
    assert_int_equal(len, 4 + 4 + 1); /* id, data_id, two bytes */
    assert_int_equal(f[6], 0xF8); /* -1800 */
    assert_int_equal(f[7], 0xF8);
    r.data = -1801;
    assert_int_equal(sb_encode_write_data(&r, f, sizeof f, &len).status, SB_E_RANGE);
    r.data_id = 35; /* reserved */
    r.data = 0;
    assert_int_equal(sb_encode_write_data(&r, f, sizeof f, &len).status, SB_E_UNKNOWN_ITEM);
    r.data_id = 1; /* read-only */
    assert_int_equal(sb_encode_write_data(&r, f, sizeof f, &len).status, SB_E_UNKNOWN_ITEM);
    sb_read_data_request q = {1, 200};
    assert_null(sb_item(200)); /* no item of the schema: ReadData refused as WriteData is */
    sb_error e = sb_encode_read_data(&q, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_UNKNOWN_ITEM);
    assert_string_equal(e.field, "data_id");
    assert_int_equal(e.value, 200);
    q.data_id = 35; /* reserved: the servo answers it without a value */
    assert_int_equal(sb_encode_read_data(&q, f, sizeof f, &len).status, SB_OK);
}

static void answers_are_checked(void **state)
{
    sb_monitor_answer m;
    uint8_t c[16] = {5, 0xE8, 0x1C, 0, 0, 0, 0, 0, 0, 1, 0xFF, 0xFF, 0xFF, 0xFF, 2, 0};
    sb_error e = sb_decode_monitor(c, sizeof c, &m);
    assert_int_equal(e.status, SB_OK);
    assert_int_equal(m.id, 5);
    assert_int_equal(m.voltage, 7400);
    assert_int_equal(m.status, 1);
    assert_int_equal(m.angle, -1);
    assert_int_equal(m.turns, 2);
    e = sb_decode_monitor(c, 15, &m);
    assert_int_equal(e.status, SB_E_BAD_ANSWER);
    assert_int_equal(e.servo, 5);
    /* ReadFaults' count is 0..16 (the schema's range on an answer field). */
    uint8_t fault[32];
    memset(fault, 0, sizeof fault);
    fault[0] = 2;
    fault[1] = 17;
    sb_read_faults_answer fa;
    e = sb_decode_read_faults(fault, 27, &fa);
    assert_int_equal(e.status, SB_E_BAD_ANSWER);
    assert_string_equal(e.field, "count");
    fault[1] = 16;
    assert_int_equal(sb_decode_read_faults(fault, 27, &fa).status, SB_OK);
}

static void read_data_answers_at_the_items_size(void **state)
{
    sb_read_data_answer a;
    uint8_t c[4] = {1, SB_ITEM_ANGLE_MIN_DECIDEG, 0x08, 0xF9};
    assert_int_equal(sb_decode_read_data(c, 4, &a).status, SB_OK);
    assert_int_equal(a.data, -1784);
    assert_int_equal(a.data_size, 2);
    assert_int_equal(sb_decode_read_data(c, 3, &a).status, SB_E_BAD_ANSWER);
    uint8_t hidden[2] = {1, 35}; /* a reserved item: no value */
    assert_int_equal(sb_decode_read_data(hidden, 2, &a).status, SB_OK);
    assert_int_equal(a.data_size, 0);
}

static void the_frame_finder_skips_garbage_and_bad_frames(void **state)
{
    uint8_t stream[64];
    size_t n = 0, len = 0, used = 0, clen = 0;
    sb_value v[2] = {{4, NULL, 0}, {-5, NULL, 0}};
    stream[n++] = 0x05;
    stream[n++] = 0x99; /* not a header */
    assert_int_equal(sb_encode_answer(SB_PKT_READ_ANGLE, v, 2, stream + n, sizeof stream - n, &len).status, SB_OK);
    memcpy(stream + n + len, stream + n, len);
    stream[n + len - 1] ^= 1; /* the first copy's checksum broken */
    n += 2 * len;
    sb_parser p;
    sb_parser_init(&p, false);
    uint8_t code = 0;
    const uint8_t *content = NULL;
    assert_int_equal(sb_parse(&p, stream, n, &used, &code, &content, &clen), 1);
    assert_int_equal(used, n);
    assert_int_equal(code, SB_PKT_READ_ANGLE);
    assert_int_equal(clen, 3);
    assert_int_equal(content[0], 4);
    assert_int_equal(p.bad_frames, 1);
    assert_int_equal(p.stray_bytes, 2);
    assert_int_equal(sb_parse(&p, stream, 0, &used, &code, &content, &clen), 0);
}

/* Every frame the finder returns from stream, at once: their servos in order. */
static size_t servos_found(const uint8_t *stream, size_t n, uint8_t *servos)
{
    sb_parser p;
    size_t found = 0, at = 0, used = 0, clen = 0;
    uint8_t code = 0;
    const uint8_t *content = NULL;
    sb_parser_init(&p, false);
    while (sb_parse(&p, stream + at, n - at, &used, &code, &content, &clen)) {
        at += used;
        servos[found++] = content[0];
    }
    assert_int_equal(at + used, n);
    return found;
}

static void the_frame_finder_rescans_after_a_false_header(void **state)
{
    uint8_t stream[96], servos[4];
    size_t n = 0, len = 0;
    sb_value v[2] = {{1, NULL, 0}, {-5, NULL, 0}};
    stream[n++] = SB_RESPONSE_HEADER_0; /* noise that looks like a header: a 33-byte frame */
    stream[n++] = SB_RESPONSE_HEADER_1;
    for (int id = 1; id <= 3; id++, n += len) {
        v[0].n = id;
        assert_int_equal(sb_encode_answer(SB_PKT_READ_ANGLE, v, 2, stream + n, sizeof stream - n, &len).status, SB_OK);
    }
    assert_int_equal(servos_found(stream, n, servos), 3);
    assert_memory_equal(servos, "\x01\x02\x03", 3);
    /* one answer alone behind the noise: found without a byte more */
    assert_int_equal(servos_found(stream, 2 + len, servos), 1);
    /* the first answer cut short after 5 bytes: the next two found */
    memmove(stream + 7, stream + 2 + len, 2 * len);
    assert_int_equal(servos_found(stream + 2, 5 + 2 * len, servos), 2);
    assert_memory_equal(servos, "\x02\x03", 2);
}

/* Noise that makes a frame with a good checksum out of an answer's first
 * bytes, or one that ends where the answer does: both frames found. */
static void the_frame_finder_misses_no_answer_that_overlaps_noise(void **state)
{
    uint8_t stream[64], servos[4];
    size_t len = 0;
    sb_value v[8];
    memset(v, 0, sizeof v);
    v[0].n = 1;
    v[1].n = 7400;
    assert_int_equal(sb_encode_answer(SB_PKT_MONITOR, v, 8, stream + 4, sizeof stream - 4, &len).status, SB_OK);
    stream[0] = SB_RESPONSE_HEADER_0;
    stream[1] = SB_RESPONSE_HEADER_1;
    stream[3] = 5; /* a 10-byte frame: its last byte the answer's sixth */
    stream[2] = (uint8_t)(stream[9] - sb_checksum(stream, 9) + stream[2]);
    assert_int_equal(sb_checksum(stream, 9), stream[9]);
    assert_int_equal(servos_found(stream, 4 + len, servos), 2);
    assert_int_equal(servos[1], 1);
    stream[3] = (uint8_t)(len - 1u); /* a frame that ends where the answer does */
    stream[2] = (uint8_t)(0u - sb_checksum(stream, 2) - stream[3]);
    assert_int_equal(sb_checksum(stream, 4 + len - 1u), stream[4 + len - 1u]);
    assert_int_equal(servos_found(stream, 4 + len, servos), 2);
    assert_int_equal(servos[1], 1);
}

static void the_typed_sync_command_checks_what_sb_sync_frame_checks(void **state)
{
    uint8_t records[4] = {1, 2, 3, 4}, f[32];
    size_t len = 0;
    sb_sync_command_request r = {SB_PKT_MONITOR, 1, 4, records, 4};
    assert_int_equal(sb_encode_sync_command(&r, f, sizeof f, &len).status, SB_OK);
    r.cmd = SB_PKT_PING; /* not syncable */
    assert_int_equal(sb_encode_sync_command(&r, f, sizeof f, &len).status, SB_E_USAGE);
    r.cmd = SB_PKT_MONITOR;
    r.record_len = 2; /* not Monitor's length */
    r.count = 2;
    assert_int_equal(sb_encode_sync_command(&r, f, sizeof f, &len).status, SB_E_USAGE);
    r.record_len = 1;
    r.count = 0;
    r.records_len = 0;
    assert_int_equal(sb_encode_sync_command(&r, f, sizeof f, &len).status, SB_E_USAGE);
    r.count = 3; /* three records said, four given */
    r.records_len = 4;
    sb_error e = sb_encode_sync_command(&r, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_USAGE);
    assert_string_equal(e.field, "records");
}

/* sb_check_request checks the fields' ranges before the rules that add them up. */
static void the_rules_check_the_ranges_first(void **state)
{
    sb_value v[6];
    memset(v, 0, sizeof v);
    v[0].n = 1;
    v[3].n = INT64_MAX; /* acc_interval: acc + dec would overflow */
    v[4].n = 1;
    sb_error e = sb_check_request(SB_PKT_MOVE_ANGLE_BY_INTERVAL, v, 6);
    assert_int_equal(e.status, SB_E_RANGE);
    assert_int_equal(e.servo, 1);
    assert_string_equal(e.field, sb_packet(SB_PKT_MOVE_ANGLE_BY_INTERVAL)->request[3].name);
    assert_true(e.value == INT64_MAX);
}

/* Each record is checked as its packet's request would be. */
static void a_sync_command_s_records_are_checked_as_requests(void **state)
{
    /* MoveOnAngleMode: servo 1 to 180.0 deg in 100 ms, servo 2 to 0 in 100 ms */
    uint8_t m[14] = {1, 0x08, 0x07, 100, 0, 0, 0, 2, 0, 0, 100, 0, 0, 0}, f[64];
    size_t len = 0;
    assert_int_equal(sb_sync_frame(SB_PKT_MOVE_ANGLE, m, 7, 2, f, sizeof f, &len).status, SB_OK);
    m[1] = 0xB8; /* 300.0 deg: beyond the angle's range */
    m[2] = 0x0B;
    sb_error e = sb_sync_frame(SB_PKT_MOVE_ANGLE, m, 7, 2, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_RANGE);
    assert_int_equal(e.servo, 1);
    assert_int_equal(e.value, 3000);
    m[1] = m[2] = 0;
    m[10] = 0; /* servo 2's move in 0 ms: shorter than its ramps */
    e = sb_sync_frame(SB_PKT_MOVE_ANGLE, m, 7, 2, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_RANGE);
    assert_int_equal(e.servo, 2);
    m[10] = 100;
    m[7] = 1; /* servo 1 twice */
    e = sb_sync_frame(SB_PKT_MOVE_ANGLE, m, 7, 2, f, sizeof f, &len);
    assert_int_equal(e.status, SB_E_DUPLICATE_ID);
    assert_int_equal(e.servo, 1);
    m[7] = SB_BROADCAST_ID;
    assert_int_equal(sb_sync_frame(SB_PKT_MOVE_ANGLE, m, 7, 2, f, sizeof f, &len).status, SB_E_BROADCAST);
    uint8_t ids[3] = {1, 1, SB_BROADCAST_ID};
    assert_int_equal(sb_sync_frame(SB_PKT_MONITOR, ids, 1, 3, f, sizeof f, &len).status, SB_E_DUPLICATE_ID);
}

static void every_item_decodes_at_its_size_and_signedness(void **state)
{
    uint8_t c[2 + 4] = {1, SB_ITEM_SERIAL_NUMBER, 0xFF, 0xFF, 0xFF, 0xFF};
    sb_read_data_answer a;
    assert_int_equal(sb_decode_read_data(c, 6, &a).status, SB_OK);
    assert_true(a.data == INT64_C(0xFFFFFFFF)); /* a serial number above 0x7FFFFFFF, not negative */
    for (size_t k = 0; k < SB_ITEM_COUNT; k++) {
        const sb_item_desc *item = &sb_items[k];
        int64_t most = item->is_signed ? (INT64_C(1) << (8 * item->size - 1)) - 1 : (INT64_C(1) << (8 * item->size)) - 1;
        int64_t least = item->is_signed ? -most - 1 : 0;
        if (item->access == SB_ACCESS_RESERVED)
            continue;
        for (int end = 0; end < 2; end++) {
            uint8_t f[16];
            size_t len = 0;
            sb_value v[3] = {{1, NULL, 0}, {item->id, NULL, 0}, {end ? most : least, NULL, 0}};
            assert_int_equal(sb_encode_answer(SB_PKT_READ_DATA, v, 3, f, sizeof f, &len).status, SB_OK);
            assert_int_equal(sb_decode_read_data(f + 4, len - 5, &a).status, SB_OK);
            assert_true(a.data == v[2].n);
            assert_int_equal(a.data_size, item->size);
        }
    }
}

static void a_long_sync_command_takes_the_extended_length(void **state)
{
    uint8_t records[30 * 9], f[300];
    size_t len = 0;
    memset(records, 0, sizeof records);
    for (size_t k = 0; k < 30; k++)
        records[k * 9] = (uint8_t)k; /* servos 0 to 29 */
    assert_int_equal(sb_sync_frame(SB_PKT_STREAM_SETPOINT, records, 9, 30, f, sizeof f, &len).status, SB_OK);
    assert_int_equal(len, 6 + 3 + 270 + 1);
    assert_int_equal(f[3], 0xFF);
    assert_int_equal(f[4] | f[5] << 8, 273);
    assert_int_equal(f[6], SB_PKT_STREAM_SETPOINT);
    assert_int_equal(sb_sync_frame(SB_PKT_PING, records, 1, 1, f, sizeof f, &len).status, SB_E_USAGE);
    assert_int_equal(sb_sync_frame(SB_PKT_MONITOR, records, 2, 1, f, sizeof f, &len).status, SB_E_USAGE);
    assert_int_equal(sb_sync_frame(SB_PKT_MONITOR, records, 1, 300, f, sizeof f, &len).status, SB_E_USAGE);
}

static void the_wire_limit_is_servoctls(void **state)
{
    /* docs/streaming.md: 495 and 195 cycles/s at 1 Mbaud for 6 and 16 servos. */
    assert_int_equal(sb_cycle_bytes(6), 62 + 14 + 6 * 21);
    assert_int_equal((int)sb_wire_limit_hz(6, 1000000), 495);
    assert_int_equal((int)sb_wire_limit_hz(16, 1000000), 195);
    assert_int_equal(sb_answer_frame_size(SB_PKT_MONITOR), 21);
    assert_int_equal(sb_answer_frame_size(SB_PKT_READ_DATA), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(ping_frame_is_the_protocols),
        cmocka_unit_test(a_field_beyond_its_range_is_refused_naming_servo_packet_field),
        cmocka_unit_test(write_data_takes_the_items_size_and_range),
        cmocka_unit_test(answers_are_checked),
        cmocka_unit_test(read_data_answers_at_the_items_size),
        cmocka_unit_test(the_frame_finder_skips_garbage_and_bad_frames),
        cmocka_unit_test(a_long_sync_command_takes_the_extended_length),
        cmocka_unit_test(the_wire_limit_is_servoctls),
        cmocka_unit_test(the_frame_finder_rescans_after_a_false_header),
        cmocka_unit_test(the_frame_finder_misses_no_answer_that_overlaps_noise),
        cmocka_unit_test(the_typed_sync_command_checks_what_sb_sync_frame_checks),
        cmocka_unit_test(a_sync_command_s_records_are_checked_as_requests),
        cmocka_unit_test(the_rules_check_the_ranges_first),
        cmocka_unit_test(every_item_decodes_at_its_size_and_signedness),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
