/* Benchmark (not a test): instructions to plan a move and to run a control
 * tick. Run it through tests/bench/target/run_target_bench.py.
 *
 * Regions (bench_region.h):
 *   plan_interval, plan_velocity, plan_short_stroke, plan_preempt
 *       motion_submit() of one move: clamping, timing, profile planning
 *   plan_jerk_rest, plan_jerk_preempt  the same for a jerk-limited move
 *       (item 70), from rest and over a moving setpoint (the M3 only)
 *   ticks_follow  MOTION_BENCH_TICKS control ticks of a move the horn
 *          follows (the encoder replays the setpoint of a first run): real
 *          time, the braking guard's full check, the whole controller
 *   ticks_at_limit  MOTION_BENCH_TICKS ticks of a move faster than the horn
 *          (the encoder turns 5 counts a tick): the slowed clock, then the
 *          guard's braking
 *   servo_tick  each of MOTION_BENCH_TICKS servo_control_tick calls as the
 *          firmware runs them (sensors, protection monitors, motion,
 *          status) on the same followed move, sensors at their healthy
 *          readings: one region per tick, for the worst tick
 *   ticks_stream  MOTION_BENCH_TICKS ticks of a 50 Hz stream the horn
 *          follows: the cubic's walk, a segment begun every 20 ticks
 *   safety_pass  what the main loop's pass runs after each of those ticks
 *          (safety_tend): the bus watchdog (on, never firing), the winding's
 *          sample and its model's step every 80 ms
 * The runner takes the HAL double's own instructions (hal_double.c, found
 * by the plugin's per-block profile) off every tick region; the firmware's
 * calls to it stay in. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/bench_region.h"
#include "doubles/hal_double.h"
#include "doubles/ideal_encoder.h"
#include "motion/motion.h"
#include "app/servo.h"
#include "app/servo_safety.h"

#define MOTION_BENCH_TICKS 2000u
#define STREAM_PERIOD_TICKS 20u /* 50 Hz */

static struct hal_double hal;
static struct registers regs;
static struct motion motion;
static struct servo servo;

static void fresh(void)
{
    hal_double_init(&hal);
    memset(&regs, 0, sizeof regs);
    /* The data table's factory values where motion reads them. */
    regs.user = (struct user_config){.check_flag = 1, .baud_index = 5, .power_limit_mw = 10000,
                                     .current_limit_ma = 4000,
                                     .low_voltage_mv = 4000, .high_voltage_mv = 8400,
                                     .angle_limit_on = 1, .angle_max_decideg = 1350,
                                     .angle_min_decideg = -1350};
    motion_init(&motion, &regs, &hal.port);
    motion.soft_start_pending = 0;
}

/* A refused move would measure nothing: the run stops and says so. */
static void must_accept(enum motion_submit_result result, const char *what)
{
    if (result != MOTION_ACCEPTED) {
        printf("bench: %s refused (result %d)\n", what, (int)result);
        exit(1);
    }
}

static void plan(const char *name, const struct motion_command *cmd)
{
    bench_begin();
    enum motion_submit_result result = motion_submit(&motion, cmd);
    bench_end(name);
    must_accept(result, name);
}

/* The encoder readings of a horn that follows the setpoint exactly. */
static uint16_t follow_raw[MOTION_BENCH_TICKS];

