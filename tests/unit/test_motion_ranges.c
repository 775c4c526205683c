/* The ends of the position range (docs/decisions-motion.md, "The ends of every
 * range"): whatever turns the horn, the multi-turn reading stays within
 * +-3 686 400, its turn count agrees with it, a move in flight goes on
 * across a shift of the origin, and the controller's error saturates
 * instead of changing sign. The encoder is turned by the test (a load, a
 * wheel) by 1000 counts per ms, so that even two ticks late (the harness
 * runs no tick while it feeds a request's bytes) it has turned less than
 * the half turn the multi-turn tracking can follow. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "support/by_name.h"
#include "support/servo_harness.h"

enum { LIMIT = 3686400, SHIFT = 3686400, TURN = 3600 };

/* The horn turned by something outside: counts per ms from a start time. */
static struct {
    int32_t start_counts;
    uint32_t start_us;
    int32_t counts_per_ms;
} spin;

static uint16_t spun_encoder(void *model)
{
    (void)model;
    int64_t ms = (int64_t)(hal.now_us - spin.start_us) / 1000;
    int64_t counts = spin.start_counts + ms * spin.counts_per_ms;
    return (uint16_t)(counts & (ENCODER_COUNTS - 1));
}

static void spin_at(int32_t counts_per_ms)
{
    spin.start_counts = servo.motion.encoder.counts;
    spin.start_us = hal.now_us;
    spin.counts_per_ms = counts_per_ms;
    hal.encoder_model = spun_encoder;
}

static int setup(void **state)
{
    (void)state;
    harness_init();
    WRITE_ITEM(0, ITEM_SOFT_START_ON, 0); /* no soft start */
    WRITE_ITEM(0, ITEM_STALL_RELEASE, 0); /* a stall limits the power, keeps control */
    return 0;
}

/* ReadMultiTurnAngle (16), decoded. */
static void read_multi_turn(int32_t *angle, int16_t *turns)
{
    REQUEST(PKT_READ_MULTI_TURN_ANGLE, 0);
    *angle = ANSWER_FIELD(PKT_READ_MULTI_TURN_ANGLE, ANSWER_READ_MULTI_TURN_ANGLE_ANGLE);
    *turns = (int16_t)ANSWER_FIELD(PKT_READ_MULTI_TURN_ANGLE, ANSWER_READ_MULTI_TURN_ANGLE_TURNS);
}

/* Until the horn has spun for ms milliseconds: the reading within the range, its turns the whole
 * turns in it, and it moved the way the horn turns, by no more than the
 * horn can have turned (a read takes time on the wire too), once a shift at
 * an end is taken off. Returns the shifts seen. */
static unsigned watch_reading(uint32_t ms, int32_t counts_per_ms)
{
    int32_t last;
    int16_t turns;
    read_multi_turn(&last, &turns);
    unsigned shifts = 0;
    int32_t most = 4 * counts_per_ms * 225 / 256; /* decideg in 4 ms */
    while (hal.now_us - spin.start_us < ms * 1000u) {
        harness_run_ms(1);
        int32_t angle;
        read_multi_turn(&angle, &turns);
        assert_true(angle >= -LIMIT && angle <= LIMIT);
        assert_int_equal(turns, angle / TURN);
        int32_t moved = angle - last;
        if (moved > SHIFT / 2 || moved < -SHIFT / 2) {
            moved += moved < 0 ? SHIFT : -SHIFT;
            shifts++;
        }
        assert_true(most > 0 ? moved >= 0 && moved <= most : moved <= 0 && moved >= most);
        last = angle;
    }
    return shifts;
}

/* Released and turned by a load through 1500 turns either way: the reading
 * passes each end once and goes on from about 0 (it used to read
 * 5 400 000). */
static void test_a_back_driven_reading_stays_in_range(void **state)
{
    (void)state;
    REQUEST(PKT_STOP_ON_CONTROL_MODE, 0, 0x10, 0, 0); /* released */
    spin_at(1000);              /* 0.24 turn per ms */
    assert_int_equal(watch_reading(6150, 1000), 1); /* 1500 turns */
    spin_at(-1000);
    assert_int_equal(watch_reading(12300, -1000), 2);
}

/* Wheel mode for a number of turns that crosses the end of the range: the
 * move goes on across the shift and stops exactly that many turns on. */
