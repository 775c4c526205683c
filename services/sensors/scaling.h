/* Raw ADC counts to the status area's units (mV, mA, mW, NTC ADC value),
 * in integers, low-pass filtered at the rate each reading changes: the
 * current every control tick (a stall or a short moves it within one), the
 * supply, the power and the temperature one per tick in turn, each every
 * SENSE_ROUND_TICKS (docs/benchmark.md, "Monitors at the rate of their
 * physics"). */
#ifndef SENSORS_SCALING_H
#define SENSORS_SCALING_H

#include <stdint.h>

#include "hal/hal_sensors.h"

struct sensor_readings {
    uint16_t voltage_mv;
    uint16_t current_ma;
    uint16_t power_mw;
    uint16_t temperature_adc;
};

/* The slow readings' turns within a round; the rest of the round's ticks
 * refresh the current only. */
enum sense_slot {
    SENSE_VOLTAGE,
    SENSE_POWER, /* from the filtered supply and current */
    SENSE_TEMPERATURE,
    SENSE_ROUND_TICKS = 5, /* 5 ms: each slow reading at 200 Hz */
};

/* Low-pass state (Q4 of each reading) and the filtered readings. */
struct sensor_filter {
    uint32_t voltage_q4;
    uint32_t current_q4;
    uint32_t temperature_q4;
    struct sensor_readings out;
    uint16_t current_zero; /* the current amplifier's reading at no current (item 91) */
    uint8_t slot;   /* the turn of the next tick */
    uint8_t primed;
};

/* One tick's samples: the current, and the slow reading whose turn it is
 * (the first call primes them all, as they are). Returns the slot served. */
enum sense_slot sensors_update(struct sensor_filter *f, const struct sensor_calibration *cal,
                               const struct sensor_raw *raw);

#endif
