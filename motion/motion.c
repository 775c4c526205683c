#include "motion/motion.h"

#include <stddef.h>

#include "motion/gains.h"

/* Limits of behaviour.md, "Motion". */
enum {
    SINGLE_TURN_LIMIT = 1800,
    MULTI_TURN_LIMIT = 3686400,
    MIN_RAMP_MS = 20,
    MAX_INTERVAL_MS = 4096000,
    MIN_VELOCITY = 10,     /* 0.1 deg/s */
    MAX_VELOCITY = 7500,
    MAX_WHEEL_SPEED = 750, /* deg/s, the angle modes' top speed */
    DECIDEG_PER_TURN = 3600,
    WHEEL_RAMP_MS = 20,
    SUPPLY_HYSTERESIS_MV = 128,
    CLOCK_REAL_TIME = 256, /* clock_rate, Q8 */
};

/* Setpoint and horn agree within these: 0.5 degree, 25 deg/s. */
#define FOLLOW_GAP_Q32 (5 * DECIDEG_Q32)
enum { FOLLOW_SPEED_Q8 = 64 };

/* The profile's clock (see "the profile's clock" below). */
enum {
    LEAD_FREE_Q8 = 5 << 8, /* 0.5 degree */
    LEAD_SPAN_SHIFT = 3,   /* (lead - free) >> 3: 256 at 8 decideg */
    LEAD_FILTER_SHIFT = 2, /* time constant 4 ticks */
    CLOCK_SLOWING = 64,    /* the clock stops within 4 ticks */
    CLOCK_RECOVERY = 8,    /* a stopped clock is back to real time in 32 ticks */
};

