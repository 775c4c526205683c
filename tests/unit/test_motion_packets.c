/* Every motion packet and every rule of docs/protocol.md, "Moves": request
 * bytes in, response bytes and behaviour out, on an ideal servo (the encoder
 * follows the setpoint while under control). Its power and current
 * protections are at their most, so that the motor's own limits (the
 * firmware brakes no harder than the output can) leave the moves' timing
 * alone; tests of those limits run on the plant (test_control_loop.c). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "motion/controller.h"
#include "motion/gains.h"
#include "protocol/packet_table.h"
#include "support/by_name.h"
#include "support/servo_harness.h"

static void full_power(void)
{
    WRITE_ITEM(0, ITEM_POWER_LIMIT_MW, 65535);
    WRITE_ITEM(0, ITEM_CURRENT_LIMIT_MA, 65535);
}

static int setup(void **state)
{
    (void)state;
    harness_init();
    harness_ideal_tracking();
    full_power();
    WRITE_ITEM(0, ITEM_SOFT_START_ON, 0); /* soft start off, except where a test turns it on */
    return 0;
}

static int setup_soft_start(void **state)
{
    (void)state;
    harness_init();
    harness_ideal_tracking();
    full_power();
    return 0;
}

static bool executing(void)
{
    return servo.regs.status.status & STATUS_EXECUTING;
}

static int32_t angle_now(void)
{
    struct motion_angle a;
    motion_read_angle(&servo.motion, &a);
    return a.multi_turn_decideg;
}

/* Runs until the executing bit falls and returns the milliseconds that
 * took; then lets 5 ms pass, as the encoder reads a tick behind. */
static uint32_t run_until_done(uint32_t limit_ms)
{
    uint32_t ms = 0;
    while (executing() && ms < limit_ms) {
        harness_run_ms(1);
        ms++;
    }
    assert_false(executing());
    harness_run_ms(5);
    return ms;
}

static void test_angle_move_reaches_target(void **state)
{
    (void)state;
    REQUEST(PKT_MOVE_ANGLE, 0, 0x84, 0x03, 0xF4, 0x01, 0x00, 0x00); /* 90.0 deg in 500 ms */
    EXPECT_SILENCE();
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_RESPONSE(PKT_READ_DATA, 0, ITEM_STATUS, STATUS_EXECUTING);
    assert_in_range(run_until_done(1000), 495, 505);
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_ITEM(0, ITEM_STATUS, 0);
    REQUEST(PKT_READ_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_ANGLE, 0, 0x84, 0x03);
    REQUEST(PKT_READ_MULTI_TURN_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_MULTI_TURN_ANGLE, 0, 0x84, 0x03, 0x00, 0x00, 0x00, 0x00);
    /* Then it holds there, under control. */
    assert_false(motion_is_released(&servo.motion));
    assert_false(hal.coasting);
}

static void test_soft_start_times_the_first_move(void **state)
{
    (void)state;
    REQUEST(PKT_MOVE_ANGLE, 0, 0x84, 0x03, 0xF4, 0x01, 0x00, 0x00);
    assert_in_range(run_until_done(5000), 2995, 3005); /* 3000 ms (data 50) */
    REQUEST(PKT_MOVE_ANGLE, 0, 0x00, 0x00, 0xF4, 0x01, 0x00, 0x00);
    assert_in_range(run_until_done(5000), 495, 505); /* only the first */
    REQUEST(PKT_READ_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_ANGLE, 0, 0x00, 0x00);
}

static void test_single_turn_targets_are_clamped_to_the_limits(void **state)
{
    (void)state;
    REQUEST(PKT_MOVE_ANGLE, 0, 0xDC, 0x05, 0xC8, 0x00, 0x00, 0x00); /* 150.0 > 135.0 limit */
    run_until_done(1000);
    REQUEST(PKT_READ_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_ANGLE, 0, 0x46, 0x05); /* 1350 */
    REQUEST(PKT_MOVE_ANGLE, 0, 0x24, 0xFA, 0xC8, 0x00, 0x00, 0x00); /* -150.0 */
    run_until_done(1000);
    REQUEST(PKT_READ_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_ANGLE, 0, 0xBA, 0xFA); /* -1350 */
    WRITE_ITEM(0, ITEM_ANGLE_MAX_DECIDEG, 900);                      /* upper limit 90.0 */
    REQUEST(PKT_MOVE_ANGLE, 0, 0xE8, 0x03, 0xC8, 0x00, 0x00, 0x00); /* 100.0 */
    run_until_done(1000);
    REQUEST(PKT_READ_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_ANGLE, 0, 0x84, 0x03);
    WRITE_ITEM(0, ITEM_ANGLE_LIMIT_ON, 0);                               /* limits off */
    REQUEST(PKT_MOVE_ANGLE, 0, 0xA4, 0x06, 0xC8, 0x00, 0x00, 0x00); /* 170.0 */
    run_until_done(1000);
    REQUEST(PKT_READ_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_ANGLE, 0, 0xA4, 0x06);
    REQUEST(PKT_MOVE_ANGLE, 0, 0x10, 0x27, 0xC8, 0x00, 0x00, 0x00); /* 1000.0: clamped to 180.0 */
    run_until_done(1000);
    assert_int_equal(angle_now(), 1800);
}

