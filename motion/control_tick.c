/* The control tick: the horn's position and speed from the encoder, the
 * profile's clock (slowed while the horn cannot follow), the braking check,
 * the controller, and when a move has finished. Once per 1/MOTION_TICK_HZ s,
 * from the main loop. Positions are Q8 decidegrees in int32 (motion.h says
 * why they fit); 64-bit arithmetic only where a phase of the profile begins,
 * and no division except when a deceleration is replanned. */
#include "motion/motion.h"

#include "motion/div64.h"
#include "motion/gains.h"
#include "motion/motion_internal.h"

/* A move has finished when its setpoint has reached the target and the
 * horn has arrived there, within ARRIVE_DECIDEG, and nearly stopped (not
 * just passing through). */
enum { ARRIVE_DECIDEG = 3 }; /* 0.3 degree */

static bool arrived(const struct motion *m)
{
    int32_t gap = m->target_q8 - m->measured_q8;
    int32_t speed = m->measured_velocity_q8;
    return gap <= ARRIVE_DECIDEG * 256 && gap >= -ARRIVE_DECIDEG * 256 &&
           speed < FOLLOW_SPEED_Q8 && speed > -FOLLOW_SPEED_Q8;
}

/* Turning without end (wheel run) must not outgrow the tick count: the
 * profile restarts its clock before it gets large (endless_until is
 * REBASE_TICKS). A stream whose next setpoint is late stops there instead,
 * from where its setpoint is, within the output's braking, and holds. */
static void rebase_endless(struct motion *m)
{
    if (m->tick < m->endless_until) {
        return;
    }
    if (m->streaming) {
        motion_stop(m, STOP_HOLD);
        return;
    }
    int64_t v = m->profile.cruise;
    profile_plan_endless(&m->profile, q8_to_q32(m->setpoint_q8), v, v, 0);
    motion_clock_restart(m);
}

/* The multi-turn reading stays within +-MULTI_TURN_LIMIT whatever turns the
 * horn (wheel mode, many turns, a load back-driving it): past either end
 * the origin moves FRAME_SHIFT (1024 turns) the same way and the reading
 * goes on from about 0 (docs/decisions-motion.md, "The ends of every range"). A
 * whole range lies between two shifts, so a horn held at an end does not
 * shift back and forth. */
#define FRAME_SHIFT_COUNTS ((int32_t)(MULTI_TURN_LIMIT / DECIDEG_PER_TURN) * ENCODER_COUNTS)
#define READING_LIMIT_Q8 (MULTI_TURN_LIMIT * 256)

/* Within this of the origin, no center offset (53: +-1800) takes the
 * reading past either end. */
#define SURELY_IN_RANGE_Q8 ((MULTI_TURN_LIMIT - 1800) * 256)

static void keep_in_range(struct motion *m)
{
    if ((uint32_t)(m->measured_q8 + SURELY_IN_RANGE_Q8) <= 2u * SURELY_IN_RANGE_Q8) {
        return;
    }
    int32_t reading = m->measured_q8 - motion_center_offset_q8(m);
    if (reading > READING_LIMIT_Q8) {
        motion_move_origin(m, FRAME_SHIFT_COUNTS);
    } else if (reading < -READING_LIMIT_Q8) {
        motion_move_origin(m, -FRAME_SHIFT_COUNTS);
    }
}

/* The horn's speed from a 12-bit encoder: one count per tick is 88 deg/s, so
 * a plain difference is mostly rounding. An alpha-beta tracker predicts
 * where the horn should be and corrects position and speed by part of the
 * miss (1/2 and 1/8): it follows a steady speed without lag, where a
 * low-pass lags by its time constant, which left the current limit working
 * around a stale back-EMF after a preemption. It tracks the horn relative
 * to the encoder's reading (the residual), so it needs no multi-turn
 * position of its own and no change of origin moves it. A count is 225 x 16
 * decideg Q12; the encoder moves less than half a turn a tick, so every
 * term is far within int32. */
enum { TRACK_POSITION_SHIFT = 1, TRACK_VELOCITY_SHIFT = 3, TRACK_LIMIT_Q12 = 1 << 28 };

static void measure(struct motion *m)
{
    int32_t moved = encoder_update(&m->encoder, m->hal->motor.read_encoder(m->hal->ctx));
    m->measured_q8 = counts_to_q8(m->encoder.counts - m->origin_counts);
    /* Where the tracker expects the horn, less where the encoder says it is:
     * minus the miss. */
    int32_t predicted = m->track_residual_q12 + m->track_velocity_q12 - moved * (DECIDEG_Q8_PER_COUNT * 16);
    int32_t miss = sat_q(-predicted, TRACK_LIMIT_Q12);
    m->track_residual_q12 = (miss >> TRACK_POSITION_SHIFT) - miss;
    m->track_velocity_q12 = sat_q(m->track_velocity_q12 + (miss >> TRACK_VELOCITY_SHIFT), TRACK_LIMIT_Q12);
    /* Q12 inside, so the rounding left over is far below one Q8 step. */
    m->measured_velocity_q8 = (m->track_velocity_q12 + 8) >> 4;
    keep_in_range(m);
}

