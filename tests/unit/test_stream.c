/* Streamed setpoints (StreamSetpoint, 0x45) closing the loop around the
 * physical plant (hal/ports/host/plant.c): a host's 50 Hz stream is
 * tracked more closely and more smoothly than the same path sent as plain
 * angle moves, a stream whose host stops brakes to a hold within the
 * output's braking, the period is learned or told, and a stream takes over
 * from a move. Requests go in as bytes, as in the field. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#include "support/by_name.h"
#include "support/plant_harness.h"

static void stream(uint8_t id, int32_t angle_decideg, int16_t velocity_decideg_s, uint16_t host_ms)
{
    uint32_t a = (uint32_t)angle_decideg;
    uint16_t v = (uint16_t)velocity_decideg_s;
    REQUEST(PKT_STREAM_SETPOINT, id, (uint8_t)a, (uint8_t)(a >> 8), (uint8_t)(a >> 16), (uint8_t)(a >> 24),
            (uint8_t)v, (uint8_t)(v >> 8), (uint8_t)host_ms, (uint8_t)(host_ms >> 8));
}

static void move_angle(int16_t angle_decideg, uint16_t interval_ms)
{
    uint16_t a = (uint16_t)angle_decideg;
    REQUEST(PKT_MOVE_ANGLE, 0, (uint8_t)a, (uint8_t)(a >> 8), (uint8_t)interval_ms,
            (uint8_t)(interval_ms >> 8), 0x00, 0x00);
}

static double setpoint_deg(void)
{
    return (double)servo.motion.setpoint_q8 / 2560.0;
}

/* The path: a 0.5 Hz sine of +-60 degrees, sent at 50 Hz. */
enum { PERIOD_MS = 20, PATH_MS = 4000 };
#define AMPLITUDE_DEG 60.0
#define OMEGA (2.0 * M_PI * 0.5)

static double path_deg(double t_s)
{
    return AMPLITUDE_DEG * sin(OMEGA * t_s);
}

struct tracking {
    double rms_deg;   /* of the horn against the path, after the first cycle */
    double peak_deg_s2; /* of the setpoint's second difference */
};

static double now_s(void)
{
    return (double)hal.now_us / 1e6;
}

/* Sends the path one period ahead (each setpoint is where to be a period
 * after it is sent), streamed or as 20 ms angle moves, on the servo's own
 * clock (a request takes its bytes' time on the wire), and measures after
 * the first second: the horn against the path, and the setpoint's
 * acceleration (the walk's second difference, tick by tick). */
static struct tracking follow_path(bool streamed)
{
    double sum = 0, peak = 0;
    unsigned n = 0;
    double t0 = now_s(), next = 0;
    while (now_s() - t0 < PATH_MS / 1000.0) {
        double t = now_s() - t0;
        if (t >= next) {
            double at = next + PERIOD_MS / 1000.0;
            int32_t angle = (int32_t)lround(path_deg(at) * 10.0);
            if (streamed) {
                int16_t v = (int16_t)lround(AMPLITUDE_DEG * OMEGA * cos(OMEGA * at) * 10.0);
                stream(0, angle, v, (uint16_t)lround(next * 1000.0));
            } else {
                move_angle((int16_t)angle, PERIOD_MS);
            }
            next += PERIOD_MS / 1000.0;
        }
        hal.now_us += 250u; /* a main-loop pass, as harness_run_ms */
        servo_poll(&servo);
        if (now_s() - t0 >= 1.0) {
            double acc = fabs((double)servo.motion.walk.change_q40) / 1099511627776.0 * 1e5; /* deg/s^2 */
            peak = acc > peak ? acc : peak;
            double e = plant_angle_deg(&plant) - path_deg(now_s() - t0);
            sum += e * e;
            n++;
        }
    }
    return (struct tracking){sqrt(sum / n), peak};
}

static void test_a_stream_tracks_the_path_smoothly(void **state)
{
    (void)state;
    stream(0, 0, 0, 0); /* start from rest at 0 */
    harness_run_ms(200);
    struct tracking streamed = follow_path(true);
    plant_harness_setup(state);
    move_angle(0, 100);
    harness_run_ms(200);
    struct tracking moves = follow_path(false);
    printf("# 0.5 Hz +-60 deg at 50 Hz: streamed RMS %.3f deg, peak setpoint acceleration %.0f deg/s^2; "
           "angle moves %.3f deg, %.0f deg/s^2 (the path's own: %.0f)\n",
           streamed.rms_deg, streamed.peak_deg_s2, moves.rms_deg, moves.peak_deg_s2,
           AMPLITUDE_DEG * OMEGA * OMEGA);
    assert_true(streamed.rms_deg < 0.5);
    assert_true(streamed.rms_deg < moves.rms_deg / 2);
    /* The stream's setpoint bends about as the path does; the moves'
     * trapezoids start and stop every period. */
    assert_true(streamed.peak_deg_s2 < 4 * AMPLITUDE_DEG * OMEGA * OMEGA);
    assert_true(streamed.peak_deg_s2 < moves.peak_deg_s2 / 4);
}

/* The host stops at full speed (100 deg/s): the segment's end speed goes
 * on for a period, then the servo brakes at the output's braking, never
 * jumps, and holds. */
