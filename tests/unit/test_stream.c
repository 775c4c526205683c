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

/* A StreamSetpoint frame's time on the wire: 16 bytes. */
enum { STREAM_FRAME_US = 16 * HARNESS_BYTE_US };

/* Runs the servo until hal.now_us is us, exactly. */
static void run_until_us(uint64_t us)
{
    while (hal.now_us < us) {
        hal.now_us += us - hal.now_us < 250u ? us - hal.now_us : 250u;
        servo_poll(&servo);
        hal_double_dma_reads(&hal);
    }
}

/* A setpoint whose frame ends at end_us: a punctual host's, whose stamps
 * keep the servo's time. */
static void stream_on_time(uint64_t end_us, int32_t angle_decideg, int16_t velocity, uint16_t host_ms)
{
    run_until_us(end_us - STREAM_FRAME_US);
    stream(0, angle_decideg, velocity, host_ms);
}

static double setpoint_deg(void)
{
    return (double)servo.motion.setpoint_q8 / 2560.0;
}

/* The path: a 0.5 Hz sine of +-60 degrees, sent at 50 Hz. */
/* Measured from MEASURE_MS on: the servo's estimate of the host's clock
 * starts at the first frame's arrival, up to 10 ms off with a jittery host,
 * and moves 1/8 ms a frame (80 frames, 1.6 s, at most). */
enum { PERIOD_MS = 20, PATH_MS = 5000, MEASURE_MS = 2000 };
#define AMPLITUDE_DEG 60.0
#define OMEGA (2.0 * M_PI * 0.5)

static double path_deg(double t_s)
{
    return AMPLITUDE_DEG * sin(OMEGA * t_s);
}

struct tracking {
    double rms_deg;   /* of the horn against the path */
    double peak_deg_s2; /* of the setpoint's second difference */
    double shape_rms_deg; /* against the path at the lag that fits best */
    double lag_ms;
};

/* The lags tried: 0 to 20 ms in 0.5 ms steps. */
enum { LAGS = 41 };
#define LAG_STEP_S 0.0005

static double now_s(void)
{
    return (double)hal.now_us / 1e6;
}

/* A host's timing (docs/streaming.md, "On the host's timeline"): each
 * frame sent up to jitter_ms early or late (uniform), one in late_every a
 * whole period late (with the next, a burst), 0 for none. */
struct host_timing {
    uint32_t jitter_ms;
    uint32_t late_every;
};

static uint64_t rng_state = 0x2545F4914F6CDD1Du;

static uint32_t rng_next(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (uint32_t)(rng_state >> 32);
}

/* Where frame k leaves the host, s: on its period's grid, moved by the
 * host's timing; never before the one before it. */
static double send_time_s(uint32_t k, struct host_timing h, double last_s)
{
    double at = (double)k * PERIOD_MS / 1000.0;
    if (h.jitter_ms != 0u) {
        at += ((double)(rng_next() % (2000u * h.jitter_ms + 1u)) / 1000.0 - (double)h.jitter_ms) / 1000.0;
    }
    if (h.late_every != 0u && k % h.late_every == h.late_every - 1u) {
        at = (double)(k + 1u) * PERIOD_MS / 1000.0;
    }
    return at > last_s ? at : last_s;
}

/* Sends the path, streamed or as 20 ms angle moves, on the servo's own
 * clock (a request takes its bytes' time on the wire), and measures from
 * MEASURE_MS: the horn against the path, and the setpoint's
 * acceleration (the walk's second difference, tick by tick). A setpoint is
 * stamped with its period's moment on the host's timeline and is where
 * the path is a depth (3/2 period) later, when the servo reaches it; an
 * angle move is where the path is a period after it is sent. */
