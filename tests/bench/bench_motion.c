/* Benchmark (not a test): instructions to plan a move and to run a control
 * tick. Run it through tests/bench/target/run_target_bench.py.
 *
 * Regions (bench_region.h):
 *   plan_interval, plan_velocity, plan_short_stroke, plan_preempt
 *       motion_submit() of one move: clamping, timing, profile planning
 *   ticks  MOTION_BENCH_TICKS control ticks of a move (encoder read,
 *          profile evaluation, controller, motor output) */
#include <stdio.h>
#include <string.h>

#include "bench_region.h"
#include "hal_double.h"
#include "motion/motion.h"

#define MOTION_BENCH_TICKS 2000u

static struct hal_double hal;
static struct registers regs;
static struct motion motion;

static void fresh(void)
{
    hal_double_init(&hal);
    memset(&regs, 0, sizeof regs);
    regs.user = (struct user_config){.check_flag = 1, .baud_index = 5, .power_limit_mw = 10000,
                                     .low_voltage_mv = 4000, .high_voltage_mv = 8400,
                                     .angle_limit_on = 1, .angle_max_decideg = 1350,
                                     .angle_min_decideg = -1350};
    motion_init(&motion, &regs, &hal.port);
    motion.soft_start_pending = 0;
}

static void plan(const char *name, const struct motion_command *cmd)
{
    bench_begin();
    motion_submit(&motion, cmd);
    bench_end(name);
}

int main(void)
{
    fresh();
    bench_setup();
    const struct motion_command interval = {.packet = 14, .kind = MOTION_ANGLE, .multi_turn = 1,
                                            .angle_decideg = 36000, .interval_ms = 3000,
                                            .acc_ms = 300, .dec_ms = 300};
    plan("plan_interval", &interval);

    /* Ticks of that move: ramp and cruise, the encoder following. */
    bench_begin();
    for (unsigned i = 0; i < MOTION_BENCH_TICKS; i++) {
        hal.encoder_raw = (uint16_t)(hal.encoder_raw + 5u);
        motion_tick(&motion);
    }
    bench_end("ticks");

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
    printf("ticks %u\n", MOTION_BENCH_TICKS);
    return 0;
}
