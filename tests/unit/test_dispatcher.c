/* The dispatcher: addressing, broadcast, length and command-error rules of
 * docs/protocol.md, and how every motion packet reaches the motion layer
 * (mocked with cmocka). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "doubles/motion_mock.h"
#include "registers/data_table.h"
#include "protocol/dispatcher.h"
#include "protocol/packet_table.h"

#define OWN_ID 3

static struct registers regs;
static struct dispatcher d;
static volatile uint8_t own_id;
static struct response resp;
static struct dispatch_result result;

static int setup(void **state)
{
    (void)state;
    memset(&regs, 0, sizeof regs);
    user_config_factory(&regs.user);
    own_id = OWN_ID;
    dispatcher_init(&d, &regs, NULL, &own_id);
    memset(&resp, 0, sizeof resp);
    memset(&motion_mock_last, 0, sizeof motion_mock_last);
    return 0;
}

static void run(uint8_t code, const uint8_t *content, uint16_t length)
{
    struct rx_frame f = {.code = code, .length = length, .sync_index = FRAME_SYNC_NO_RECORD};
    for (uint16_t i = 0; i < length && i < FRAME_CONTENT_MAX; i++) {
        f.content[i] = content[i];
    }
    f.stored = (uint8_t)(length < FRAME_CONTENT_MAX ? length : FRAME_CONTENT_MAX);
    if (length > FRAME_CONTENT_MAX) {
        f.flags = FRAME_TRUNCATED;
    }
    dispatch(&d, &f, &resp, &result);
}

#define RUN(code, ...)                                                   \
    do {                                                                 \
        const uint8_t c_[] = {__VA_ARGS__};                              \
        run((code), c_, (uint16_t)sizeof c_);                            \
    } while (0)

static void assert_answer(uint8_t code, const uint8_t *content, uint8_t length)
{
    assert_true(result.answer);
    assert_int_equal(resp.code, code);
    assert_int_equal(resp.length, length);
    assert_memory_equal(resp.content, content, length);
}

#define ASSERT_ANSWER(code, ...)                                         \
    do {                                                                 \
        const uint8_t e_[] = {__VA_ARGS__};                              \
        assert_answer((code), e_, (uint8_t)sizeof e_);                   \
    } while (0)

static bool command_error(void)
{
    return regs.status.status & STATUS_COMMAND_ERROR;
}

static void test_table_rows_are_in_packet_order(void **state)
{
    (void)state;
    for (unsigned code = 1; code <= 25; code++) {
        const struct packet_desc *p = packet_find((uint8_t)code);
        assert_non_null(p);
        assert_int_equal(p->code, code);
        assert_true(p->length.min <= p->length.max);
    }
    assert_null(packet_find(0));
    assert_null(packet_find(26));
}

static void test_ping_own_other_broadcast(void **state)
{
    (void)state;
    RUN(1, OWN_ID);
    ASSERT_ANSWER(1, OWN_ID);
    RUN(1, 4);
    assert_false(result.answer);
    RUN(1, 0xFF); /* answering packets never run on broadcast */
    assert_false(result.answer);
    assert_false(command_error());
}

static void test_answering_packets_are_not_executed_on_broadcast(void **state)
{
    (void)state;
    RUN(4, 0xFF, 33, 1); /* WriteData control response to everyone */
    assert_false(result.answer);
    assert_int_equal(regs.user.control_response, 0);
    RUN(2, 0xFF);
    assert_false(result.answer);
    RUN(6, 0xFF, 1, 1, 9, 0, 5, 0, 0x10, 0x27, 0xA0, 0x0F, 0xD0, 0x20, 0x8B, 0x02, 0x10,
        0x27, 0xA0, 0x0F, 0, 0, 0, 0, 1, 1, 0xB8, 0x0B, 0x46, 0x05, 0xBA, 0xFA, 0, 0);
    assert_false(result.answer);
    assert_int_equal(regs.user.servo_id, 0);
    assert_false(command_error());
}