static struct tracking follow_path(bool streamed, struct host_timing h)
{
    double sum = 0, peak = 0, lagged[LAGS] = {0};
    unsigned n = 0;
    double t0 = now_s();
    uint32_t k = 0;
    double next = send_time_s(0, h, 0.0);
    while (now_s() - t0 < PATH_MS / 1000.0) {
        double t = now_s() - t0;
        while (t >= next) {
            double moment = (double)k * PERIOD_MS / 1000.0;
            double at = moment + (streamed ? 1.5 : 1.0) * PERIOD_MS / 1000.0;
            int32_t angle = (int32_t)lround(path_deg(at) * 10.0);
            if (streamed) {
                int16_t v = (int16_t)lround(AMPLITUDE_DEG * OMEGA * cos(OMEGA * at) * 10.0);
                stream(0, angle, v, (uint16_t)(k * PERIOD_MS));
            } else {
                move_angle((int16_t)angle, PERIOD_MS);
            }
            next = send_time_s(++k, h, next);
        }
        hal.now_us += 250u; /* a main-loop pass, as harness_run_ms */
        servo_poll(&servo);
        if (now_s() - t0 >= MEASURE_MS / 1000.0) {
            double acc = fabs((double)servo.motion.walk.change_q40) / 1099511627776.0 * 1e5; /* deg/s^2 */
            peak = acc > peak ? acc : peak;
            double e = plant_angle_deg(&plant) - path_deg(now_s() - t0);
            sum += e * e;
            for (int l = 0; l < LAGS; l++) {
                double el = plant_angle_deg(&plant) - path_deg(now_s() - t0 - l * LAG_STEP_S);
                lagged[l] += el * el;
            }
            n++;
        }
    }
    int best = 0;
    for (int l = 1; l < LAGS; l++) {
        best = lagged[l] < lagged[best] ? l : best;
    }
    return (struct tracking){sqrt(sum / n), peak, sqrt(lagged[best] / n), best * LAG_STEP_S * 1000.0};
}

static const struct host_timing PUNCTUAL = {0, 0};

