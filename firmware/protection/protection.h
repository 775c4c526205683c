/* Protection monitors: supply voltage (39/40), current (43), power (42),
 * temperature (41) and stall (37/38). Fed once per control tick, they set
 * status bits 2-7 while a condition lasts and say what the output must do
 * (behaviour.md, "Protection"):
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
#include "scaling.h"

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

struct protection_input {
    const struct sensor_readings *readings; /* filtered */
    enum sense_slot slot;             /* the slow reading refreshed this tick */
    int8_t output_at_limit;           /* the controller is saturated, driving
                                       * this way (+1/-1); 0: it is not */
    int32_t speed_q8;                 /* measured, decideg per tick Q8 */
    uint32_t motion_commands;         /* count of motion commands so far */
};

/* What the output must do now. */
struct protection_action {
    bool inhibit;          /* release and refuse motion while set */
    bool release_now;      /* release once (stall in release mode) */
    bool derate;           /* halve the current the output may draw */
    uint16_t power_cap_mw; /* 0: none; else the most power any move may use */
};

/* The threshold monitors every tick first, then in the order of their
 * readings' slots. */
enum monitor_id {
    MON_CURRENT,
    MON_LOW_VOLTAGE,
    MON_HIGH_VOLTAGE,
    MON_POWER,
    MON_TEMPERATURE,
    MON_STALL,
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

struct protection {
    struct monitor mon[MON_COUNT];
    uint8_t threshold_bits;     /* of the threshold monitors set now */
    uint8_t stall_latched;      /* release mode: held until the next command */
    uint32_t commands_at_stall;
};

void protection_init(struct protection *p);
/* One sample; returns status bits 2-7. */
uint8_t protection_update(struct protection *p, const struct user_config *cfg,
                          const struct protection_input *in, struct protection_action *act);

#endif
