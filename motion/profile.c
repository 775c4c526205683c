#include "motion/profile.h"

#include "motion/div64.h"

/* Right shifts of negative values are arithmetic with gcc and clang, the
 * only compilers this code is built with (implementation-defined in C11). */

/* A plan without a window (profile_smooth adds one where there is
 * smoothing at all). */
#if PROFILE_SMOOTHING
#define NO_WINDOW(p) ((p)->smooth_ticks = 0)
#else
#define NO_WINDOW(p) ((void)(p))
#endif

static int64_t div_round(int64_t num, int64_t den)
{
    return div64_round(num, den);
}

static int64_t abs64(int64_t v)
{
    return v < 0 ? -v : v;
}

void profile_plan(struct profile *p, int64_t start, int64_t v0, int64_t target,
                  struct profile_timing timing)
{
    int64_t n1 = timing.accel;
    int64_t n3 = timing.decel;
    int64_t nc = timing.cruise;
    if (v0 > PROFILE_MAX_VELOCITY) {
        v0 = PROFILE_MAX_VELOCITY;
    } else if (v0 < -PROFILE_MAX_VELOCITY) {
        v0 = -PROFILE_MAX_VELOCITY;
    }
    int64_t num = 2 * (target - start) - v0 * n1;
    int64_t den = n1 + 2 * nc + n3;
    if (den == 0) {
        den = 2; /* nothing to time: arrive on the next tick */
        nc = 1;
    }
    /* Stretch the cruise so V stays within the planner's limit. */
    int64_t needed = (abs64(num) + PROFILE_MAX_VELOCITY - 1) / PROFILE_MAX_VELOCITY;
    if (needed > den) {
        nc += (needed - den + 1) / 2;
        den = n1 + 2 * nc + n3;
    }
    int64_t v = div_round(num, den);

    p->start = start;
    p->target = target;
    p->v0 = v0;
    p->cruise = v;
    p->accel_k = n1 ? div_round((v - v0) * 256, 2 * n1) : 0;
    p->accel_j = 0;
    p->decel_k = n3 ? div_round(v * 256, 2 * n3) : 0;
    p->accel_ticks = (uint32_t)n1;
    NO_WINDOW(p);
    p->cruise_end = (uint32_t)(n1 + nc);
    p->total_ticks = (uint32_t)(n1 + nc + n3);
}

void profile_plan_endless(struct profile *p, int64_t start, int64_t v0, int64_t velocity,
                          uint32_t accel)
{
    p->start = start;
    p->target = start;
    p->v0 = v0;
    p->cruise = velocity;
    p->accel_k = accel ? div_round((velocity - v0) * 256, 2 * (int64_t)accel) : 0;
    p->accel_j = 0;
    p->decel_k = 0;
    p->accel_ticks = accel;
    NO_WINDOW(p);
    p->cruise_end = UINT32_MAX;
    p->total_ticks = UINT32_MAX;
}

/* p(t) = start + v0 t + c t^2 + d t^3 with p(T) = target, p'(T) = v1:
 *     c = (3 D - (2 v0 + v1) T) / T^2,  d = ((v0 + v1) T - 2 D) / T^3.
 * Within the segment's limits (profile.h) both numerators fit int32 in Q8
 * (|3D| <= 2^23.6, |(2 v0 + v1) T| <= 2^27.6), so each coefficient is one
 * division of a Q40 numerator within 2^60; the coefficients then keep
 * every product here, in the closed form and in the walk within 2^61. */
void profile_plan_segment(struct profile *p, int32_t start_q8, int32_t v0_q8, int32_t target_q8,
                          int32_t v1_q8, uint32_t ticks)
{
    const int64_t q24 = (int64_t)1 << 24, q32 = (int64_t)1 << 32;
    int32_t t = (int32_t)ticks;
    int32_t d = target_q8 - start_q8;
    int64_t tt = (int64_t)t * t;
    p->start = start_q8 * q24;
    p->target = target_q8 * q24;
    p->v0 = v0_q8 * q24;
    p->cruise = v1_q8 * q24;
    p->accel_k = div_round((3 * d - (2 * v0_q8 + v1_q8) * t) * q32, tt);
    p->accel_j = div_round(((v0_q8 + v1_q8) * t - 2 * d) * q32, tt * t);
    p->decel_k = 0;
    p->accel_ticks = ticks;
    NO_WINDOW(p);
    /* At rest at the end: a move that ends there, which the braking guard
     * watches. Else on at v1 for ever. */
    p->cruise_end = v1_q8 != 0 ? UINT32_MAX : ticks;
    p->total_ticks = p->cruise_end;
}

