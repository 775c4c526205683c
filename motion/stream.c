/* Streamed setpoints (StreamSetpoint): each one is for a moment of the
 * host's timeline, its stamp, played a depth after it on the servo's clock
 * (docs/streaming.md, "On the host's timeline"): a segment from where the
 * setpoint is (position and speed) to the host's, a cubic (Hermite) that
 * ends at that moment, walked at the tick rate; the segment's end speed
 * goes on until the next setpoint comes, and a depth after its end the
 * servo brakes to a hold. A setpoint the cubic cannot reach within the
 * stream's limits in its time is reached later (a longer segment) where
 * the host asks a speed, else as a move at them to rest
 * (docs/streaming.md).
 * Plans: divides. */
#include "motion/motion_internal.h"
#include "motion/saturate.h"

/* A setpoint's angle and velocity take the angle moves' ranges. */
_Static_assert(FIELD_STREAM_SETPOINT_ANGLE_MAX == MULTI_TURN_LIMIT &&
                   FIELD_STREAM_SETPOINT_ANGLE_MIN == -MULTI_TURN_LIMIT &&
                   FIELD_STREAM_SETPOINT_VELOCITY_MAX == MAX_VELOCITY &&
                   FIELD_STREAM_SETPOINT_VELOCITY_MIN == -MAX_VELOCITY,
               "StreamSetpoint's ranges are the moves'");

/* The stream's limits, those of the angle modes: their top speed (750
 * deg/s) and the steepest ramp a move asks, that speed in the shortest
 * ramp (20 ms: 37 500 deg/s^2). Q8 decideg per tick, and per tick^2. */
enum {
    STREAM_SPEED_Q8 = MAX_VELOCITY * 256 / (int32_t)MOTION_TICK_HZ, /* 1920 */
    STREAM_ACCEL_Q8 = STREAM_SPEED_Q8 / MIN_RAMP_MS,                /* 96 */
};

/* The servo's clock less the host's (Q16 ms: its whole ms wrap as the
 * host's stamps do) and the host's period (Q4 ms) are followed by 1/8 ms a
 * setpoint toward each new one (not at all on the mark): a median, which a
 * late frame or a burst hardly moves, and which moves the host's timeline smoothly (a segment's
 * end is placed to 1/16 ms); it follows a host clock that drifts by up to
 * 1/8 ms a period (0.375 % at 30 Hz). */
enum { TRACK_STEP_Q16 = 1 << 13, TRACK_STEP_Q4 = 2 };

static uint32_t track(uint32_t value, uint32_t sample, uint32_t step)
{
    int32_t away = (int32_t)(sample - value);
    return away > 0 ? value + step : away < 0 ? value - step : value;
}

/* The period, ms Q4: item 69 if set, else the step between the host's
 * stamps (a stream's first step, its second where shorter: a host that
 * sends a first setpoint and waits; then followed; 20 ms, 50 Hz, until
 * then).
 * A gap of none, or longer than a segment, is a new stream: the servo's
 * clock at its first stamp is the offset then. *late_q4: how much later
 * than its place (the stamp + the offset) this setpoint came, ms Q4. */
static int32_t stream_period(struct motion *m, uint16_t host_ms, int32_t *late_q4)
{
    uint32_t since = (uint16_t)(host_ms - m->stream_host_ms);
    uint32_t offset_q16 = (uint32_t)(m->stream_clock_ms - host_ms) << 16; /* wraps as 16 bits */
    m->stream_host_ms = host_ms;
    bool fresh = !m->streaming || since - 1u >= PROFILE_MAX_SEGMENT;
    uint32_t count = fresh ? 0u : m->streaming;
    uint32_t step_q4 = since << 4;
    if (fresh) {
        m->stream_offset_q16 = offset_q16;
    } else if (count == 1u || ((count == 2u) & (step_q4 < m->stream_period_q4))) {
        m->stream_period_q4 = (uint16_t)step_q4; /* a first setpoint and a wait: the second step says */
    } else {
        m->stream_period_q4 = (uint16_t)track(m->stream_period_q4, step_q4, TRACK_STEP_Q4);
    }
    m->streaming = (uint8_t)(count + (count < 3u));
    uint32_t median = m->stream_offset_q16;
    *late_q4 = (int32_t)(offset_q16 - median) >> 12; /* +-32 s */
    m->stream_offset_q16 = track(median, offset_q16, TRACK_STEP_Q16);
    uint32_t told = (uint32_t)m->regs->firmware.stream_period_ms << 4;
    return (int32_t)(told != 0u ? told : m->stream_period_q4);
}

