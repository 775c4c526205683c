/* Jerk-limited (S-curve) profiles: the trapezoid averaged over a window,
 * walked tick by tick in fixed point, against the same average worked out
 * in doubles, and against the limits it promises (jerk, acceleration, the
 * exact target, the start's position and speed). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "motion/profile.h"
#include "support/xorshift.h"

#define Q32 4294967296.0
#define Q8_UNIT (1.0 / 256.0) /* decideg: the tick's setpoint resolution */
/* The walked positions are the exact average's plus an error e (each step
 * rounded down; the jerk rounded to Q40, over a window's ticks); the end
 * takes e back in a tick, its position being the target exactly. A third
 * difference of them is off by up to 8 |e|: below what the Q8 setpoint
 * shows. The walk's own jerk, phase by phase, is within the limit. */
#define JERK_NOISE(w) (8.0 * ((w).worst_error + 1.0 / Q32))

/* The trapezoid p in doubles at time t (any real), from its own
 * coefficients: before it, its start moving at v0; after it, the target. */
static double trapezoid(const struct profile *p, double t)
{
    double start = (double)p->start / Q32, v0 = (double)p->v0 / Q32;
    double k1 = (double)p->accel_k / Q32 / 256.0, k3 = (double)p->decel_k / Q32 / 256.0;
    double n1 = p->accel_ticks, ce = p->cruise_end, total = p->total_ticks;
    if (t < n1) {
        return start + v0 * t + (t > 0 ? k1 * t * t : 0);
    }
    if (t < ce) {
        return start + v0 * n1 + k1 * n1 * n1 + (double)p->cruise / Q32 * (t - n1);
    }
    if (t < total) {
        return (double)p->target / Q32 - k3 * (total - t) * (total - t);
    }
    return (double)p->target / Q32;
}

/* Its average over [t - T, t]: Simpson's rule on whole ticks, exact for the
 * quadratic pieces between the trapezoid's (whole-tick) phase ends. */
static double average(const struct profile *p, double t)
{
    double window = p->smooth_ticks, sum = 0;
    for (double a = t - window; a < t; a += 1.0) {
        sum += (trapezoid(p, a) + 4 * trapezoid(p, a + 0.5) + trapezoid(p, a + 1.0)) / 6.0;
    }
    return sum / window;
}

struct walked {
    double worst_error;      /* decideg, against average() */
    double peak_jerk;        /* decideg per tick^3: the walk's third difference */
    double peak_acceleration; /* decideg per tick^2 */
    double peak_planned_jerk; /* decideg per tick^3: the walk's jerk, phase by phase */
    uint32_t ticks;          /* to the end */
};

/* Walks p from its start as the control tick does, to its end and beyond. */
static struct walked walk(const struct profile *p, int64_t origin, int64_t v0)
{
    struct walked w = {0};
    struct profile_walk pw;
    profile_walk_begin(&pw, p);
    double last[4] = {(double)(origin - 2 * v0) / Q32, (double)(origin - v0) / Q32, (double)origin / Q32, 0};
    assert_true(profile_origin(p) == origin);
    uint32_t end = p->total_ticks + p->smooth_ticks;
    for (uint32_t tick = 1; tick <= end + 5u; tick++) {
        double at = (double)pw.at / Q32;
        last[3] = at;
        double error = fabs(at - average(p, tick));
        w.worst_error = error > w.worst_error ? error : w.worst_error;
        double acceleration = last[3] - 2 * last[2] + last[1];
        double jerk = last[3] - 3 * last[2] + 3 * last[1] - last[0];
        w.peak_acceleration = fmax(w.peak_acceleration, fabs(acceleration));
        /* From tick 3 on, all four samples are the move's own. */
        if (tick >= 3u) {
            w.peak_jerk = fmax(w.peak_jerk, fabs(jerk));
        }
        memmove(last, last + 1, 3 * sizeof last[0]);
        if (tick == end) {
            assert_true(pw.at == p->target); /* exactly */
        }
        if (tick >= end) {
            assert_true(profile_done(p, tick));
        } else {
            assert_false(profile_done(p, tick));
        }
        w.peak_planned_jerk = fmax(w.peak_planned_jerk, fabs((double)pw.jerk_q40 / Q32 / 256.0));
        profile_walk_next(&pw, p);
    }
    w.ticks = end;
    return w;
}

/* A move planned the way planning.c plans one, smoothed for jerk (Q24). */
static uint32_t plan(struct profile *p, int64_t start, int64_t v0, int64_t target,
                     struct profile_timing timing, uint32_t jerk_q24)
{
    profile_plan(p, start, v0, target, timing);
    uint32_t window = profile_smooth_ticks(p, jerk_q24);
    if (v0 != 0 && window != 0u) {
        profile_plan(p, start + profile_smooth_shift(v0, window), v0, target, timing);
    }
    profile_smooth(p, window);
    return window;
}

