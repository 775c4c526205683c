/* The fixed-point profile against the protocol's worked examples and
 * against an exact double-precision evaluation of the same profile over
 * randomized moves (floating point lives only here, in the test). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "motion/profile.h"
#include "support/profile_closed_form.h"
#include "support/xorshift.h"

#define TOLERANCE_DECIDEG 0.5 /* 0.05 degree */

static double to_decideg(int64_t q32)
{
    return (double)q32 / 4294967296.0;
}

static int64_t from_decideg(double d)
{
    return (int64_t)llround(d * 4294967296.0);
}

/* Q32 decideg per tick for a velocity in 0.1 deg/s. */
static int64_t velocity_q32(uint32_t decideg_per_s)
{
    return (int64_t)(((uint64_t)decideg_per_s << 32) / MOTION_TICK_HZ);
}

/* The same profile in doubles: phase lengths from the plan, cruise velocity
 * from its defining equation. */
struct reference {
    double start, target, v0, v;
    double n1, c_end, total;
};

static struct reference reference_of(const struct profile *p)
{
    struct reference r = {
        .start = to_decideg(p->start),
        .target = to_decideg(p->target),
        .v0 = to_decideg(p->v0),
        .n1 = p->accel_ticks,
        .c_end = p->cruise_end,
        .total = p->total_ticks,
    };
    double nc = r.c_end - r.n1;
    double n3 = r.total - r.c_end;
    r.v = (2.0 * (r.target - r.start) - r.v0 * r.n1) / (r.n1 + 2.0 * nc + n3);
    return r;
}

static double reference_position(const struct reference *r, double t)
{
    if (t >= r->total) {
        return r->target;
    }
    if (t < r->n1) {
        return r->start + r->v0 * t + (r->v - r->v0) * t * t / (2.0 * r->n1);
    }
    double p1 = r->start + (r->v0 + r->v) * r->n1 / 2.0;
    if (t < r->c_end) {
        return p1 + r->v * (t - r->n1);
    }
    double u = r->total - t;
    return r->target - r->v * u * u / (2.0 * (r->total - r->c_end));
}

static double worst_error;

static void check_tick(const struct profile *p, const struct reference *r, uint32_t t)
{
    double err = fabs(to_decideg(profile_position(p, t)) - reference_position(r, t));
    if (err > worst_error) {
        worst_error = err;
    }
    if (err > TOLERANCE_DECIDEG) {
        fail_msg("tick %u of %u: setpoint off by %.4f decideg", t, p->total_ticks, err);
    }
}

/* Every tick of every move up to 50 000 ticks. Longer moves: every tick of
 * the ramps and of 10 000 ticks each side of every phase boundary, and in
 * between every 64th tick, or 4096 evenly spaced ones in cruises longer
 * than 262 144 ticks (the error there grows linearly, so the edges bound it). */
static void check_profile(const struct profile *p)
{
    struct reference r = reference_of(p);
    uint32_t total = p->total_ticks;
    const uint32_t dense = 10000;
    uint32_t stride = total / 4096 > 64 ? total / 4096 : 64;
    for (uint32_t t = 0; t <= total; t++) {
        bool near_edge = total <= 50000 || t < p->accel_ticks + dense ||
                         (t + dense > p->cruise_end && t < p->cruise_end + dense) ||
                         t + dense > total;
        if (near_edge) {
            check_tick(p, &r, t);
        } else {
            check_tick(p, &r, t);
            t += stride - 1; /* the loop adds one */
        }
    }
    assert_true(profile_position(p, total) == p->target);
    assert_true(profile_position(p, total + 1000) == p->target);
}

static void test_interval_example(void **state)
{
    (void)state;
    /* 100 deg in 1000 ms, ramps 100/200 ms: cruise 117.6 deg/s. */
    struct profile p;
    profile_plan(&p, 0, 0, 1000 * DECIDEG_Q32, (struct profile_timing){100, 700, 200});
    double cruise_deg_s = to_decideg(p.cruise) * MOTION_TICK_HZ / 10.0;
    assert_true(fabs(cruise_deg_s - 100.0 / 0.85) < 1e-6);
    assert_int_equal(p.total_ticks, 1000);
    check_profile(&p);
}

