/* The analogue sensors as the core needs them: raw 12-bit ADC readings and
 * the board's calibration, which a port provides. */
#ifndef HAL_HAL_SENSORS_H
#define HAL_HAL_SENSORS_H

#include <stdint.h>

struct sensor_raw {
    uint16_t supply;   /* supply divider */
    uint16_t current;  /* shunt amplifier */
    uint16_t ntc;      /* NTC divider (appendix 5.1: 10 k to the rail, NTC to ground) */
};

/* Everything a board's analogue front end needs to turn counts into units.
 * The NTC divider is the protocol's own, so its reading is reported as is. */
struct sensor_calibration {
    uint32_t supply_uv_per_count;  /* uV at the supply per count (divider, reference) */
    uint32_t current_ua_per_count; /* uA in the shunt per count (shunt, gain, reference) */
    uint16_t current_zero_counts;  /* reading at zero current (amplifier offset) */
};

#endif