/* |v| <= limit, limit >= 0. */
static bool within(int32_t v, int32_t limit)
{
    return (uint32_t)(v + limit) <= 2u * (uint32_t)limit;
}

/* The cubic over t ticks keeps within the limits. In Bezier form its speed
 * is the quadratic through v0, w = 3 d / t - v0 - v1 and v1, never beyond
 * the largest of the three (|v0|, |v1| are within the speed), and its
 * acceleration is linear, from 2 (w - v0) / t to 2 (v1 - w) / t: each side
 * x t (no division). |w| within the speed needs |d| within it x t first
 * (|v0 + v1| is), which keeps every product within 2^25 and d within a
 * segment's reach (profile.h). */
_Static_assert(STREAM_SPEED_Q8 * (int32_t)PROFILE_MAX_SEGMENT <= PROFILE_MAX_SEGMENT_DISTANCE,
               "a segment within the speed is within a segment's reach");

static bool segment_within(int32_t d, int32_t v0, int32_t v1, int32_t t)
{
    int32_t s = STREAM_SPEED_Q8 * t;
    if (!within(d, s)) {
        return false;
    }
    int32_t e = 3 * d - (v0 + v1) * t;
    int32_t a = STREAM_ACCEL_Q8 * t * t / 2;
    return within(e, s) && within(e - v0 * t, a) && within(e - v1 * t, a);
}

/* With the angle limits on (48), the segment's path keeps within them
 * (those of the multi-turn reading, after the center offset 53), its run-on
 * included. t is the time to the stop, the segment and its run-on (a
 * depth): the cubic lies within the hull of its Bezier points (start,
 * start + v0 s / 3, target - v1 s / 3, target, s the segment's ticks),
 * here taken at t / 2 (further out on the same side: a hull that holds the
 * true one); after it the end speed runs on, counted for all of t, and
 * then brakes, counted at two thirds of the stream's ramp (v^2 / 2^7, a
 * longer way). The target is within them already (motion_target_q8); a
 * start outside (the limits were off, or changed) may come back, no
 * further out. t is at most 321 + 1500 ticks (a depth of a 1 s period):
 * products within 2^22. Where the path does not keep within them, the
 * limiter says angle. */
static bool path_within(struct motion *m, int32_t start, int32_t target, int32_t v0, int32_t v1,
                        int32_t t)
{
    const struct user_config *cfg = &m->regs->user;
    if (!cfg->angle_limit_on) {
        return true;
    }
    int32_t lo = (cfg->angle_min_decideg + cfg->center_offset_decideg) * 256;
    uint32_t span = (uint32_t)(cfg->angle_max_decideg - cfg->angle_min_decideg) * 256u;
    int32_t v1t = v1 * t;
    bool within = (uint32_t)(start + ((v0 * t) >> 1) - lo) <= span &&
                  (uint32_t)(target - (v1t >> 1) - lo) <= span &&
                  (uint32_t)(target + v1t + ((v1 * (v1 < 0 ? -v1 : v1)) >> 7) - lo) <= span;
    m->angle_clamped |= !within;
    return within;
}

/* From start moving at v0 to rest at target within the limits: a ramp of
 * 2 x MIN_RAMP ticks from v0 to the cruise V, a ramp of MIN_RAMP to rest,
 * and a cruise long enough that |V| is within the top speed (ramps and
 * cruise at it cover d, the cruise rounded up). The first ramp changes
 * the speed by at most twice the top speed, the second by it: neither is
 * steeper than the limit. Any distance (a multi-turn target): |d| < 2^31,
 * a 32-bit cruise. Not the fastest such move (that needs a square root,
 * and a trim of the ramps for whole ticks, which the M0 has no room for):
 * at most 60 ms slower. */