static void test_velocity_example(void **state)
{
    (void)state;
    /* 100 deg at 300 deg/s, ramps 100/200 ms: cruise 183 ms, total 483 ms. */
    struct profile_timing t =
        profile_velocity_timing(1000 * DECIDEG_Q32, 0, velocity_q32(3000), 100, 200);
    assert_int_equal(t.accel, 100);
    assert_int_equal(t.cruise, 183);
    assert_int_equal(t.decel, 200);
    struct profile p;
    profile_plan(&p, 0, 0, 1000 * DECIDEG_Q32, t);
    assert_int_equal(p.total_ticks, 483);
    check_profile(&p);
}

static void test_short_stroke_example(void **state)
{
    (void)state;
    /* 20 deg at 300 deg/s, ramps 100/200 ms: T1' = 44 ms, T3' = 88 ms. */
    struct profile_timing t =
        profile_velocity_timing(200 * DECIDEG_Q32, 0, velocity_q32(3000), 100, 200);
    assert_int_equal(t.accel, 44);
    assert_int_equal(t.decel, 88);
    /* Exact total 133.3 ms: within one tick. */
    assert_int_equal(t.accel + t.cruise + t.decel, 133);
    struct profile p;
    profile_plan(&p, 0, 0, 200 * DECIDEG_Q32, t);
    /* The peak stays at the target velocity (to within the rounding). */
    double peak = to_decideg(p.cruise) * MOTION_TICK_HZ;
    assert_true(fabs(peak - 3000.0) < 3000.0 * 0.01);
    check_profile(&p);
}

/* A stroke too short for its ramps shrinks both by distance / ramps: each
 * ramp's ticks the exact floor, their sum the exact rounded quotient. */
static void test_short_strokes_count_exactly(void **state)
{
    (void)state;
    srand(7);
    unsigned checked = 0;
    for (int i = 0; i < 20000; i++) {
        uint32_t accel = 1u + (uint32_t)rand() % 3000u;
        uint32_t decel = 1u + (uint32_t)rand() % 3000u;
        int64_t vmax = velocity_q32(1u + (uint32_t)rand() % 40000u);
        int64_t v0 = rand() % 2 ? 0 : velocity_q32((uint32_t)rand() % 20000u) * (rand() % 2 ? 1 : -1);
        int64_t distance = (int64_t)(rand() % 36000 - 18000) * DECIDEG_Q32 + rand();
        int64_t v = distance >= 0 ? vmax : -vmax;
        int64_t ramps = ((v0 + v) * (int64_t)accel + v * (int64_t)decel) / 2;
        int64_t rest = distance - ramps;
        if (distance == 0 || rest == 0 || (rest > 0) == (v > 0) || (ramps > 0) != (distance > 0)) {
            continue; /* not a short stroke */
        }
        uint64_t d16 = (uint64_t)llabs(distance) >> 16;
        uint64_t r16 = (uint64_t)llabs(ramps) >> 16;
        if (r16 == 0u) {
            continue;
        }
        struct profile_timing t = profile_velocity_timing(distance, v0, vmax, accel, decel);
        __extension__ typedef unsigned __int128 u128;
        assert_int_equal(t.accel, (uint64_t)((u128)accel * d16 / r16));
        assert_int_equal(t.decel, (uint64_t)((u128)decel * d16 / r16));
        u128 sum = (u128)(accel + decel) * d16;
        assert_int_equal(t.accel + t.cruise + t.decel, (uint64_t)((sum + r16 / 2u) / r16));
        checked++;
    }
    assert_true(checked > 1000u);
}

static void test_negative_and_multi_turn(void **state)
{
    (void)state;
    struct profile p;
    profile_plan(&p, 3686400 * DECIDEG_Q32, 0, -3686400 * DECIDEG_Q32,
                 (struct profile_timing){65535, 4096000 - 2 * 65535, 65535});
    check_profile(&p);
    assert_true(p.cruise < 0);
}

static void test_endless(void **state)
{
    (void)state;
    struct profile p;
    int64_t v = velocity_q32(7500);
    profile_plan_endless(&p, 0, 0, v, 20);
    assert_false(profile_done(&p, 4000000000u));
    assert_true(profile_position(&p, 21) - profile_position(&p, 20) == v); /* at speed */
    /* After the ramp: 10 ticks of mean velocity, then v per tick. */
    double expect = to_decideg(v) * (10.0 + 1000.0);
    assert_true(fabs(to_decideg(profile_position(&p, 1020)) - expect) < 1e-3);
}