/* With item 48 at 2 the limits (135.0 deg) hold multi-turn
 * targets too, in the reading's own frame (a multi-turn 300.0 deg is not
 * -60.0 deg of the next turn), and a SyncCommand's records; the limiter
 * says angle. At 1, the maker's "on" and the factory's, a multi-turn move
 * passes them, as the maker's servo lets it. */
static void test_multi_turn_and_sync_targets_keep_to_the_limits(void **state)
{
    (void)state;
    REQUEST(PKT_MOVE_MULTI_TURN, 0, 0xB8, 0x0B, 0, 0, 0xF4, 0x01, 0, 0, 0, 0); /* 300.0 deg, 500 ms */
    run_until_done(2000);
    assert_int_equal(angle_now(), 3000);
    assert_int_equal(motion_limiter(&servo.motion), LIMITER_NONE);
    WRITE_ITEM(0, ITEM_ANGLE_LIMIT_ON, 2);
    REQUEST(PKT_MOVE_MULTI_TURN, 0, 0xB8, 0x0B, 0, 0, 0xF4, 0x01, 0, 0, 0, 0);
    run_until_done(2000);
    assert_int_equal(angle_now(), 1350);
    assert_int_equal(motion_limiter(&servo.motion), LIMITER_ANGLE);
    /* 15: -400 000.0 deg at 300 deg/s, 20 ms ramps */
    REQUEST(PKT_MOVE_MULTI_TURN_BY_VELOCITY, 0, 0x00, 0xF7, 0xC2, 0xFF, 0xB8, 0x0B, 20, 0, 20, 0, 0, 0);
    run_until_done(2000);
    assert_int_equal(angle_now(), -1350);
    assert_int_equal(motion_limiter(&servo.motion), LIMITER_ANGLE);
    REQUEST(PKT_MOVE_MULTI_TURN, 0, 0xE8, 0x03, 0, 0, 0xF4, 0x01, 0, 0, 0, 0); /* 100.0 deg: within */
    run_until_done(2000);
    assert_int_equal(angle_now(), 1000);
    assert_int_equal(motion_limiter(&servo.motion), LIMITER_NONE);
    /* A SyncCommand of multi-turn moves: servo 4's and ours, 720.0 deg. */
    const uint8_t sync[] = {PKT_MOVE_MULTI_TURN, 11, 2, 4, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
                            0, 0x20, 0x1C, 0, 0, 0xF4, 0x01, 0, 0, 0, 0};
    harness_request(PKT_SYNC_COMMAND, sync, sizeof sync);
    run_until_done(2000);
    assert_int_equal(angle_now(), 1350);
    assert_int_equal(motion_limiter(&servo.motion), LIMITER_ANGLE);
    /* The limits are in the reading's frame, after the center offset. */
    WRITE_ITEM(0, ITEM_CENTER_OFFSET_DECIDEG, 100);
    REQUEST(PKT_MOVE_MULTI_TURN, 0, 0xB8, 0x0B, 0, 0, 0xF4, 0x01, 0, 0, 0, 0);
    run_until_done(2000);
    assert_int_equal(angle_now(), 1350);
}

static void test_single_turn_angle_is_within_the_current_turn(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_ANGLE_LIMIT_ON, 0); /* multi-turn work: the limits would hold it in them */
    REQUEST(PKT_MOVE_MULTI_TURN, 0, 0x10, 0x0E, 0, 0, 0xB8, 0x0B, 0, 0, 0, 0); /* 360.0 deg, 3 s */
    run_until_done(4000);
    REQUEST(PKT_MOVE_ANGLE, 0, 0x84, 0x03, 0xF4, 0x01, 0x00, 0x00); /* 90.0 */
    run_until_done(1000);
    REQUEST(PKT_READ_MULTI_TURN_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_MULTI_TURN_ANGLE, 0, 0x94, 0x11, 0x00, 0x00, 0x01, 0x00); /* 450.0, 1 turn */
    REQUEST(PKT_READ_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_ANGLE, 0, 0x84, 0x03);
}

static void test_multi_turn_target_is_clamped(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_ANGLE_LIMIT_ON, 0); /* multi-turn work: the limits would hold it in them */
    /* 400 000.0 deg asked, 368 640.0 deg (1024 turns) allowed; 10 s. */
    REQUEST(PKT_MOVE_MULTI_TURN, 0, 0x00, 0x09, 0x3D, 0x00, 0x10, 0x27, 0x00, 0x00, 0x00, 0x00);
    run_until_done(11000);
    REQUEST(PKT_READ_MULTI_TURN_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_MULTI_TURN_ANGLE, 0, 0x00, 0x40, 0x38, 0x00, 0x00, 0x04);
}