static void plan_at_limits(struct profile *p, int32_t start, int32_t v0, int32_t target)
{
    /* |d - 20 v0| is |d| - 20 u (u: v0 towards the target), or, where the
     * two differ, under 20 |v0|: no cruise either way. */
    int32_t d = target - start - v0 * MIN_RAMP_MS;
    int32_t rest = (d < 0 ? -d : d) - STREAM_SPEED_Q8 * MIN_RAMP_MS * 3 / 2;
    uint32_t cruise = rest > 0 ? ((uint32_t)rest + STREAM_SPEED_Q8 - 1u) / STREAM_SPEED_Q8 : 0u;
    profile_plan(p, q8_to_q32(start), q8_to_q32(v0), q8_to_q32(target),
                 (struct profile_timing){2u * MIN_RAMP_MS, cruise, MIN_RAMP_MS});
}

enum motion_submit_result motion_stream(struct motion *m, const struct motion_setpoint *sp)
{
    if (m->inhibit) {
        return MOTION_REFUSED; /* not counted (motion_submit) */
    }
    motion_take_over(m); /* nothing below reads what it sets */
    int32_t late_q4;
    int32_t period_q4 = stream_period(m, sp->host_ms, &late_q4);
    /* The setpoint's place: a depth of 3/2 period after its stamp on the
     * servo's clock, so a frame up to that late changes nothing. The
     * segment ends on the tick before it, its target run back along the
     * setpoint's velocity by the fraction; one later than half a period
     * before its place ends half a period on, the target run on as far (at
     * most a period). */
    int32_t half = period_q4 >> 5;
    int32_t depth_q4 = period_q4 + (period_q4 >> 1);
    int32_t place_q4 = depth_q4 - late_q4;
    int32_t ticks = clamp_i32(place_q4 >> 4, half + 1, (int32_t)PROFILE_MAX_SEGMENT);
    int32_t run_on_q4 = clamp_i32(ticks * 16 - place_q4, -16, period_q4);
    /* The stream's reference goes on from the setpoint, however the horn
     * lags (the profile's clock keeps the two together, and slows the
     * segment where it asks more than the output can give), or from the
     * horn at rest. */
    int32_t start = m->measured_q8;
    int32_t v0 = 0;
    if (m->mode == MODE_POSITION) {
        start = m->setpoint_q8;
        v0 = clamp_i32(start - m->last_setpoint_q8, -STREAM_SPEED_Q8, STREAM_SPEED_Q8);
    }
    int32_t target = motion_target_q8(m, sp->angle_decideg, MULTI_TURN_LIMIT, 0, LIMITS_ON);
    /* 0.1 deg/s to Q8 decideg per tick: x 256 / 1000, as 16777 / 2^16
     * (an arithmetic shift: toward minus infinity, under 2^-8 decideg). */
    int32_t v1 = (clamp_i32(sp->velocity_decideg_s, -MAX_VELOCITY, MAX_VELOCITY) * 16777) >> 16;
    /* Within 1920 x 16000: the path's checks hold it within the limits. */
    int32_t placed = target + ((v1 * run_on_q4) >> 4);

    /* A segment the cubic cannot make in its time within the stream's
     * limits is made later (a quarter longer at a time, to 0.32 s) where the
     * host asks a speed, not as a move to rest: the stream goes on,
     * behind, and the next setpoint plans from there. */
    bool fits;
    while (!(fits = segment_within(placed - start, v0, v1, ticks)) && v1 != 0 && ticks < 256) {
        ticks += (ticks >> 2) + 1; /* to 321 at most; 256: an immediate on the M0 */
    }
    /* A depth after the segment's end with no setpoint: the stream has
     * stopped. A frame a period late, jitter on top, is not a stop, however
     * short the segment before it (a frame that looked late). The path's
     * hull is taken over both (the longer of the two would do, for bytes
     * the M0 does not have). */
    int32_t until = ticks + (depth_q4 >> 4);
    m->endless_until = (uint32_t)until;
    bool cubic = fits && path_within(m, start, placed, v0, v1, until);
    if (cubic) {
        profile_plan_segment(&m->profile, start, v0, placed, v1, (uint32_t)ticks);
    } else {
        plan_at_limits(&m->profile, start, v0, target);
    }
    motion_begin_profile(m, END_HOLD);
    m->endless = cubic && v1 != 0;
    return MOTION_ACCEPTED;
}