static void test_unknown_packet_sets_command_error(void **state)
{
    (void)state;
    RUN(30, 4, 1, 2); /* for another servo: not ours to judge */
    assert_false(command_error());
    RUN(30, OWN_ID, 1, 2);
    assert_false(result.answer);
    assert_true(command_error());
    /* A query leaves the bit; the next executed command clears it. */
    RUN(1, OWN_ID);
    assert_true(command_error());
    RUN(4, OWN_ID, 44, 9);
    ASSERT_ANSWER(4, OWN_ID, 44, 1);
    assert_false(command_error());
}

static void test_wrong_length_is_not_executed(void **state)
{
    (void)state;
    const struct {
        uint8_t code;
        uint8_t length;
    } wrong[] = {{1, 2}, {2, 2}, {3, 1}, {3, 3}, {4, 2}, {4, 7}, {5, 2}, {6, 32},
                 {7, 5}, {8, 8}, {9, 2}, {10, 2}, {11, 10}, {12, 12}, {13, 7},
                 {14, 11}, {15, 15}, {16, 2}, {17, 2}, {22, 2}, {23, 1}, {24, 3}};
    for (size_t i = 0; i < sizeof wrong / sizeof wrong[0]; i++) {
        setup(NULL);
        uint8_t content[40] = {OWN_ID, 33, 1, 1, 1, 1, 1, 1};
        run(wrong[i].code, content, wrong[i].length);
        assert_false(result.answer);
        assert_true(command_error());
        assert_int_equal(regs.user.control_response, 0);
    }
    /* No-ID packets judged by their length alone. */
    setup(NULL);
    RUN(18, 0);
    assert_true(command_error());
    setup(NULL);
    RUN(19, 0, 0);
    assert_true(command_error());
}

static void test_oversized_request_is_a_length_error(void **state)
{
    (void)state;
    uint8_t content[60] = {OWN_ID};
    run(6, content, sizeof content);
    assert_false(result.answer);
    assert_true(command_error());
}

static void test_addressed_packet_without_id(void **state)
{
    (void)state;
    run(1, NULL, 0);
    assert_false(result.answer);
    assert_true(command_error());
}

static void test_monitor_packets_20_21_are_ignored(void **state)
{
    (void)state;
    RUN(20, OWN_ID);
    assert_false(result.answer);
    RUN(21, OWN_ID, 1, 2, 3);
    assert_false(result.answer);
    assert_false(command_error());
}

static void test_write_data_result_and_config_flag(void **state)
{
    (void)state;
    RUN(4, OWN_ID, 33, 1);
    ASSERT_ANSWER(4, OWN_ID, 33, 1);
    assert_true(result.config_changed);
    RUN(4, OWN_ID, 33, 1); /* the same value again: nothing to save */
    ASSERT_ANSWER(4, OWN_ID, 33, 1);
    assert_false(result.config_changed);
    RUN(4, OWN_ID, 33, 2); /* out of range */
    ASSERT_ANSWER(4, OWN_ID, 33, 0);
    assert_false(result.config_changed);
    assert_true(command_error());
}

/* A drive item (80-89) is kept like a user item, and the motion layer is
 * told, so the feed-forward follows; a change the store refuses is put
 * back, and the motion layer told again; a refused value tells nothing. */
static bool persist_ok;
static bool persist_stub(void *ctx, const struct user_config *cfg)
{
    (void)ctx;
    (void)cfg;
    return persist_ok;
}

static void test_a_drive_item_is_kept_and_followed(void **state)
{
    (void)state;
    d.persist = persist_stub;
    persist_ok = true;
    motion_mock_drive_changes = 0;
    RUN(4, OWN_ID, 86, 0x00, 0x02); /* gain_kp 512 */
    ASSERT_ANSWER(4, OWN_ID, 86, 1);
    assert_true(result.config_changed);
    assert_int_equal(regs.user.gain_kp, 512);
    assert_int_equal(motion_mock_drive_changes, 1);
    persist_ok = false;
    RUN(4, OWN_ID, 80, 0x00, 0x19); /* resistance 6400 mOhm, refused by the store */
    ASSERT_ANSWER(4, OWN_ID, 80, 0);
    assert_int_equal(regs.user.resistance_mohm, ITEM_RESISTANCE_MOHM_FACTORY);
    assert_int_equal(motion_mock_drive_changes, 2);
    RUN(4, OWN_ID, 86, 0x00, 0x04); /* 1024: above the most */
    ASSERT_ANSWER(4, OWN_ID, 86, 0);
    assert_int_equal(regs.user.gain_kp, 512);
    assert_int_equal(motion_mock_drive_changes, 2);
}

