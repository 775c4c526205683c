/* The output: the current the bridge may draw (the move's power, a stall's
 * cap, the current protection, a derate), as a duty for the supply now; the
 * braking a load leaves; letting it go. Divides only when what it depends on
 * has changed. */
#include <stddef.h>

#include "motion/gains.h"
#include "motion/motion_internal.h"

/* The braking duty of a current window limit when a load takes assisting
 * of it, less the quarter kept for the controller (motion_brake_duty). */
static int32_t brake_duty(int32_t limit, int32_t assisting)
{
    int32_t duty = limit - assisting;
    duty -= duty >> 2;
    return duty > 1 ? duty : 1;
}

uint16_t motion_supply_mv(const struct motion *m)
{
    uint16_t v = m->regs->status.voltage_mv;
    return v ? v : NOMINAL_SUPPLY_MV;
}

/* The current the output may draw: the move's power (0 or above 42 means
 * 42), capped by a stall, within the current protection (43), halved while
 * over-current or over-power lasts. Divides: on changes only. */
void motion_update_limits(struct motion *m)
{
    const struct user_config *cfg = &m->regs->user;
    uint16_t power = m->power_mw;
    if (power == 0u || power > cfg->power_limit_mw) {
        power = cfg->power_limit_mw;
    }
    if (m->power_cap_mw != 0u && power > m->power_cap_mw) {
        power = m->power_cap_mw;
    }
    /* Every command asks; the divisions run only when what they depend on
     * has changed (a write to 42 or 43, a derate, a new supply, the drive
     * train: motion_drive_train_changed). */
    struct drive_inputs now = {power, motion_supply_mv(m), cfg->current_limit_ma, m->derate};
    if (now.power_mw == m->drive_inputs.power_mw && now.supply_mv == m->drive_inputs.supply_mv &&
        now.current_limit_ma == m->drive_inputs.current_limit_ma && now.derate == m->drive_inputs.derate) {
        return;
    }
    m->drive_inputs = now;
    const struct user_config *dt = &m->regs->user; /* its drive area */
    int16_t by_power = duty_limit_for_power(power, now.supply_mv, dt->resistance_mohm);
    int16_t by_current = duty_limit_for_current(cfg->current_limit_ma, now.supply_mv, dt->resistance_mohm);
    int16_t limit = (int16_t)(by_power < by_current ? by_power : by_current);
    bool capped = m->power_cap_mw != 0u && power == m->power_cap_mw;
    m->drive_limiter = limit == INT16_MAX       ? LIMITER_SUPPLY
                       : by_power >= by_current ? LIMITER_CURRENT
                       : capped                 ? m->cap_limiter
                                                : LIMITER_POWER;
    m->drive.duty_limit = (int16_t)(m->derate ? limit / 2 : limit);
    drive_limits_for_supply(&m->drive, dt, now.supply_mv);
    motion_take_accel_duty(m, m->tick);
    /* The least of motion_brake_duty: a load taking all it may. */
    m->brake_floor_duty = brake_duty(m->drive.duty_limit, m->drive.duty_limit / 2);
}

void motion_take_over(struct motion *m)
{
    m->commands++;
    m->queue.count = 0;
    m->answer_packet = 0;
    m->power_mw = 0;
    motion_update_limits(m);
}

void motion_drive_train_changed(struct motion *m)
{
    m->drive_inputs.supply_mv = 0; /* never a supply motion_supply_mv gives */
    motion_update_limits(m);
}

/* ---- braking within what the motor can do --------------------------------
 * The deceleration the output can count on moving in direction dir: the
 * duty margin of the current limit, less what holding a load that pushes
 * the way the horn turns takes (the integral term carries it; counted up
 * to half the margin, since in motion it also holds transient errors: a
 * load of 0.8 of the stall torque at this power takes 0.8 x efficiency^2 =
 * 0.26, plant.c), and a quarter of that kept for the controller to correct
 * errors with. As a duty; duty / ka is decideg per tick^2. */
int32_t motion_brake_duty(const struct motion *m, int32_t dir)
{
    int32_t limit = m->drive.duty_limit;
    int32_t assisting = dir > 0 ? -m->controller.integral_q15 : m->controller.integral_q15;
    assisting = assisting < 0 ? 0 : assisting > limit / 2 ? limit / 2 : assisting;
    return brake_duty(limit, assisting);
}

void motion_coast(struct motion *m)
{
    m->mode = MODE_RELEASED;
    m->damping_duty_q15 = 0;
    m->running = 0;
    m->streaming = 0;
    m->controller.at_limit = 0;
    m->hal->motor.coast(m->hal->ctx);
}

/* ---- the oscillation monitor's detector (item 72, docs/safety.md) -------
 * Counts two each tick the horn moves away from its setpoint, more than
 * RUNAWAY_AMPLITUDE_Q8 off it and faster than RUNAWAY_CREEP_Q8, and back
 * one each tick it is within the amplitude; trips at twice the item's time.
 * A runaway trips in the item's time; a swing wider than about 1.4 x the
 * amplitude (14 deg) does too, later: its outward quarters outweigh half
 * its time within. Not counted: the output pushing
 * back at its limit below the speed where the limit's band (the back-EMF of
 * kv, +-duty_limit) turns the duty the way the horn runs: a load stronger
 * than the motor, the stall monitor's. Above that speed the servo's own
 * output drives the horn away (kv beyond the motor's: a runaway). */
bool motion_runs_away(struct motion *m, uint16_t limit_ms)
{
    /* Seen from the side the horn is on: off > 0, away > 0 moving off. */
    int32_t off = m->measured_q8 - m->setpoint_q8;
    int32_t away = m->measured_velocity_q8;
    int32_t pushing_back = m->controller.at_limit;
    if (off < 0) {
        off = -off;
        away = -away;
        pushing_back = -pushing_back;
    }
    uint32_t n = m->runaway_ticks;
    if (m->mode != MODE_POSITION) {
        n = 0;
    } else if (off <= RUNAWAY_AMPLITUDE_Q8) {
        n -= n != 0u;
    } else if (away > RUNAWAY_CREEP_Q8 &&
               (pushing_back >= 0 || (uint32_t)away * (uint32_t)(m->drive.kv >> 8) > (uint32_t)m->drive.duty_limit)) {
        n += 2u; /* speeds past 2^32 / 2^8 wrap: beyond any encoder's */
    }
    m->runaway_ticks = n;
    return n >= 2u * limit_ms;
}