static void test_a_stream_tracks_the_path_smoothly(void **state)
{
    (void)state;
    stream(0, 0, 0, 0); /* start from rest at 0 */
    harness_run_ms(200);
    struct tracking streamed = follow_path(true, PUNCTUAL);
    plant_harness_setup(state);
    move_angle(0, 100);
    harness_run_ms(200);
    struct tracking moves = follow_path(false, PUNCTUAL);
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

/* Frames that leave the host up to 10 ms early or late, and one in twenty
 * a whole period late (a burst with the next), keep the motion's shape and
 * its delay: at the lag that fits best, nearly the punctual host's error
 * and lag, and no sharper bend. A servo that played each setpoint from
 * its arrival saw 5 deg and thousands of deg/s^2. */
static void test_a_host_late_or_early_changes_nothing(void **state)
{
    (void)state;
    stream(0, 0, 0, 0);
    harness_run_ms(200);
    struct tracking punctual = follow_path(true, PUNCTUAL);
    printf("# punctual: RMS %.3f deg, at its best lag (%.1f ms) %.3f deg, peak setpoint acceleration %.0f deg/s^2\n",
           punctual.rms_deg, punctual.lag_ms, punctual.shape_rms_deg, punctual.peak_deg_s2);
    const struct host_timing timings[] = {{5, 0}, {10, 0}, {10, 20}};
    for (size_t i = 0; i < sizeof timings / sizeof timings[0]; i++) {
        plant_harness_setup(state);
        stream(0, 0, 0, 0);
        harness_run_ms(200);
        struct tracking t = follow_path(true, timings[i]);
        printf("# +-%u ms%s: RMS %.3f deg, at its best lag (%.1f ms) %.3f deg, peak setpoint acceleration "
               "%.0f deg/s^2\n", timings[i].jitter_ms, timings[i].late_every ? ", 1 in 20 a period late" : "",
               t.rms_deg, t.lag_ms, t.shape_rms_deg, t.peak_deg_s2);
        assert_true(t.shape_rms_deg < punctual.shape_rms_deg + 0.1);
        assert_true(fabs(t.lag_ms - punctual.lag_ms) <= 1.0);
        /* The horn's bound (docs/streaming.md); the setpoint bends sharper. */
        assert_true(t.peak_deg_s2 < 2000.0);
    }
}

/* The host stops at full speed (100 deg/s): the segment's end speed goes
 * on for a period, then the servo brakes at the output's braking, never
 * jumps, and holds. */
static void test_a_late_stream_brakes_to_a_hold(void **state)
{
    (void)state;
    uint64_t base = hal.now_us + 10000u;
    for (uint16_t ms = 0; ms <= 400; ms += PERIOD_MS) {
        /* 0.1 deg a ms: 100 deg/s, each setpoint where the path is at its place. */
        stream_on_time(base + ms * 1000u, (int32_t)ms + 3 * PERIOD_MS / 2, 1000, ms);
    }
    run_until_us(base + 400000u + 3000u * PERIOD_MS / 2u); /* the last setpoint's place */
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

/* Each segment ends a depth of 3/2 period after its setpoint's place on the
 * host's timeline: with the frames on time, 3/2 period after each arrives. */
static void test_the_period_is_learned_or_told(void **state)
{
    (void)state;
    uint64_t base = hal.now_us + 10000u;
    /* Steps of 0.3 deg: segments within the stream's limits. */
    stream_on_time(base, 0, 0, 0);
    assert_int_equal(servo.motion.profile.accel_ticks, 30); /* nothing learned yet: 50 Hz */
    stream_on_time(base + 10000u, 3, 0, 10);
    assert_int_equal(servo.motion.stream_period_q4 >> 4, 10);
    assert_int_equal(servo.motion.profile.accel_ticks, 15);
    stream_on_time(base + 20000u, 6, 0, 20);
    assert_int_equal(servo.motion.profile.accel_ticks, 15);
    WRITE_ITEM(0, ITEM_STREAM_PERIOD_MS, 30); /* told: the stamps no longer count */
    stream_on_time(base + 30000u, 9, 0, 30);
    assert_int_equal(servo.motion.profile.accel_ticks, 45);
    /* A stamp from another stream (a gap of more than PROFILE_MAX_SEGMENT)
     * teaches nothing, and starts the host's timeline afresh. */
    WRITE_ITEM(0, ITEM_STREAM_PERIOD_MS, 0);
    stream(0, 9, 0, 5000);
    assert_int_equal(servo.motion.profile.accel_ticks, 15);
}

/* A frame late by less than its depth less half a period keeps its place:
 * its segment is shorter by as much. One later ends half a period (and a
 * tick) on, its target run on along its velocity to where its path is
 * then. */
static void test_a_late_frame_keeps_its_place(void **state)
{
    (void)state;
    uint64_t base = hal.now_us + 10000u;
    /* A path at 100 deg/s: 0.1 deg a ms. */
    stream_on_time(base, 0, 1000, 0);
    stream_on_time(base + 20000u, 20, 1000, 20);
    stream_on_time(base + 45000u, 40, 1000, 40); /* 5 ms late */
    assert_int_equal(servo.motion.profile.accel_ticks, 30 - 5);
    stream_on_time(base + 85000u, 60, 1000, 60); /* 25 ms late */
    assert_int_equal(servo.motion.profile.accel_ticks, 11);
    /* Its place was 5 ms on; the segment ends 11 ms on: 6 ms further on
     * its path, 0.6 deg. */
    double target = (double)servo.motion.target_q8 / 2560.0;
    printf("# 25 ms late: its segment 11 ms, the target %.3f deg (stamped 6.0 at 100 deg/s)\n", target);
    assert_true(fabs(target - 6.6) < 0.02);
}

/* At 60 Hz a first frame 10 ms early makes every frame after it look 10 ms
 * late until the servo's clock has followed (1/8 ms a frame); one of them
 * 10 ms late on top looks 20 ms late, its segment is short, and the next,
 * a whole period late, came after the servo had braked to a hold. The
 * run-on after a segment is the depth whatever the segment's length: the
 * stream goes on. */
static void test_an_early_first_frame_and_a_late_one_stop_nothing(void **state)
{
    (void)state;
    enum { P = 16 }; /* ms */
    uint64_t base = hal.now_us + 20000u;
    double last = 0, slowest = 1e9;
    for (uint16_t k = 0; k <= 20; k++) {
        uint16_t stamp = (uint16_t)(k * P);
        int64_t arrive_ms = k == 0 ? -10 : k == 10 ? stamp + 10 : k == 11 ? stamp + P : stamp;
        uint64_t end_us = (uint64_t)((int64_t)base + arrive_ms * 1000);
        while (hal.now_us + 1000u <= end_us - STREAM_FRAME_US) {
            harness_run_ms(1);
            double step = setpoint_deg() - last;
            last = setpoint_deg();
            if (k >= 3u) { /* under way */
                slowest = step < slowest ? step : slowest;
            }
        }
        /* 100 deg/s, each setpoint where the path is at its place. */
        stream_on_time(end_us, stamp + 3 * P / 2, 1000, stamp);
    }
    printf("# 60 Hz at 100 deg/s, a first frame 10 ms early, one 10 ms late and the next a period late: "
           "the setpoint's slowest step %.3f deg/ms\n", slowest);
    assert_true(slowest > 0.05); /* a hold brakes to 0 */
}

/* The host-timing model at 60 and 50 Hz (every frame up to 10 ms early
 * or late, one in twenty a whole period late), 60 seeds each, a path at
 * 100 deg/s: no run stops (brakes the setpoint to a hold) while frames
 * come. At 100 Hz, where the jitter is the period, runs are counted. */
static unsigned stops_in_runs(uint32_t period_ms, unsigned runs, void **state)
{
    unsigned stopped = 0;
    for (unsigned run = 0; run < runs; run++) {
        plant_harness_setup(state);
        WRITE_ITEM(0, ITEM_ANGLE_LIMIT_ON, 0);
        rng_state = 0x9E3779B97F4A7C15u * (run + 1u);
        uint64_t base = hal.now_us + 20000u;
        double last = 0, slowest = 1e9, at_ms = -20.0;
        for (uint32_t k = 0; k < 60u; k++) {
            double send = (double)(k * period_ms) + (double)(rng_next() % 20001u) / 1000.0 - 10.0;
            send = k % 20u == 19u ? (double)((k + 1u) * period_ms) : send;
            at_ms = send > at_ms ? send : at_ms; /* never before the one before */
            uint64_t end_us = (uint64_t)((double)base + at_ms * 1000.0);
            while (hal.now_us + 1000u <= end_us - STREAM_FRAME_US) {
                harness_run_ms(1);
                double step = setpoint_deg() - last;
                last = setpoint_deg();
                slowest = k >= 3u && step < slowest ? step : slowest;
            }
            uint16_t stamp = (uint16_t)(k * period_ms);
            stream_on_time(end_us, (int32_t)(stamp + 3u * period_ms / 2u), 1000, stamp);
        }
        stopped += slowest < 0.05;
    }
    return stopped;
}

static void test_a_jittery_host_stops_no_stream(void **state)
{
    unsigned at_60 = stops_in_runs(16, 60, state), at_50 = stops_in_runs(20, 60, state);
    unsigned at_100 = stops_in_runs(10, 60, state);
    printf("# +-10 ms and 1 in 20 a period late: streams stopped of 60 at 60 Hz %u, at 50 Hz %u, "
           "at 100 Hz %u\n", at_60, at_50, at_100);
    assert_int_equal(at_60, 0);
    assert_int_equal(at_50, 0);
}

/* Runs until the setpoint has not moved for 20 ms (at most 3 s): how long
 * that took, ms, and where it stopped, deg. */
static uint32_t run_until_still(double *at_deg)
{
    double last = setpoint_deg();
    uint32_t still = 0, ms = 0;
    while (still < 20u && ms < 3000u) {
        harness_run_ms(1);
        ms++;
        still = fabs(setpoint_deg() - last) < 1e-6 ? still + 1u : 0u;
        last = setpoint_deg();
    }
    *at_deg = last;
    return ms - still;
}

/* A first setpoint, a wait of 300 ms, then a 50 Hz stream: the period was
 * the wait's (1/8 ms a setpoint back to 20 ms took 45 s), the depth 450
 * ms, and the servo ran on 70 deg past the host's last setpoint once it
 * stopped. The second step, shorter, says the period. */
static void test_a_first_setpoint_and_a_wait_teach_no_period(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_ANGLE_LIMIT_ON, 0);
    uint64_t base = hal.now_us + 10000u;
    stream_on_time(base, 0, 0, 0);
    uint16_t ms = 300;
    for (int k = 0; k < 30; k++, ms = (uint16_t)(ms + PERIOD_MS)) {
        stream_on_time(base + ms * 1000u, (ms - 300) * 2, 2000, ms); /* 200 deg/s */
    }
    assert_int_equal(servo.motion.stream_period_q4 >> 4, PERIOD_MS);
    double last = (double)((ms - PERIOD_MS - 300) * 2) / 10.0, at = 0;
    uint32_t took = run_until_still(&at);
    printf("# a first setpoint, 300 ms, then 50 Hz at 200 deg/s: still %u ms after the last frame, "
           "%.1f deg past its setpoint\n", took, at - last);
    assert_true(took < 200u && at - last < 15.0);
}

/* One frame stamped 500 ms early, the host then gone: its segment ends at
 * its place, and ran on as long again (156 deg past its setpoint at 300
 * deg/s). A run-on is the depth, 3/2 period, at most. */
static void test_an_early_last_frame_stops_within_periods(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_ANGLE_LIMIT_ON, 0);
    uint64_t base = hal.now_us + 10000u;
    for (uint16_t ms = 0; ms <= 400; ms += PERIOD_MS) {
        uint16_t stamp = ms == 400 ? 900 : ms;
        stream_on_time(base + ms * 1000u, ms * 3 + 3 * PERIOD_MS * 3 / 2, 3000, stamp); /* 300 deg/s */
    }
    assert_int_equal(servo.motion.profile.accel_ticks, 3 * PERIOD_MS / 2 + 500);
    double at = 0;
    uint32_t took = run_until_still(&at);
    printf("# a last frame 500 ms early at 300 deg/s: still %u ms after it, at %.1f deg (its setpoint 129)\n",
           took, at);
    /* Its place, the depth's run-on (9 deg) and the brake. */
    assert_true(took < 530u + 3u * PERIOD_MS / 2u + 100u && at < 129.0 + 20.0);
}