int main(void)
{
    fresh();
    bench_setup();
    const struct motion_command interval = {.packet = 14, .kind = MOTION_ANGLE, .multi_turn = 1,
                                            .angle_decideg = 36000, .interval_ms = 3000,
                                            .acc_ms = 300, .dec_ms = 300};
    /* A move the horn follows: its readings first, then the ticks again
     * on them. The first 2000 ticks of the 3000 ms move (240 deg/s): the
     * ramp and the cruise. */
    const struct motion_command follow = {.packet = 14, .kind = MOTION_ANGLE, .multi_turn = 1,
                                          .angle_decideg = 6000, .interval_ms = 3000,
                                          .acc_ms = 500, .dec_ms = 500};
    must_accept(motion_submit(&motion, &follow), "the followed move");
    for (unsigned i = 0; i < MOTION_BENCH_TICKS; i++) {
        hal.encoder_raw = follow_raw[i] = ideal_encoder_raw(&motion);
        motion_tick(&motion);
    }
    fresh();
    must_accept(motion_submit(&motion, &follow), "the followed move");
    bench_begin();
    for (unsigned i = 0; i < MOTION_BENCH_TICKS; i++) {
        hal.encoder_raw = follow_raw[i];
        motion_tick(&motion);
    }
    bench_end("ticks_follow");

    /* The whole tick: a servo on the same move. The double's healthy
     * readings (7.4 V, 25 degC) and 0.3 A keep every monitor quiet. */
    hal_double_init(&hal);
    hal.sensors.current = 300;
    servo_init(&servo, &hal.port);
    servo.motion.soft_start_pending = 0;
    servo.regs.firmware.watchdog_ms = 60000; /* on, counting; it never fires here */
    must_accept(motion_submit(&servo.motion, &follow), "the servo's followed move");
    for (unsigned i = 0; i < MOTION_BENCH_TICKS; i++) {
        hal.encoder_raw = follow_raw[i];
        bench_begin();
        servo_control_tick(&servo);
        bench_end("servo_tick");
        bench_begin();
        safety_tend(&servo.safety, &servo.regs, &servo.motion, servo.dispatcher.heard);
        bench_end("safety_pass");
    }
    if (servo.regs.status.status & ~STATUS_EXECUTING) {
        printf("bench: the servo's monitors tripped (status %#x)\n", servo.regs.status.status);
        exit(1);
    }

    fresh();
    plan("plan_interval", &interval);
    /* Ticks of a move faster than the horn: the encoder turns 5 counts a
     * tick (440 deg/s) where the move asks 1200. */
    bench_begin();
    for (unsigned i = 0; i < MOTION_BENCH_TICKS; i++) {
        hal.encoder_raw = (uint16_t)(hal.encoder_raw + 5u);
        motion_tick(&motion);
    }
    bench_end("ticks_at_limit");

    const struct motion_command preempt = {.packet = 12, .kind = MOTION_ANGLE,
                                           .profile = PROFILE_VELOCITY, .angle_decideg = -900,
                                           .velocity_decideg_s = 3000, .acc_ms = 100,
                                           .dec_ms = 200};
    plan("plan_preempt", &preempt);

    fresh();
    const struct motion_command velocity = {.packet = 12, .kind = MOTION_ANGLE,
                                            .profile = PROFILE_VELOCITY, .angle_decideg = 1000,
                                            .velocity_decideg_s = 3000, .acc_ms = 100,
                                            .dec_ms = 200};
    plan("plan_velocity", &velocity);

    fresh();
    const struct motion_command short_stroke = {.packet = 12, .kind = MOTION_ANGLE,
                                                .profile = PROFILE_VELOCITY, .angle_decideg = 200,
                                                .velocity_decideg_s = 3000, .acc_ms = 100,
                                                .dec_ms = 200};
    plan("plan_short_stroke", &short_stroke);

    /* Jerk-limited moves (item 70, 20 (deg/s^2)/ms): from rest, then over
     * the moving setpoint 300 ticks on. On every CPU: the Cortex-M0's
     * library plans them as trapezoids (run_target_bench.py shows nan). */
    {
        fresh();
        regs.firmware.jerk_limit = 20;
        plan("plan_jerk_rest", &velocity);
        for (unsigned i = 0; i < 300u; i++) {
            motion_tick(&motion);
        }
        plan("plan_jerk_preempt", &preempt);
    }

    /* A host's stream at 50 Hz (StreamSetpoint): setpoints on arches of
     * 0..60 deg, 2 s each, with their speeds; the horn follows (the
     * readings of a first run replayed). The setpoints' arrivals are
     * outside the region, each period's 20 ticks in it. */
    for (int replay = 0; replay < 2; replay++) {
        fresh();
        for (unsigned k = 0; k < MOTION_BENCH_TICKS / STREAM_PERIOD_TICKS; k++) {
            int32_t p = (int32_t)(k % 100u);
            const struct motion_setpoint sp = {
                .angle_decideg = 600 - 24 * p * (100 - p) / 100,
                .velocity_decideg_s = (int16_t)(-12 * (100 - 2 * p)),
                .host_ms = (uint16_t)(k * STREAM_PERIOD_TICKS)};
            must_accept(motion_stream(&motion, &sp), "a streamed setpoint");
            unsigned at = k * STREAM_PERIOD_TICKS;
            if (!replay) {
                for (unsigned i = at; i < at + STREAM_PERIOD_TICKS; i++) {
                    hal.encoder_raw = follow_raw[i] = ideal_encoder_raw(&motion);
                    motion_tick(&motion);
                }
                continue;
            }
            bench_begin();
            for (unsigned i = at; i < at + STREAM_PERIOD_TICKS; i++) {
                hal.encoder_raw = follow_raw[i];
                motion_tick(&motion);
            }
            bench_end("ticks_stream");
        }
    }
    printf("ticks %u\n", MOTION_BENCH_TICKS);
    return 0;
}