static double jerk_of(uint32_t jerk_q24)
{
    return jerk_q24 / 16777216.0;
}

/* 90 degrees from rest, ramps of 200 ms around a 600 ms cruise. */
static void test_a_move_from_rest(void **state)
{
    (void)state;
    struct profile p;
    uint32_t jerk = 168u * 10u; /* 10 (deg/s^2)/ms, about 1e-4 decideg per tick^3 */
    uint32_t window = plan(&p, 0, 0, 900 * (int64_t)Q32, (struct profile_timing){200, 600, 200}, jerk);
    /* 900 decideg over 200 + 600 + 200 ticks: V = 1.125, a = 1.125 / 200
     * decideg per tick^2, so the window is a / J = 56.2 ticks, rounded up. */
    assert_int_equal(window, 57);
    struct walked w = walk(&p, 0, 0);
    assert_true(w.worst_error < Q8_UNIT);
    assert_true(w.peak_planned_jerk <= jerk_of(jerk));
    assert_true(w.peak_jerk <= jerk_of(jerk) + JERK_NOISE(w));
    assert_true(w.peak_jerk > 0.95 * jerk_of(jerk));
    assert_true(w.peak_acceleration <= 1.125 / 200 * 1.0001); /* the trapezoid's */
    assert_int_equal(w.ticks, 1000 + 57);
}

/* A retarget while moving at v0: the walk starts where the setpoint is, at
 * its speed, and the window's shift keeps the target exact. */
static void test_a_move_that_takes_over_a_moving_setpoint(void **state)
{
    (void)state;
    struct profile p;
    int64_t v0 = (int64_t)(0.8 * Q32), start = 1234 * (int64_t)Q32;
    uint32_t window = plan(&p, start, v0, -3000 * (int64_t)Q32, (struct profile_timing){150, 2000, 300},
                           168u * 50u);
    assert_true(window > 0u);
    struct walked w = walk(&p, start, v0);
    assert_true(w.worst_error < Q8_UNIT);
    /* The window's shift changes the ramps' accelerations a little. */
    assert_true(w.peak_jerk <= 1.05 * jerk_of(168u * 50u) + JERK_NOISE(w));
}

/* A cruise shorter than the window: the window spans the end of one ramp
 * and the start of the other, whose jumps add, and the window grows so the
 * jerk stays within its limit. */
static void test_a_short_cruise_lengthens_the_window(void **state)
{
    (void)state;
    struct profile p;
    uint32_t jerk = 168u * 20u;
    plan(&p, 0, 0, 300 * (int64_t)Q32, (struct profile_timing){100, 5, 100}, jerk);
    struct walked w = walk(&p, 0, 0);
    assert_true(w.worst_error < Q8_UNIT);
    assert_true(w.peak_jerk <= jerk_of(jerk) + JERK_NOISE(w));
}

/* Randomized moves: every one within the jerk, on the average, exactly at
 * its target. */
static void test_randomized_smoothed_moves(void **state)
{
    (void)state;
    uint64_t seed = 20261126u;
    for (int i = 0; i < 300; i++) {
        struct profile p;
        int64_t start = (int64_t)((uint32_t)xorshift64(&seed) % 200000u) - 100000;
        int64_t distance = (int64_t)((uint32_t)xorshift64(&seed) % 40000u) - 20000;
        int64_t v0 = i % 3 == 0 ? (int64_t)((uint32_t)xorshift64(&seed) % 4000u) - 2000 : 0;
        struct profile_timing t = {20u + (uint32_t)xorshift64(&seed) % 400u, (uint32_t)xorshift64(&seed) % 1500u,
                                   20u + (uint32_t)xorshift64(&seed) % 400u};
        uint32_t jerk = 168u * (1u + (uint32_t)xorshift64(&seed) % 300u);
        uint32_t window = plan(&p, start * (int64_t)Q32 / 10, v0 * (int64_t)Q32 / 1000,
                               (start + distance) * (int64_t)Q32 / 10, t, jerk);
        struct walked w = walk(&p, start * (int64_t)Q32 / 10, v0 * (int64_t)Q32 / 1000);
        assert_true(w.worst_error < 2 * Q8_UNIT);
        if (v0 == 0 && window < PROFILE_MAX_SMOOTH) {
            assert_true(w.peak_planned_jerk <= jerk_of(jerk));
            assert_true(w.peak_jerk <= jerk_of(jerk) + JERK_NOISE(w));
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_a_move_from_rest),
        cmocka_unit_test(test_a_move_that_takes_over_a_moving_setpoint),
        cmocka_unit_test(test_a_short_cruise_lengthens_the_window),
        cmocka_unit_test(test_randomized_smoothed_moves),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
