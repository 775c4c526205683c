/* servobus's bus on a link that misbehaves: noise that looks like a header,
 * an answer cut short or of the wrong length, requests no servo would
 * answer, and a transport's odd return values. */
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
static const uint8_t three[3] = {1, 2, 3};
static sb_monitor_answer states[3];
static bool got[3];

static int set_up(void **state)
{
    fake_init(&fake, 1000000);
    sb_bus_init(&bus, fake_transport(&fake), 1000000);
    fake.present[1] = fake.present[2] = fake.present[3] = true;
    return 0;
}

/* Two noise bytes that look like an answer's header, ahead of this request's answers. */
static void noise_ahead(void)
{
    fake.late[0] = SB_RESPONSE_HEADER_0;
    fake.late[1] = SB_RESPONSE_HEADER_1;
    fake.late_len = 2;
}

static void noise_that_looks_like_a_header_costs_only_its_bytes(void **state)
{
    noise_ahead();
    assert_int_equal(sb_sync_monitor(&bus, three, 3, states, got).status, SB_OK);
    assert_true(got[0] && got[1] && got[2]);
    assert_int_equal(states[0].id, 1);
    /* A single call: its answer found behind the noise, not at its time-out. */
    sb_read_angle_request r = {3};
    sb_read_angle_answer a;
    uint64_t before = fake.now_us;
    noise_ahead();
    assert_int_equal(sb_call_read_angle(&bus, &r, &a).status, SB_OK);
    assert_int_equal(a.angle, -123);
    assert_true(fake.now_us - before < 1000u); /* the fake's clock: the wire's time, not 100 ms */
}

static void an_answer_cut_short_costs_only_its_bytes(void **state)
{
    fake.cut[1] = 6; /* header, code, length, ID and a byte: then servo 2's answer */
    sb_error e = sb_sync_monitor(&bus, three, 3, states, got);
    assert_int_equal(e.status, SB_E_BAD_CHECKSUM); /* servo 1's, with servo 2's first bytes */
    assert_int_equal(e.servo, 1);
    assert_true(!got[0] && got[1] && got[2]);
    assert_int_equal(states[1].id, 2);
}

static void an_answer_of_the_wrong_length_is_skipped_and_the_round_goes_on(void **state)
{
    fake.one_short[2] = true;
    sb_error e = sb_sync_monitor(&bus, three, 3, states, got);
    assert_int_equal(e.status, SB_E_BAD_ANSWER);
    assert_int_equal(e.servo, 2);
    assert_true(got[0] && !got[1] && got[2]);
    assert_int_equal(states[2].id, 3);
}

/* 7173 mV, 3 mA, 36 mW: the answer's content holds a whole frame of its own
 * (05 1c 03 00 24); the answer is still found, at once. */
static void an_answer_whose_content_holds_a_frame_is_not_lost(void **state)
{
    sb_monitor_request r = {2};
    sb_monitor_answer a;
    uint64_t before;
    fake.power[0] = 7173;
    fake.power[1] = 3;
    fake.power[2] = 36;
    assert_int_equal(sb_sync_monitor(&bus, three, 3, states, got).status, SB_OK);
    assert_true(got[0] && got[1] && got[2]);
    assert_int_equal(states[0].voltage, 7173);
    before = fake.now_us;
    assert_int_equal(sb_call_monitor(&bus, &r, &a).status, SB_OK);
    assert_int_equal(a.voltage, 7173);
    assert_true(fake.now_us - before < 1000u); /* the fake's clock: the wire's time, not 100 ms */
}

static void duplicate_ids_are_refused_before_anything_is_sent(void **state)
{
    uint8_t ids[3] = {1, 2, 1};
    char text[120];
    sb_error e = sb_sync_monitor(&bus, ids, 3, states, got);
    assert_int_equal(e.status, SB_E_DUPLICATE_ID);
    assert_int_equal(e.servo, 1);
    assert_int_equal(e.packet, SB_PKT_MONITOR);
    assert_int_equal(fake.frames, 0);
    sb_error_text(&e, text, sizeof text);
    assert_string_equal(text, "servo 1: Monitor: ids listed twice; nothing was sent");
}