/* Angle packets: request bytes in, the motion command out. */
static void test_angle_packets_decode(void **state)
{
    (void)state;
    const struct {
        uint8_t code;
        uint8_t content[15];
        uint8_t length;
        int32_t angle;
        uint32_t interval;
        uint16_t velocity, acc, dec, power;
        uint8_t profile, multi_turn;
    } cases[] = {
        /* 8: angle -90.0, interval 1000, power 500 */
        {8, {OWN_ID, 0x7C, 0xFC, 0xE8, 0x03, 0xF4, 0x01}, 7, -900, 1000, 0, 20, 20, 500,
         PROFILE_INTERVAL, 0},
        /* 11: 100.0, 1000 ms, acc 100, dec 200, power 0 */
        {11, {OWN_ID, 0xE8, 0x03, 0xE8, 0x03, 0x64, 0x00, 0xC8, 0x00, 0x00, 0x00}, 11, 1000,
         1000, 0, 100, 200, 0, PROFILE_INTERVAL, 0},
        /* 12: 20.0, 300.0 deg/s, 100/200, power 1000 */
        {12, {OWN_ID, 0xC8, 0x00, 0xB8, 0x0B, 0x64, 0x00, 0xC8, 0x00, 0xE8, 0x03}, 11, 200, 0,
         3000, 100, 200, 1000, PROFILE_VELOCITY, 0},
        /* 13: -3686400, 4096000 ms, power 7 */
        {13, {OWN_ID, 0x00, 0xC0, 0xC7, 0xFF, 0x00, 0x80, 0x3E, 0x00, 0x07, 0x00}, 11,
         -3686400, 4096000, 0, 20, 20, 7, PROFILE_INTERVAL, 1},
        /* 14: 3686400, 5000 ms, acc 20, dec 30, power 65535 */
        {14, {OWN_ID, 0x00, 0x40, 0x38, 0x00, 0x88, 0x13, 0x00, 0x00, 0x14, 0x00, 0x1E, 0x00,
              0xFF, 0xFF}, 15, 3686400, 5000, 0, 20, 30, 65535, PROFILE_INTERVAL, 1},
        /* 15: 7200, 7500 (750 deg/s), 50/60, power 2 */
        {15, {OWN_ID, 0x20, 0x1C, 0x00, 0x00, 0x4C, 0x1D, 0x32, 0x00, 0x3C, 0x00, 0x02, 0x00},
         13, 7200, 0, 7500, 50, 60, 2, PROFILE_VELOCITY, 1},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        setup(NULL);
        expect_function_call(motion_submit);
        will_return(motion_submit, MOTION_ACCEPTED);
        run(cases[i].code, cases[i].content, cases[i].length);
        const struct motion_command *m = &motion_mock_last;
        assert_int_equal(m->packet, cases[i].code);
        assert_int_equal(m->kind, MOTION_ANGLE);
        assert_int_equal(m->angle_decideg, cases[i].angle);
        assert_int_equal(m->interval_ms, cases[i].interval);
        assert_int_equal(m->velocity_decideg_s, cases[i].velocity);
        assert_int_equal(m->acc_ms, cases[i].acc);
        assert_int_equal(m->dec_ms, cases[i].dec);
        assert_int_equal(m->power_mw, cases[i].power);
        assert_int_equal(m->profile, cases[i].profile);
        assert_int_equal(m->multi_turn, cases[i].multi_turn);
        assert_int_equal(m->answer_when_done, 0);
        assert_false(result.answer); /* control response off */
        assert_false(command_error());
    }
}

