/* servobus's rounds on a hostile line: a servo or a stray frame that
 * babbles cannot hold a Sync Monitor open past its schedule; what an early
 * refusal leaves in got[]; a late answer about another item; the bus clock
 * near its end; a transport's returns that have no errno. The clock is the line's, never the host's. */
#include <errno.h>
#include <limits.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "tests/fake_servo.h"

/* A line on which one frame comes again every every_us until stop_us. */
typedef struct babble {
    uint64_t now_us, next_us, every_us, stop_us;
    uint8_t frame[32];
    size_t len;
    int read_rc; /* 1: reads as told above; else what every read returns */
} babble;

static babble line;
static sb_bus bus;
static const uint8_t two[2] = {1, 2};
static sb_monitor_answer states[2];
static bool got[2];

static int babble_write(void *ctx, const uint8_t *data, size_t len)
{
    (void)data;
    ((babble *)ctx)->now_us += len * 10u; /* 1 Mbaud */
    return 0;
}

static int babble_read(void *ctx, uint8_t *buf, size_t cap, size_t want, uint32_t wait_us)
{
    babble *b = (babble *)ctx;
    uint64_t ready = b->next_us + b->len * 10u;
    if (b->read_rc != 1)
        return b->read_rc;
    if (b->len == 0 || b->next_us >= b->stop_us || ready > b->now_us + wait_us || cap < b->len) {
        b->now_us += wait_us;
        return 0;
    }
    b->now_us = ready > b->now_us ? ready : b->now_us;
    b->next_us += b->every_us;
    memcpy(buf, b->frame, b->len);
    return (int)b->len;
}

static uint64_t babble_now(void *ctx)
{
    return ((babble *)ctx)->now_us;
}

static int set_up(void **state)
{
    memset(&line, 0, sizeof line);
    line.read_rc = 1;
    line.next_us = 100;
    line.every_us = 2000;
    line.stop_us = 1000000; /* a second of babble: far past any round */
    sb_bus_init(&bus, sb_transport_make(&line, babble_write, babble_read, babble_now), 1000000);
    return 0;
}

/* The latest a round of count may end: each servo's slot and silence. */
static uint64_t round_end(size_t count)
{
    uint64_t slot = SB_TURNAROUND_US + (2u + sb_answer_frame_size(SB_PKT_MONITOR)) * 10u + bus.answer_margin_us;
    return bus.sent_end_us + count * (slot + SB_SYNC_SILENCE_US);
}

static void servo_1_babbles(void)
{
    sb_value v[8];
    memset(v, 0, sizeof v);
    v[0].n = 1;
    v[1].n = 7400;
    v[5].n = 1;
    assert_int_equal(sb_encode_answer(SB_PKT_MONITOR, v, 8, line.frame, sizeof line.frame, &line.len).status, SB_OK);
}

static void a_servo_answering_again_and_again_cannot_hold_a_round_open(void **state)
{
    sb_loop l;
    int32_t angles[2] = {0, 0};
    servo_1_babbles();
    sb_error e = sb_sync_monitor(&bus, two, 2, states, got);
    assert_true(line.now_us <= round_end(2));
    assert_int_equal(e.status, SB_E_NO_ANSWER);
    assert_int_equal(e.servo, 2);
    assert_true(got[0] && !got[1]);
    assert_int_equal(sb_loop_init(&l, &bus, two, 2, 10).status, SB_OK);
    e = sb_loop_cycle(&l, angles, NULL, states, got);
    assert_true(line.now_us <= round_end(2));
    assert_int_equal(e.status, SB_E_NO_ANSWER);
}

static void a_misshapen_frame_of_another_servo_cannot_hold_a_round_open(void **state)
{
    uint8_t content[3] = {9, 0, 0}; /* servo 9's Monitor, its checksum good, its length not */
    assert_int_equal(sb_frame(false, SB_PKT_MONITOR, content, 3, line.frame, sizeof line.frame, &line.len).status,
                     SB_OK);
    sb_error e = sb_sync_monitor(&bus, two, 2, states, got);
    assert_true(line.now_us <= round_end(2));
    assert_int_equal(e.status, SB_E_NO_ANSWER);
    assert_int_equal(e.servo, 1);
    assert_true(!got[0] && !got[1]);
}