static void test_interval_shorter_than_ramps_is_clamped(void **state)
{
    (void)state;
    /* 11: 90.0 deg, interval 100 ms, ramps 100 + 200 ms: runs 300 ms. */
    REQUEST(PKT_MOVE_ANGLE_BY_INTERVAL, 0, 0x84, 0x03, 0x64, 0x00, 0x64, 0x00, 0xC8, 0x00, 0x00, 0x00);
    assert_in_range(run_until_done(1000), 297, 303);
    /* 14: ramps below 20 ms count as 20; 1 ms interval becomes 40 ms (to
     * 88.0 deg: a stroke the motor can brake in 20 ms). */
    REQUEST(PKT_MOVE_MULTI_TURN_BY_INTERVAL, 0, 0x70, 0x03, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x05, 0x00, 0x05, 0x00, 0x00, 0x00);
    assert_in_range(run_until_done(1000), 37, 43);
    REQUEST(PKT_READ_MULTI_TURN_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_MULTI_TURN_ANGLE, 0, 0x70, 0x03, 0x00, 0x00, 0x00, 0x00);
}

static void test_velocity_is_clamped(void **state)
{
    (void)state;
    /* 90.0 deg at 900 deg/s asked, 750 deg/s allowed, 100/100 ms ramps:
     * 75 deg on the ramps, 20 ms of cruise, 220 ms (900 would take 200). */
    REQUEST(PKT_MOVE_ANGLE_BY_VELOCITY, 0, 0x84, 0x03, 0x28, 0x23, 0x64, 0x00, 0x64, 0x00, 0x00, 0x00);
    assert_in_range(run_until_done(1000), 217, 223);
    /* 1.0 deg at 0.5 deg/s asked, 1 deg/s the least: 1020 ms. */
    REQUEST(PKT_MOVE_ANGLE_BY_VELOCITY, 0, 0x8E, 0x03, 0x05, 0x00, 0x14, 0x00, 0x14, 0x00, 0x00, 0x00);
    assert_in_range(run_until_done(3000), 1017, 1023);
}

static void test_velocity_profile_worked_examples(void **state)
{
    (void)state;
    /* 100 deg at 300 deg/s, ramps 100/200 ms: 483 ms. */
    REQUEST(PKT_MOVE_ANGLE_BY_VELOCITY, 0, 0xE8, 0x03, 0xB8, 0x0B, 0x64, 0x00, 0xC8, 0x00, 0x00, 0x00);
    assert_in_range(run_until_done(1000), 481, 485);
    /* 20 deg more at 300 deg/s: ramps shrink to 44/88 ms, 133 ms in all. */
    REQUEST(PKT_MOVE_ANGLE_BY_VELOCITY, 0, 0xB0, 0x04, 0xB8, 0x0B, 0x64, 0x00, 0xC8, 0x00, 0x00, 0x00);
    assert_int_equal(servo.motion.profile.accel_ticks, 44);
    assert_int_equal(servo.motion.profile.total_ticks - servo.motion.profile.cruise_end, 88);
    assert_in_range(run_until_done(1000), 131, 135);
    REQUEST(PKT_READ_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_ANGLE, 0, 0xB0, 0x04); /* 120.0 */
}

/* ReadMotion (0x40) as decoded from its answer. */
struct motion_snapshot {
    int32_t angle, setpoint, target;
    int16_t speed, tracking_error;
    uint8_t status, flags;
    uint32_t tick_us; /* the servo's clock at the tick the values are from */
};


static struct motion_snapshot read_motion(void)
{
    REQUEST(PKT_READ_MOTION, 0);
    return (struct motion_snapshot){
        ANSWER_FIELD(PKT_READ_MOTION, ANSWER_READ_MOTION_ANGLE),
        ANSWER_FIELD(PKT_READ_MOTION, ANSWER_READ_MOTION_SETPOINT),
        ANSWER_FIELD(PKT_READ_MOTION, ANSWER_READ_MOTION_TARGET),
        (int16_t)ANSWER_FIELD(PKT_READ_MOTION, ANSWER_READ_MOTION_VELOCITY),
        (int16_t)ANSWER_FIELD(PKT_READ_MOTION, ANSWER_READ_MOTION_TRACKING_ERROR),
        (uint8_t)ANSWER_FIELD(PKT_READ_MOTION, ANSWER_READ_MOTION_STATUS),
        (uint8_t)ANSWER_FIELD(PKT_READ_MOTION, ANSWER_READ_MOTION_MOTION_FLAGS),
        (uint32_t)ANSWER_FIELD(PKT_READ_MOTION, ANSWER_READ_MOTION_TIME)};
}

/* ReadMotion: angle, setpoint, target, the servo's own speed and tracking
 * error, all of one instant; flags for where the profile is. */