static void test_too_fast_moves_take_longer(void **state)
{
    (void)state;
    struct profile p;
    /* 2048 turns in 40 ms would need 18 million deg/s. */
    profile_plan(&p, -3686400 * DECIDEG_Q32, 0, 3686400 * DECIDEG_Q32,
                 (struct profile_timing){20, 0, 20});
    assert_true(p.cruise <= PROFILE_MAX_VELOCITY);
    assert_true(p.total_ticks > 40);
    check_profile(&p);
}

/* Log-uniform integer in [lo, hi]. */
static uint32_t log_uniform(uint32_t lo, uint32_t hi)
{
    double x = log((double)lo) + (log((double)hi) - log((double)lo)) * (rand() / (double)RAND_MAX);
    uint32_t v = (uint32_t)llround(exp(x));
    return v < lo ? lo : v > hi ? hi : v;
}

static int64_t random_position(bool multi_turn)
{
    int32_t range = multi_turn ? 3686400 : 1800;
    double frac = rand() / (double)RAND_MAX * 2.0 - 1.0;
    return from_decideg(frac * range) + (rand() % 65536);
}

/* A move as the protocol can ask for it, clamped as docs/protocol.md says. */
static void random_move(struct profile *p, int64_t start, int64_t v0, bool *velocity_based,
                        double *analytic_ticks)
{
    bool multi_turn = rand() % 2;
    int64_t target = random_position(multi_turn);
    if (rand() % 10 == 0) { /* short strokes */
        target = start + from_decideg((rand() % 2001 - 1000) / 100.0);
    }
    uint32_t acc = log_uniform(20, 65535);
    uint32_t dec = log_uniform(20, 65535);
    *velocity_based = rand() % 2;
    if (!*velocity_based) {
        uint32_t interval = log_uniform(40, 4096000);
        if (interval < acc + dec) {
            interval = acc + dec;
        }
        profile_plan(p, start, v0, target, (struct profile_timing){acc, interval - acc - dec, dec});
        *analytic_ticks = interval;
        return;
    }
    uint32_t vel = log_uniform(10, 7500);
    int64_t vmax = velocity_q32(vel);
    struct profile_timing t = profile_velocity_timing(target - start, v0, vmax, acc, dec);
    profile_plan(p, start, v0, target, t);
    /* The exact duration of the same velocity-based move. */
    double d = to_decideg(target - start);
    double v = (d >= 0 ? 1 : -1) * to_decideg(vmax);
    double w0 = to_decideg(v0);
    double ramps = ((w0 + v) * acc + v * dec) / 2.0;
    double rest = d - ramps;
    if (rest == 0 || (rest > 0) == (v > 0)) {
        *analytic_ticks = acc + dec + fabs(rest / v);
    } else if (d != 0 && (ramps > 0) == (d > 0)) {
        *analytic_ticks = (acc + dec) * d / ramps;
    } else {
        *analytic_ticks = acc + dec;
    }
}

/* The duration the planner's documented speed limit imposes, if larger. */
static double speed_limited_ticks(const struct profile *p)
{
    double need = fabs(2.0 * to_decideg(p->target - p->start) - to_decideg(p->v0) * p->accel_ticks) /
                  to_decideg(PROFILE_MAX_VELOCITY);
    double n1 = p->accel_ticks, n3 = p->total_ticks - p->cruise_end;
    return (need - n1 - n3) / 2.0 + n1 + n3;
}

/* The profile's analytic velocity at a tick (the firmware needs none: its
 * setpoint speed is the difference of two positions). */
static int64_t velocity_at(const struct profile *p, uint32_t tick)
{
    if (tick < p->accel_ticks) {
        return p->v0 + ((2 * p->accel_k * (int64_t)tick) >> 8);
    }
    if (tick < p->cruise_end) {
        return p->cruise;
    }
    if (tick >= p->total_ticks) {
        return 0;
    }
    return (2 * p->decel_k * (int64_t)(p->total_ticks - tick)) >> 8;
}