static void got_says_none_after_a_refusal_or_a_link_error(void **state)
{
    uint8_t twice[2] = {1, 1};
    sb_loop l;
    int32_t angles[2] = {0, 0};
    got[0] = got[1] = true; /* as a round before left them */
    assert_int_equal(sb_sync_monitor(&bus, twice, 2, states, got).status, SB_E_DUPLICATE_ID);
    assert_true(!got[0] && !got[1]);
    assert_int_equal(sb_loop_init(&l, &bus, two, 2, 10).status, SB_OK);
    assert_int_equal(sb_loop_cycle(&l, angles, NULL, states, got).status, SB_E_NO_ANSWER);
    got[0] = got[1] = true;
    angles[0] = 1000; /* 100 deg in 10 ms: faster than the servo moves */
    assert_int_equal(sb_loop_cycle(&l, angles, NULL, states, got).status, SB_E_RANGE);
    assert_true(!got[0] && !got[1]);
    got[0] = got[1] = true;
    line.read_rc = -EIO;
    assert_int_equal(sb_sync_monitor(&bus, two, 2, states, got).status, SB_E_LINK);
    assert_true(!got[0] && !got[1]);
}

static void a_transport_return_without_an_errno_is_a_link_error(void **state)
{
    sb_ping_request r = {1};
    sb_ping_answer a;
    line.read_rc = INT_MIN; /* its negation would overflow */
    sb_error e = sb_call_ping(&bus, &r, &a);
    assert_int_equal(e.status, SB_E_LINK);
    assert_int_equal(e.os_error, EIO);
}

/* The answer of a ReadData about item 8 before (late), to one about item 1. */
static void an_answer_about_another_item_is_not_taken_for_this_one(void **state)
{
    sb_read_data_request r = {1, 1};
    sb_read_data_answer a;
    sb_value v[3] = {{1, NULL, 0}, {8, NULL, 0}, {0x12345678, NULL, 0}};
    assert_int_equal(sb_encode_answer(SB_PKT_READ_DATA, v, 3, line.frame, sizeof line.frame, &line.len).status, SB_OK);
    line.stop_us = line.next_us + 1u; /* once */
    sb_error e = sb_call_read_data(&bus, &r, &a);
    assert_int_equal(e.status, SB_E_BAD_ANSWER);
    assert_string_equal(e.field, "data_id");
    assert_int_equal(e.value, 8);
    assert_int_equal(e.least, 1);
    assert_int_equal(e.most, 1);
}

static void a_bus_clock_near_its_end_does_not_wrap_a_deadline(void **state)
{
    fake_bus fake;
    sb_ping_request r = {1};
    sb_ping_answer a;
    fake_init(&fake, 1000000);
    fake.present[1] = true;
    sb_bus_init(&bus, fake_transport(&fake), 1000000);
    fake.now_us = UINT64_MAX - 50000u; /* 50 ms before the clock's end: the 100 ms time-out passes it */
    assert_int_equal(sb_call_ping(&bus, &r, &a).status, SB_OK);
    assert_int_equal(a.id, 1);
}

/* A line that carries given bytes after the request, a byte each 10 us (1 Mbaud). */
typedef struct script {
    const uint8_t *bytes;
    size_t len, at;
    bool sent;
    uint64_t now_us;
} script;

static int script_write(void *ctx, const uint8_t *data, size_t len)
{
    (void)data;
    script *w = (script *)ctx;
    w->now_us += 10u * len;
    w->sent = true;
    return 0;
}

static int script_read(void *ctx, uint8_t *buf, size_t cap, size_t want, uint32_t wait_us)
{
    (void)want;
    script *w = (script *)ctx;
    if (!w->sent || w->at == w->len || cap == 0) {
        w->now_us += wait_us;
        return 0;
    }
    w->now_us += 10u;
    buf[0] = w->bytes[w->at++];
    return 1;
}

static uint64_t script_now(void *ctx)
{
    return ((script *)ctx)->now_us;
}

