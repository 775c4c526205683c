/* The motion layer's start (the power-on state, 46) and what the
 * protection monitors ask of the output. The layer's parts: setpoint.c, stream.c,
 * position.c, drive.c, planning.c, command_queue.c and control_tick.c. */
#include "motion/motion.h"

#include "motion/motion_internal.h"

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
        m->damping_duty_q15 = 0;
    }
    m->mode = MODE_POSITION;
    m->end = END_HOLD;
}

void motion_init(struct motion *m, const struct registers *regs, const struct hal_port *hal)
{
    *m = (struct motion){.regs = regs, .hal = hal, .soft_start_pending = 1,
                        .stream_period_q4 = STREAM_DEFAULT_PERIOD_MS << 4};
    encoder_start(&m->encoder, hal->motor.read_encoder(hal->ctx));
    m->measured_q8 = counts_to_q8(m->encoder.counts);
    /* Item 90 is the horn's zero. Powered up, the horn is in the turn in
     * which it reads -180..180 deg, as ReadAngle reads it, after the center
     * offset (53; decideg to counts: x 4096 / 3600, as 1165 / 2^10, within
     * a count): the zero moves by the whole turns that put the count within
     * half a turn of zero + offset (a mask floors; ENCODER_COUNTS is a power
     * of two). */
    int32_t zero = regs->user.encoder_zero;
    int32_t offset_counts = (regs->user.center_offset_decideg * 1165) >> 10;
    zero += (m->encoder.counts - zero - offset_counts + ENCODER_COUNTS / 2) & -ENCODER_COUNTS;
    motion_move_origin(m, zero);
    motion_update_limits(m);
    if (regs->user.power_on_lock) {
        hold_here(m);
    } else {
        motion_coast(m);
    }
}

/* ---- what the protection monitors ask of the output --------------------- */

void motion_guard(struct motion *m, bool inhibit, bool derate, uint16_t power_cap_mw,
                  uint8_t cap_limiter)
{
    m->cap_limiter = cap_limiter;
    if (inhibit && !m->inhibit) {
        motion_release(m);
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
    motion_coast(m);
}