static void test_the_host_clock_wraps(void **state)
{
    (void)state;
    uint64_t base = hal.now_us + 10000u;
    stream_on_time(base, 0, 0, 65530);
    stream_on_time(base + 15000u, 10, 0, 9); /* 65530 + 15 */
    assert_int_equal(servo.motion.stream_period_q4 >> 4, 15);
    assert_int_equal(servo.motion.profile.accel_ticks, 22); /* on time: 3/2 of 15 ms */
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

static int32_t read_item(enum data_item_id item)
{
    REQUEST(PKT_READ_DATA, 0, (uint8_t)item);
    assert_true(hal.sent_length >= 8u);
    return ANSWER_FIELD(PKT_READ_DATA, 2, hal.sent_length - 7u, 0);
}

/* With the limits on (the factory's, 135 deg), a setpoint of
 * 300 deg, alone or as a SyncCommand's record, leaves the horn at the
 * limit, and the limiter says angle; one within them says nothing. */
static void test_a_streamed_setpoint_keeps_to_the_angle_limits(void **state)
{
    (void)state;
    stream(0, 3000, 0, 0);
    harness_run_ms(1500);
    printf("# a setpoint of 300 deg, limits +-135: the horn at %.2f deg\n", plant_angle_deg(&plant));
    assert_true(fabs(plant_angle_deg(&plant) - 135.0) < 0.2);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_ANGLE);
    uint32_t a = (uint32_t)-3000;
    const uint8_t sync[] = {PKT_STREAM_SETPOINT, 9, 1, 0, (uint8_t)a, (uint8_t)(a >> 8), (uint8_t)(a >> 16),
                            (uint8_t)(a >> 24), 0, 0, 20, 0};
    harness_request(PKT_SYNC_COMMAND, sync, sizeof sync);
    harness_run_ms(2000);
    assert_true(fabs(plant_angle_deg(&plant) + 135.0) < 0.2);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_ANGLE);
    stream(0, 100, 0, 40);
    harness_run_ms(1500);
    assert_true(fabs(plant_angle_deg(&plant) - 10.0) < 0.2);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_NONE);
    /* Off, the stream goes beyond them. */
    WRITE_ITEM(0, ITEM_ANGLE_LIMIT_ON, 0);
    stream(0, 3000, 0, 60);
    harness_run_ms(2000);
    assert_true(fabs(plant_angle_deg(&plant) - 300.0) < 0.2);
}

