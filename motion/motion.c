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
    m->duty_limit = (int16_t)(m->derate ? limit / 2 : limit);
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

/* Hold still where the setpoint is now (or where the servo is, if it was
 * released): a zero-length profile. */
static void hold_here(struct motion *m)
{
    int64_t here = m->mode == MODE_POSITION ? m->setpoint : m->measured;
    profile_plan(&m->profile, here, 0, here, (struct profile_timing){0, 0, 0});
    m->profile.total_ticks = 0;
    m->tick = 0;
    m->setpoint = here;
    m->last_setpoint = here;
    if (m->mode != MODE_POSITION) {
        controller_reset(&m->controller);
    }
    m->mode = MODE_POSITION;
    m->end = END_HOLD;
}

/* Where a new profile starts: the current setpoint and its velocity when
 * following one (no jerk to a stop), else the measured position at rest. */
static void start_state(const struct motion *m, int64_t *start, int64_t *v0)
{
    if (m->mode == MODE_POSITION) {
        *start = m->setpoint;
        *v0 = profile_velocity(&m->profile, m->tick);
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
    m->last_setpoint = m->profile.start;
    m->mode = MODE_POSITION;
    m->tick = 0;
    m->end = end;
    m->running = 1;
}

/* Q32 decideg per tick for a velocity in 0.1 deg/s. */
static int64_t velocity_q32(uint32_t decideg_per_s)
{
    return (int64_t)(((uint64_t)decideg_per_s << 32) / MOTION_TICK_HZ);
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
        /* Stop: come to rest within one ramp, from the present speed. */
        timing = (struct profile_timing){0, 0, WHEEL_RAMP_MS};
        target = start + v0 * (WHEEL_RAMP_MS / 2);
    }
    profile_plan(&m->profile, start, v0, target, timing);
    begin_profile(m, end);
}

static void run_stop(struct motion *m, const struct motion_command *cmd)
{
    switch (cmd->method) {
    case STOP_HOLD:
        m->mode = MODE_RELEASED; /* hold where the servo is, not where it aimed */
        hold_here(m);
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
    set_power(m, 0);
    if (regs->user.power_on_lock) {
        hold_here(m);
    } else {
        release(m);
    }
}

/* ---- the control tick --------------------------------------------------- */

/* A move that ends released (wheel mode with 47 = 0) first holds its end
 * until the horn is there and nearly still, at most SETTLE_MAX_TICKS. */
enum {
    SETTLE_MAX_TICKS = 200,
    SETTLE_DECIDEG = 10,   /* 1 degree */
    SETTLE_SPEED_Q8 = 64,  /* 0.25 decideg per tick, 25 deg/s */
};

static bool settled(const struct motion *m)
{
    int64_t gap = m->setpoint - m->measured;
    int32_t speed = m->measured_velocity_q8;
    return gap < SETTLE_DECIDEG * DECIDEG_Q32 && gap > -SETTLE_DECIDEG * DECIDEG_Q32 &&
           speed < SETTLE_SPEED_Q8 && speed > -SETTLE_SPEED_Q8;
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
        m->tick = 0;
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
    }
}

/* One encoder count per tick is 88 deg/s, so the per-tick difference is
 * low-passed (time constant 2^VELOCITY_FILTER_SHIFT ticks; state in Q12 so
 * it decays to zero) before the controller and the current limit use it. */
enum { VELOCITY_FILTER_SHIFT = 3 };

static void measure(struct motion *m)
{
    int64_t before = m->measured;
    encoder_update(&m->encoder, m->hal->encoder_read(m->hal->ctx));
    m->measured = counts_to_q32(m->encoder.counts - m->origin_counts);
    int32_t raw_q12 = (int32_t)((m->measured - before) >> 20);
    m->velocity_filter_q12 += (raw_q12 - m->velocity_filter_q12) >> VELOCITY_FILTER_SHIFT;
    m->measured_velocity_q8 = (m->velocity_filter_q12 + 8) >> 4; /* nearest */
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

void motion_tick(struct motion *m)
{
    measure(m);
    if (++m->supply_check == SUPPLY_CHECK_TICKS) {
        m->supply_check = 0;
        follow_supply(m);
    }
    switch (m->mode) {
    case MODE_DAMPING:
        m->hal->motor_drive(m->hal->ctx, controller_damping(m->measured_velocity_q8, m->duty_limit));
        return;
    case MODE_POSITION:
        break;
    default:
        return; /* released: the output stays off */
    }
    if (m->endless) {
        rebase_endless(m);
    }
    if (m->tick < UINT32_MAX) {
        m->tick++;
    }
    int64_t last_step = m->setpoint - m->last_setpoint;
    m->last_setpoint = m->setpoint;
    m->setpoint = profile_position(&m->profile, m->tick);
    int64_t step = m->setpoint - m->last_setpoint;
    const struct controller_input in = {
        .error_q8 = (int32_t)((m->setpoint - m->measured) >> 24),
        .velocity_q8 = (int32_t)(step >> 24),
        .acceleration_q16 = (int32_t)((step - last_step) >> 16),
        .measured_velocity_q8 = m->measured_velocity_q8,
        .duty_limit = m->duty_limit,
    };
    m->hal->motor_drive(m->hal->ctx, controller_position(&m->controller, &in));
    bool done = m->endless ? m->tick >= m->profile.accel_ticks : profile_done(&m->profile, m->tick);
    if (done && m->end == END_RELEASE && !settled(m) &&
        m->tick - m->profile.total_ticks < SETTLE_MAX_TICKS) {
        done = false; /* released now, the horn would coast on past the end */
    }
    if (m->running && done) {
        finish(m);
    }
}
