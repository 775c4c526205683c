/* Positions and the frames they are given in: measured_q8 is Q8 decideg
 * from the origin (SetOriginPoint, ResetMultiTurnAngle); protocol angles are
 * that minus the center offset (53). Moving the origin, and the readings. */
#include "motion/div64.h"
#include "motion/motion_internal.h"

static int32_t q8_to_decideg(int32_t q8)
{
    return (q8 + 128) >> 8; /* nearest */
}

void motion_move_origin(struct motion *m, int32_t counts)
{
    int32_t shift_q8 = counts_to_q8(counts);
    int64_t shift = q8_to_q32(shift_q8);
    m->origin_counts += counts;
    m->measured_q8 -= shift_q8;
    m->profile.start -= shift;
    m->profile.target -= shift;
    m->walk.at -= shift;
    /* The setpoint may be further from the horn than Q8 holds (a load has
     * turned the horn back thousands of turns): it is taken from the
     * walk again, one step back (on the tick a phase starts, along the new
     * phase: off by about half that tick's change of acceleration, 0.005
     * decideg for 1000 deg/s^2). */
    int32_t step = m->setpoint_q8 - m->last_setpoint_q8;
    motion_take_profile_q8(m, m->walk.at - ((m->walk.step_q40 - m->walk.change_q40 + m->walk.jerk_q40) >> 8));
    m->last_setpoint_q8 = m->setpoint_q8 - step;
    /* Whole turns of the origin come off the encoder's count too: the raw
     * reading's place in the turn, and the difference, stay as they were
     * (the tracker follows the count's changes, not the count). */
    _Static_assert((ENCODER_COUNTS & (ENCODER_COUNTS - 1)) == 0, "a mask floors to whole turns");
    int32_t within = m->origin_counts & (ENCODER_COUNTS - 1);
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

/* One unsigned comparison for the common case (within range). */
static int16_t saturate_i16(int32_t v)
{
    if ((uint32_t)(v + INT16_MAX) > 2u * INT16_MAX) {
        v = v < 0 ? -INT16_MAX : INT16_MAX;
    }
    return (int16_t)v;
}

/* The tracking error's centidegrees ((Q8 x 5) >> 7), saturated to
 * +-INT16_MAX: one clamp of the Q8 error to the range that maps within
 * (5 x 838860 >> 7 = 32767, 5 x -838835 >> 7 = -32767), so x 5 stays in
 * 32 bits (no 64-bit multiply on the M0) and no second saturation follows.
 * Inline: ReadMotion's answer has no time for a call on the M0. */
#define TRACKING_ERROR_MAX_Q8 838860
#define TRACKING_ERROR_MIN_Q8 (-838835)
_Static_assert((5 * TRACKING_ERROR_MAX_Q8) >> 7 == INT16_MAX && (5 * (TRACKING_ERROR_MAX_Q8 + 1)) >> 7 > INT16_MAX &&
                   (5 * TRACKING_ERROR_MIN_Q8) >> 7 == -INT16_MAX &&
                   (5 * (TRACKING_ERROR_MIN_Q8 - 1)) >> 7 < -INT16_MAX,
               "the clamp's ends map to the saturation's");

void motion_read_diagnostics(const struct motion *m, struct motion_diagnostics *out)
{
    bool controlled = m->mode == MODE_POSITION;
    int32_t offset = motion_center_offset_q8(m);
    int32_t setpoint = controlled ? m->setpoint_q8 : m->measured_q8;
    /* decideg per tick Q8 to decideg per s: x 1000 / 256 = x 125 / 32. */
    int32_t error_q8 = setpoint - m->measured_q8;
    /* Q32 to Q8 first, rounded after: the same decidegree (a shift's floor
     * taken twice is the floor of both), without 64-bit sums on the M0. */
    int32_t target = controlled ? (int32_t)(m->profile.target >> 24) : m->measured_q8;
    /* The flags and motion_limiter()'s value, each test made once. */
    uint32_t flags = motion_is_released(m) ? DIAG_RELEASED : 0u; /* open loop: driven */
    uint32_t limiter = LIMITER_NONE;
    if (controlled) {
        int8_t at_limit = m->controller.at_limit;
        flags = (profile_done(&m->profile, m->tick) ? DIAG_PROFILE_ENDED : 0u) |
                (m->clock_rate != CLOCK_REAL_TIME ? DIAG_CLOCK_SLOWED : 0u) |
                (m->braking ? DIAG_BRAKING : 0u) | (at_limit != 0 ? DIAG_AT_LIMIT : 0u);
        limiter = motion_own_limiter(m);
    }
    if (m->regs->held_by != 0u) {
        limiter = m->regs->held_by;
    }
    *out = (struct motion_diagnostics){
        .angle_decideg = q8_to_decideg(m->measured_q8 - offset),
        .setpoint_decideg = q8_to_decideg(setpoint - offset),
        .target_decideg = q8_to_decideg(target - offset),
        /* Shifts, not divisions: they round down (by less than the last
         * digit), where a division by a power of two rounds to zero at some
         * instructions' cost on the M0. */
        .velocity_decideg_s = saturate_i16((m->measured_velocity_q8 * 125) >> 5),
        .duty_q15 = m->damping_duty_q15, /* 0 outside damping and open loop */
        .tracking_error_centideg = (int16_t)((clamp_i32(error_q8, TRACKING_ERROR_MIN_Q8, TRACKING_ERROR_MAX_Q8) * 5) >> 7),
        .flags = (uint8_t)(flags | limiter << LIMITER_SHIFT),
    };
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