static void test_read_motion_snapshot(void **state)
{
    (void)state;
    struct motion_snapshot at_rest = read_motion();
    assert_true(at_rest.flags & DIAG_RELEASED);
    REQUEST(PKT_MOVE_ANGLE_BY_VELOCITY, 0, 0x84, 0x03, 0xE8, 0x03, 0x14, 0x00, 0x14, 0x00, 0x00, 0x00); /* 100 deg/s */
    harness_run_ms(400);
    struct motion_snapshot moving = read_motion();
    /* Stamped with the servo's clock: the last tick ran within a period of
     * the request, a whole number of ticks after the first snapshot's (400
     * ms and two requests' byte times). */
    assert_in_range(moving.tick_us, hal.now_us - 1000u, hal.now_us);
    assert_in_range(moving.tick_us - at_rest.tick_us, 400000u, 403000u);
    assert_int_equal((moving.tick_us - at_rest.tick_us) % 1000u, 0u);
    /* 0.1 deg/s. The encoder counts 1.14 per tick here; the tracker's
     * share of a half-count miss leaves about +-55 of noise. */
    assert_in_range(moving.speed, 940, 1060);
    assert_in_range(moving.angle, angle_now() - 1, angle_now() + 1);
    assert_true(abs(moving.setpoint - moving.angle) <= 1); /* the ideal servo follows */
    assert_true(abs(moving.tracking_error) <= 9);         /* within a count, 0.01 deg */
    assert_int_equal(moving.target, 900);
    assert_int_equal(moving.status & STATUS_EXECUTING, STATUS_EXECUTING);
    assert_int_equal(moving.flags & (DIAG_PROFILE_ENDED | DIAG_RELEASED), 0);
    run_until_done(1000);
    struct motion_snapshot done = read_motion();
    assert_int_equal(done.setpoint, 900);
    assert_true(done.flags & DIAG_PROFILE_ENDED);
    assert_true(abs(done.speed) <= 10); /* settling: under 1 deg/s */
    /* A wrong length is a command error, as for the maker's packets. */
    REQUEST(PKT_READ_MOTION, 0, 0);
    EXPECT_SILENCE();
    assert_true(servo.regs.status.status & STATUS_COMMAND_ERROR);
}

/* ReadMotion's answer, byte for byte, against the fields worked out here
 * from the motion state (docs/packets.md): the tracking error saturated at
 * both ends and next to them, the target rounded to the nearest decidegree
 * with a center offset, every field at its offset. */
static int64_t floor_div(int64_t n, int64_t d)
{
    return n >= 0 ? n / d : -((-n + d - 1) / d);
}

static uint32_t le_bytes(const uint8_t *p, unsigned n)
{
    uint32_t v = 0;
    for (unsigned i = n; i-- > 0;) {
        v = v << 8 | p[i];
    }
    return v;
}

static void test_read_motion_answer_bytes(void **state)
{
    (void)state;
    static const int32_t errors[] = {0, 1000, -1000, 838860, 838861, 1 << 22, 1 << 30,
                                     -838835, -838836, -(1 << 22), -(1 << 30)};
    static const int64_t targets[] = {0, INT64_C(3686400) << 32, -(INT64_C(3686400) << 32), 0x7FFFFFFF,
                                      INT64_C(900) << 32, -(INT64_C(1234) << 32) + (INT64_C(1) << 31)};
    struct motion *m = &servo.motion;
    servo.regs.user.center_offset_decideg = -37;
    servo.regs.status.current_ma = 0x1234;
    servo.regs.firmware.winding_decic = -5;
    m->mode = MODE_POSITION;
    m->measured_q8 = 300 * 256 + 100;
    m->measured_velocity_q8 = -1000;
    m->damping_duty_q15 = -1234;
    for (size_t e = 0; e < sizeof errors / sizeof errors[0]; e++) {
        for (size_t t = 0; t < sizeof targets / sizeof targets[0]; t++) {
            m->setpoint_q8 = m->measured_q8 + errors[e];
            m->profile.target = targets[t];
            struct response r;
            memset(&r, 0xA5, sizeof r);
            r.content[0] = 1;
            struct dispatch_result result;
            struct packet_call call = {.d = &servo.dispatcher, .content = r.content, .length = 1,
                                       .result = &result};
            assert_int_equal(handle_read_motion(&call, &r), OUTCOME_OK);
            assert_int_equal(r.length, 29);
            const uint8_t *p = r.content;
            int32_t offset_q8 = -37 * 256;
            int64_t error_cd = floor_div((int64_t)errors[e] * 5, 128);
            error_cd = error_cd > INT16_MAX ? INT16_MAX : error_cd < -INT16_MAX ? -INT16_MAX : error_cd;
            int64_t target = floor_div(targets[t] - (int64_t)offset_q8 * (INT64_C(1) << 24) + (INT64_C(1) << 31),
                                       INT64_C(1) << 32);
            assert_int_equal(p[0], 1);
            assert_int_equal((int32_t)le_bytes(&p[1], 4), floor_div(m->measured_q8 - offset_q8 + 128, 256));
            assert_int_equal((int32_t)le_bytes(&p[5], 4), floor_div(m->setpoint_q8 - offset_q8 + 128, 256));
            assert_int_equal((int32_t)le_bytes(&p[9], 4), (int32_t)target);
            assert_int_equal((int16_t)le_bytes(&p[13], 2), floor_div(-1000 * 125, 32));
            assert_int_equal((int16_t)le_bytes(&p[15], 2), error_cd);
            assert_int_equal(le_bytes(&p[17], 2), 0x1234);
            assert_int_equal(p[19], servo.regs.status.status);
            assert_int_equal(p[20] & DIAG_RELEASED, 0);
            assert_int_equal(le_bytes(&p[21], 4), servo.next_tick_us - 1000u);
            assert_int_equal((int16_t)le_bytes(&p[25], 2), -5);
            assert_int_equal((int16_t)le_bytes(&p[27], 2), -1234);
        }
    }
}