static void test_a_late_stream_brakes_to_a_hold(void **state)
{
    (void)state;
    for (uint16_t ms = 0; ms <= 400; ms += PERIOD_MS) {
        stream(0, (int32_t)ms * 1 + PERIOD_MS, 1000, ms); /* 0.1 deg per ms: 100 deg/s */
        harness_run_ms(PERIOD_MS);
    }
    double last = setpoint_deg(), last_step = 0.1, peak_acc = 0;
    uint32_t stopped_at = 0;
    for (uint32_t ms = 1; ms <= 500; ms++) {
        harness_run_ms(1);
        double step = setpoint_deg() - last;
        last = setpoint_deg();
        double acc = fabs(step - last_step) * 1e6;
        peak_acc = acc > peak_acc ? acc : peak_acc;
        if (stopped_at == 0u && fabs(step) < 1e-9) {
            stopped_at = ms;
        }
        last_step = step;
    }
    printf("# host gone at 100 deg/s: the setpoint stopped %u ms later, at %.2f deg (the last setpoint: 42 deg), "
           "peak deceleration %.0f deg/s^2; the horn at %.2f deg\n",
           stopped_at, setpoint_deg(), peak_acc, plant_angle_deg(&plant));
    assert_true(stopped_at > 0u && stopped_at < 200u);
    assert_true(peak_acc < 100000.0); /* no jump: a jump of 1 deg in a tick is 1e6 deg/s^2 */
    assert_true(setpoint_deg() > 42.0 && setpoint_deg() < 60.0);
    assert_true(fabs(plant_angle_deg(&plant) - setpoint_deg()) < 0.2);
    assert_int_equal(servo.motion.mode, MODE_POSITION); /* held, not released */
    assert_false(servo.motion.running);
}

static void test_the_period_is_learned_or_told(void **state)
{
    (void)state;
    stream(0, 0, 0, 1000);
    assert_int_equal(servo.motion.profile.accel_ticks, 20); /* nothing learned yet: 50 Hz */
    harness_run_ms(10);
    stream(0, 10, 0, 1010);
    assert_int_equal(servo.motion.stream_period_ms, 10);
    assert_int_equal(servo.motion.profile.accel_ticks, 10);
    harness_run_ms(10);
    stream(0, 20, 0, 1020);
    assert_int_equal(servo.motion.profile.accel_ticks, 10);
    WRITE_ITEM(0, ITEM_STREAM_PERIOD_MS, 30); /* told: the stamps no longer count */
    harness_run_ms(10);
    stream(0, 30, 0, 1030);
    assert_int_equal(servo.motion.profile.accel_ticks, 30);
    /* A stamp from another stream (a gap of more than PROFILE_MAX_SEGMENT)
     * teaches nothing. */
    WRITE_ITEM(0, ITEM_STREAM_PERIOD_MS, 0);
    stream(0, 30, 0, 5000);
    assert_int_equal(servo.motion.profile.accel_ticks, 10);
}

static void test_the_host_clock_wraps(void **state)
{
    (void)state;
    stream(0, 0, 0, 65530);
    harness_run_ms(15);
    stream(0, 10, 0, 9); /* 65530 + 15 */
    assert_int_equal(servo.motion.stream_period_ms, 15);
}

/* A stream takes over from a long move and drops what is queued behind it;
 * the move's answer is not owed any more. */
static void test_a_stream_takes_over_a_move(void **state)
{
    (void)state;
    move_angle(900, 3000);
    harness_run_ms(100);
    assert_true(servo.motion.running);
    double before = setpoint_deg();
    stream(0, -100, 0, 0);
    harness_run_ms(300);
    printf("# a move at %.2f deg taken over by a stream to -10 deg: setpoint %.2f, horn %.2f deg\n", before,
           setpoint_deg(), plant_angle_deg(&plant));
    assert_true(fabs(setpoint_deg() + 10.0) < 0.05);
    assert_true(fabs(plant_angle_deg(&plant) + 10.0) < 0.2);
    assert_int_equal(servo.motion.queue.count, 0);
}

/* Broadcast: every servo takes it, none answers. A setpoint at rest far
 * from the horn (20 degrees in one period: far beyond the output) is a
 * move that ends there: the braking guard keeps it from overshooting. */
static void test_a_broadcast_setpoint_is_taken_silently(void **state)
{
    (void)state;
    stream(0xFF, 200, 0, 0);
    EXPECT_SILENCE();
    harness_run_ms(500);
    assert_true(fabs(plant_angle_deg(&plant) - 20.0) < 0.1);
    assert_false(servo.motion.running);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_a_stream_tracks_the_path_smoothly, plant_harness_setup),
        cmocka_unit_test_setup(test_a_late_stream_brakes_to_a_hold, plant_harness_setup),
        cmocka_unit_test_setup(test_the_period_is_learned_or_told, plant_harness_setup),
        cmocka_unit_test_setup(test_the_host_clock_wraps, plant_harness_setup),
        cmocka_unit_test_setup(test_a_stream_takes_over_a_move, plant_harness_setup),
        cmocka_unit_test_setup(test_a_broadcast_setpoint_is_taken_silently, plant_harness_setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
