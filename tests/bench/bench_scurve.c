/* Benchmark (not a test): jerk-limited moves (item 70) against the maker's
 * trapezoid. Each move is planned as the firmware plans it (motion_submit)
 * with and without the jerk limit, and both profiles are walked as the
 * control tick walks them; it prints, per move, the window, the peak jerk
 * of the walked setpoint against the limit, the peak acceleration and the
 * profile's duration against the trapezoid's. Host build:
 *     build/host/tests/bench_scurve
 * (docs/benchmark.md, "Jerk-limited moves"). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "doubles/hal_double.h"
#include "motion/motion.h"

#define Q32 4294967296.0
#define S_TO_TICKS 1000.0 /* MOTION_TICK_HZ */

struct walked {
    double peak_jerk, peak_acceleration; /* decideg per tick^3, ^2 */
    uint32_t ticks;
};

static struct walked walk(const struct profile *p)
{
    struct walked w = {0};
    struct profile_walk pw;
    profile_walk_begin(&pw, p);
    double x[4] = {0}; /* the last four positions */
    uint32_t end = p->total_ticks + p->smooth_ticks;
    for (uint32_t t = 1; t <= end + 3u; t++) {
        memmove(x, x + 1, 3 * sizeof x[0]);
        x[3] = (double)pw.at / Q32;
        if (t >= 4u) {
            w.peak_acceleration = fmax(w.peak_acceleration, fabs(x[3] - 2 * x[2] + x[1]));
            w.peak_jerk = fmax(w.peak_jerk, fabs(x[3] - 3 * x[2] + 3 * x[1] - x[0]));
        }
        profile_walk_next(&pw, p);
    }
    w.ticks = end;
    return w;
}

static struct profile planned(const struct motion_command *cmd, uint16_t jerk_limit)
{
    static struct hal_double hal;
    static struct registers regs;
    static struct motion motion;
    hal_double_init(&hal);
    memset(&regs, 0, sizeof regs);
    regs.user = (struct user_config){.check_flag = 1, .baud_index = 5, .power_limit_mw = 10000,
                                     .current_limit_ma = 4000, .low_voltage_mv = 4000,
                                     .high_voltage_mv = 8400};
    regs.firmware.jerk_limit = jerk_limit;
    motion_init(&motion, &regs, &hal.port);
    motion.soft_start_pending = 0;
    if (motion_submit(&motion, cmd) != MOTION_ACCEPTED) {
        printf("bench_scurve: a move was refused\n");
    }
    return motion.profile;
}

struct move {
    const char *what;
    struct motion_command cmd;
    uint16_t jerk_limit; /* (deg/s^2)/ms */
};

int main(void)
{
    static const struct move moves[] = {
        {"90 deg in 1 s, ramps 200 ms", {.packet = 11, .kind = MOTION_ANGLE, .profile = PROFILE_INTERVAL,
          .angle_decideg = 900, .interval_ms = 1000, .acc_ms = 200, .dec_ms = 200}, 10},
        {"the same, 50 (deg/s^2)/ms", {.packet = 11, .kind = MOTION_ANGLE, .profile = PROFILE_INTERVAL,
          .angle_decideg = 900, .interval_ms = 1000, .acc_ms = 200, .dec_ms = 200}, 50},
        {"100 deg at 300 deg/s, ramps 100/200 ms", {.packet = 12, .kind = MOTION_ANGLE,
          .profile = PROFILE_VELOCITY, .angle_decideg = 1000, .velocity_decideg_s = 3000, .acc_ms = 100,
          .dec_ms = 200}, 20},
        {"short stroke: 20 deg, the same", {.packet = 12, .kind = MOTION_ANGLE,
          .profile = PROFILE_VELOCITY, .angle_decideg = 200, .velocity_decideg_s = 3000, .acc_ms = 100,
          .dec_ms = 200}, 20},
        {"10 turns at 600 deg/s, ramps 50 ms", {.packet = 15, .kind = MOTION_ANGLE, .multi_turn = 1,
          .profile = PROFILE_VELOCITY, .angle_decideg = 36000, .velocity_decideg_s = 6000,
          .acc_ms = 50, .dec_ms = 50}, 200},
    };
    printf("| move | limit ((deg/s^2)/ms) | window (ms) | peak jerk / limit | peak acceleration, "
           "S / trapezoid (deg/s^2) | duration, S / trapezoid (ms) |\n|---|---:|---:|---:|---:|---:|\n");
    for (size_t i = 0; i < sizeof moves / sizeof moves[0]; i++) {
        struct profile trapezoid = planned(&moves[i].cmd, 0);
        struct profile smooth = planned(&moves[i].cmd, moves[i].jerk_limit);
        struct walked t = walk(&trapezoid), s = walk(&smooth);
        /* decideg per tick^n to deg per s^n: / 10 x 1000^n. */
        double limit = moves[i].jerk_limit * 1000.0;
        double jerk = s.peak_jerk / 10.0 * S_TO_TICKS * S_TO_TICKS * S_TO_TICKS;
        printf("| %s | %u | %u | %.4f | %.0f / %.0f | %u / %u |\n", moves[i].what,
               (unsigned)moves[i].jerk_limit, (unsigned)smooth.smooth_ticks, jerk / limit,
               s.peak_acceleration / 10.0 * S_TO_TICKS * S_TO_TICKS,
               t.peak_acceleration / 10.0 * S_TO_TICKS * S_TO_TICKS, (unsigned)s.ticks,
               (unsigned)t.ticks);
    }
    return 0;
}