static void test_wheel_packet_decodes(void **state)
{
    (void)state;
    expect_function_call(motion_submit);
    will_return(motion_submit, MOTION_ACCEPTED);
    RUN(7, OWN_ID, 0x82, 0x5A, 0x00, 0x03, 0x00); /* CW, fixed turns, 90 deg/s, 3 */
    assert_int_equal(motion_mock_last.kind, MOTION_WHEEL);
    assert_int_equal(motion_mock_last.method, 0x82);
    assert_int_equal(motion_mock_last.wheel_speed_deg_s, 90);
    assert_int_equal(motion_mock_last.wheel_value, 3);
    assert_false(result.answer);
}

static void test_motion_answers_when_done_with_control_response(void **state)
{
    (void)state;
    regs.user.control_response = 1;
    expect_function_call(motion_submit);
    will_return(motion_submit, MOTION_ACCEPTED);
    RUN(8, OWN_ID, 0x64, 0x00, 0xE8, 0x03, 0x00, 0x00);
    assert_int_equal(motion_mock_last.answer_when_done, 1);
    assert_false(result.answer); /* the answer comes when the move ends */
    /* The same to everyone: runs, never answered. */
    expect_function_call(motion_submit);
    will_return(motion_submit, MOTION_ACCEPTED);
    RUN(8, 0xFF, 0x64, 0x00, 0xE8, 0x03, 0x00, 0x00);
    assert_int_equal(motion_mock_last.answer_when_done, 0);
    assert_false(result.answer);
}

/* StreamSetpoint (0x45): angle, velocity and host time as sent, signs
 * kept; never answered, addressed or broadcast; a refusal (the output
 * inhibited) flags the command error. */
static void test_stream_setpoint_decodes(void **state)
{
    (void)state;
    regs.user.control_response = 1;
    expect_function_call(motion_stream);
    will_return(motion_stream, MOTION_ACCEPTED);
    RUN(0x45, OWN_ID, 0x18, 0xFC, 0xFF, 0xFF, 0x0C, 0xFE, 0xFE, 0xFF); /* -1000, -500, 65534 */
    assert_int_equal(motion_mock_last_setpoint.angle_decideg, -1000);
    assert_int_equal(motion_mock_last_setpoint.velocity_decideg_s, -500);
    assert_int_equal(motion_mock_last_setpoint.host_ms, 65534);
    assert_false(result.answer);
    expect_function_call(motion_stream);
    will_return(motion_stream, MOTION_ACCEPTED);
    RUN(0x45, 0xFF, 0x40, 0x42, 0x0F, 0x00, 0x10, 0x27, 0x01, 0x00); /* 1 000 000, 10 000, 1 */
    assert_int_equal(motion_mock_last_setpoint.angle_decideg, 1000000);
    assert_int_equal(motion_mock_last_setpoint.velocity_decideg_s, 10000);
    assert_false(result.answer);
    expect_function_call(motion_stream);
    will_return(motion_stream, MOTION_REFUSED);
    RUN(0x45, OWN_ID, 0, 0, 0, 0, 0, 0, 0, 0);
    assert_false(result.answer);
    assert_true(command_error());
}

/* DriveDuty (0x46): a signed duty and a time as sent; never answered; a
 * refusal (inhibited, or a time out of range) flags the command error. */
static void test_drive_duty_decodes(void **state)
{
    (void)state;
    expect_value(motion_drive_duty, duty_q15, -16384);
    expect_value(motion_drive_duty, ms, 10000);
    will_return(motion_drive_duty, MOTION_ACCEPTED);
    RUN(0x46, OWN_ID, 0x00, 0xC0, 0x10, 0x27); /* -16384, 10 000 ms */
    assert_false(result.answer);
    assert_false(command_error());
    expect_value(motion_drive_duty, duty_q15, 32767);
    expect_value(motion_drive_duty, ms, 0);
    will_return(motion_drive_duty, MOTION_REFUSED);
    RUN(0x46, OWN_ID, 0xFF, 0x7F, 0x00, 0x00);
    assert_false(result.answer);
    assert_true(command_error());
}

static void test_full_queue_drops_and_flags(void **state)
{
    (void)state;
    regs.user.control_response = 1;
    expect_function_call(motion_submit);
    will_return(motion_submit, MOTION_QUEUE_FULL);
    RUN(11, OWN_ID, 0xE8, 0x03, 0xE8, 0x03, 0x64, 0x00, 0xC8, 0x00, 0x00, 0x00);
    assert_false(result.answer);
    assert_true(command_error());
}

