/* Motion commands and the motion state: clamps, profiles for each packet,
 * the queue and async buffer, origin and readings, what protection asks of
 * the output. The control tick that runs it all is control_tick.c. */
#include "motion/motion.h"

#include <stddef.h>

#include "motion/div64.h"
#include "motion/gains.h"
#include "motion_internal.h"

/* Limits of docs/protocol.md, "Moves". */
enum {
    SINGLE_TURN_LIMIT = 1800,
    MIN_RAMP_MS = 20,
    MAX_INTERVAL_MS = 4096000,
    MIN_VELOCITY = 10,     /* 0.1 deg/s */
    MAX_VELOCITY = 7500,
    MAX_WHEEL_SPEED = 750, /* deg/s, the angle modes' top speed */
    WHEEL_RAMP_MS = 20,
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
 * measured_q8: Q8 decideg from the origin (SetOriginPoint, ResetMultiTurn).
 * Protocol angles are that minus the center offset (53). */

static int32_t q8_to_decideg(int32_t q8)
{
    return (q8 + 128) >> 8; /* nearest */
}

/* The tick's copies of the profile (Q8, saturated): at tick (at_tick, Q32),
 * at tick + 1 (where the walk is), the target, and the setpoint between
 * them at the clock's fraction. */
static void take_profile_q8(struct motion *m, int64_t at_tick)
{
    m->profile_at_tick_q8 = q32_to_q8_sat(at_tick, TARGET_LIMIT_Q8);
    m->profile_at_next_tick_q8 = q32_to_q8_sat(m->walk.at, TARGET_LIMIT_Q8);
    m->target_q8 = q32_to_q8_sat(m->profile.target, TARGET_LIMIT_Q8);
    m->setpoint_q8 = m->profile_at_tick_q8 + (((m->profile_at_next_tick_q8 - m->profile_at_tick_q8) * m->tick_frac) >> 8);
}

void motion_move_origin(struct motion *m, int32_t counts)
{
    int32_t shift_q8 = counts_to_q8(counts);
    int64_t shift = q8_to_q32(shift_q8);
    m->origin_counts += counts;
    m->measured_q8 -= shift_q8;
    m->profile.start -= shift;
    m->profile.target -= shift;
    m->profile.cruise_start -= shift;
    m->walk.at -= shift;
    /* The setpoint may be further from the horn than Q8 holds (a load has
     * turned the horn back thousands of turns): it is taken from the
     * profile again, which holds it exactly. */
    int32_t step = m->setpoint_q8 - m->last_setpoint_q8;
    take_profile_q8(m, profile_position(&m->profile, m->tick));
    m->last_setpoint_q8 = m->setpoint_q8 - step;
    /* Whole turns of the origin come off the encoder's count too: the raw
     * reading's place in the turn, and the difference, stay as they were
     * (the tracker follows the count's changes, not the count). */
    int32_t within = m->origin_counts % ENCODER_COUNTS;
    within = within < 0 ? within + ENCODER_COUNTS : within;
    int32_t whole = m->origin_counts - within;
    m->origin_counts = within;
    m->encoder.counts -= whole;
}

/* The angle within its turn, [-180, 180) degrees. */
static int32_t wrap_single_turn(int32_t decideg, int32_t turns)
{
    int32_t r = decideg - turns * DECIDEG_PER_TURN;
    if (r >= DECIDEG_PER_TURN / 2) {
        r -= DECIDEG_PER_TURN;
    } else if (r < -DECIDEG_PER_TURN / 2) {
        r += DECIDEG_PER_TURN;
    }
    return r;
}

void motion_read_angle(const struct motion *m, struct motion_angle *out)
{
    int32_t angle = q8_to_decideg(m->measured_q8 - motion_center_offset_q8(m));
    out->multi_turn_decideg = angle;
    int32_t turns = decideg_whole_turns(angle);
    out->turns = (int16_t)turns;
    out->single_turn_decideg = (int16_t)wrap_single_turn(angle, turns);
}

static int16_t saturate_i16(int32_t v)
{
    return (int16_t)(v > INT16_MAX ? INT16_MAX : v < -INT16_MAX ? -INT16_MAX : v);
}

/* Errors this large (1638 deg) already saturate the answer's centidegrees;
 * clamped to it, x 10 stays in 32 bits (no 64-bit multiply on the M0). */
#define TRACKING_ERROR_SPAN_Q8 (INT32_C(1) << 22)

void motion_read_diagnostics(const struct motion *m, struct motion_diagnostics *out)
{
    bool controlled = m->mode == MODE_POSITION;
    int32_t offset = motion_center_offset_q8(m);
    int32_t setpoint = controlled ? m->setpoint_q8 : m->measured_q8;
    /* decideg per tick Q8 to decideg per s: x 1000 / 256 = x 125 / 32. */
    int32_t error_q8 = setpoint - m->measured_q8;
    int64_t target = controlled ? m->profile.target : q8_to_q32(m->measured_q8);
    *out = (struct motion_diagnostics){
        .angle_decideg = q8_to_decideg(m->measured_q8 - offset),
        .setpoint_decideg = q8_to_decideg(setpoint - offset),
        .target_decideg = (int32_t)((target - q8_to_q32(offset) + (DECIDEG_Q32 / 2)) >> 32),
        .velocity_decideg_s = saturate_i16(m->measured_velocity_q8 * 125 / 32),
        .tracking_error_centideg = saturate_i16(sat_q(error_q8, TRACKING_ERROR_SPAN_Q8) * 10 / 256),
        .flags = (uint8_t)((controlled && m->tick >= m->profile.total_ticks ? DIAG_PROFILE_ENDED : 0u) |
                           (controlled && m->clock_rate != CLOCK_REAL_TIME ? DIAG_CLOCK_SLOWED : 0u) |
                           (controlled && m->braking ? DIAG_BRAKING : 0u) |
                           (motion_output_at_limit(m) != 0 ? DIAG_AT_LIMIT : 0u) |
                           (controlled ? 0u : DIAG_RELEASED)),
    };
}

/* ---- the output --------------------------------------------------------- */

static void set_power(struct motion *m, uint16_t power_mw)
{
    m->power_mw = power_mw;
    motion_update_limits(m);
}

static void release(struct motion *m)
{
    m->mode = MODE_RELEASED;
    m->running = 0;
    m->controller.at_limit = 0;
    m->hal->motor.coast(m->hal->ctx);
}

/* Starts the profile's clock at its tick 0. */
void motion_clock_restart(struct motion *m)
{
    m->tick = 0;
    m->tick_frac = 0;
    m->clock_rate = CLOCK_REAL_TIME;
    m->lead_q8 = 0;
    m->braking = 0;
    profile_walk_start(&m->walk, &m->profile, 1);
    /* The feed-forward is the second difference of the last three
     * setpoints, and the setpoint moved at v0 until tick 0: 0 there, half
     * the first phase's at tick 1 (control_tick.c), the phase's from 2. */
    m->accel_duty = 0;
    motion_take_accel_duty(m, 2);
    take_profile_q8(m, m->profile.start);
}

/* The second difference of the walk's phase is change_q40; in Q16 decideg
 * per tick^2 that is >> 24, and ka turns it into a duty (64-bit: once a
 * phase). */
void motion_take_accel_duty(struct motion *m, uint32_t tick)
{
    int64_t duty = ((m->walk.change_q40 >> 24) * m->drive.ka) >> 16;
    m->accel_duty_next = (int32_t)(duty > ACCEL_DUTY_LIMIT ? ACCEL_DUTY_LIMIT
                                   : duty < -ACCEL_DUTY_LIMIT ? -ACCEL_DUTY_LIMIT : duty);
    m->accel_from = tick;
    if (m->tick >= tick) {
        m->accel_duty = m->accel_duty_next;
    }
}

/* Hold still where the setpoint is now (or where the servo is, if it was
 * released): a zero-length profile. */
static void hold_here(struct motion *m)
{
    int32_t here = m->mode == MODE_POSITION ? m->setpoint_q8 : m->measured_q8;
    profile_plan(&m->profile, q8_to_q32(here), 0, q8_to_q32(here), (struct profile_timing){0, 0, 0});
    m->profile.total_ticks = 0;
    motion_clock_restart(m);
    m->last_setpoint_q8 = m->setpoint_q8;
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
    int32_t gap = m->setpoint_q8 - m->measured_q8;
    int32_t speed = (m->setpoint_q8 - m->last_setpoint_q8) - m->measured_velocity_q8;
    return gap < FOLLOW_GAP_Q8 && gap > -FOLLOW_GAP_Q8 && speed < FOLLOW_SPEED_Q8 &&
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
        *start = q8_to_q32(m->measured_q8);
        *v0 = q8_to_q32(m->measured_velocity_q8);
    } else if (m->mode == MODE_POSITION) {
        *start = q8_to_q32(m->setpoint_q8);
        *v0 = q8_to_q32(m->setpoint_q8 - m->last_setpoint_q8);
    } else {
        *start = q8_to_q32(m->measured_q8);
        *v0 = 0;
    }
}