static void test_center_offset_shifts_the_zero(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_CENTER_OFFSET_DECIDEG, 100); /* +10.0 deg */
    REQUEST(PKT_READ_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_ANGLE, 0, 0x9C, 0xFF); /* the servo at raw 0 reads -10.0 */
    REQUEST(PKT_MOVE_ANGLE, 0, 0x00, 0x00, 0xC8, 0x00, 0x00, 0x00);
    run_until_done(1000);
    REQUEST(PKT_READ_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_ANGLE, 0, 0x00, 0x00);
    /* Raw: 10.0 deg = 113.8 counts. */
    assert_int_equal(servo.motion.encoder.counts, 114);
}

static void test_power_bounds_the_output(void **state)
{
    (void)state;
    /* P R / V^2 in Q15 with R = 2.741 ohm, V = 7.4 V. */
    assert_int_equal(duty_limit_for_power(500, 7400, ITEM_RESISTANCE_MOHM_FACTORY), 820);
    assert_int_equal(duty_limit_for_power(10000, 7400, ITEM_RESISTANCE_MOHM_FACTORY), 16401);
    WRITE_ITEM(0, ITEM_POWER_LIMIT_MW, 10000); /* power protection back at 10 000 mW */
    /* Hold at 0 with 500 mW while a hand holds the horn 20 degrees away: the
     * output stands at 500 mW's duty. */
    REQUEST(PKT_MOVE_ANGLE, 0, 0x00, 0x00, 0x14, 0x00, 0xF4, 0x01);
    run_until_done(100);
    hal.encoder_model = NULL;
    hal.encoder_raw = 228; /* 20.04 degrees */
    harness_run_ms(200);   /* the jump's filtered velocity dies away */
    assert_int_equal(hal.duty, -820);
    /* 0, and anything above the power protection (42), mean 42. */
    REQUEST(PKT_MOVE_ANGLE, 0, 0x00, 0x00, 0x14, 0x00, 0x00, 0x00);
    harness_run_ms(50);
    assert_int_equal(hal.duty, -16401);
    REQUEST(PKT_MOVE_ANGLE, 0, 0x00, 0x00, 0x14, 0x00, 0x60, 0xEA);
    harness_run_ms(50);
    assert_int_equal(hal.duty, -16401);
    WRITE_ITEM(0, ITEM_POWER_LIMIT_MW, 1000); /* power protection 1000 mW */
    REQUEST(PKT_MOVE_ANGLE, 0, 0x00, 0x00, 0x14, 0x00, 0x00, 0x00);
    harness_run_ms(50);
    assert_int_equal(hal.duty, -duty_limit_for_power(1000, 7400, ITEM_RESISTANCE_MOHM_FACTORY));
}

/* A finished move's answer goes out in this ID's slot on the bus (servo.h):
 * within one cycle of 254 slots, 133 ms at 115200 baud. Waits for the first
 * thing sent, at most limit_ms; the milliseconds that took. */
static uint32_t wait_for_answer(uint32_t limit_ms)
{
    hal_double_clear_sent(&hal);
    uint32_t waited = 0;
    while (hal.sent_length == 0 && waited < limit_ms) {
        harness_run_ms(1);
        waited++;
    }
    return waited;
}