/* The horn's extremes over ms. */
static void run_extremes(uint32_t ms, double *lowest, double *highest)
{
    for (uint32_t t = 0; t < ms; t++) {
        harness_run_ms(1);
        double a = plant_angle_deg(&plant);
        *lowest = a < *lowest ? a : *lowest;
        *highest = a > *highest ? a : *highest;
    }
}

/* A stream's path keeps within the limits between its setpoints too: a
 * setpoint at the limit whose end speed runs on past it (a 1 s period,
 * 750 deg/s at 135 deg: before, the run-on took the horn to 893 deg), and
 * one whose cubic bulges past it and then runs on the other way (100 deg,
 * then 135 deg at -600 deg/s: before, 216 deg, then -470 deg). */
static void test_a_streams_path_keeps_within_the_limits(void **state)
{
    (void)state;
    double lowest = 0.0, highest = 0.0;
    stream(0, 0, 0, 0);
    harness_run_ms(500);
    stream(0, 1350, 7500, 1000);
    run_extremes(3000, &lowest, &highest);
    printf("# 135 deg at 750 deg/s, a 1 s period: the horn within %.2f..%.2f deg\n", lowest, highest);
    assert_true(highest < 135.5 && lowest > -0.5);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_ANGLE);
    stream(0, 1000, 0, 4000);
    harness_run_ms(1500);
    lowest = highest = plant_angle_deg(&plant);
    stream(0, 1350, -6000, 5000);
    run_extremes(3000, &lowest, &highest);
    printf("# 100, then 135 deg at -600 deg/s: the horn within %.2f..%.2f deg\n", lowest, highest);
    assert_true(highest < 135.5 && lowest > -135.5);
    assert_int_equal(read_item(ITEM_LIMITER), LIMITER_ANGLE);
}