static void test_damping_answers_at_once_with_control_response(void **state)
{
    (void)state;
    expect_function_call(motion_submit);
    will_return(motion_submit, MOTION_ACCEPTED);
    RUN(9, OWN_ID, 0xF4, 0x01);
    assert_int_equal(motion_mock_last.kind, MOTION_DAMPING);
    assert_int_equal(motion_mock_last.power_mw, 500);
    assert_false(result.answer);
    regs.user.control_response = 1;
    expect_function_call(motion_submit);
    will_return(motion_submit, MOTION_ACCEPTED);
    RUN(9, OWN_ID, 0xF4, 0x01);
    ASSERT_ANSWER(9, OWN_ID, 1);
}

static void test_stop_on_control_mode(void **state)
{
    (void)state;
    regs.user.control_response = 1;
    for (uint8_t method = 0x10; method <= 0x12; method++) {
        expect_function_call(motion_submit);
        will_return(motion_submit, MOTION_ACCEPTED);
        RUN(24, OWN_ID, method, 0x2C, 0x01);
        assert_int_equal(motion_mock_last.kind, MOTION_STOP);
        assert_int_equal(motion_mock_last.method, method);
        assert_int_equal(motion_mock_last.power_mw, 300);
        assert_false(result.answer); /* 24 never answers */
    }
    RUN(24, OWN_ID, 0x13, 0, 0); /* unknown method: not executed */
    assert_true(command_error());
}

static void test_read_angles(void **state)
{
    (void)state;
    static const struct motion_angle angle = {
        .multi_turn_decideg = -7250, .turns = -2, .single_turn_decideg = -50};
    will_return(motion_read_angle, &angle);
    RUN(10, OWN_ID);
    ASSERT_ANSWER(10, OWN_ID, 0xCE, 0xFF);
    will_return(motion_read_angle, &angle);
    RUN(16, OWN_ID);
    ASSERT_ANSWER(16, OWN_ID, 0xAE, 0xE3, 0xFF, 0xFF, 0xFE, 0xFF);
}

static void test_reset_multi_turn_and_origin(void **state)
{
    (void)state;
    expect_function_call(motion_reset_multi_turn);
    will_return(motion_reset_multi_turn, false);
    RUN(17, OWN_ID);
    assert_false(result.answer); /* control response off */
    assert_true(command_error());
    regs.user.control_response = 1;
    expect_function_call(motion_reset_multi_turn);
    will_return(motion_reset_multi_turn, false);
    RUN(17, OWN_ID);
    ASSERT_ANSWER(17, OWN_ID, 0);
    expect_function_call(motion_reset_multi_turn);
    will_return(motion_reset_multi_turn, true);
    RUN(17, OWN_ID);
    ASSERT_ANSWER(17, OWN_ID, 1);
    assert_false(command_error());
    expect_function_call(motion_set_origin);
    will_return(motion_set_origin, false);
    RUN(23, OWN_ID, 0);
    assert_false(result.answer);
    assert_true(command_error());
    expect_function_call(motion_set_origin);
    will_return(motion_set_origin, true);
    RUN(23, 0xFF, 0); /* broadcast runs */
    assert_false(result.answer);
    assert_false(command_error());
}

static void test_async(void **state)
{
    (void)state;
    expect_function_call(motion_begin_async);
    run(18, NULL, 0);
    assert_false(result.answer);
    expect_value(motion_end_async, cancel, false);
    RUN(19, 0);
    expect_value(motion_end_async, cancel, true);
    RUN(19, 1);
    RUN(19, 2); /* neither run nor cancel */
    assert_true(command_error());
}

static void test_monitor_bytes(void **state)
{
    (void)state;
    static const struct motion_angle angle = {.multi_turn_decideg = 36100, .turns = 10};
    regs.status = (struct status_area){.voltage_mv = 7400, .current_ma = 300, .power_mw = 2220,
                                       .temperature_adc = 2048, .status = 0x01};
    will_return(motion_read_angle, &angle);
    RUN(22, OWN_ID);
    ASSERT_ANSWER(22, OWN_ID, 0xE8, 0x1C, 0x2C, 0x01, 0xAC, 0x08, 0x00, 0x08, 0x01, 0x04,
                  0x8D, 0x00, 0x00, 0x0A, 0x00);
}

