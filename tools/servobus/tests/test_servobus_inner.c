/* servobus with frames inside answers: a frame made of one answer's tail
 * and the next one's head, or of an answer's own content, is a good frame
 * the finder hands back; the bus takes the real answer, not it. The line
 * is scripted (1 Mbaud: a byte every 10 us on the line's clock, never the
 * host's). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "servobus/servobus.h"

/* The answers, queued after each request: readable a byte every 10 us. */
typedef struct script {
    uint64_t now_us, from_us;
    uint8_t reply[256];
    size_t len, at;
} script;

static script line;
static sb_bus bus;

static int script_write(void *ctx, const uint8_t *data, size_t len)
{
    script *s = (script *)ctx;
    (void)data;
    s->now_us += len * 10u;
    s->from_us = s->now_us + 100u; /* the servos' turnaround */
    s->at = 0;
    return 0;
}

static int script_read(void *ctx, uint8_t *buf, size_t cap, size_t want, uint32_t wait_us)
{
    script *s = (script *)ctx;
    size_t n = 0;
    (void)want;
    if (s->at < s->len && s->from_us + (s->at + 1u) * 10u > s->now_us + wait_us) {
        s->now_us += wait_us;
        return 0;
    }
    if (s->at >= s->len) {
        s->now_us += wait_us;
        return 0;
    }
    if (s->from_us + (s->at + 1u) * 10u > s->now_us)
        s->now_us = s->from_us + (s->at + 1u) * 10u;
    while (n < cap && s->at < s->len && s->from_us + (s->at + 1u) * 10u <= s->now_us)
        buf[n++] = s->reply[s->at++];
    return (int)n;
}

static uint64_t script_now(void *ctx)
{
    return ((script *)ctx)->now_us;
}

static int set_up(void **state)
{
    (void)state;
    memset(&line, 0, sizeof line);
    sb_bus_init(&bus, sb_transport_make(&line, script_write, script_read, script_now), 1000000);
    return 0;
}

/* A Monitor answer of id queued on the line. */
static void monitor(int64_t id, int64_t mv, int64_t ma, int64_t mw, int64_t adc, int64_t angle)
{
    sb_value v[8] = {{id, NULL, 0}, {mv, NULL, 0}, {ma, NULL, 0}, {mw, NULL, 0},
                     {adc, NULL, 0}, {1, NULL, 0},  {angle, NULL, 0}, {0, NULL, 0}};
    size_t n = 0;
    assert_int_equal(sb_encode_answer(SB_PKT_MONITOR, v, 8, line.reply + line.len, sizeof line.reply - line.len, &n)
                         .status,
                     SB_OK);
    line.len += n;
}

static const char *words(sb_error e)
{
    static char text[160];
    sb_error_text(&e, text, sizeof text);
    return text;
}

/* Servo 2 at 7173 mV, 4118 mA, 29442 mW, ADC 1903: its bytes from its
 * voltage on and servo 4's answer's first five make a whole Monitor frame
 * of servo 2 (05 1c 16 10 02 ... 05 1c 16 10 04), ending after servo 2's
 * answer was taken; with 29441 mW and ADC 1904, one of servo 1. */
static void a_frame_across_two_answers_does_not_replace_one_taken(void **state)
{
    static const uint8_t ids[3] = {1, 2, 4};
    sb_monitor_answer st[3];
    bool got[3];
    for (int claimed = 1; claimed <= 2; claimed++) {
        set_up(state);
        monitor(1, 7400, 300, 2200, 1800, 100);
        monitor(2, 7173, 4118, 0x7300 + claimed, claimed == 2 ? 1903 : 1904, 900);
        monitor(4, 7400, 310, 2300, 1810, -450);
        assert_int_equal(sb_checksum(line.reply + 26, 20), line.reply[46]); /* the frame across is good */
        assert_int_equal(sb_sync_monitor(&bus, ids, 3, st, got).status, SB_OK);
        assert_true(got[0] && got[1] && got[2]);
        assert_int_equal(st[0].voltage, 7400);
        assert_int_equal(st[0].angle, 100);
        assert_int_equal(st[1].voltage, 7173);
        assert_int_equal(st[1].current, 4118);
        assert_int_equal(st[1].angle, 900);
        assert_int_equal(st[2].angle, -450);
    }
}

