/* What keeps the servo safe when its host is not (docs/safety.md): the bus
 * watchdog, the winding's estimate and its derating, what holds the output
 * back, and what goes into the fault history (servo_safety.h). */
#include "app/servo_safety.h"

#include <stddef.h>
#include <string.h>

#include "sensors/ntc.h"

/* What a protection or the watchdog holds the output back by (enum
 * limiter), from the status bits: on their changes only (the motion's
 * own limit is added as item 67 or ReadMotion is read). */
static void note_held_by(const struct servo_safety *sf, struct registers *regs, uint8_t bits)
{
    regs->held_by = sf->watchdog.fired || regs->firmware.safe_mode != 0u        ? LIMITER_WATCHDOG
                    : (bits & (STATUS_LOW_VOLTAGE | STATUS_HIGH_VOLTAGE)) != 0u ? LIMITER_SUPPLY
                    : (bits & STATUS_OVER_TEMPERATURE) != 0u                    ? LIMITER_HEAT
                    : (bits & STATUS_STALL) != 0u && regs->user.stall_release   ? LIMITER_STALL
                                                                                : LIMITER_NONE;
}

/* A step of the winding's model (every WINDING_SAMPLES rounds): its
 * estimate to item 68, its derating to the output. */
__attribute__((noinline)) static void heat_step(struct servo_safety *sf, struct registers *regs)
{
    const struct user_config *cfg = &regs->user;
    winding_step(&sf->winding, sf->hal->calibration, regs->status.temperature_adc, cfg->temperature_limit_adc);
    regs->firmware.winding_decic = sf->winding.winding_decic;
    uint16_t cap = regs->firmware.derating_on ? winding_power_cap(&sf->winding, cfg->power_limit_mw) : 0u;
    if (cap != sf->heat_cap_mw) {
        sf->heat_cap_mw = cap;
        protection_note_act_change(sf->protection);
    }
}

/* The tighter of the stall's cap and the derating's, and whose it is. */
void safety_guard(const struct servo_safety *sf, struct registers *regs, struct motion *m,
                  const struct protection *p, uint8_t bits)
{
    uint16_t stall_cap = p->act.power_cap_mw;
    uint16_t heat_cap = sf->heat_cap_mw;
    bool heat_binds = heat_cap != 0u && (stall_cap == 0u || heat_cap < stall_cap);
    motion_guard(m, protection_inhibits(p->threshold_bits) || regs->firmware.safe_mode != 0u,
                 protection_derates(p->threshold_bits), heat_binds ? heat_cap : stall_cap,
                 heat_binds ? LIMITER_HEAT : LIMITER_STALL);
    note_held_by(sf, regs, bits);
}

/* Status bits 2-7: each one that sets is a fault for the history. */
#define FAULT_STATUS_BITS                                                                        \
    (STATUS_STALL | STATUS_HIGH_VOLTAGE | STATUS_LOW_VOLTAGE | STATUS_OVER_CURRENT |            \
     STATUS_OVER_POWER | STATUS_OVER_TEMPERATURE)

/* One fault into the history's queue, with the readings of this moment. */
static void log_fault(const struct servo_safety *sf, const struct registers *regs,
                      const struct motion *m, uint8_t what)
{
    const struct safety_log log = sf->log;
    const struct status_area *st = &regs->status;
    struct motion_angle angle;
    motion_read_angle(m, &angle);
    const struct fault_entry e = {
        .op_seconds = save_policy_op_seconds(log.clock),
        .angle_decideg = angle.multi_turn_decideg,
        .voltage_mv = st->voltage_mv,
        .current_ma = st->current_ma,
        .power_mw = st->power_mw,
        .winding_decic = regs->firmware.winding_decic,
        .case_decic = ntc_decicelsius(st->temperature_adc),
        .what = what,
    };
    (void)fault_log_add(log.faults, &e); /* one not logged is counted */
}

__attribute__((noinline)) static void note_faults(struct servo_safety *sf, const struct registers *regs,
                                                  const struct motion *m, uint8_t trips)
{
    uint8_t rose = (uint8_t)(trips & ~sf->fault_bits_seen);
    sf->fault_bits_seen = trips;
    for (uint8_t bit = 2; bit < 8u; bit++) {
        if (rose & (1u << bit)) {
            log_fault(sf, regs, m, bit);
        }
    }
}

/* The bus watchdog, where it is on (item 64): item 65's stop, once. */
__attribute__((noinline)) static void watch_bus(struct servo_safety *sf, struct registers *regs,
                                                struct motion *m, uint32_t heard)
{
    const struct firmware_area *fw = &regs->firmware;
    if (bus_watchdog_tick(&sf->watchdog, fw->watchdog_ms, !motion_is_released(m), heard,
                          m->commands)) {
        static const uint8_t method[] = {
            [WATCHDOG_HOLD] = STOP_HOLD, [WATCHDOG_DAMP] = STOP_DAMPING, [WATCHDOG_RELEASE] = STOP_RELEASE};
        motion_stop(m, method[fw->watchdog_action < 3u ? fw->watchdog_action : WATCHDOG_RELEASE]);
        note_held_by(sf, regs, regs->status.status);
        log_fault(sf, regs, m, FAULT_WATCHDOG);
    }
}