/* The supply moves slowly: the duty margin for the power follows it every
 * SUPPLY_CHECK_TICKS ticks, when it has moved more than the hysteresis. */
enum { SUPPLY_CHECK_TICKS = 32 }; /* a power of two */

static void follow_supply(struct motion *m)
{
    uint16_t v = motion_supply_mv(m);
    uint16_t used = m->drive_inputs.supply_mv;
    if (v > used + SUPPLY_HYSTERESIS_MV || v + SUPPLY_HYSTERESIS_MV < used) {
        motion_update_limits(m);
    }
}

/* ---- the profile's clock -------------------------------------------------
 * The setpoint runs along the profile at clock_rate: in real time while the
 * horn follows, slower while the output is at its limit and the setpoint
 * leads the horn by more than LEAD_FREE (it stops at LEAD_FREE + 8 decideg),
 * so a move faster than the motor arrives late instead of running away
 * from the horn. The lead is low-passed (the encoder's counts are coarse
 * beside one tick's motion); the rate falls by at most CLOCK_SLOWING and
 * rises by at most CLOCK_RECOVERY per tick, so the setpoint's speed changes
 * smoothly, and a clock that must stop (a reversal the motor cannot make
 * as fast as planned) stops before the profile has run out. */

static void govern_clock(struct motion *m, int32_t error_q8)
{
    int32_t step = m->profile_at_next_tick_q8 - m->profile_at_tick_q8;
    int32_t lead = step > 0 ? error_q8 : step < 0 ? -error_q8 : 0;
    m->lead_q8 += (lead - m->lead_q8) >> LEAD_FILTER_SHIFT;
    uint32_t target = CLOCK_REAL_TIME;
    if (m->controller.at_limit && m->lead_q8 > LEAD_FREE_Q8) {
        uint32_t slow = (uint32_t)(m->lead_q8 - LEAD_FREE_Q8) >> LEAD_SPAN_SHIFT;
        target = slow >= CLOCK_REAL_TIME ? 0u : CLOCK_REAL_TIME - slow;
    }
    uint32_t rate = m->clock_rate;
    if (target + CLOCK_SLOWING < rate) {
        rate -= CLOCK_SLOWING;
    } else if (target > rate + CLOCK_RECOVERY) {
        rate += CLOCK_RECOVERY;
    } else {
        rate = target;
    }
    m->clock_rate = (uint16_t)rate;
}

/* Moves the setpoint on by clock_rate: between the profile's positions at
 * two whole ticks, linearly (the profile bends by far less than an encoder
 * count within one tick). A step is below 2^23 (PROFILE_MAX_VELOCITY), so
 * step x frac fits int32. */
static void advance_clock(struct motion *m)
{
    uint32_t frac = (uint32_t)m->tick_frac + m->clock_rate;
    if (frac >= CLOCK_REAL_TIME && m->tick < UINT32_MAX) {
        frac -= CLOCK_REAL_TIME;
        m->tick++;
        m->profile_at_tick_q8 = m->profile_at_next_tick_q8;
        if (profile_walk_next(&m->walk, &m->profile)) {
            motion_take_accel_duty(m, m->walk.tick + 1u);
        }
        m->profile_at_next_tick_q8 = q32_to_q8_sat(m->walk.at);
        if (m->tick == m->accel_from) {
            m->accel_duty = m->accel_duty_next;
        } else if (m->tick == 1u) {
            /* p(1) - 2 p(0) + (p(0) - v0): half the first phase's. */
            m->accel_duty = m->accel_duty_next / 2;
        }
    }
    m->tick_frac = (uint16_t)frac;
    m->setpoint_q8 = m->profile_at_tick_q8 + (((m->profile_at_next_tick_q8 - m->profile_at_tick_q8) * (int32_t)frac) >> 8);
}

/* A profile whose horn could no longer stop on the target at the output's
 * braking (v^2 > 2 a r, a = brake_duty / ka, v the setpoint's or the horn's
 * speed, r what is left from the horn) decelerates from where the horn is, at v^2 / 2r,
 * and is left alone after that (braking). Starting from the horn rather
 * than the setpoint drops the lead the slowed clock kept, which would
 * otherwise push on against the braking. This catches plans whose ramps
 * are steeper than the motor, and setpoints the slowed clock has left
 * moving at another speed, in any phase. Speeds beyond 2^16 - 1 (256 decideg
 * per tick) count as 2^16 - 1: far beyond any servo, and v^2 fits 32 bits,
 * so both sides are one 32 x 32 -> 64-bit product. */