static void test_randomized_moves(void **state)
{
    (void)state;
    srand(20261121);
    const unsigned moves = 10000;
    unsigned preempted = 0, short_strokes = 0, checked_long = 0;
    struct profile prev;
    profile_plan(&prev, 0, 0, 0, (struct profile_timing){0, 0, 0});
    for (unsigned i = 0; i < moves; i++) {
        int64_t start = random_position(rand() % 2);
        int64_t v0 = 0;
        if (i > 0 && rand() % 3 == 0) {
            /* Preempt the previous move somewhere, often mid-ramp. */
            uint32_t at = rand() % 2 ? (uint32_t)rand() % (prev.accel_ticks + 1)
                                     : (uint32_t)((uint64_t)rand() * prev.total_ticks / RAND_MAX);
            start = profile_position(&prev, at);
            v0 = velocity_at(&prev, at);
            preempted++;
        }
        struct profile p;
        bool velocity_based;
        double analytic;
        random_move(&p, start, v0, &velocity_based, &analytic);
        if (p.accel_ticks < 20 || p.total_ticks - p.cruise_end < 20) {
            short_strokes++;
        }
        double limited = speed_limited_ticks(&p);
        if (limited > analytic) {
            analytic = limited;
        }
        if (fabs((double)p.total_ticks - analytic) > 1.0) {
            fail_msg("move %u: %u ticks, exact %.3f", i, p.total_ticks, analytic);
        }
        check_profile(&p);
        checked_long += p.total_ticks > 50000;
        prev = p;
    }
    printf("# %u moves (%u preempted, %u with shrunk ramps, %u longer than 50 000 ticks); "
           "worst setpoint error %.5f decideg\n",
           moves, preempted, short_strokes, checked_long, worst_error);
    assert_true(preempted > moves / 5);
    assert_true(short_strokes > 100);
}

/* The walk the tick takes through a profile (additions only) meets the
 * closed form exactly where each phase starts and at the target. Between,
 * each rounds differently (the walk a Q32 unit a tick, the closed form up
 * to a unit per tick of the phase, as it floors before its last product),
 * so they stay within two units per tick of the phase's length: below
 * 2^-14 decideg for the longest ramp. Random moves, preempted ones among
 * them (v0 != 0). */
static void test_the_walk_follows_the_closed_form(void **state)
{
    (void)state;
    srand(20261123);
    unsigned walked = 0, phases = 0;
    for (unsigned i = 0; i < 3000; i++) {
        int64_t start = random_position(rand() % 2);
        int64_t v0 = rand() % 2 ? 0 : ((int64_t)(rand() % 2001) - 1000) * ((int64_t)1 << 24);
        struct profile p;
        bool velocity_based;
        double analytic;
        random_move(&p, start, v0, &velocity_based, &analytic);
        if (p.total_ticks > 200000u) {
            continue;
        }
        struct profile_walk w = {.at = p.start};
        profile_walk_start(&w, &p, 0);
        uint32_t phase_start = 0;
        for (uint32_t t = 1; t <= p.total_ticks + 2u; t++) {
            bool started = profile_walk_next(&w, &p);
            bool boundary = (t == p.accel_ticks || t == p.cruise_end || t == p.total_ticks);
            int64_t exact = profile_position(&p, t);
            if (started) {
                phases++;
                phase_start = t;
            }
            if (boundary && t > 0 && !started && t != phase_start) {
                fail_msg("move %u: no phase started at tick %u", i, t);
            }
            int64_t off = w.at - exact;
            /* Each step rounds (the closed form too): two Q32 units a tick.
             * And the closed form's ramps are each exact at their own end
             * (the start, the target): k and dk, rounded by up to half a
             * Q40 unit, meet n^2 / 2 Q40 apart, and V, rounded by half a
             * Q32 unit, by (N1 + 2 Nc + N3) / 4; quadratic() truncates
             * k t before it multiplies by t: up to n. The end takes it
             * back. */
            int64_t n1 = p.accel_ticks, n3 = p.total_ticks - p.cruise_end;
            int64_t den = (int64_t)p.total_ticks + p.cruise_end - n1;
            int64_t bound = t < p.total_ticks ? 2 * (int64_t)t + 2 + n1 + n3 + (n1 * n1 + n3 * n3) / 512 + den / 4 + 1
                                        : 0;
            if (off > bound || off < -bound) {
                fail_msg("move %u tick %u (phase from %u; %u/%u/%u): walk %lld, closed form %lld (%lld apart)", i, t, phase_start, p.accel_ticks, p.cruise_end, p.total_ticks,
                         (long long)w.at, (long long)exact, (long long)off);
            }
        }
        assert_true(w.at == p.target);
        walked++;
    }
    printf("# %u moves walked, %u phases started\n", walked, phases);
    assert_true(walked > 1000u);
}