__attribute__((noinline)) void safety_after_frame(struct servo_safety *sf, struct registers *regs,
                                                  uint32_t commands)
{
    if (bus_watchdog_command(&sf->watchdog, commands)) {
        note_held_by(sf, regs, regs->status.status);
    }
}

/* The oscillation monitor (item 72; inline: it runs every tick, and is
 * smaller so on the M0): a horn that runs away from its
 * setpoint is released and the fault logged. It sets the watchdog's latch:
 * item 67 says 7 (a monitor acted) until the next motion command. */
static void watch_swing(struct servo_safety *sf, struct registers *regs, struct motion *m)
{
    if (motion_runs_away(m, regs->firmware.oscillation_ms)) {
        bus_watchdog_latch(&sf->watchdog, m->commands);
        motion_stop(m, STOP_RELEASE);
        note_held_by(sf, regs, regs->status.status);
        log_fault(sf, regs, m, FAULT_OSCILLATION);
    }
}

/* In the pass of each control tick, after it: the bus watchdog (it acts
 * within a tick of its time) and, every SENSE_ROUND_TICKS, a sample of
 * the winding's heat. Neither is part of the control law, so neither
 * lengthens the control tick. */
void safety_tend(struct servo_safety *sf, struct registers *regs, struct motion *m, uint32_t heard)
{
    const struct hal_port *hal = sf->hal;
    if (hal->stack_watch != NULL) {
        hal->stack_watch();
    }
    if (regs->firmware.watchdog_ms != 0u) {
        watch_bus(sf, regs, m, heard);
    }
    if (regs->firmware.oscillation_ms != 0u) {
        watch_swing(sf, regs, m);
    }
    uint8_t trips = (uint8_t)(regs->status.status & FAULT_STATUS_BITS);
    if (trips != sf->fault_bits_seen) {
        note_faults(sf, regs, m, trips);
    }
    if (++sf->heat_ticks == SENSE_ROUND_TICKS) {
        sf->heat_ticks = 0;
        if (hal->stack_unused != NULL) {
            regs->firmware.stack_unused = *hal->stack_unused;
        }
        if (winding_sample(&sf->winding, regs->status.current_ma)) {
            heat_step(sf, regs);
        }
    }
}

_Static_assert((int)HAL_RESET_FIRMWARE_FAULT == (int)FAULT_FIRMWARE &&
                   (int)HAL_RESET_WATCHDOG == (int)FAULT_RESET_WATCHDOG &&
                   (int)HAL_RESET_SOFTWARE == (int)FAULT_RESET_SOFTWARE &&
                   (int)HAL_RESET_BROWN_OUT == (int)FAULT_BROWN_OUT && (int)HAL_RESET_PIN == (int)FAULT_RESET_PIN &&
                   (int)HAL_RESET_LOW_POWER == (int)FAULT_RESET_LOW_POWER,
               "a reset's kind is its fault's");
/* The reset's record from pc on is a fault's code (hal_reset.h). */
#define CODE_AT(field) (offsetof(struct hal_reset, field) - offsetof(struct hal_reset, pc))
_Static_assert(CODE_AT(lr) == offsetof(struct fault_code, lr) &&
                   CODE_AT(sp_offset) == offsetof(struct fault_code, sp_offset) &&
                   CODE_AT(mm_bus_status) == offsetof(struct fault_code, mm_bus_status) &&
                   CODE_AT(exception) == offsetof(struct fault_code, exception) &&
                   CODE_AT(usage_status) == offsetof(struct fault_code, usage_status) &&
                   CODE_AT(usage_status) + 1u == sizeof(struct fault_code),
               "a reset's record is laid out as a fault's code");

/* The reset the board read at start-up: its counts (item 73), its fault
 * history entry, and safe mode after SAFE_MODE_RESETS in a row, which
 * logs no more of them (a boot loop would wear the log's pages). */
static void take_reset(struct registers *regs, struct protection *p, struct safety_log log,
                       const struct hal_reset *r)
{
    regs->firmware.reset_counts = (uint32_t)r->counts[0] | (uint32_t)r->counts[1] << 8 |
                                  (uint32_t)r->counts[2] << 16 | (uint32_t)r->counts[3] << 24;
    if (r->kind >= FAULT_FIRMWARE && r->in_row <= SAFE_MODE_RESETS) {
        struct fault_entry e; /* field by field: an initialiser is a memset call on the M0 */
        e.number = 0;
        e.op_seconds = save_policy_op_seconds(log.clock);
        /* A firmware fault's record; zeros with another kind. */
        memcpy(&e.code, &r->pc, sizeof e.code);
        e.what = r->kind;
        (void)fault_log_add(log.faults, &e);
    }
    if (r->in_row >= SAFE_MODE_RESETS) {
        regs->firmware.safe_mode = 1;
        protection_note_act_change(p); /* the guard takes it at the first tick */
    }
}

void safety_init(struct servo_safety *sf, struct registers *regs, struct protection *p,
                 struct safety_log log, const struct hal_port *hal)
{
    sf->hal = hal;
    sf->protection = p;
    sf->log = log;
    winding_init(&sf->winding);
    if (hal->reset != NULL) {
        take_reset(regs, p, log, hal->reset);
    }
}