static void test_control_response_queues_and_answers_each(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_CONTROL_RESPONSE, 1);
    REQUEST(PKT_MOVE_ANGLE, 0, 0x64, 0x00, 0x64, 0x00, 0x00, 0x00); /* 10.0, 100 ms */
    REQUEST(PKT_MOVE_ANGLE, 0, 0xC8, 0x00, 0x64, 0x00, 0x00, 0x00); /* 20.0 */
    REQUEST(PKT_MOVE_ANGLE, 0, 0x2C, 0x01, 0x64, 0x00, 0x00, 0x00); /* 30.0 */
    EXPECT_SILENCE();
    for (int i = 1; i <= 3; i++) {
        wait_for_answer(300);
        EXPECT_RESPONSE(PKT_MOVE_ANGLE, 0, 1);
        assert_true(angle_now() >= 100 * i); /* after its move, in order */
    }
    harness_run_ms(5);
    assert_int_equal(angle_now(), 300);
    assert_false(executing());
    /* One running and MOTION_QUEUE_DEPTH waiting; the next is dropped. */
    for (unsigned i = 0; i < 1 + MOTION_QUEUE_DEPTH; i++) {
        REQUEST(PKT_MOVE_ANGLE, 0, 0x00, 0x00, 0xE8, 0x03, 0x00, 0x00);
    }
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_RESPONSE(PKT_READ_DATA, 0, ITEM_STATUS, STATUS_EXECUTING);
    REQUEST(PKT_MOVE_ANGLE, 0, 0x00, 0x00, 0xE8, 0x03, 0x00, 0x00);
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_RESPONSE(PKT_READ_DATA, 0, ITEM_STATUS, STATUS_EXECUTING | STATUS_COMMAND_ERROR);
    assert_int_equal(servo.motion.queue.count, MOTION_QUEUE_DEPTH);
}

static void test_new_move_replaces_the_running_one_smoothly(void **state)
{
    (void)state;
    /* 10 turns in 10 s with 1 s ramps; 0.5 s in, mid-ramp, turn back. */
    REQUEST(PKT_MOVE_MULTI_TURN_BY_INTERVAL, 0, 0xA0, 0x8C, 0x00, 0x00, 0x10, 0x27, 0x00, 0x00, 0xE8, 0x03, 0xE8, 0x03, 0x00, 0x00);
    harness_run_ms(500);
    int32_t before = servo.motion.setpoint_q8 - servo.motion.last_setpoint_q8;
    assert_true(before > 0);
    REQUEST(PKT_MOVE_MULTI_TURN_BY_INTERVAL, 0, 0x00, 0x00, 0x00, 0x00, 0x88, 0x13, 0x00, 0x00, 0xE8, 0x03, 0xE8, 0x03, 0x00, 0x00);
    harness_run_ms(1);
    int32_t after = servo.motion.setpoint_q8 - servo.motion.last_setpoint_q8;
    /* The velocity carries over: no jerk to a stop (the change within two
     * ticks is a few thousandths of a degree per tick). */
    assert_true(abs(after - before) < 256 / 20);
    assert_in_range(run_until_done(6000), 4990, 5010);
    assert_int_equal(angle_now(), 0);
}

static void test_reset_turns_and_origin_only_when_released(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_ANGLE_LIMIT_ON, 0); /* multi-turn work: the limits would hold it in them */
    WRITE_ITEM(0, ITEM_CONTROL_RESPONSE, 1);
    REQUEST(PKT_MOVE_MULTI_TURN, 0, 0x10, 0x1F, 0, 0, 0xB8, 0x0B, 0, 0, 0, 0); /* 795.2 deg */
    run_until_done(4000);
    REQUEST(PKT_RESET_MULTI_TURN_ANGLE, 0);
    EXPECT_RESPONSE(PKT_RESET_MULTI_TURN_ANGLE, 0, 0); /* under angle control */
    REQUEST(PKT_SET_ORIGIN_POINT, 0, 0);
    EXPECT_SILENCE();
    REQUEST(PKT_READ_MULTI_TURN_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_MULTI_TURN_ANGLE, 0, 0x10, 0x1F, 0, 0, 0x02, 0x00);
    REQUEST(PKT_STOP_ON_CONTROL_MODE, 0, 0x10, 0, 0); /* stop and release */
    EXPECT_SILENCE();
    assert_true(hal.coasting);
    REQUEST(PKT_RESET_MULTI_TURN_ANGLE, 0);
    EXPECT_RESPONSE(PKT_RESET_MULTI_TURN_ANGLE, 0, 1);
    REQUEST(PKT_READ_MULTI_TURN_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_MULTI_TURN_ANGLE, 0, 0xF0, 0x02, 0, 0, 0, 0); /* 75.2 deg, 0 turns */
    REQUEST(PKT_SET_ORIGIN_POINT, 0, 0);
    REQUEST(PKT_READ_ANGLE, 0);
    EXPECT_RESPONSE(PKT_READ_ANGLE, 0, 0, 0);
}