static void run_sync(const uint8_t *header, const uint8_t *record, uint8_t record_len,
                     uint16_t total_length, uint8_t index)
{
    struct rx_frame f = {.code = 25, .length = total_length, .sync_index = index};
    memcpy(f.content, header, 3);
    f.stored = 3;
    if (record != NULL) {
        memcpy(&f.content[3], record, record_len);
        f.stored = (uint8_t)(3 + record_len);
    }
    dispatch(&d, &f, &resp, &result);
}

static void test_sync_motion_record_runs_without_answer(void **state)
{
    (void)state;
    regs.user.control_response = 1;
    const uint8_t header[] = {8, 7, 4};
    const uint8_t record[] = {OWN_ID, 0x84, 0x03, 0xF4, 0x01, 0x00, 0x00};
    expect_function_call(motion_submit);
    will_return(motion_submit, MOTION_ACCEPTED);
    run_sync(header, record, 7, 3 + 4 * 7, 2);
    assert_int_equal(motion_mock_last.packet, 8);
    assert_int_equal(motion_mock_last.angle_decideg, 900);
    assert_int_equal(motion_mock_last.interval_ms, 500);
    assert_int_equal(motion_mock_last.answer_when_done, 0);
    assert_false(result.answer);
}

static void test_sync_monitor_answers_in_list_order(void **state)
{
    (void)state;
    static const struct motion_angle angle = {0};
    const uint8_t header[] = {22, 1, 5};
    const uint8_t record[] = {OWN_ID};
    will_return(motion_read_angle, &angle);
    run_sync(header, record, 1, 3 + 5, 3);
    assert_true(result.answer);
    assert_int_equal(resp.code, 22);
    assert_int_equal(resp.length, 16);
    assert_int_equal(result.wait_responses, 3);
}

/* The table keeps a length in a byte: a SyncCommand longer than 255 bytes
 * (unbounded) is still carried out, and a bounded packet announced 256 or
 * 511 bytes long (a byte's wrap would make it 0 or 255) is still refused. */
static void test_lengths_beyond_a_byte(void **state)
{
    (void)state;
    static const struct motion_angle angle = {0};
    const uint8_t header[] = {22, 1, 5};
    const uint8_t record[] = {OWN_ID};
    for (unsigned i = 0; i < 3; i++) {
        static const uint16_t lengths[] = {255, 256, 0xFFFF};
        setup(NULL);
        will_return(motion_read_angle, &angle);
        run_sync(header, record, 1, lengths[i], 0);
        assert_true(result.answer);
        assert_false(command_error());
    }
    for (unsigned i = 0; i < 3; i++) {
        static const uint16_t lengths[] = {256, 257, 511};
        setup(NULL);
        struct rx_frame f = {.code = 1, .length = lengths[i], .stored = 1,
                             .sync_index = FRAME_SYNC_NO_RECORD, .content = {OWN_ID}};
        dispatch(&d, &f, &resp, &result);
        assert_false(result.answer);
        assert_true(command_error());
    }
}

/* ReadStore's answer byte for byte: every count's four bytes at its place
 * (each byte of the counts a different value). */
static void test_read_store_answer_bytes(void **state)
{
    (void)state;
    regs.store = (struct store_health){
        .flags = 0x5A, .records = 0x04030201u, .page_erases = 0x08070605u,
        .rated_cycles = 0x0C0B0A09u, .budget = 0x100F0E0Du, .op_seconds = 0x14131211u,
        .failures = 0x18171615u, .answers_dropped = 0x1C1B1A19u, .bytes_lost = 0x201F1E1Du};
    memset(&resp, 0xA5, sizeof resp);
    RUN(0x41, OWN_ID);
    uint8_t expected[34] = {OWN_ID, 0x5A};
    for (unsigned i = 0; i < 32; i++) {
        expected[2 + i] = (uint8_t)(i + 1);
    }
    assert_answer(0x41, expected, sizeof expected);
}

