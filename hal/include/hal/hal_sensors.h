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
 * The NTC divider is the protocol's own, so its reading is reported as is.
 * The scales are Q12 (1/4096 units a count, below 16 a count): a reading
 * is a multiply and a shift, no division (the Cortex-M0 has no divider). */
struct sensor_calibration {
    uint16_t supply_mv_q12;       /* mV at the supply per count (divider, reference), Q12 */
    uint16_t current_ma_q12;      /* mA in the shunt per count (shunt, gain, reference), Q12 */
    /* The winding's thermal model (protection/winding.h), from the motor's
     * data (board.h): I^2 (mA^2/16) to the rise it settles at, degC Q16,
     * x winding_heat_k / 256; a model step's share of its time constant,
     * Q16; the winding's temperature limit, 0.1 degC. 0: no model. */
    uint16_t winding_heat_k;
    uint16_t winding_step_k;
    int16_t winding_limit_decic;
};

/* A count's worth in uV (or uA) as the Q12 of mV (mA), rounded. */
#define SENSOR_Q12_FROM_MICRO(micro_per_count) ((uint16_t)(((micro_per_count) * 4096u + 500u) / 1000u))

#endif