/* A streamed segment (profile_plan_segment): the Hermite cubic from
 * (start, v0) to (target, v1) in T ticks, then on at v1. Against the same
 * cubic in doubles at every tick, within the two coefficients' rounding
 * (half a Q40 unit each: (T^2 + T^3) / 2 Q40 at the end, under 0.001
 * decideg) and the closed form's own (t + 1 Q32 units at tick t), and the walk against the closed form as for the moves. Random
 * segments over the whole of profile.h's limits. */
static void test_segments_meet_their_ends(void **state)
{
    (void)state;
    uint64_t seed = 20261126;
    double worst = 0, worst_end = 0;
    for (unsigned i = 0; i < 2000; i++) {
        uint32_t ticks = 1u + (uint32_t)(xorshift64(&seed) % PROFILE_MAX_SEGMENT);
        int32_t start = (int32_t)(xorshift64(&seed) % (1u << 30)) - (1 << 29);
        int32_t distance = (int32_t)(xorshift64(&seed) % (2u * PROFILE_MAX_SEGMENT_DISTANCE + 1u)) - PROFILE_MAX_SEGMENT_DISTANCE;
        int32_t v0 = (int32_t)(xorshift64(&seed) % (2u * PROFILE_MAX_SEGMENT_SPEED + 1u)) - PROFILE_MAX_SEGMENT_SPEED;
        int32_t v1 = (int32_t)(xorshift64(&seed) % (2u * PROFILE_MAX_SEGMENT_SPEED + 1u)) - PROFILE_MAX_SEGMENT_SPEED;
        if (i % 4 == 0) { /* the common case: small steps of a smooth path */
            distance /= 256;
            v0 /= 256;
            v1 = v0 + (v1 / 4096);
        }
        struct profile p;
        profile_plan_segment(&p, start, v0, start + distance, v1, ticks);
        double T = ticks, d = distance / 256.0, a = v0 / 256.0, b = v1 / 256.0;
        double c2 = (3 * d - (2 * a + b) * T) / (T * T), c3 = ((a + b) * T - 2 * d) / (T * T * T);
        assert_true(profile_position(&p, 0) == start * ((int64_t)1 << 24));
        struct profile_walk w = {.at = p.start};
        profile_walk_start(&w, &p, 0);
        for (uint32_t t = 1; t <= ticks + 3u; t++) {
            bool started = profile_walk_next(&w, &p);
            double x = t <= ticks ? ((c3 * t + c2) * t + a) * t : d + b * (t - T);
            double off = fabs(to_decideg(profile_position(&p, t)) - start / 256.0 - x);
            double bound = (T * T + T * T * T) / 2.0 / 1099511627776.0 + (t + 2.0) / 4294967296.0;
            if (off > bound) {
                fail_msg("segment %u (T %u, d %d, v0 %d, v1 %d) tick %u: %.3g decideg off the cubic", i,
                         ticks, distance, v0, v1, t, off);
            }
            worst = off > worst ? off : worst;
            if (t == ticks) {
                worst_end = off > worst_end ? off : worst_end;
                assert_true(started); /* the cubic ends: the walk starts again there */
            }
            /* As for the moves; the cubic's own rounding (its closed form
             * is exact at the start only) goes on after it. */
            int64_t walked_bound = 2 * (int64_t)t + 1 + (int64_t)((T * T + T * T * T) / 512.0) + 1;
            int64_t walked_off = w.at - profile_position(&p, t);
            if (walked_off > walked_bound || walked_off < -walked_bound) {
                fail_msg("segment %u tick %u: the walk is %lld Q32 off the closed form", i, t,
                         (long long)walked_off);
            }
        }
        /* After the cubic, on at v1 exactly. */
        assert_true(profile_position(&p, ticks + 2u) - profile_position(&p, ticks + 1u) == v1 * ((int64_t)1 << 24));
    }
    printf("# 2000 segments: at most %.2g decideg off the cubic, %.2g at its end\n", worst, worst_end);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_interval_example),
        cmocka_unit_test(test_velocity_example),
        cmocka_unit_test(test_short_stroke_example),
        cmocka_unit_test(test_short_strokes_count_exactly),
        cmocka_unit_test(test_negative_and_multi_turn),
        cmocka_unit_test(test_endless),
        cmocka_unit_test(test_too_fast_moves_take_longer),
        cmocka_unit_test(test_randomized_moves),
        cmocka_unit_test(test_the_walk_follows_the_closed_form),
        cmocka_unit_test(test_segments_meet_their_ends),
    };
    return cmocka_run_group_tests_name("profile", tests, NULL, NULL);
}
