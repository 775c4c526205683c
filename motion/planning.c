/* A profile for each motion command: where it starts (the setpoint it
 * takes over, or the horn), where it ends and how long each phase takes,
 * clamped to the limits of docs/protocol.md, "Moves". Plans: divides. */
#include "motion/div64.h"
#include "motion/gains.h"
#include "motion/motion_internal.h"

/* Limits of docs/protocol.md, "Moves": the schema's ranges of the fields. */
enum {
    SINGLE_TURN_LIMIT = FIELD_MOVE_ANGLE_ANGLE_MAX,
    MAX_INTERVAL_MS = FIELD_MOVE_MULTI_TURN_INTERVAL_MAX,
    MIN_VELOCITY = FIELD_MOVE_ANGLE_BY_VELOCITY_TARGET_VELOCITY_MIN, /* 0.1 deg/s */
    MAX_WHEEL_SPEED = FIELD_MOVE_WHEEL_SPEED_MAX, /* deg/s, the angle modes' top speed */
    WHEEL_RAMP_MS = 20,
};
/* The clamps below take a range of +-its most, and one ramp's least for both. */
_Static_assert(FIELD_MOVE_ANGLE_ANGLE_MIN == -SINGLE_TURN_LIMIT &&
                   FIELD_MOVE_MULTI_TURN_ANGLE_MIN == -MULTI_TURN_LIMIT,
               "the angle ranges are symmetric");
_Static_assert(FIELD_MOVE_ANGLE_BY_INTERVAL_DEC_INTERVAL_MIN == MIN_RAMP_MS &&
                   FIELD_MOVE_ANGLE_BY_INTERVAL_ACC_INTERVAL_MAX == PROFILE_MAX_RAMP &&
                   FIELD_MOVE_ANGLE_BY_INTERVAL_DEC_INTERVAL_MAX == PROFILE_MAX_RAMP,
               "one ramp range");