static void test_wheel_run_and_stop(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_CONTROL_RESPONSE, 1);
    REQUEST(PKT_MOVE_WHEEL, 0, 0x01, 0x5A, 0x00, 0x00, 0x00); /* counter-clockwise, 90 deg/s */
    EXPECT_SILENCE();
    harness_run_ms(25);
    wait_for_answer(300);
    EXPECT_RESPONSE(PKT_MOVE_WHEEL, 0, 1); /* answered once at speed */
    int32_t a0 = angle_now();
    harness_run_ms(1000);
    assert_in_range(angle_now() - a0, 898, 902); /* 90.0 deg in a second */
    REQUEST(PKT_MOVE_WHEEL, 0, 0x00, 0x00, 0x00, 0x00, 0x00);  /* stop */
    harness_run_ms(25);
    wait_for_answer(300);
    EXPECT_RESPONSE(PKT_MOVE_WHEEL, 0, 1);
    assert_true(hal.coasting); /* 47 = 0: released when stopped */
    assert_true(motion_is_released(&servo.motion));
    WRITE_ITEM(0, ITEM_WHEEL_BRAKE, 1);
    REQUEST(PKT_MOVE_WHEEL, 0, 0x81, 0x5A, 0x00, 0x00, 0x00); /* clockwise */
    harness_run_ms(500);
    assert_true(angle_now() < a0 + 900 - 400);
    REQUEST(PKT_MOVE_WHEEL, 0, 0x80, 0x00, 0x00, 0x00, 0x00);
    harness_run_ms(25);
    assert_false(hal.coasting); /* 47 = 1: holds when stopped */
    assert_false(motion_is_released(&servo.motion));
}

static void test_wheel_turns_and_time(void **state)
{
    (void)state;
    int32_t a0 = angle_now();
    REQUEST(PKT_MOVE_WHEEL, 0, 0x82, 0xB4, 0x00, 0x02, 0x00); /* clockwise, 180 deg/s, 2 turns */
    uint32_t ms = run_until_done(6000);
    /* 4 s at speed plus half of each ramp (4020 ms), then it holds until the
     * horn is still (filtered speed under 25 deg/s) before releasing. */
    assert_in_range(ms, 4020, 4040);
    assert_int_equal(angle_now(), a0 - 7200);
    assert_true(hal.coasting);
    REQUEST(PKT_MOVE_WHEEL, 0, 0x03, 0x5A, 0x00, 0xF4, 0x01); /* ccw, 90 deg/s, 500 ms */
    assert_in_range(run_until_done(1000), 497, 510); /* and its settle */
    assert_int_equal(angle_now(), a0 - 7200 + 432); /* 0.9 x (500 - 20) */
}

/* Braking effort: how far the output stands below the back-EMF duty of the
 * present speed (the winding current, in duty terms). */
static int32_t braking_effort(void)
{
    int64_t emf = ((int64_t)servo.motion.measured_velocity_q8 * servo.motion.drive.kv) >> 8;
    return (int32_t)(emf > 32767 ? 32767 : emf) - hal.duty;
}

static void test_damping_brakes_in_proportion_to_speed(void **state)
{
    (void)state;
    REQUEST(PKT_MOVE_DAMPING, 0, 0x10, 0x27); /* 10 000 mW */
    EXPECT_SILENCE();
    hal.encoder_model = NULL; /* an outside hand turns the horn */
    for (int i = 0; i < 40; i++) {
        hal.encoder_raw = (uint16_t)(hal.encoder_raw + (i % 4 == 0)); /* 22 deg/s */
        harness_run_ms(1);
    }
    int32_t slow = braking_effort();
    assert_true(slow > 0);
    for (int i = 0; i < 40; i++) {
        hal.encoder_raw = (uint16_t)(hal.encoder_raw + (i % 2 == 0)); /* 44 deg/s */
        harness_run_ms(1);
    }
    assert_true(braking_effort() > slow); /* twice the speed, more braking */
    for (int i = 0; i < 40; i++) {
        hal.encoder_raw = (uint16_t)(hal.encoder_raw + 40);
        harness_run_ms(1);
    }
    /* Bounded by the power: the braking current is at most P / V. */
    assert_int_equal(braking_effort(), duty_limit_for_power(10000, 7400, ITEM_RESISTANCE_MOHM_FACTORY));
    assert_true(motion_is_released(&servo.motion)); /* not angle control */
}

static void test_stop_on_control_mode(void **state)
{
    (void)state;
    REQUEST(PKT_MOVE_ANGLE, 0, 0x84, 0x03, 0xE8, 0x03, 0x00, 0x00);
    harness_run_ms(500);
    int32_t mid = angle_now();
    REQUEST(PKT_STOP_ON_CONTROL_MODE, 0, 0x11, 0x00, 0x00); /* stop and hold */
    EXPECT_SILENCE();
    harness_run_ms(200);
    assert_false(executing());
    assert_false(hal.coasting);
    assert_in_range(angle_now(), mid - 10, mid + 10);
    REQUEST(PKT_STOP_ON_CONTROL_MODE, 0, 0x12, 0xE8, 0x03); /* stop into damping */
    assert_int_equal(servo.motion.mode, MODE_DAMPING);
    REQUEST(PKT_STOP_ON_CONTROL_MODE, 0, 0x10, 0x00, 0x00); /* stop and release */
    assert_true(hal.coasting);
    assert_int_equal(servo.motion.mode, MODE_RELEASED);
}