/* The limits a stream keeps to (docs/streaming.md), deg/s and deg/s^2. */
#define SPEED_LIMIT 750.0
#define ACCEL_LIMIT 37500.0
/* The walk's last step takes up its rounding (under 2^-32 decideg a
 * tick): on a move across the whole multi-turn range, 5 deg/s^2. */
#define WALK_ROUNDING 1.001

struct peaks {
    double speed, accel; /* deg/s, deg/s^2 */
    uint32_t ticks;      /* until the plan rests or runs on at its end speed */
};

/* The plan the last setpoint made, walked as the tick walks it (Q32
 * decideg per tick to deg/s: x 100 / 2^32), from the speed it started at. */
static struct peaks plan_peaks(void)
{
    const struct profile *p = &servo.motion.profile;
    struct profile_walk w;
    profile_walk_begin(&w, p);
    int64_t last = profile_origin(p), last_step = p->v0;
    struct peaks k = {0, 0, 0};
    uint32_t end = p->total_ticks != UINT32_MAX ? p->total_ticks : p->accel_ticks + 2u;
    for (uint32_t t = 1; t <= end + 1u; t++) {
        int64_t step = w.at - last;
        double speed = fabs((double)step) / 4294967296.0 * 100.0;
        double accel = fabs((double)(step - last_step)) / 4294967296.0 * 1e5;
        k.speed = speed > k.speed ? speed : k.speed;
        k.accel = accel > k.accel ? accel : k.accel;
        last = w.at;
        last_step = step;
        profile_walk_next(&w, p);
    }
    k.ticks = end;
    return k;
}

/* A 100 deg step in 20 ms from rest asked 7 500 deg/s of the
 * cubic. Now the setpoint is reached as a move at the stream's limits:
 * 750 deg/s at most, 37 500 deg/s^2. */
static void test_a_step_keeps_to_the_speed_and_acceleration_limits(void **state)
{
    (void)state;
    stream(0, 0, 0, 0);
    harness_run_ms(20);
    stream(0, 1000, 0, 20);
    struct peaks k = plan_peaks();
    harness_run_ms(1000);
    printf("# a 100 deg step in 20 ms: planned over %u ms, peak %.1f deg/s and %.0f deg/s^2; the horn at %.2f deg\n",
           k.ticks, k.speed, k.accel, plant_angle_deg(&plant));
    assert_true(k.speed <= SPEED_LIMIT && k.accel <= ACCEL_LIMIT * WALK_ROUNDING);
    assert_true(k.ticks >= 100000u / 750u);
    assert_true(fabs(plant_angle_deg(&plant) - 100.0) < 0.2);
}