static int32_t clamp_i32(int32_t v, int32_t lo, int32_t hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

static uint32_t clamp_u32(uint32_t v, uint32_t lo, uint32_t hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

/* ---- positions and the frames they are given in -------------------------
 * measured: Q32 decideg from the origin (SetOriginPoint, ResetMultiTurn).
 * Protocol angles are that minus the center offset (53). */

static int64_t counts_to_q32(int32_t counts)
{
    return (int64_t)counts * DECIDEG_Q8_PER_COUNT * ((int64_t)1 << 24);
}

static int32_t q32_to_decideg(int64_t q32)
{
    return (int32_t)((q32 + (DECIDEG_Q32 / 2)) >> 32); /* nearest */
}

/* Q32 to Q8 (decideg, or decideg per tick), saturated to int32. */
static int32_t q32_to_q8_sat(int64_t v)
{
    int64_t q8 = v >> 24;
    return q8 > INT32_MAX ? INT32_MAX : q8 < -INT32_MAX ? -INT32_MAX : (int32_t)q8;
}

static int64_t center_offset_q32(const struct motion *m)
{
    return (int64_t)m->regs->user.center_offset_decideg * DECIDEG_Q32;
}

static int32_t wrap_single_turn(int32_t decideg)
{
    int32_t r = decideg % DECIDEG_PER_TURN;
    if (r >= DECIDEG_PER_TURN / 2) {
        r -= DECIDEG_PER_TURN;
    } else if (r < -DECIDEG_PER_TURN / 2) {
        r += DECIDEG_PER_TURN;
    }
    return r;
}

void motion_read_angle(const struct motion *m, struct motion_angle *out)
{
    int32_t angle = q32_to_decideg(m->measured - center_offset_q32(m));
    out->multi_turn_decideg = angle;
    out->turns = (int16_t)(angle / DECIDEG_PER_TURN);
    out->single_turn_decideg = (int16_t)wrap_single_turn(angle);
}

static int16_t saturate_i16(int32_t v)
{
    return (int16_t)(v > INT16_MAX ? INT16_MAX : v < -INT16_MAX ? -INT16_MAX : v);
}

void motion_read_diagnostics(const struct motion *m, struct motion_diagnostics *out)
{
    bool controlled = m->mode == MODE_POSITION;
    int64_t offset = center_offset_q32(m);
    int64_t setpoint = controlled ? m->setpoint : m->measured;
    /* decideg per tick Q8 to decideg per s: x 1000 / 256 = x 125 / 32. */
    int32_t error_q8 = q32_to_q8_sat(setpoint - m->measured);
    *out = (struct motion_diagnostics){
        .angle_decideg = q32_to_decideg(m->measured - offset),
        .setpoint_decideg = q32_to_decideg(setpoint - offset),
        .target_decideg = q32_to_decideg((controlled ? m->profile.target : m->measured) - offset),
        .velocity_decideg_s = saturate_i16(m->measured_velocity_q8 * 125 / 32),
        .tracking_error_centideg = saturate_i16((int32_t)(((int64_t)error_q8 * 10) / 256)),
        .flags = (uint8_t)((controlled && m->tick >= m->profile.total_ticks ? DIAG_PROFILE_ENDED : 0u) |
                           (controlled && m->clock_rate != CLOCK_REAL_TIME ? DIAG_CLOCK_SLOWED : 0u) |
                           (controlled && m->braking ? DIAG_BRAKING : 0u) |
                           (motion_output_at_limit(m) ? DIAG_AT_LIMIT : 0u) |
                           (controlled ? 0u : DIAG_RELEASED)),
    };
}

/* ---- the output --------------------------------------------------------- */

static uint16_t supply_mv(const struct motion *m)
{
    uint16_t v = m->regs->status.voltage_mv;
    return v ? v : NOMINAL_SUPPLY_MV;
}

/* The current the output may draw: the move's power (0 or above 42 means
 * 42), capped by a stall, within the current protection (43), halved while
 * over-current or over-power lasts. Divides: on changes only. */
static void update_duty_limit(struct motion *m)
{
    const struct user_config *cfg = &m->regs->user;
    uint16_t power = m->power_mw;
    if (power == 0u || power > cfg->power_limit_mw) {
        power = cfg->power_limit_mw;
    }
    if (m->power_cap_mw != 0u && power > m->power_cap_mw) {
        power = m->power_cap_mw;
    }
    m->supply_mv_used = supply_mv(m);
    int16_t by_power = duty_limit_for_power(power, m->supply_mv_used);
    int16_t by_current = duty_limit_for_current(cfg->current_limit_ma, m->supply_mv_used);
    int16_t limit = (int16_t)(by_power < by_current ? by_power : by_current);
    m->drive.duty_limit = (int16_t)(m->derate ? limit / 2 : limit);
    drive_limits_for_supply(&m->drive, m->supply_mv_used);
}

static void set_power(struct motion *m, uint16_t power_mw)
{
    m->power_mw = power_mw;
    update_duty_limit(m);
}

static void release(struct motion *m)
{
    m->mode = MODE_RELEASED;
    m->running = 0;
    m->controller.at_limit = 0;
    m->hal->motor_coast(m->hal->ctx);
}

/* Starts the profile's clock at its tick 0. */
static void clock_restart(struct motion *m)
{
    m->tick = 0;
    m->tick_frac = 0;
    m->clock_rate = CLOCK_REAL_TIME;
    m->lead_q8 = 0;
    m->braking = 0;
    m->at_tick = profile_position(&m->profile, 0);
    m->at_next = profile_position(&m->profile, 1);
}

/* Hold still where the setpoint is now (or where the servo is, if it was
 * released): a zero-length profile. */
static void hold_here(struct motion *m)
{
    int64_t here = m->mode == MODE_POSITION ? m->setpoint : m->measured;
    profile_plan(&m->profile, here, 0, here, (struct profile_timing){0, 0, 0});
    m->profile.total_ticks = 0;
    clock_restart(m);
    m->setpoint = here;
    m->last_setpoint = here;
    if (m->mode != MODE_POSITION) {
        controller_reset(&m->controller);
    }
    m->mode = MODE_POSITION;
    m->end = END_HOLD;
}

/* The horn is within FOLLOW_GAP of the setpoint and within FOLLOW_SPEED
 * of its speed. */
static bool horn_follows(const struct motion *m)
{
    int64_t gap = m->setpoint - m->measured;
    int64_t speed = ((m->setpoint - m->last_setpoint) >> 24) - m->measured_velocity_q8;
    return gap < FOLLOW_GAP_Q32 && gap > -FOLLOW_GAP_Q32 && speed < FOLLOW_SPEED_Q8 &&
           speed > -FOLLOW_SPEED_Q8;
}

/* Where a new profile starts: the current setpoint and its velocity when
 * following one (no jerk to a stop; the velocity the slowed clock gives
 * it), else the measured position at rest. */
static void start_state(const struct motion *m, int64_t *start, int64_t *v0)
{
    if (m->mode == MODE_POSITION && !horn_follows(m)) {
        /* The horn is elsewhere or moves otherwise than the setpoint (a
         * slowed clock, a load): take over from where it really is. */
        *start = m->measured;
        *v0 = (int64_t)m->measured_velocity_q8 * ((int64_t)1 << 24);
    } else if (m->mode == MODE_POSITION) {
        *start = m->setpoint;
        *v0 = m->setpoint - m->last_setpoint;
    } else {
        *start = m->measured;
        *v0 = 0;
    }
}

static void begin_profile(struct motion *m, uint8_t end)
{
    if (m->mode != MODE_POSITION) {
        controller_reset(&m->controller);
    }
    m->setpoint = m->profile.start;
    m->last_setpoint = m->profile.start - m->profile.v0; /* moving at v0 */
    m->mode = MODE_POSITION;
    clock_restart(m);
    m->end = end;
    m->running = 1;
}

/* Q32 decideg per tick for a velocity in 0.1 deg/s. */
static int64_t velocity_q32(uint32_t decideg_per_s)
{
    return (int64_t)(((uint64_t)decideg_per_s << 32) / MOTION_TICK_HZ);
}

/* ---- braking within what the motor can do --------------------------------
 * The deceleration the output can count on moving in direction dir: the
 * duty margin of the current limit, less what holding a load that pushes
 * the way the horn turns takes (the integral term carries it; counted up
 * to half the margin, since in motion it also holds transient errors: a
 * load of 0.8 of the stall torque at this power takes 0.8 x efficiency^2 =
 * 0.26, plant.c), and a quarter of that kept for the controller to correct
 * errors with. As a duty; duty / ka is decideg per tick^2. */
static int32_t brake_duty(const struct motion *m, int32_t dir)
{
    int32_t limit = m->drive.duty_limit;
    int32_t assisting = dir > 0 ? -m->controller.integral_q15 : m->controller.integral_q15;
    assisting = assisting < 0 ? 0 : assisting > limit / 2 ? limit / 2 : assisting;
    int32_t duty = limit - assisting;
    duty -= duty >> 2;
    return duty > 1 ? duty : 1;
}


/* From start moving at v0, come to rest at the output's braking (in at
 * least min_ticks): the target is where that ends. Plans: it divides. */
static void plan_stop(struct motion *m, int64_t start, int64_t v0, uint32_t min_ticks)
{
    int32_t v = q32_to_q8_sat(v0);
    uint64_t speed = (uint64_t)(v < 0 ? -(int64_t)v : v);
    uint64_t per_tick = (uint64_t)brake_duty(m, v) << 8; /* x ka: decideg Q8 per tick^2 */
    uint64_t n = (speed * (uint64_t)m->drive.ka + per_tick - 1u) / per_tick;
    n = n > min_ticks ? n : min_ticks;
    n = n < PROFILE_MAX_RAMP ? n : PROFILE_MAX_RAMP;
    int64_t target = start + v0 * (int64_t)n / 2;
    profile_plan(&m->profile, start, v0, target, (struct profile_timing){0, 0, (uint32_t)n});
}

/* ---- commands ----------------------------------------------------------- */

static int64_t angle_target(const struct motion *m, const struct motion_command *cmd)
{
    const struct user_config *cfg = &m->regs->user;
    if (cmd->multi_turn) {
        int32_t angle = clamp_i32(cmd->angle_decideg, -MULTI_TURN_LIMIT, MULTI_TURN_LIMIT);
        return (int64_t)angle * DECIDEG_Q32 + center_offset_q32(m);
    }
    int32_t angle = clamp_i32(cmd->angle_decideg, -SINGLE_TURN_LIMIT, SINGLE_TURN_LIMIT);
    if (cfg->angle_limit_on) {
        angle = clamp_i32(angle, cfg->angle_min_decideg, cfg->angle_max_decideg);
    }
    /* A single-turn angle is within the turn the servo is in now. */
    struct motion_angle now;
    motion_read_angle(m, &now);
    int32_t turn_base = now.multi_turn_decideg - now.single_turn_decideg;
    return ((int64_t)turn_base + angle) * DECIDEG_Q32 + center_offset_q32(m);
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
    profile_plan(&m->profile, start, v0, target, timing);
    begin_profile(m, END_HOLD);
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
        begin_profile(m, END_HOLD);
        m->endless = 1;
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
        begin_profile(m, end);
        return;
    }
    profile_plan(&m->profile, start, v0, target, timing);
    begin_profile(m, end);
}

static void run_stop(struct motion *m, const struct motion_command *cmd)
{
    switch (cmd->method) {
    case STOP_HOLD:
        /* Hold where the servo comes to rest, braking as hard as the motor
         * can from where it is, not where it aimed. */
        if (m->mode == MODE_POSITION) {
            plan_stop(m, m->setpoint, m->setpoint - m->last_setpoint, 0);
        } else {
            int64_t v = (int64_t)m->measured_velocity_q8 * ((int64_t)1 << 24);
            plan_stop(m, m->measured, v, 0);
        }
        begin_profile(m, END_HOLD);
        break;
    case STOP_DAMPING:
        m->mode = MODE_DAMPING;
        break;
    default:
        release(m);
        break;
    }
    m->running = 0;
}

static void run(struct motion *m, const struct motion_command *cmd)
{
    m->endless = 0;
    m->answer_packet = cmd->answer_when_done ? cmd->packet : 0u;
    set_power(m, cmd->power_mw);
    switch (cmd->kind) {
    case MOTION_ANGLE:
        run_angle(m, cmd);
        break;
    case MOTION_WHEEL:
        run_wheel(m, cmd);
        break;
    case MOTION_DAMPING:
        m->mode = MODE_DAMPING;
        m->running = 0;
        break;
    default:
        run_stop(m, cmd);
        break;
    }
}

static bool queue_push(struct motion_queue *q, const struct motion_command *cmd)
{
    if (q->count >= MOTION_QUEUE_DEPTH) {
        return false;
    }
    q->slots[(q->head + q->count) % MOTION_QUEUE_DEPTH] = *cmd;
    q->count++;
    return true;
}

static const struct motion_command *queue_pop(struct motion_queue *q)
{
    if (q->count == 0u) {
        return NULL;
    }
    const struct motion_command *cmd = &q->slots[q->head];
    q->head = (uint8_t)((q->head + 1u) % MOTION_QUEUE_DEPTH);
    q->count--;
    return cmd;
}

/* Damping and stop act at once and drop what waits; other commands queue
 * behind a running one while control response is on. */
static enum motion_submit_result dispatch_command(struct motion *m, const struct motion_command *cmd)
{
    bool immediate = cmd->kind == MOTION_DAMPING || cmd->kind == MOTION_STOP;
    if (immediate) {
        m->queue.count = 0;
    } else if (m->regs->user.control_response && m->running) {
        return queue_push(&m->queue, cmd) ? MOTION_ACCEPTED : MOTION_QUEUE_FULL;
    }
    run(m, cmd);
    return MOTION_ACCEPTED;
}

enum motion_submit_result motion_submit(struct motion *m, const struct motion_command *cmd)
{
    m->commands++;
    if (m->inhibit) {
        return MOTION_REFUSED;
    }
    if (m->async_open) {
        return queue_push(&m->async, cmd) ? MOTION_ACCEPTED : MOTION_QUEUE_FULL;
    }
    return dispatch_command(m, cmd);
}

void motion_begin_async(struct motion *m)
{
    m->async_open = 1;
    m->async.count = 0;
    m->async.head = 0;
}

void motion_end_async(struct motion *m, bool cancel)
{
    m->async_open = 0;
    const struct motion_command *cmd;
    while ((cmd = queue_pop(&m->async)) != NULL) {
        if (!cancel) {
            (void)dispatch_command(m, cmd); /* overflow here drops, as on the wire */
        }
    }
}

bool motion_is_released(const struct motion *m)
{
    return m->mode != MODE_POSITION;
}

bool motion_is_executing(const struct motion *m)
{
    return m->running != 0u;
}

bool motion_reset_multi_turn(struct motion *m)
{
    if (!motion_is_released(m)) {
        return false;
    }
    /* Keep the angle within the turn; drop the whole turns. */
    int32_t rel = m->encoder.counts - m->origin_counts;
    int32_t within = rel % ENCODER_COUNTS;
    if (within >= ENCODER_COUNTS / 2) {
        within -= ENCODER_COUNTS;
    } else if (within < -ENCODER_COUNTS / 2) {
        within += ENCODER_COUNTS;
    }
    m->origin_counts += rel - within;
    m->measured = counts_to_q32(m->encoder.counts - m->origin_counts);
    return true;
}

bool motion_set_origin(struct motion *m)
{
    if (!motion_is_released(m)) {
        return false;
    }
    m->origin_counts = m->encoder.counts;
    m->measured = 0;
    return true;
}

uint8_t motion_take_finished(struct motion *m)
{
    if (m->answers_count == 0u) {
        return 0;
    }
    uint8_t packet = m->answers[0];
    for (uint8_t i = 1; i < m->answers_count; i++) {
        m->answers[i - 1u] = m->answers[i];
    }
    m->answers_count--;
    return packet;
}

static void finish(struct motion *m)
{
    m->running = 0;
    if (m->answer_packet != 0u && m->answers_count < MOTION_ANSWERS_DEPTH) {
        m->answers[m->answers_count++] = m->answer_packet;
    }
    m->answer_packet = 0;
    if (m->end == END_RELEASE) {
        release(m);
    }
    const struct motion_command *next = queue_pop(&m->queue);
    if (next != NULL) {
        run(m, next);
    }
}

void motion_init(struct motion *m, const struct registers *regs, const struct hal_port *hal)
{
    *m = (struct motion){.regs = regs, .hal = hal, .soft_start_pending = 1};
    encoder_start(&m->encoder, hal->encoder_read(hal->ctx));
    m->origin_counts = 0;
    m->measured = counts_to_q32(m->encoder.counts);
    m->track_q32 = m->measured;
    set_power(m, 0);
    if (regs->user.power_on_lock) {
        hold_here(m);
    } else {
        release(m);
    }
}

/* ---- the control tick --------------------------------------------------- */

/* A move has finished when its setpoint has reached the target and the
 * horn has arrived there, within ARRIVE_DECIDEG, and nearly stopped (not
 * just passing through). */
enum { ARRIVE_DECIDEG = 3 }; /* 0.3 degree */

static bool arrived(const struct motion *m)
{
    int64_t gap = m->profile.target - m->measured;
    int32_t speed = m->measured_velocity_q8;
    return gap <= ARRIVE_DECIDEG * DECIDEG_Q32 && gap >= -ARRIVE_DECIDEG * DECIDEG_Q32 &&
           speed < FOLLOW_SPEED_Q8 && speed > -FOLLOW_SPEED_Q8;
}

/* Turning without end (wheel run) must not outgrow the number formats: past
 * the protocol's multi-turn range the frame moves back by whole turns, and
 * the profile restarts its clock before the tick count gets large. */
enum { REBASE_TICKS = 1u << 24 };
#define REBASE_COUNTS ((int32_t)(MULTI_TURN_LIMIT / DECIDEG_PER_TURN) * ENCODER_COUNTS)

static void rebase_endless(struct motion *m)
{
    if (m->tick >= REBASE_TICKS) {
        int64_t v = m->profile.cruise;
        profile_plan_endless(&m->profile, m->setpoint, v, v, 0);
        clock_restart(m);
    }
    int32_t rel = m->encoder.counts - m->origin_counts;
    if (rel > REBASE_COUNTS || rel < -REBASE_COUNTS) {
        int32_t shift = rel > 0 ? REBASE_COUNTS : -REBASE_COUNTS;
        int64_t shift_q32 = counts_to_q32(shift);
        m->origin_counts += shift;
        m->measured -= shift_q32;
        m->setpoint -= shift_q32;
        m->last_setpoint -= shift_q32;
        m->profile.start -= shift_q32;
        m->profile.target -= shift_q32;
        m->profile.cruise_start -= shift_q32;
        m->at_tick -= shift_q32;
        m->at_next -= shift_q32;
    }
}

/* The horn's speed from a 12-bit encoder: one count per tick is 88 deg/s, so
 * a plain difference is mostly rounding. An alpha-beta tracker predicts
 * where the horn should be and corrects position and speed by part of the
 * miss (1/2 and 1/8): it follows a steady speed without lag, where a
 * low-pass lags by its time constant, which left the current limit working
 * around a stale back-EMF after a preemption. It runs on the encoder's own
 * counts, which no change of origin moves. */
enum { TRACK_POSITION_SHIFT = 1, TRACK_VELOCITY_SHIFT = 3 };

static void measure(struct motion *m)
{
    encoder_update(&m->encoder, m->hal->encoder_read(m->hal->ctx));
    m->measured = counts_to_q32(m->encoder.counts - m->origin_counts);
    int64_t at = counts_to_q32(m->encoder.counts);
    int64_t predicted = m->track_q32 + (int64_t)m->track_velocity_q12 * ((int64_t)1 << 20);
    int64_t miss = (at - predicted) >> 20; /* Q12 */
    miss = miss > INT32_MAX / 2 ? INT32_MAX / 2 : miss < -INT32_MAX / 2 ? -INT32_MAX / 2 : miss;
    m->track_q32 = predicted + (miss >> TRACK_POSITION_SHIFT) * ((int64_t)1 << 20);
    int64_t v = m->track_velocity_q12 + (miss >> TRACK_VELOCITY_SHIFT);
    m->track_velocity_q12 = (int32_t)(v > INT32_MAX / 2 ? INT32_MAX / 2 : v < -INT32_MAX / 2 ? -INT32_MAX / 2 : v);
    /* Q12 inside, so the rounding left over is far below one Q8 step. */
    m->measured_velocity_q8 = (m->track_velocity_q12 + 8) >> 4;
}

/* The supply moves slowly: the duty margin for the power follows it every
 * SUPPLY_CHECK_TICKS ticks, when it has moved more than the hysteresis. */
enum { SUPPLY_CHECK_TICKS = 32 };

static void follow_supply(struct motion *m)
{
    uint16_t v = supply_mv(m);
    if (v > m->supply_mv_used + SUPPLY_HYSTERESIS_MV || v + SUPPLY_HYSTERESIS_MV < m->supply_mv_used) {
        update_duty_limit(m);
    }
}

void motion_guard(struct motion *m, bool inhibit, bool derate, uint16_t power_cap_mw)
{
    if (inhibit && !m->inhibit) {
        m->queue.count = 0;
        m->answer_packet = 0;
        release(m);
    }
    m->inhibit = inhibit;
    if (derate != m->derate || power_cap_mw != m->power_cap_mw) {
        m->derate = derate;
        m->power_cap_mw = power_cap_mw;
        update_duty_limit(m);
    }
}

void motion_release(struct motion *m)
{
    m->queue.count = 0;
    m->answer_packet = 0;
    release(m);
}

bool motion_output_at_limit(const struct motion *m)
{
    return m->mode == MODE_POSITION && m->controller.at_limit;
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
    int64_t step = m->at_next - m->at_tick;
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
 * count within one tick). */
static void advance_clock(struct motion *m)
{
    uint32_t frac = (uint32_t)m->tick_frac + m->clock_rate;
    if (frac >= CLOCK_REAL_TIME && m->tick < UINT32_MAX) {
        frac -= CLOCK_REAL_TIME;
        m->tick++;
        m->at_tick = m->at_next;
        m->at_next = profile_position(&m->profile, m->tick + 1u);
    }
    m->tick_frac = (uint16_t)frac;
    m->setpoint = m->at_tick + (((m->at_next - m->at_tick) * (int64_t)frac) >> 8);
}

/* A profile whose horn could no longer stop on the target at the output's
 * braking (v^2 > 2 a r, a = brake_duty / ka, v the setpoint's or the horn's
 * speed, r what is left from the horn) decelerates from where the horn is, at v^2 / 2r,
 * and is left alone after that (braking). Starting from the horn rather
 * than the setpoint drops the lead the slowed clock kept, which would
 * otherwise push on against the braking. This catches plans whose ramps
 * are steeper than the motor, and setpoints the slowed clock has left
 * moving at another speed, in any phase. Speeds beyond 2^16 (256 decideg
 * per tick) count as 2^16: far beyond any servo, and the products stay
 * within int64. */
static void guard_braking(struct motion *m)
{
    if (m->endless || m->braking) {
        return;
    }
    /* The faster of setpoint and horn must stop: in a slowed deceleration
     * the setpoint moves slower than the horn still does. */
    int64_t v_q32 = m->setpoint - m->last_setpoint;
    int32_t v = q32_to_q8_sat(v_q32);
    int32_t w = m->measured_velocity_q8;
    if ((w > 0) == (v > 0) && (w > v) == (v > 0) && w != v) {
        v = w;
        v_q32 = (int64_t)w * ((int64_t)1 << 24);
    }
    int32_t r = q32_to_q8_sat(m->profile.target - m->measured);
    if (v == 0 || r == 0 || (v > 0) != (r > 0)) {
        return;
    }
    int64_t speed = v < 0 ? -(int64_t)v : v;
    int64_t room = r < 0 ? -(int64_t)r : r;
    int64_t capped = speed < (1 << 16) ? speed : (1 << 16);
    if (capped * capped * m->drive.ka <= ((int64_t)brake_duty(m, v) * room) << 9) {
        return;
    }
    uint32_t n = (uint32_t)((2 * room + speed - 1) / speed);
    n = n < PROFILE_MAX_RAMP ? n : PROFILE_MAX_RAMP;
    profile_plan(&m->profile, m->measured, v_q32, m->profile.target,
                 (struct profile_timing){0, 0, n});
    clock_restart(m);
    m->setpoint = m->profile.start;
    m->last_setpoint = m->profile.start - v_q32;
    m->braking = 1;
}

void motion_tick(struct motion *m)
{
    measure(m);
    if (++m->supply_check == SUPPLY_CHECK_TICKS) {
        m->supply_check = 0;
        follow_supply(m);
    }
    switch (m->mode) {
    case MODE_DAMPING:
        m->hal->motor_drive(m->hal->ctx, controller_damping(m->measured_velocity_q8, &m->drive));
        return;
    case MODE_POSITION:
        break;
    default:
        return; /* released: the output stays off */
    }
    if (m->endless) {
        rebase_endless(m);
    }
    govern_clock(m, q32_to_q8_sat(m->setpoint - m->measured));
    int64_t last_step = m->setpoint - m->last_setpoint;
    bool real_time = m->clock_rate == CLOCK_REAL_TIME;
    m->last_setpoint = m->setpoint;
    advance_clock(m);
    guard_braking(m);
    int64_t step = m->setpoint - m->last_setpoint;
    /* The acceleration feed-forward only while the clock keeps real time:
     * a rate change is no acceleration the horn should be given (the
     * output is at its limit then anyway). */
    real_time = real_time && m->clock_rate == CLOCK_REAL_TIME;
    const struct controller_input in = {
        .error_q8 = q32_to_q8_sat(m->setpoint - m->measured),
        .velocity_q8 = q32_to_q8_sat(step),
        .acceleration_q16 = real_time ? (int32_t)((step - last_step) >> 16) : 0,
        .measured_velocity_q8 = m->measured_velocity_q8,
        /* While the clock is slowed and the horn lags, the motor is the
         * bottleneck: drive at the limit the way the profile goes (not
         * while braking, nor once the horn has caught up). */
        .push = real_time || m->braking || m->lead_q8 <= LEAD_FREE_Q8 ? 0
                : m->at_next > m->at_tick                             ? 1
                : m->at_next < m->at_tick                             ? -1
                                                                      : 0,
    };
    m->hal->motor_drive(m->hal->ctx, controller_position(&m->controller, &in, &m->drive));
    bool done = m->endless ? m->tick >= m->profile.accel_ticks
                           : profile_done(&m->profile, m->tick) && arrived(m);
    if (m->running && done) {
        finish(m);
    }
}