struct profile_timing profile_velocity_timing(int64_t distance, int64_t v0, int64_t vmax,
                                              uint32_t accel, uint32_t decel)
{
    struct profile_timing t = {.accel = accel, .cruise = 0, .decel = decel};
    int64_t v = distance >= 0 ? vmax : -vmax;
    /* Distance the two ramps cover at full velocity, and what is left. */
    int64_t ramps = ((v0 + v) * (int64_t)accel + v * (int64_t)decel) / 2;
    int64_t rest = distance - ramps;
    if (rest == 0 || (rest > 0) == (v > 0)) {
        /* Ticks at vmax: both scaled until vmax fits 32 bits (fast
         * division), which changes the count by far less than a tick. A
         * bit a step: the Cortex-M0 has no 64-bit shift by a variable but
         * libgcc's (28 B), and planning has the time. */
        int64_t r = abs64(rest);
        int64_t vm = vmax;
        while (vm >> 32 != 0) {
            vm >>= 1;
            r >>= 1;
        }
        int64_t cruise = div_round(r, vm);
        t.cruise = cruise < PROFILE_MAX_CRUISE ? (uint32_t)cruise : PROFILE_MAX_CRUISE;
        return t;
    }
    if (distance == 0 || (ramps > 0) != (distance > 0)) {
        return t; /* no stroke to fit: the ramps as commanded, no cruise */
    }
    /* Too short: shrink both ramps by distance / ramps, in Q16 so the
     * products stay within int64. */
    int64_t d16 = abs64(distance) >> 16;
    int64_t r16 = abs64(ramps) >> 16;
    if (r16 == 0) {
        t.accel = 0; /* a stroke of under 2^-16 decideg */
        t.decel = 0;
        return t;
    }
    /* The total's product is the two ramps' sum: one multiply fewer. */
    uint64_t accel_part = (uint64_t)d16 * accel;
    uint64_t decel_part = (uint64_t)d16 * decel;
    t.accel = (uint32_t)div64_u(accel_part, (uint64_t)r16);
    t.decel = (uint32_t)div64_u(decel_part, (uint64_t)r16);
    int64_t total = div_round((int64_t)(accel_part + decel_part), r16);
    int64_t cruise = total - (int64_t)t.accel - (int64_t)t.decel;
    t.cruise = (uint32_t)(cruise > 0 ? cruise : 0);
    return t;
}

/* The trapezoid's phase at tick: 1 accelerating, 2 cruising, 3
 * decelerating, 4 after it (0: before it, which a window's far end sees). */
static unsigned phase_at(const struct profile *p, uint32_t tick)
{
    return 1u + (tick >= p->accel_ticks) + (tick >= p->cruise_end) + (tick >= p->total_ticks);
}

static uint32_t phase_end(const struct profile *p, unsigned phase)
{
    return phase == 0u   ? 0u
           : phase == 1u ? p->accel_ticks
           : phase == 2u ? p->cruise_end
           : phase == 3u ? p->total_ticks
                         : UINT32_MAX;
}

/* A smoothed phase's jerk ([0]) or its sixth ([1]): the ramps' only. */
static int64_t phase_jerk(const struct profile *p, unsigned phase, unsigned sixth)
{
#if PROFILE_SMOOTHING
    return phase & 1u ? p->smooth_jerk[phase >> 1][sixth] : 0;
#else
    (void)p, (void)phase, (void)sixth;
    return 0;
#endif
}