static void a_request_that_answers_is_not_sent_to_the_broadcast_id(void **state)
{
    sb_ping_request p = {SB_BROADCAST_ID};
    sb_ping_answer pa;
    uint8_t ids[2] = {1, SB_BROADCAST_ID};
    char text[120];
    uint64_t before = fake.now_us;
    sb_error e = sb_call_ping(&bus, &p, &pa);
    assert_int_equal(e.status, SB_E_BROADCAST);
    assert_int_equal(e.servo, SB_BROADCAST_ID);
    assert_int_equal(fake.frames, 0);
    assert_int_equal(fake.now_us, before); /* no time-out waited */
    sb_error_text(&e, text, sizeof text);
    assert_string_equal(text, "servo 255: Ping: id is the broadcast ID: no servo answers it or carries it out; "
                              "nothing was sent");
    assert_int_equal(sb_sync_monitor(&bus, ids, 2, states, got).status, SB_E_BROADCAST);
    assert_int_equal(fake.frames, 0);
    sb_move_angle_request m = {SB_BROADCAST_ID, 0, 100, 0}; /* every servo moves, none answers */
    assert_int_equal(sb_send_move_angle(&bus, &m).status, SB_OK);
}

/* A transport over the fake that misbehaves as told. */
static int eintr_reads, eintr_writes;
static bool reads_too_much;

static int odd_read(void *ctx, uint8_t *buf, size_t cap, size_t want, uint32_t wait_us)
{
    int n;
    if (eintr_reads > 0) {
        eintr_reads--;
        return -EINTR;
    }
    n = fake_transport(&fake).read(ctx, buf, cap, want, wait_us);
    return reads_too_much && n > 0 ? (int)cap + 1 : n;
}

static int odd_write(void *ctx, const uint8_t *data, size_t len)
{
    if (eintr_writes > 0) {
        eintr_writes--;
        return -EINTR;
    }
    return fake_transport(&fake).write(ctx, data, len);
}

static int odd_set_up(void **state)
{
    set_up(state);
    eintr_reads = eintr_writes = 0;
    reads_too_much = false;
    bus.t.read = odd_read;
    bus.t.write = odd_write;
    return 0;
}

static void a_read_beyond_its_cap_is_a_link_error(void **state)
{
    sb_read_angle_request r = {3};
    sb_read_angle_answer a;
    reads_too_much = true;
    sb_error e = sb_call_read_angle(&bus, &r, &a);
    assert_int_equal(e.status, SB_E_LINK);
    assert_int_equal(e.os_error, EOVERFLOW);
    assert_int_equal(e.servo, 3);
}

static void an_interrupted_read_or_write_is_tried_again(void **state)
{
    sb_read_angle_request r = {3};
    sb_read_angle_answer a;
    eintr_writes = 2;
    eintr_reads = 3;
    assert_int_equal(sb_call_read_angle(&bus, &r, &a).status, SB_OK);
    assert_int_equal(a.angle, -123);
    assert_int_equal(eintr_reads + eintr_writes, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(noise_that_looks_like_a_header_costs_only_its_bytes, set_up),
        cmocka_unit_test_setup(an_answer_cut_short_costs_only_its_bytes, set_up),
        cmocka_unit_test_setup(an_answer_of_the_wrong_length_is_skipped_and_the_round_goes_on, set_up),
        cmocka_unit_test_setup(an_answer_whose_content_holds_a_frame_is_not_lost, set_up),
        cmocka_unit_test_setup(duplicate_ids_are_refused_before_anything_is_sent, set_up),
        cmocka_unit_test_setup(a_request_that_answers_is_not_sent_to_the_broadcast_id, set_up),
        cmocka_unit_test_setup(a_read_beyond_its_cap_is_a_link_error, odd_set_up),
        cmocka_unit_test_setup(an_interrupted_read_or_write_is_tried_again, odd_set_up),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