/* A host back from a stall: its path went on at 300 deg/s while the servo
 * held at 0. Its first setpoint (30 deg at 300 deg/s, one 20 ms period on)
 * asks more than the stream's limits. It, and every one after it for 40
 * frames, was planned as a move at the limits to rest at its setpoint, each
 * cut short by the next (7.6 deg behind after 0.8 s, peak 18 750 deg/s^2).
 * Now each segment is made later instead: none is a move to rest, the
 * setpoint never slows far, and it joins the path (6.9 deg behind, peak
 * 14 091 deg/s^2). */
static void test_a_segment_past_the_limits_keeps_the_stream_going(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_ANGLE_LIMIT_ON, 0); /* the path runs to 264 deg */
    WRITE_ITEM(0, ITEM_STREAM_PERIOD_MS, 20);
    stream(0, 0, 0, 0);
    harness_run_ms(300); /* the stream has stopped: held at 0 */
    double slowest = 1e9, last = setpoint_deg(), peak = 0;
    unsigned moves = 0;
    for (uint32_t k = 0; k < 40; k++) {
        stream(0, (int32_t)(300u + 60u * k), 3000, (uint16_t)(300u + 20u * k));
        moves += servo.motion.profile.accel_j == 0; /* a move to rest, not a segment */
        for (int ms = 0; ms < 20; ms++) {
            harness_run_ms(1);
            double now = setpoint_deg();
            double acc = fabs((double)servo.motion.walk.change_q40) / 1099511627776.0 * 1e5; /* deg/s^2 */
            peak = acc > peak ? acc : peak;
            if (k >= 3u) { /* under way: from the ramp out of rest on */
                double speed = (now - last) * 1000.0;
                slowest = speed < slowest ? speed : slowest;
            }
            last = now;
        }
    }
    double behind = 30.0 + 6.0 * 39.0 - setpoint_deg();
    printf("# back from a stall at 300 deg/s: the setpoint's slowest once under way %.1f deg/s, "
           "%.2f deg behind the last setpoint, peak %.0f deg/s^2, %u of 40 setpoints as moves to rest\n",
           slowest, behind, peak, moves);
    assert_int_equal(moves, 0); /* all 40 were, before */
    assert_true(slowest > 150.0);
    assert_true(behind < 10.0 && behind > -3.0);
}

/* Random setpoints (limits off: +-400 deg, +-900 deg/s asked, 5-100 ms
 * periods, sent at any moment of the last segment, so from every speed
 * the stream reaches): no plan asks more than the limits, whether a cubic
 * or a move at them. */
enum { TRIALS = 3000 };

static void test_no_setpoint_asks_more_than_the_limits(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_ANGLE_LIMIT_ON, 0);
    uint64_t rng = 0x9E3779B97F4A7C15u;
    struct peaks worst = {0, 0, 0};
    unsigned moves = 0;
    uint16_t host_ms = 0;
    for (int trial = 0; trial < TRIALS; trial++) {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        uint32_t r = (uint32_t)(rng >> 20);
        uint16_t period = (uint16_t)(5u + r % 96u);
        int32_t angle = (int32_t)((r >> 7) % 8001u) - 4000;
        /* Mostly near the last one (a stream), now and then far. */
        if (r & 0x10000000u) {
            angle = (int32_t)lround(setpoint_deg() * 10.0) + angle / 40;
        }
        int16_t velocity = (int16_t)((int32_t)((r >> 3) % 18001u) - 9000);
        WRITE_ITEM(0, ITEM_STREAM_PERIOD_MS, period);
        stream(0, angle, velocity, host_ms);
        struct peaks k = plan_peaks();
        moves += servo.motion.profile.accel_j == 0;
        if (k.accel > ACCEL_LIMIT || k.speed > SPEED_LIMIT) {
            printf("# over: trial %d, %d decideg at %d decideg/s, %u ms: %.2f deg/s, %.0f deg/s^2\n", trial, angle,
                   velocity, period, k.speed, k.accel);
        }
        worst.speed = k.speed > worst.speed ? k.speed : worst.speed;
        worst.accel = k.accel > worst.accel ? k.accel : worst.accel;
        uint32_t wait = 1u + (r >> 11) % (2u * period);
        host_ms = (uint16_t)(host_ms + wait);
        harness_run_ms(wait);
    }
    printf("# %d random setpoints (%u as moves at the limits): the plans' peaks %.2f deg/s, %.0f deg/s^2\n", TRIALS,
           moves, worst.speed, worst.accel);
    assert_true(worst.speed <= SPEED_LIMIT);
    assert_true(worst.accel <= ACCEL_LIMIT * WALK_ROUNDING);
    assert_true(moves > TRIALS / 10 && moves < TRIALS * 9 / 10);
}