static void begin_profile(struct motion *m, uint8_t end)
{
    if (m->mode != MODE_POSITION) {
        controller_reset(&m->controller);
    }
    m->mode = MODE_POSITION;
    motion_clock_restart(m);
    m->last_setpoint_q8 = m->setpoint_q8 - q32_to_q8_sat(m->profile.v0, TARGET_LIMIT_Q8); /* moving at v0 */
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
    int32_t v = q32_to_q8_sat(v0, INT32_MAX);
    uint64_t speed = (uint64_t)(v < 0 ? -(int64_t)v : v);
    uint64_t per_tick = (uint64_t)motion_brake_duty(m, v) << 8; /* x ka: decideg Q8 per tick^2 */
    uint64_t n = div64_u(speed * (uint64_t)m->drive.ka + per_tick - 1u, per_tick);
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
        return (int64_t)angle * DECIDEG_Q32 + q8_to_q32(motion_center_offset_q8(m));
    }
    int32_t angle = clamp_i32(cmd->angle_decideg, -SINGLE_TURN_LIMIT, SINGLE_TURN_LIMIT);
    if (cfg->angle_limit_on) {
        angle = clamp_i32(angle, cfg->angle_min_decideg, cfg->angle_max_decideg);
    }
    /* A single-turn angle is within the turn the servo is in now. */
    struct motion_angle now;
    motion_read_angle(m, &now);
    int32_t turn_base = now.multi_turn_decideg - now.single_turn_decideg;
    return ((int64_t)turn_base + angle) * DECIDEG_Q32 + q8_to_q32(motion_center_offset_q8(m));
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
            plan_stop(m, q8_to_q32(m->setpoint_q8), q8_to_q32(m->setpoint_q8 - m->last_setpoint_q8), 0);
        } else {
            plan_stop(m, q8_to_q32(m->measured_q8), q8_to_q32(m->measured_velocity_q8), 0);
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

bool motion_is_idle(const struct motion *m)
{
    return m->mode == MODE_RELEASED && !motion_is_moving(m) && m->queue.count == 0u &&
           m->async.count == 0u;
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
    motion_move_origin(m, rel - within);
    return true;
}

bool motion_set_origin(struct motion *m)
{
    if (!motion_is_released(m)) {
        return false;
    }
    motion_move_origin(m, m->encoder.counts - m->origin_counts);
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

void motion_finish(struct motion *m)
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
    encoder_start(&m->encoder, hal->motor.read_encoder(hal->ctx));
    m->origin_counts = 0;
    m->measured_q8 = counts_to_q8(m->encoder.counts);
    set_power(m, 0);
    if (regs->user.power_on_lock) {
        hold_here(m);
    } else {
        release(m);
    }
}

/* ---- what the protection monitors ask of the output --------------------- */

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
        motion_update_limits(m);
    }
}

void motion_release(struct motion *m)
{
    m->queue.count = 0;
    m->answer_packet = 0;
    release(m);
}