void profile_walk_start(struct profile_walk *w, const struct profile *p, uint32_t tick)
{
    uint32_t window = profile_window(p);
    unsigned lead = phase_at(p, tick);
    unsigned lag = lead;
    uint32_t end = phase_end(p, lead);
    if (window != 0u) {
        lag = tick < window ? 0u : phase_at(p, tick - window);
        uint32_t lag_end = phase_end(p, lag); /* finite unless lead's is too */
        if (lag < 4u && lag_end + window < end) {
            end = lag_end + window;
        }
    }
    w->phase_end = end;
    w->tick = tick;
    if (lead != lag) {
        /* The window spans a change of acceleration: the average's third
         * derivative changes by delta there, and (t - tick)^3 delta / 6
         * adds delta / 6, delta and delta to the walk's three differences. */
        int64_t jerk = phase_jerk(p, lead, 0) - phase_jerk(p, lag, 0);
        int64_t jerk6 = phase_jerk(p, lead, 1) - phase_jerk(p, lag, 1);
        w->step_q40 += jerk6 - w->jerk6_q40;
        w->change_q40 += jerk - w->jerk_q40;
        w->jerk_q40 = jerk;
        w->jerk6_q40 = jerk6;
        return;
    }
    /* p(t + 1) - p(t) of each phase's closed form, in Q40: v0 + k (2t + 1)
     * + j (3t^2 + 3t + 1) ramping up (j: a segment's cubic), V cruising,
     * dk (2r - 1) ramping down (r = T - t). The products are within
     * the closed form's bounds. A smoothed move's window lies in one phase:
     * the phase's average over it is the phase half a window late (a
     * quadratic's average is its middle's value plus a constant), so t is
     * tick - window / 2 (2t is whole). */
    int64_t step = 0, change = 0, jerk = 0;
    if (lead == 1u) {
        step = p->v0 * 256 + p->accel_k * (int64_t)(2u * tick + 1u - window);
        change = 2 * p->accel_k;
        if (p->accel_j != 0) { /* a segment: tick < PROFILE_MAX_SEGMENT, 32 bits */
            step += p->accel_j * (int64_t)(3u * tick * (tick + 1u) + 1u);
            change += p->accel_j * (int64_t)(6u * tick + 6u);
            jerk = 6 * p->accel_j;
        }
    } else if (lead == 2u) {
        step = p->cruise * 256;
    } else if (lead == 3u) {
        step = p->decel_k * (int64_t)(2u * (p->total_ticks - tick) + window - 1u);
        change = -2 * p->decel_k;
    } else {
        w->at = p->target; /* exactly, whatever the steps' rounding left */
    }
    w->step_q40 = step;
    w->change_q40 = change;
    w->jerk_q40 = jerk;
    w->jerk6_q40 = 0;
}

#ifdef SERVO_SIZE_FIRST
bool profile_walk_next(struct profile_walk *w, const struct profile *p)
{
    return profile_walk_next_inline(w, p);
}
#endif

void profile_walk_begin(struct profile_walk *w, const struct profile *p)
{
    w->at = profile_origin(p);
    if (profile_window(p) != 0u) {
        /* Before tick 0 the window holds the start moving at v0. */
        w->step_q40 = p->v0 * 256;
        w->change_q40 = 0;
        w->jerk_q40 = 0;
        w->jerk6_q40 = 0;
    }
    profile_walk_start(w, p, 0);
    profile_walk_next(w, p);
}

/* |a| in Q24 from Q40, rounded up: within 32 bits for any acceleration a
 * ramp of the angle moves reaches (|a| < 2^46, 64 decideg per tick^2). */
static uint32_t q24_up(int64_t a_q40)
{
    return (uint32_t)((abs64(a_q40) + 0xFFFF) >> 16);
}

uint32_t profile_smooth_ticks(const struct profile *p, uint32_t jerk_q24)
{
    /* The ramps' accelerations (2k), and the jump where the end of the one
     * meets the start of the other (decelerating after accelerating adds),
     * each rounded up: never a shorter window. */
    uint32_t a1 = q24_up(2 * p->accel_k), a3 = q24_up(2 * p->decel_k);
    uint32_t both = q24_up(2 * (p->accel_k + p->decel_k));
    uint32_t most = a1 > a3 ? a1 : a3;
    uint32_t t = 0;
    for (unsigned pass = 0; pass < 2u; pass++) {
        /* A window longer than the cruise spans both ramps' edges. */
        uint32_t jump = t > p->cruise_end - p->accel_ticks && both > most ? both : most;
        uint32_t need = (jump + jerk_q24 - 1u) / jerk_q24;
        t = need < PROFILE_MAX_SMOOTH ? need : PROFILE_MAX_SMOOTH;
    }
    return t;
}

void profile_smooth(struct profile *p, uint32_t smooth_ticks)
{
#if PROFILE_SMOOTHING
    p->smooth_ticks = smooth_ticks;
    if (smooth_ticks == 0u) {
        return;
    }
    /* jerk / 6 by 10923 / 2^16: off by 3.4e-5 of it, for at most a window:
     * 3.4e-5 of the acceleration in position, far below a Q8 unit. */
    int64_t k[2] = {p->accel_k, -p->decel_k};
    for (unsigned i = 0; i < 2u; i++) {
        int64_t jerk = div_round(2 * k[i], smooth_ticks);
        p->smooth_jerk[i][0] = jerk;
        p->smooth_jerk[i][1] = (jerk * 10923) >> 16;
    }
#else
    (void)p, (void)smooth_ticks;
#endif
}