static void test_a_wheel_move_across_the_end_keeps_its_length(void **state)
{
    (void)state;
    REQUEST(PKT_STOP_ON_CONTROL_MODE, 0, 0x10, 0, 0);
    spin_at(1000);
    harness_run_ms(4180); /* 1020.5 turns */
    harness_ideal_tracking();
    int32_t start;
    int16_t turns;
    read_multi_turn(&start, &turns);
    assert_true(start > LIMIT - 5 * TURN && start < LIMIT - 3 * TURN);
    REQUEST(PKT_MOVE_WHEEL, 0, 0x02, 0xEE, 0x02, 0x08, 0x00); /* ccw (growing), 750 deg/s, 8 turns */
    harness_run_ms(5000);
    assert_false(servo.regs.status.status & STATUS_EXECUTING);
    int32_t end;
    read_multi_turn(&end, &turns);
    assert_int_equal(end, start + 8 * TURN - SHIFT);
    assert_int_equal(turns, end / TURN);
}

/* Held near the top of the range while a load turns the horn back 3000
 * turns: the origin shifts with the horn, the error grows past what a
 * 32-bit Q8 number holds (2330 turns), and the output must keep pushing
 * towards the setpoint all the way; an unsaturated error changed sign and
 * drove the horn away from its target. */
static void test_the_error_saturates_instead_of_changing_sign(void **state)
{
    (void)state;
    /* The multi-turn range is beyond the angle limits: off, straight in
     * the register (a WriteData's save would stall the loop mid-spin). */
    servo.regs.user.angle_limit_on = 0;
    servo.regs.firmware.oscillation_ms = 0; /* the load's spin is no runaway of its own */
    REQUEST(PKT_STOP_ON_CONTROL_MODE, 0, 0x10, 0, 0);
    spin_at(1000);
    harness_run_ms(4180);
    harness_ideal_tracking();
    REQUEST(PKT_MOVE_MULTI_TURN, 0, 0x00, 0x40, 0x38, 0x00, 0x64, 0x00, 0x00, 0x00, 0, 0); /* 3 686 400, 100 ms */
    harness_run_ms(5000);
    int32_t angle;
    int16_t turns;
    read_multi_turn(&angle, &turns);
    assert_int_equal(angle, LIMIT);
    spin_at(-1000);
    int32_t furthest = 0;
    for (int ms = 0; ms < 12300; ms++) {
        harness_run_ms(1);
        assert_int_equal(motion_output_at_limit(&servo.motion), 1);
        /* The distance the profile holds exactly; the tick's Q8 copy of
         * the setpoint saturates at 2^30 on the same side. */
        int64_t error = ((servo.motion.profile.target >> 24) - servo.motion.measured_q8) >> 8;
        assert_true(servo.motion.setpoint_q8 > servo.motion.measured_q8);
        assert_true(error > 0);
        furthest = error > furthest ? (int32_t)error : furthest;
    }
    assert_true(furthest > 2330 * TURN); /* beyond int32 in Q8 */
}

/* Powered up, the horn is in the turn around its zero (item 90): the
 * reading is -180..180 deg whichever side of the zero the encoder's count
 * is (servo_sim and the F030 read -30 deg as 330 deg). */
static void test_power_up_takes_the_turn_around_the_zero(void **state)
{
    (void)state;
    static const struct {
        uint16_t zero, raw;
        int16_t offset; /* item 53: the reading is in -180..180 deg after it */
        int32_t decideg;
    } cases[] = {
        {0, 4096 - 342, 0, -301}, {0, 342, 0, 301},      {0, 2047, 0, 1799}, {0, 2048, 0, -1800},
        {1000, 3500, 0, -1403},   {1000, 2500, 0, 1318}, {4000, 100, 0, 172},
        {0, 2617, 1000, 1300},    {0, 1479, -1000, -1300}, {1000, 3617, 1000, 1300},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        WRITE_ITEM(0, ITEM_ENCODER_ZERO, cases[i].zero);
        WRITE_ITEM(0, ITEM_CENTER_OFFSET_DECIDEG, cases[i].offset);
        hal.encoder_model = NULL;
        hal.encoder_raw = cases[i].raw;
        harness_restart();
        harness_run_ms(2);
        int32_t angle;
        int16_t turns;
        read_multi_turn(&angle, &turns);
        assert_int_equal(angle, cases[i].decideg);
        assert_int_equal(turns, 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_power_up_takes_the_turn_around_the_zero, setup),
        cmocka_unit_test_setup(test_a_back_driven_reading_stays_in_range, setup),
        cmocka_unit_test_setup(test_a_wheel_move_across_the_end_keeps_its_length, setup),
        cmocka_unit_test_setup(test_the_error_saturates_instead_of_changing_sign, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
