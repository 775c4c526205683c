/* What keeps the servo safe when its host is not (docs/safety.md): the bus
 * watchdog, the winding's estimate and its derating, what holds the output
 * back, and the fault history, wired into the servo core. */
#include "app/servo_safety.h"

#include <stddef.h>
#include <string.h>

#include "sensors/ntc.h"

/* What a protection or the watchdog holds the output back by (enum
 * limiter), from the status bits: on their changes only (the motion's
 * own limit is added as item 67 or ReadMotion is read). */
static void note_held_by(struct servo *s, uint8_t bits)
{
    s->regs.held_by = s->watchdog.fired || s->regs.firmware.safe_mode != 0u      ? LIMITER_WATCHDOG
                      : (bits & (STATUS_LOW_VOLTAGE | STATUS_HIGH_VOLTAGE)) != 0u ? LIMITER_SUPPLY
                      : (bits & STATUS_OVER_TEMPERATURE) != 0u                    ? LIMITER_HEAT
                      : (bits & STATUS_STALL) != 0u && s->regs.user.stall_release ? LIMITER_STALL
                                                                                  : LIMITER_NONE;
}

/* A step of the winding's model (every WINDING_SAMPLES rounds): its
 * estimate to item 68, its derating to the output. */
__attribute__((noinline)) static void heat_step(struct servo *s)
{
    const struct user_config *cfg = &s->regs.user;
    winding_step(&s->winding, s->hal->calibration, s->regs.status.temperature_adc,
                 cfg->temperature_limit_adc);
    s->regs.firmware.winding_decic = s->winding.winding_decic;
    uint16_t cap = s->regs.firmware.derating_on ? winding_power_cap(&s->winding, cfg->power_limit_mw) : 0u;
    if (cap != s->heat_cap_mw) {
        s->heat_cap_mw = cap;
        s->protection.act_changes++;
    }
}

/* The tighter of the stall's cap and the derating's, and whose it is. */
void safety_guard(struct servo *s, uint8_t bits)
{
    const struct protection *p = &s->protection;
    uint16_t stall_cap = p->act.power_cap_mw;
    uint16_t heat_cap = s->heat_cap_mw;
    bool heat_binds = heat_cap != 0u && (stall_cap == 0u || heat_cap < stall_cap);
    motion_guard(&s->motion, protection_inhibits(p->threshold_bits) || s->regs.firmware.safe_mode != 0u,
                 protection_derates(p->threshold_bits), heat_binds ? heat_cap : stall_cap,
                 heat_binds ? LIMITER_HEAT : LIMITER_STALL);
    note_held_by(s, bits);
}

/* Status bits 2-7: each one that sets is a fault for the history. */
#define FAULT_STATUS_BITS                                                                        \
    (STATUS_STALL | STATUS_HIGH_VOLTAGE | STATUS_LOW_VOLTAGE | STATUS_OVER_CURRENT |            \
     STATUS_OVER_POWER | STATUS_OVER_TEMPERATURE)

/* One fault into the history's queue, with the readings of this moment. */
static void log_fault(struct servo *s, uint8_t what)
{
    const struct status_area *st = &s->regs.status;
    struct motion_angle angle;
    motion_read_angle(&s->motion, &angle);
    const struct fault_entry e = {
        .op_seconds = save_policy_op_seconds(&s->saver),
        .angle_decideg = angle.multi_turn_decideg,
        .voltage_mv = st->voltage_mv,
        .current_ma = st->current_ma,
        .power_mw = st->power_mw,
        .winding_decic = s->regs.firmware.winding_decic,
        .case_decic = ntc_decicelsius(st->temperature_adc),
        .what = what,
    };
    (void)fault_log_add(&s->faults, &e); /* one not logged is counted */
}

__attribute__((noinline)) static void note_faults(struct servo *s, uint8_t trips)
{
    uint8_t rose = (uint8_t)(trips & ~s->fault_bits_seen);
    s->fault_bits_seen = trips;
    for (uint8_t bit = 2; bit < 8u; bit++) {
        if (rose & (1u << bit)) {
            log_fault(s, bit);
        }
    }
}

/* Not through log_fault: the readings would take the M0's answer past
 * its 30 us (target benchmark, answer_clear_faults). */
static bool clear_faults(void *ctx)
{
    struct servo *s = ctx;
    struct fault_entry marker; /* field by field: an initialiser is a memset call on the M0 */
    marker.number = 0;
    marker.op_seconds = save_policy_op_seconds(&s->saver);
    marker.angle_decideg = 0;
    marker.voltage_mv = marker.current_ma = marker.power_mw = 0;
    marker.winding_decic = marker.case_decic = 0;
    marker.what = FAULT_CLEARED;
    return fault_log_add(&s->faults, &marker);
}