/* The last servo's answer holds 05 1c 16 02 f6 0e 3d, a Monitor frame of
 * servo 246 two bytes long: skipped, it does not end the round before the
 * answer does. */
static void the_last_servos_answer_holding_a_short_frame_of_itself_is_taken(void **state)
{
    static const uint8_t ids[3] = {1, 2, 246};
    sb_monitor_answer st[3];
    bool got[3];
    (void)state;
    monitor(1, 7400, 300, 2200, 1800, 900);
    monitor(2, 7400, 300, 2200, 1800, 900);
    monitor(246, 7173, 534, 3830, 1853, 900);
    assert_int_equal(sb_sync_monitor(&bus, ids, 3, st, got).status, SB_OK);
    assert_true(got[0] && got[1] && got[2]);
    assert_int_equal(st[2].voltage, 7173);
    assert_int_equal(st[2].power, 3830);
}

/* Single calls: the answer's content holds a shorter frame of the same
 * packet and servo; the call waits for the answer. */
static void a_call_skips_a_shorter_frame_inside_its_answer(void **state)
{
    sb_monitor_request m = {246};
    sb_monitor_answer ma;
    sb_read_faults_request f;
    sb_read_faults_answer fa;
    sb_value v[12] = {{57, NULL, 0},   {3, NULL, 0},   {0, NULL, 0},   {12, NULL, 0},
                      {3600, NULL, 0}, {900, NULL, 0}, {7173, NULL, 0}, {579, NULL, 0},
                      {4153, NULL, 0}, {431, NULL, 0}, {350, NULL, 0}, {5, NULL, 0}};
    monitor(246, 7173, 534, 3830, 1853, 900);
    assert_int_equal(sb_call_monitor(&bus, &m, &ma).status, SB_OK);
    assert_int_equal(ma.voltage, 7173);
    assert_int_equal(ma.temperature, 1853);
    set_up(state);
    assert_int_equal(sb_encode_answer(SB_PKT_READ_FAULTS, v, 12, line.reply, sizeof line.reply, &line.len).status,
                     SB_OK);
    memset(&f, 0, sizeof f);
    f.id = 57;
    assert_int_equal(sb_call_read_faults(&bus, &f, &fa).status, SB_OK);
    assert_int_equal(fa.id, 57);
}

/* Only a frame of the wrong length came: the error says both lengths. */
static void a_wrong_length_says_the_lengths(void **state)
{
    static const uint8_t ids[1] = {7};
    static const uint8_t content[2] = {7, 0};
    sb_monitor_request m = {7};
    sb_monitor_answer ma;
    sb_monitor_answer st[1];
    bool got[1];
    assert_int_equal(sb_frame(false, SB_PKT_MONITOR, content, 2, line.reply, sizeof line.reply, &line.len).status,
                     SB_OK);
    assert_string_equal(words(sb_call_monitor(&bus, &m, &ma)), "servo 7: Monitor: length a bad answer: 2 bytes, not 16");
    assert_string_equal(words(sb_sync_monitor(&bus, ids, 1, st, got)),
                        "servo 7: Monitor: length a bad answer: 2 bytes, not 16");
    (void)state;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(a_frame_across_two_answers_does_not_replace_one_taken, set_up),
        cmocka_unit_test_setup(the_last_servos_answer_holding_a_short_frame_of_itself_is_taken, set_up),
        cmocka_unit_test_setup(a_call_skips_a_shorter_frame_inside_its_answer, set_up),
        cmocka_unit_test_setup(a_wrong_length_says_the_lengths, set_up),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
