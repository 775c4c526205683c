/* Raw ADC counts to the status area's units (mV, mA, mW, NTC ADC value),
 * in integers, with a light low-pass so one noisy sample moves a reading
 * by at most an eighth of its jump. */
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

/* Low-pass state, Q4 of each reading. */
struct sensor_filter {
    uint32_t voltage_q4;
    uint32_t current_q4;
    uint32_t temperature_q4;
    uint8_t primed;
};

/* Voltage, current and the NTC reading; power is the filter's. */
void sensors_scale(const struct sensor_calibration *cal, const struct sensor_raw *raw,
                   struct sensor_readings *out);
/* Filters voltage, current and temperature (time constant 8 samples; the
 * first sample primes it) and derives power from the filtered values. */
void sensors_filter(struct sensor_filter *f, const struct sensor_readings *in,
                    struct sensor_readings *out);

#endif