static uint32_t clamp_u32(uint32_t v, uint32_t lo, uint32_t hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

/* The horn is within FOLLOW_GAP of the setpoint and within FOLLOW_SPEED
 * of its speed. */
static bool horn_follows(const struct motion *m)
{
    int32_t gap = m->setpoint_q8 - m->measured_q8;
    int32_t speed = (m->setpoint_q8 - m->last_setpoint_q8) - m->measured_velocity_q8;
    return gap < FOLLOW_GAP_Q8 && gap > -FOLLOW_GAP_Q8 && speed < FOLLOW_SPEED_Q8 &&
           speed > -FOLLOW_SPEED_Q8;
}

/* The reference a profile takes over: the setpoint and its velocity (the
 * velocity the slowed clock gives it), or the horn as measured. */
static void reference(const struct motion *m, bool setpoint, int64_t *start, int64_t *v0)
{
    int32_t at = setpoint ? m->setpoint_q8 : m->measured_q8;
    int32_t v = setpoint ? m->setpoint_q8 - m->last_setpoint_q8 : m->measured_velocity_q8;
    *start = q8_to_q32(at);
    *v0 = q8_to_q32(v);
}

/* Where a new profile starts: the current setpoint and its velocity when
 * following one (no jerk to a stop), else where the horn really is (it is
 * elsewhere or moves otherwise than the setpoint: a slowed clock, a load),
 * at rest unless a setpoint drove it. */
static void start_state(const struct motion *m, int64_t *start, int64_t *v0)
{
    bool position = m->mode == MODE_POSITION;
    reference(m, position && horn_follows(m), start, v0);
    if (!position) {
        *v0 = 0;
    }
}

void motion_begin_profile(struct motion *m, uint8_t end)
{
    if (m->mode != MODE_POSITION) {
        controller_reset(&m->controller);
        m->damping_duty_q15 = 0;
    }
    m->mode = MODE_POSITION;
    motion_clock_restart(m);
    m->last_setpoint_q8 = m->setpoint_q8 - q32_to_q8_sat(m->profile.v0); /* moving at v0 */
    m->end = end;
    m->running = 1;
}

/* Q32 decideg per tick for a velocity in 0.1 deg/s. */
static int64_t velocity_q32(uint32_t decideg_per_s)
{
    _Static_assert(MOTION_TICK_HZ == 1000u && MAX_VELOCITY < 59074, "thousandth_q32's range");
    return (int64_t)thousandth_q32(decideg_per_s);
}

/* From start moving at v0, come to rest at the output's braking (in at
 * least min_ticks): the target is where that ends. Plans: it divides. */
static void plan_stop(struct motion *m, int64_t start, int64_t v0, uint32_t min_ticks)
{
    int32_t v = q32_to_q8_sat(v0);
    uint64_t speed = (uint64_t)(v < 0 ? -(int64_t)v : v);
    uint64_t per_tick = (uint64_t)motion_brake_duty(m, v) << 8; /* x ka: decideg Q8 per tick^2 */
    uint64_t n = div64_u(speed * (uint64_t)m->drive.ka + per_tick - 1u, per_tick);
    n = n > min_ticks ? n : min_ticks;
    n = n < PROFILE_MAX_RAMP ? n : PROFILE_MAX_RAMP;
    int64_t target = start + v0 * (int64_t)n / 2;
    profile_plan(&m->profile, start, v0, target, (struct profile_timing){0, 0, (uint32_t)n});
}

/* ---- commands ----------------------------------------------------------- */

/* Every position target passes here: angle and multi-turn moves (and so
 * a SyncCommand's records, the async buffer's and the queue's, when they
 * run) and streamed setpoints. The angle (protocol frame, 0.1 deg) is
 * clamped to its packet's range, then, with the limits on for its kind
 * (item 48 at least from: LIMITS_ON, LIMITS_ALL_TARGETS), to 52..51 in its
 * own frame: base is the reading's turn a single-turn angle is taken
 * in, 0 for a multi-turn one, so a multi-turn target stays within the
 * limits of the reading itself (docs/decisions.md, "The angle limits hold
 * for every target"). The limiter says angle when the target moved. */
int32_t motion_target_q8(struct motion *m, int32_t angle_decideg, int32_t range, int32_t base,
                         uint8_t from)
{
    const struct user_config *cfg = &m->regs->user;
    int32_t angle = clamp_i32(angle_decideg, -range, range);
    if (cfg->angle_limit_on >= from) {
        angle = clamp_i32(angle, cfg->angle_min_decideg, cfg->angle_max_decideg);
    }
    m->angle_clamped = angle != angle_decideg;
    return (base + angle) * 256 + motion_center_offset_q8(m);
}

static int64_t angle_target(struct motion *m, const struct motion_command *cmd)
{
    int32_t base = 0, range = MULTI_TURN_LIMIT;
    uint8_t from = LIMITS_ALL_TARGETS;
    if (!cmd->multi_turn) {
        from = LIMITS_ON;
        /* A single-turn angle is within the turn the servo is in now. */
        struct motion_angle now;
        motion_read_angle(m, &now);
        base = now.multi_turn_decideg - now.single_turn_decideg;
        range = SINGLE_TURN_LIMIT;
    }
    return q8_to_q32(motion_target_q8(m, cmd->angle_decideg, range, base, from));
}

static void run_angle(struct motion *m, const struct motion_command *cmd)
{
    const struct user_config *cfg = &m->regs->user;
    uint32_t acc = clamp_u32(cmd->acc_ms, MIN_RAMP_MS, PROFILE_MAX_RAMP);
    uint32_t dec = clamp_u32(cmd->dec_ms, MIN_RAMP_MS, PROFILE_MAX_RAMP);
    int64_t start, v0;
    start_state(m, &start, &v0);
    int64_t target = angle_target(m, cmd);
    struct profile_timing timing;
    bool soft_start = m->soft_start_pending && cfg->soft_start_on;
    m->soft_start_pending = 0;
    if (cmd->profile == PROFILE_INTERVAL || soft_start) {
        uint32_t interval = soft_start ? cfg->soft_start_ms : cmd->interval_ms;
        interval = clamp_u32(interval, acc + dec, MAX_INTERVAL_MS);
        timing = (struct profile_timing){acc, interval - acc - dec, dec};
    } else {
        uint32_t v = clamp_u32(cmd->velocity_decideg_s, MIN_VELOCITY, MAX_VELOCITY);
        timing = profile_velocity_timing(target - start, v0, velocity_q32(v), acc, dec);
    }
    uint32_t jerk = PROFILE_SMOOTHING ? m->regs->firmware.jerk_limit : 0u;
    if (jerk != 0u) {
        /* The average of a trapezoid is C2 only if the trapezoid's
         * velocity is continuous: a ramp of at least a tick. */
        timing.accel += timing.accel == 0u;
        timing.decel += timing.decel == 0u;
    }
    profile_plan(&m->profile, start, v0, target, timing);
    if (jerk != 0u) {
        /* (deg/s^2)/ms is 1e-5 decideg per tick^3, 167.77 in Q24: 167 is
         * 0.5 % less (a longer window, never a higher jerk). */
        uint32_t window = profile_smooth_ticks(&m->profile, jerk * 167u);
        if (v0 != 0 && window != 0u) {
            profile_plan(&m->profile, start + profile_smooth_shift(v0, window), v0, target, timing);
        }
        profile_smooth(&m->profile, window);
    }
    motion_begin_profile(m, END_HOLD);
}

static void run_wheel(struct motion *m, const struct motion_command *cmd)
{
    uint8_t action = cmd->method & (uint8_t)~WHEEL_CLOCKWISE;
    uint32_t speed = clamp_u32(cmd->wheel_speed_deg_s, 0, MAX_WHEEL_SPEED);
    int64_t v = velocity_q32(speed * 10u);
    if (cmd->method & WHEEL_CLOCKWISE) {
        v = -v;
    }
    uint8_t end = m->regs->user.wheel_brake ? END_HOLD : END_RELEASE;
    int64_t start, v0;
    start_state(m, &start, &v0);
    if (action == WHEEL_RUN && speed != 0u) {
        profile_plan_endless(&m->profile, start, v0, v, WHEEL_RAMP_MS);
        motion_begin_profile(m, END_HOLD);
        m->endless = 1;
        m->endless_until = REBASE_TICKS;
        return;
    }
    struct profile_timing timing = {WHEEL_RAMP_MS, 0, WHEEL_RAMP_MS};
    int64_t target;
    if (action == WHEEL_TURNS && speed != 0u) {
        int64_t distance = (int64_t)cmd->wheel_value * DECIDEG_PER_TURN * DECIDEG_Q32;
        target = start + (v < 0 ? -distance : distance);
        timing = profile_velocity_timing(target - start, v0, v < 0 ? -v : v, WHEEL_RAMP_MS,
                                         WHEEL_RAMP_MS);
    } else if (action == WHEEL_TIME && speed != 0u) {
        /* Run for value ms at speed: the cruise fills what the ramps leave. */
        uint32_t t = clamp_u32(cmd->wheel_value, 2u * WHEEL_RAMP_MS, UINT16_MAX);
        timing.cruise = t - 2u * WHEEL_RAMP_MS;
        target = start + v * (int64_t)(t - WHEEL_RAMP_MS);
    } else {
        /* Stop: come to rest within one ramp, or as fast as the motor can. */
        plan_stop(m, start, v0, WHEEL_RAMP_MS);
        motion_begin_profile(m, end);
        return;
    }
    profile_plan(&m->profile, start, v0, target, timing);
    motion_begin_profile(m, end);
}

static void run_stop(struct motion *m, const struct motion_command *cmd)
{
    switch (cmd->method) {
    case STOP_HOLD:
        /* Hold where the servo comes to rest, braking as hard as the motor
         * can from where it is, not where it aimed. */
        {
            int64_t start, v0;
            reference(m, m->mode == MODE_POSITION, &start, &v0);
            plan_stop(m, start, v0, 0);
        }
        motion_begin_profile(m, END_HOLD);
        break;
    case STOP_DAMPING:
        m->mode = MODE_DAMPING;
        break;
    default:
        motion_coast(m);
        break;
    }
    m->running = 0;
}

void motion_run(struct motion *m, const struct motion_command *cmd)
{
    m->endless = 0;
    m->streaming = 0;
    m->angle_clamped = 0;
    m->open_duty_q15 = 0;
    m->open_ticks = 0;
    m->answer_packet = cmd->answer_when_done ? cmd->packet : 0u;
    m->power_mw = cmd->power_mw;
    motion_update_limits(m);
    if (cmd->kind == MOTION_ANGLE) {
        run_angle(m, cmd);
    } else if (cmd->kind == MOTION_WHEEL) {
        run_wheel(m, cmd);
    } else if (cmd->kind == MOTION_DAMPING) {
        m->mode = MODE_DAMPING;
        m->running = 0;
    } else {
        run_stop(m, cmd);
    }
}
