/* The NTC relation of docs/protocol.md, "The temperature reading", both ways, from a
 * table generated at build time (gen_ntc_table.py): the ADC value falls as
 * the servo heats. Between table points the conversion is linear; within
 * 0.2 degC of the exact formula from -20 to 120 degC. */
#ifndef SENSORS_NTC_H
#define SENSORS_NTC_H

#include <stdint.h>

#define NTC_TABLE_SIZE 39 /* -40 .. 150 degC in 5 degC steps */

extern const int16_t ntc_first_celsius;
extern const int16_t ntc_step_celsius;
extern const uint16_t ntc_adc_at[NTC_TABLE_SIZE];

/* Temperature in 0.1 degC for an ADC value; clamped to the table's ends. */
int16_t ntc_decicelsius(uint16_t adc);
/* ADC value for a temperature in 0.1 degC; clamped to the table's ends. */
uint16_t ntc_adc(int16_t decicelsius);

#endif
