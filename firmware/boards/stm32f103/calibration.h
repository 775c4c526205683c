/* The reference board's analogue front end: 3.3 V ADC reference; supply
 * through a 100k/10k divider (11:1); 25 mOhm shunt into a gain-of-20
 * amplifier (0.5 V/A); the NTC divider of servo-protocol.md appendix 5.1.
 * The STM32F103 port and the host simulator both use these. */
#ifndef BOARD_CALIBRATION_H
#define BOARD_CALIBRATION_H

#define BOARD_SUPPLY_UV_PER_COUNT 8862u  /* 3.3 V x 11 / 4096 */
#define BOARD_CURRENT_UA_PER_COUNT 1611u /* 3.3 V / 0.5 V/A / 4096 */
#define BOARD_CURRENT_ZERO_COUNTS 0u

/* Initialiser of a struct sensor_calibration for this front end. */
#define BOARD_SENSOR_CALIBRATION                           \
    {                                                      \
        .supply_uv_per_count = BOARD_SUPPLY_UV_PER_COUNT,  \
        .current_ua_per_count = BOARD_CURRENT_UA_PER_COUNT, \
        .current_zero_counts = BOARD_CURRENT_ZERO_COUNTS,  \
    }

#endif