/* Servo 2's Monitor answer (7173 mV, 4118 mA, power 4) and then servo 4's:
 * a frame that begins inside servo 2's answer at its bytes 05 1c 16 10
 * and ends on servo 4's ID byte has a good checksum, and names servo 4. It
 * was taken as servo 4's state (53 249 mV, angle 470 123 264), and servo
 * 4's real answer dropped as one whose turn had passed. */
static void a_frame_across_two_answers_is_not_taken_for_either(void **state)
{
    static const uint8_t wire[] = {
        0x05, 0x1c, 0x16, 0x10, 0x02, 0x05, 0x1c, 0x16, 0x10, 0x04, 0x01, 0xd0, 0x07, 0x00, 0x17,
        0x00, 0x00, 0x00, 0x00, 0x00, 0x83, 0x05, 0x1c, 0x16, 0x10, 0x04, 0xe8, 0x1c, 0x78, 0x00,
        0x84, 0x03, 0xd0, 0x07, 0x00, 0xc2, 0x01, 0x00, 0x00, 0x00, 0x00, 0xe8};
    script w = {wire, sizeof wire, 0, false, 1000};
    sb_bus sbus;
    sb_bus_init(&sbus, sb_transport_make(&w, script_write, script_read, script_now), 1000000);
    const uint8_t ids[2] = {2, 4};
    assert_int_equal(sb_sync_monitor(&sbus, ids, 2, states, got).status, SB_OK);
    assert_true(got[0] && got[1]);
    assert_int_equal(states[0].voltage, 7173);
    assert_int_equal(states[1].voltage, 7400);
    assert_int_equal(states[1].current, 120);
    assert_int_equal(states[1].angle, 450);
}

/* Servo 1's answer cut after 12 bytes (a collision, a brown-out), servo
 * 4's answer whole after it: the frame begun at servo 1's header and
 * ended inside servo 4's has a good checksum by chance (servo 4's 40 mA),
 * and was taken as servo 1's state (angle -402 386 922, 10 268 turns),
 * servo 4's dropped. A Monitor answer's angle and turns have the
 * multi-turn range: it is a bad answer, and servo 4's is taken. */
static void a_cut_answer_read_into_the_next_is_a_bad_answer(void **state)
{
    static const uint8_t wire[] = {
        0x05, 0x1c, 0x16, 0x10, 0x01, 0xe8, 0x1c, 0x78, 0x00, 0xf4, 0x01, 0xd0, 0x05, 0x1c, 0x16,
        0x10, 0x04, 0xe8, 0x1c, 0x28, 0x00, 0xf4, 0x01, 0xd0, 0x07, 0x00, 0xd4, 0xfe, 0xff, 0xff,
        0x00, 0x00, 0x13,
    };
    script w = {wire, sizeof wire, 0, false, 1000};
    sb_bus sbus;
    sb_bus_init(&sbus, sb_transport_make(&w, script_write, script_read, script_now), 1000000);
    const uint8_t ids[2] = {1, 4};
    sb_error e = sb_sync_monitor(&sbus, ids, 2, states, got);
    assert_true(!got[0] && got[1]);
    assert_int_equal(states[1].current, 40);
    assert_int_equal(states[1].angle, -300);
    assert_int_equal(e.status, SB_E_BAD_ANSWER);
    assert_int_equal(e.servo, 1);
    assert_string_equal(e.field, "angle");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(a_servo_answering_again_and_again_cannot_hold_a_round_open, set_up),
        cmocka_unit_test_setup(a_misshapen_frame_of_another_servo_cannot_hold_a_round_open, set_up),
        cmocka_unit_test_setup(got_says_none_after_a_refusal_or_a_link_error, set_up),
        cmocka_unit_test_setup(a_transport_return_without_an_errno_is_a_link_error, set_up),
        cmocka_unit_test_setup(an_answer_about_another_item_is_not_taken_for_this_one, set_up),
        cmocka_unit_test_setup(a_bus_clock_near_its_end_does_not_wrap_a_deadline, set_up),
        cmocka_unit_test_setup(a_frame_across_two_answers_is_not_taken_for_either, set_up),
        cmocka_unit_test_setup(a_cut_answer_read_into_the_next_is_a_bad_answer, set_up),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