static void test_async_moves_start_together(void **state)
{
    (void)state;
    harness_request(PKT_BEGIN_ASYNC, NULL, 0);
    REQUEST(PKT_MOVE_ANGLE, 0, 0x84, 0x03, 0xC8, 0x00, 0x00, 0x00);
    harness_run_ms(300);
    assert_int_equal(angle_now(), 0); /* buffered, not started */
    REQUEST(PKT_END_ASYNC, 0);
    run_until_done(1000);
    assert_int_equal(angle_now(), 900);
    harness_request(PKT_BEGIN_ASYNC, NULL, 0);
    REQUEST(PKT_MOVE_ANGLE, 0, 0x10, 0x00, 0xC8, 0x00, 0x00, 0x00);
    REQUEST(PKT_END_ASYNC, 1); /* discarded */
    harness_run_ms(300);
    assert_int_equal(angle_now(), 900);
}

static void test_sync_and_broadcast_moves(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_CONTROL_RESPONSE, 1); /* even with control response on: no answers */
    const uint8_t sync[] = {8, 7, 2, 4, 0x10, 0, 0, 0, 0, 0, 0, 0x84, 0x03, 0xC8, 0x00, 0, 0};
    harness_request(PKT_SYNC_COMMAND, sync, sizeof sync);
    run_until_done(1000);
    EXPECT_SILENCE();
    assert_int_equal(angle_now(), 900);
    REQUEST(PKT_MOVE_ANGLE, 0xFF, 0x00, 0x00, 0xC8, 0x00, 0x00, 0x00);
    run_until_done(1000);
    EXPECT_SILENCE();
    assert_int_equal(angle_now(), 0);
}

static void test_power_on_lock(void **state)
{
    (void)state;
    assert_true(hal.coasting); /* 46 = 0: released at power-up */
    WRITE_ITEM(0, ITEM_POWER_ON_LOCK, 1);
    harness_run_ms(60); /* saved */
    harness_restart();
    harness_run_ms(5);
    assert_false(hal.coasting); /* 46 = 1: holds at power-up */
    assert_false(motion_is_released(&servo.motion));
}

static void test_monitor_after_move(void **state)
{
    (void)state;
    REQUEST(PKT_MOVE_ANGLE_BY_VELOCITY, 0, 0x2C, 0x01, 0xB8, 0x0B, 0x64, 0x00, 0xC8, 0x00, 0x00, 0x00); /* 30.0 */
    run_until_done(1000);
    REQUEST(PKT_MONITOR, 0);
    /* Live readings from the double's sensors: 7400 mV, 0 mA, 0 mW, NTC 2048. */
    EXPECT_RESPONSE(PKT_MONITOR, 0, 0xE8, 0x1C, 0, 0, 0, 0, 0x00, 0x08, 0x00, 0x2C, 0x01, 0, 0, 0, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_angle_move_reaches_target, setup),
        cmocka_unit_test_setup(test_soft_start_times_the_first_move, setup_soft_start),
        cmocka_unit_test_setup(test_single_turn_targets_are_clamped_to_the_limits, setup),
        cmocka_unit_test_setup(test_single_turn_angle_is_within_the_current_turn, setup),
        cmocka_unit_test_setup(test_multi_turn_target_is_clamped, setup),
        cmocka_unit_test_setup(test_multi_turn_and_sync_targets_keep_to_the_limits, setup),
        cmocka_unit_test_setup(test_interval_shorter_than_ramps_is_clamped, setup),
        cmocka_unit_test_setup(test_velocity_is_clamped, setup),
        cmocka_unit_test_setup(test_velocity_profile_worked_examples, setup),
        cmocka_unit_test_setup(test_read_motion_snapshot, setup),
        cmocka_unit_test_setup(test_read_motion_answer_bytes, setup),
        cmocka_unit_test_setup(test_center_offset_shifts_the_zero, setup),
        cmocka_unit_test_setup(test_power_bounds_the_output, setup),
        cmocka_unit_test_setup(test_control_response_queues_and_answers_each, setup),
        cmocka_unit_test_setup(test_new_move_replaces_the_running_one_smoothly, setup),
        cmocka_unit_test_setup(test_reset_turns_and_origin_only_when_released, setup),
        cmocka_unit_test_setup(test_wheel_run_and_stop, setup),
        cmocka_unit_test_setup(test_wheel_turns_and_time, setup),
        cmocka_unit_test_setup(test_damping_brakes_in_proportion_to_speed, setup),
        cmocka_unit_test_setup(test_stop_on_control_mode, setup),
        cmocka_unit_test_setup(test_async_moves_start_together, setup),
        cmocka_unit_test_setup(test_sync_and_broadcast_moves, setup),
        cmocka_unit_test_setup(test_power_on_lock, setup),
        cmocka_unit_test_setup(test_monitor_after_move, setup),
    };
    return cmocka_run_group_tests_name("motion_packets", tests, NULL, NULL);
}