static void guard_braking(struct motion *m)
{
    if (m->endless || m->braking) {
        return;
    }
    /* The faster of setpoint and horn must stop: in a slowed deceleration
     * the setpoint moves slower than the horn still does. (The horn's speed
     * counts when it is beyond the setpoint's the same way; from rest, any
     * way but forwards.) */
    int32_t v = m->setpoint_q8 - m->last_setpoint_q8;
    int32_t w = m->measured_velocity_q8;
    if (v > 0 ? w > v : w < v) {
        v = w;
    }
    int32_t r = m->target_q8 - m->measured_q8;
    if (v == 0 || r == 0 || (v ^ r) < 0) {
        return;
    }
    uint32_t speed = v < 0 ? -(uint32_t)v : (uint32_t)v;
    uint32_t room = r < 0 ? -(uint32_t)r : (uint32_t)r;
    uint32_t capped = speed < 0xFFFFu ? speed : 0xFFFFu;
    uint64_t stopping = (uint64_t)(capped * capped) * (uint32_t)m->drive.ka;
    /* The least braking the output can count on settles most ticks without
     * working out the exact one. */
    if (stopping <= ((uint64_t)room * (uint32_t)m->brake_floor_duty) << 9 ||
        stopping <= ((uint64_t)room * (uint32_t)motion_brake_duty(m, v)) << 9) {
        return;
    }
    uint64_t n = div64_u(2u * (uint64_t)room + speed - 1u, speed);
    n = n < PROFILE_MAX_RAMP ? n : PROFILE_MAX_RAMP;
    int64_t v_q32 = q8_to_q32(v);
    profile_plan(&m->profile, q8_to_q32(m->measured_q8), v_q32, m->profile.target,
                 (struct profile_timing){0, 0, (uint32_t)n});
    motion_clock_restart(m);
    m->setpoint_q8 = m->measured_q8;
    m->last_setpoint_q8 = m->measured_q8 - v;
    m->braking = 1;
}

/* The duty to the bridge, the other way where the gear ratio (item 82) is
 * negative: a positive duty turns the horn the way angles grow. Inline in
 * the tick, but where size comes first (the Cortex-M0). */
#ifdef SERVO_SIZE_FIRST
static void bridge(const struct motion *m, int16_t duty)
#else
static inline __attribute__((always_inline)) void bridge(const struct motion *m, int16_t duty)
#endif
{
    m->hal->motor.drive(m->hal->ctx, m->drive.reversed ? (int16_t)-duty : duty);
}

void motion_tick(struct motion *m)
{
    measure(m);
    /* The servo's ms clock (a stream's, stream.c) times the supply's look too. */
    if ((++m->stream_clock_ms & (SUPPLY_CHECK_TICKS - 1u)) == 0u) {
        follow_supply(m);
    }
    switch (m->mode) {
    case MODE_DAMPING:
    case MODE_OPEN_LOOP:
        m->damping_duty_q15 = controller_damping(m->measured_velocity_q8, m->open_duty_q15, &m->drive);
        bridge(m, m->damping_duty_q15);
        if (m->open_ticks != 0u && --m->open_ticks == 0u) {
            motion_coast(m);
        }
        return;
    case MODE_POSITION:
        break;
    default:
        return; /* released: the output stays off */
    }
    if (m->endless) {
        rebase_endless(m);
    }
    govern_clock(m, m->setpoint_q8 - m->measured_q8);
    bool real_time = m->clock_rate == CLOCK_REAL_TIME;
    m->last_setpoint_q8 = m->setpoint_q8;
    advance_clock(m);
    guard_braking(m);
    int32_t step = m->setpoint_q8 - m->last_setpoint_q8;
    /* The acceleration feed-forward only while the clock keeps real time:
     * a rate change is no acceleration the horn should be given (the
     * output is at its limit then anyway). */
    real_time = real_time && m->clock_rate == CLOCK_REAL_TIME;
    struct controller_input in = {
        .error_q8 = m->setpoint_q8 - m->measured_q8,
        .velocity_q8 = step,
        .acceleration_duty = real_time ? m->accel_duty : 0,
        .measured_velocity_q8 = m->measured_velocity_q8,
    };
    /* While the clock is slowed and the horn lags, the motor is the
     * bottleneck: drive at the limit the way the profile goes (not while
     * braking, nor once the horn has caught up). */
    if (!real_time && !m->braking && m->lead_q8 > LEAD_FREE_Q8) {
        in.push = m->profile_at_next_tick_q8 > m->profile_at_tick_q8 ? 1 : m->profile_at_next_tick_q8 < m->profile_at_tick_q8 ? -1 : 0;
    }
    bridge(m, controller_position(&m->controller, &in, &m->drive));
    bool done = m->endless ? m->tick >= m->profile.accel_ticks
                           : profile_done(&m->profile, m->tick) && arrived(m);
    if (m->running && done) {
        motion_finish(m);
    }
}
