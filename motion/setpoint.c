/* The setpoint the tick follows: the profile's clock at its start, the
 * tick's Q8 copies of the profile, and the acceleration feed-forward of the
 * profile's phase. */
#include "motion/motion_internal.h"

#ifdef SERVO_SIZE_FIRST
__attribute__((noinline)) int32_t q32_to_q8_sat(int64_t v)
{
    return q32_to_q8_sat_inline(v);
}
#endif

void motion_take_profile_q8(struct motion *m, int64_t at_tick)
{
    m->profile_at_tick_q8 = q32_to_q8_sat(at_tick);
    m->profile_at_next_tick_q8 = q32_to_q8_sat(m->walk.at);
    m->target_q8 = q32_to_q8_sat(m->profile.target);
    m->setpoint_q8 = m->profile_at_tick_q8 + (((m->profile_at_next_tick_q8 - m->profile_at_tick_q8) * m->tick_frac) >> 8);
}

void motion_clock_restart(struct motion *m)
{
    m->tick = 0;
    m->tick_frac = 0;
    m->clock_rate = CLOCK_REAL_TIME;
    m->lead_q8 = 0;
    m->braking = 0;
    profile_walk_begin(&m->walk, &m->profile);
    /* The feed-forward is the second difference of the last three
     * setpoints, and the setpoint moved at v0 until tick 0: 0 there, half
     * the first phase's at tick 1 (control_tick.c), the phase's from 2. */
    m->accel_duty = 0;
    motion_take_accel_duty(m, 2);
    motion_take_profile_q8(m, profile_origin(&m->profile));
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
