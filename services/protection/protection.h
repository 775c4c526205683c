/* Protection monitors: supply voltage (39/40), current (43), power (42),
 * temperature (41) and stall (37/38). Fed once per control tick, they set
 * status bits 2-7 while a condition lasts and say what the output must do
 * (docs/protocol.md, "Protection"):
 *   voltage out of range, over-temperature: release, refuse motion
 *   over-current, over-power: halve the current the output may draw
 *   stall: limit the power to 38 (37 = 0), or release once (37 = 1)
 *
 * The current and the stall are judged every tick; the supply, the power
 * and the temperature when their reading is refreshed (scaling.h's round,
 * every SENSE_ROUND_TICKS). A condition trips once it has lasted
 * PROTECT_TRIP_TICKS in samples in a row beyond its limit and clears after
 * PROTECT_CLEAR_TICKS back inside its hysteresis band, so no single sample
 * trips or clears it. */
#ifndef PROTECTION_PROTECTION_H
#define PROTECTION_PROTECTION_H

#include <stdbool.h>
#include <stdint.h>

#include "registers/registers.h"
#include "sensors/scaling.h"

#define PROTECT_TRIP_TICKS 10u    /* 10 ms */
#define PROTECT_CLEAR_TICKS 100u  /* 100 ms */
/* Hysteresis bands: how far back inside its limit a reading must come. */
#define VOLTAGE_HYSTERESIS_MV 200u
#define CURRENT_HYSTERESIS_MA 100u
#define POWER_HYSTERESIS_MW 500u
#define TEMPERATURE_HYSTERESIS_DECIC 50 /* 5.0 degC, through the NTC table */
/* Stall: the output held at its limit for STALL_TICKS while the horn turns
 * slower than STALL_SPEED_Q8 (decideg per tick, Q8: 13 = 5 deg/s) or is
 * pushed the other way by a load stronger than the motor. */
#define STALL_SPEED_Q8 13
#define STALL_TICKS 1000u         /* 1 s */

/* What the output must do now, besides what the status bits say
 * (protection_inhibits, protection_derates): struct protection's act, kept
 * up to date by the monitors. */
struct protection_action {
    bool release_now;      /* release once (stall in release mode) */
    uint16_t power_cap_mw; /* 0: none; else the most power any move may use */
};

/* Release and refuse motion while set: the supply out of range, heat. */
static inline bool protection_inhibits(uint8_t bits)
{
    return (bits & (STATUS_LOW_VOLTAGE | STATUS_HIGH_VOLTAGE | STATUS_OVER_TEMPERATURE)) != 0u;
}

/* Halve the current the output may draw: over-current, over-power. */
static inline bool protection_derates(uint8_t bits)
{
    return (bits & (STATUS_OVER_CURRENT | STATUS_OVER_POWER)) != 0u;
}

/* The threshold monitors: every tick first, then in the order of their
 * readings' slots. */
enum monitor_id {
    MON_CURRENT,
    MON_LOW_VOLTAGE,
    MON_HIGH_VOLTAGE,
    MON_POWER,
    MON_TEMPERATURE,
    MON_COUNT,
};

struct monitor {
    uint16_t count;  /* samples in a row towards the other state */
    uint8_t active;
    uint8_t level_known;  /* clear_level is worked out for limit */
    uint16_t limit;
    uint16_t clear_level; /* worked out when the limit changes (the NTC
                           * conversion searches a table) */
};

/* The fields every tick touches first: within the Cortex-M0's short
 * offsets (a byte's load reaches 31). */
struct protection {
    uint8_t threshold_bits;     /* of the threshold monitors set now */
    uint8_t act_changes;        /* counts changes of the threshold bits and
                                 * the power cap; wraps: compare for inequality */
    uint8_t stall_busy;         /* a stall counted, set or latched */
    uint8_t stall_latched;      /* release mode: held until the next command */
    uint8_t stall_shown;        /* status bit 2 as last returned */
    struct protection_action act;
    uint32_t commands_at_stall;
    struct monitor stall;
    struct monitor mon[MON_COUNT];
};

void protection_init(struct protection *p);
/* Another part changed what the output may do (the derating's cap, safe
 * mode): the output's guard is worked out again at the next tick. */
static inline void protection_note_act_change(struct protection *p)
{
    p->act_changes++;
}
/* The threshold monitors, once a tick: the current, and those of the slow
 * reading refreshed this tick (slot). Returns status bits 3-7. */
uint8_t protection_update(struct protection *p, const struct user_config *cfg,
                          const struct sensor_readings *readings, enum sense_slot slot);

/* The stall monitor's tick where there is something to watch; returns
 * status bit 2. output_at_limit: the controller is saturated, driving this
 * way (+1/-1), 0: it is not; speed_q8 measured, decideg per tick Q8;
 * motion_commands the count of motion commands so far. */
uint8_t protection_watch_stall(struct protection *p, const struct user_config *cfg,
                               int8_t output_at_limit, int32_t speed_q8, uint32_t motion_commands);

/* The stall monitor, once a tick: most ticks (not at the limit, nothing
 * counted, set or latched) it has nothing to do, which is told without a
 * call where speed comes first (SERVO_SIZE_FIRST: the Cortex-M0 calls). */
static inline uint8_t protection_stall(struct protection *p, const struct user_config *cfg,
                                       int8_t output_at_limit, int32_t speed_q8,
                                       uint32_t motion_commands)
{
#ifndef SERVO_SIZE_FIRST
    if (output_at_limit == 0 && !p->stall_busy) {
        return 0;
    }
#endif
    return protection_watch_stall(p, cfg, output_at_limit, speed_q8, motion_commands);
}

#endif