/* A setpoint 2000 deg away stopped at 1638.5 deg (one
 * segment's reach) without a word. It is reached, at the stream's top
 * speed; the whole multi-turn range is planned the same way. */
static void test_a_far_setpoint_is_reached(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_ANGLE_LIMIT_ON, 0);
    stream(0, 20000, 0, 0);
    assert_int_equal(servo.motion.target_q8, 20000 * 256);
    harness_run_ms(9000);
    printf("# a setpoint 2000 deg away: the horn at %.2f deg\n", plant_angle_deg(&plant));
    assert_true(fabs(plant_angle_deg(&plant) - 2000.0) < 0.2);
    assert_false(servo.motion.running);
    stream(0, -3686400, 0, 20);
    struct peaks k = plan_peaks();
    assert_int_equal(servo.motion.target_q8, -3686400 * 256);
    printf("# and to -368 640 deg: over %u ms, peak %.2f deg/s, %.0f deg/s^2\n", k.ticks, k.speed, k.accel);
    assert_true(k.speed <= SPEED_LIMIT && k.accel <= ACCEL_LIMIT * WALK_ROUNDING);
    assert_true(k.ticks >= (uint32_t)((368640.0 + 2000.0) / SPEED_LIMIT * 1000.0));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_a_stream_tracks_the_path_smoothly, plant_harness_setup),
        cmocka_unit_test_setup(test_a_host_late_or_early_changes_nothing, plant_harness_setup),
        cmocka_unit_test_setup(test_a_late_stream_brakes_to_a_hold, plant_harness_setup),
        cmocka_unit_test_setup(test_the_period_is_learned_or_told, plant_harness_setup),
        cmocka_unit_test_setup(test_a_late_frame_keeps_its_place, plant_harness_setup),
        cmocka_unit_test_setup(test_an_early_first_frame_and_a_late_one_stop_nothing, plant_harness_setup),
        cmocka_unit_test_setup(test_a_jittery_host_stops_no_stream, plant_harness_setup),
        cmocka_unit_test_setup(test_a_first_setpoint_and_a_wait_teach_no_period, plant_harness_setup),
        cmocka_unit_test_setup(test_an_early_last_frame_stops_within_periods, plant_harness_setup),
        cmocka_unit_test_setup(test_the_host_clock_wraps, plant_harness_setup),
        cmocka_unit_test_setup(test_a_stream_takes_over_a_move, plant_harness_setup),
        cmocka_unit_test_setup(test_a_broadcast_setpoint_is_taken_silently, plant_harness_setup),
        cmocka_unit_test_setup(test_a_streamed_setpoint_keeps_to_the_angle_limits, plant_harness_setup),
        cmocka_unit_test_setup(test_a_step_keeps_to_the_speed_and_acceleration_limits, plant_harness_setup),
        cmocka_unit_test_setup(test_no_setpoint_asks_more_than_the_limits, plant_harness_setup),
        cmocka_unit_test_setup(test_a_segment_past_the_limits_keeps_the_stream_going, plant_harness_setup),
        cmocka_unit_test_setup(test_a_far_setpoint_is_reached, plant_harness_setup),
        cmocka_unit_test_setup(test_a_streams_path_keeps_within_the_limits, plant_harness_setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