/* The bus watchdog, where it is on (item 64): item 65's stop, once. */
__attribute__((noinline)) static void watch_bus(struct servo *s)
{
    const struct firmware_area *fw = &s->regs.firmware;
    if (bus_watchdog_tick(&s->watchdog, fw->watchdog_ms, !motion_is_released(&s->motion),
                          s->dispatcher.heard, s->motion.commands)) {
        static const uint8_t method[] = {
            [WATCHDOG_HOLD] = STOP_HOLD, [WATCHDOG_DAMP] = STOP_DAMPING, [WATCHDOG_RELEASE] = STOP_RELEASE};
        motion_stop(&s->motion, method[fw->watchdog_action < 3u ? fw->watchdog_action : WATCHDOG_RELEASE]);
        note_held_by(s, s->regs.status.status);
        log_fault(s, FAULT_WATCHDOG);
    }
}

__attribute__((noinline)) void safety_after_frame(struct servo *s)
{
    if (s->motion.commands != s->watchdog.commands_at_fire) {
        s->watchdog.fired = 0;
        note_held_by(s, s->regs.status.status);
    }
}

/* The oscillation monitor (item 72; inline: it runs every tick, and is
 * smaller so on the M0): a horn that runs away from its
 * setpoint is released and the fault logged. It sets the watchdog's latch:
 * item 67 says 7 (a monitor acted) until the next motion command. */
static void watch_swing(struct servo *s)
{
    if (motion_runs_away(&s->motion, s->regs.firmware.oscillation_ms)) {
        s->watchdog.fired = 1;
        s->watchdog.commands_at_fire = s->motion.commands;
        motion_stop(&s->motion, STOP_RELEASE);
        note_held_by(s, s->regs.status.status);
        log_fault(s, FAULT_OSCILLATION);
    }
}

/* In the pass of each control tick, after it: the bus watchdog (it acts
 * within a tick of its time) and, every SENSE_ROUND_TICKS, a sample of
 * the winding's heat. Neither is part of the control law, so neither
 * lengthens the control tick. */
void safety_tend(struct servo *s)
{
    if (s->hal->stack_watch != NULL) {
        s->hal->stack_watch();
    }
    if (s->regs.firmware.watchdog_ms != 0u) {
        watch_bus(s);
    }
    if (s->regs.firmware.oscillation_ms != 0u) {
        watch_swing(s);
    }
    uint8_t trips = (uint8_t)(s->regs.status.status & FAULT_STATUS_BITS);
    if (trips != s->fault_bits_seen) {
        note_faults(s, trips);
    }
    if (++s->heat_ticks == SENSE_ROUND_TICKS) {
        s->heat_ticks = 0;
        if (s->hal->stack_unused != NULL) {
            s->regs.firmware.stack_unused = *s->hal->stack_unused;
        }
        if (winding_sample(&s->winding, s->regs.status.current_ma)) {
            heat_step(s);
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
static void take_reset(struct servo *s, const struct hal_reset *r)
{
    s->regs.firmware.reset_counts = (uint32_t)r->counts[0] | (uint32_t)r->counts[1] << 8 |
                                    (uint32_t)r->counts[2] << 16 | (uint32_t)r->counts[3] << 24;
    if (r->kind >= FAULT_FIRMWARE && r->in_row <= SAFE_MODE_RESETS) {
        struct fault_entry e; /* field by field: an initialiser is a memset call on the M0 */
        e.number = 0;
        e.op_seconds = save_policy_op_seconds(&s->saver);
        /* A firmware fault's record; zeros with another kind. */
        memcpy(&e.code, &r->pc, sizeof e.code);
        e.what = r->kind;
        (void)fault_log_add(&s->faults, &e);
    }
    if (r->in_row >= SAFE_MODE_RESETS) {
        s->regs.firmware.safe_mode = 1;
        s->protection.act_changes++; /* the guard takes it at the first tick */
    }
}

void safety_init(struct servo *s)
{
    winding_init(&s->winding);
    /* The operating time goes on from the latest record in either store
     * (the config store's saves, the faults' records): no write of its own. */
    uint32_t seen = fault_log_load(&s->faults, s->hal->fault_flash);
    if (seen > s->saver.op_seconds_at_boot) {
        s->saver.op_seconds_at_boot = seen;
    }
    if (fault_log_spare_dirty(&s->faults) && !fault_log_erase_spare(&s->faults)) {
        s->regs.status.status |= STATUS_COMMAND_ERROR; /* nobody waits at power-up */
    }
    if (s->hal->reset != NULL) {
        take_reset(s, s->hal->reset);
    }
    _Static_assert(FAULT_ENTRY_BYTES == READ_FAULTS_ENTRY_BYTES, "a logged fault is its ReadFaults bytes");
    s->dispatcher.read_fault = fault_log_read;
    s->dispatcher.read_fault_ctx = &s->faults;
    s->dispatcher.clear_faults = clear_faults;
    s->dispatcher.faults_ctx = s;
}