static void test_sync_not_listed_does_nothing(void **state)
{
    (void)state;
    const uint8_t header[] = {22, 1, 5};
    run_sync(header, NULL, 0, 3 + 5, FRAME_SYNC_NO_RECORD);
    assert_false(result.answer);
    assert_false(command_error());
}

static void test_sync_bad_records_are_errors(void **state)
{
    (void)state;
    const uint8_t record[] = {OWN_ID, 0, 0, 0, 0, 0, 0};
    const uint8_t not_syncable[] = {1, 1, 1};     /* Ping */
    run_sync(not_syncable, record, 1, 4, 0);
    assert_true(command_error());
    setup(NULL);
    const uint8_t wrong_len[] = {8, 6, 1};        /* packet 8 records are 7 bytes */
    run_sync(wrong_len, record, 6, 9, 0);
    assert_true(command_error());
    setup(NULL);
    struct rx_frame f = {.code = 25, .length = 10, .flags = FRAME_BAD_SYNC, .stored = 3,
                         .sync_index = FRAME_SYNC_NO_RECORD};
    dispatch(&d, &f, &resp, &result);
    assert_true(command_error());
}

/* The framer's list of unaddressed packets (packet_codes.h) agrees with
 * the packet table's PF_ADDRESSED rows. */
static void test_the_framer_knows_which_packets_are_addressed(void **state)
{
    (void)state;
    for (unsigned code = 0; code < 256u; code++) {
        const struct packet_desc *desc = packet_find((uint8_t)code);
        bool addressed = desc == NULL || (desc->flags & PF_ADDRESSED);
        assert_int_equal(packet_is_addressed((uint8_t)code), addressed);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_table_rows_are_in_packet_order, setup),
        cmocka_unit_test(test_the_framer_knows_which_packets_are_addressed),
        cmocka_unit_test_setup(test_ping_own_other_broadcast, setup),
        cmocka_unit_test_setup(test_answering_packets_are_not_executed_on_broadcast, setup),
        cmocka_unit_test_setup(test_unknown_packet_sets_command_error, setup),
        cmocka_unit_test_setup(test_wrong_length_is_not_executed, setup),
        cmocka_unit_test_setup(test_oversized_request_is_a_length_error, setup),
        cmocka_unit_test_setup(test_addressed_packet_without_id, setup),
        cmocka_unit_test_setup(test_monitor_packets_20_21_are_ignored, setup),
        cmocka_unit_test_setup(test_write_data_result_and_config_flag, setup),
        cmocka_unit_test_setup(test_a_drive_item_is_kept_and_followed, setup),
        cmocka_unit_test_setup(test_angle_packets_decode, setup),
        cmocka_unit_test_setup(test_wheel_packet_decodes, setup),
        cmocka_unit_test_setup(test_motion_answers_when_done_with_control_response, setup),
        cmocka_unit_test_setup(test_stream_setpoint_decodes, setup),
        cmocka_unit_test_setup(test_drive_duty_decodes, setup),
        cmocka_unit_test_setup(test_full_queue_drops_and_flags, setup),
        cmocka_unit_test_setup(test_damping_answers_at_once_with_control_response, setup),
        cmocka_unit_test_setup(test_stop_on_control_mode, setup),
        cmocka_unit_test_setup(test_read_angles, setup),
        cmocka_unit_test_setup(test_reset_multi_turn_and_origin, setup),
        cmocka_unit_test_setup(test_async, setup),
        cmocka_unit_test_setup(test_monitor_bytes, setup),
        cmocka_unit_test_setup(test_sync_motion_record_runs_without_answer, setup),
        cmocka_unit_test_setup(test_sync_monitor_answers_in_list_order, setup),
        cmocka_unit_test_setup(test_lengths_beyond_a_byte, setup),
        cmocka_unit_test_setup(test_read_store_answer_bytes, setup),
        cmocka_unit_test_setup(test_sync_not_listed_does_nothing, setup),
        cmocka_unit_test_setup(test_sync_bad_records_are_errors, setup),
    };
    return cmocka_run_group_tests_name("dispatcher", tests, NULL, NULL);
}
