/* Board peripherals the same on the STM32F0 and F1 once the board has set
 * up its pins and clocks (its board_io.c): the H-bridge PWM on the timer it
 * chose, the ADC scan's values and the hal_port operations on both, the
 * watchdog, the serial number from the unique ID. */
#ifndef STM32_BOARD_COMMON_H
#define STM32_BOARD_COMMON_H

#include <stdint.h>

#include "hal/hal_port.h"

/* What the ADC scan holds, in this order: the board's adc_scan_init
 * programs its channels so (the reference board: channels 0-3 on PA0-PA3),
 * converted continuously into adc_scan_values[] by DMA1 channel 1. */
enum adc_channel { ADC_SUPPLY, ADC_CURRENT, ADC_NTC, ADC_POSITION, ADC_CHANNELS };
extern volatile uint16_t adc_scan_values[ADC_CHANNELS];

/* A hal_port's motor group (hal_motor: drive, coast, read_encoder,
 * read_sensors) on the bridge PWM and the ADC scan (ctx unused), named whole
 * by BOARD_MOTOR in the board's hal_port. */
void board_motor_drive(void *ctx, int16_t duty);
void board_motor_coast(void *ctx);
uint16_t board_encoder_read(void *ctx);
void board_sensors_read(void *ctx, struct sensor_raw *out);
#define BOARD_MOTOR                                                                    \
    {.drive = board_motor_drive, .coast = board_motor_coast,                           \
     .read_encoder = board_encoder_read, .read_sensors = board_sensors_read}

/* CH1/CH2 of the general-purpose timer at timer_base (the reference
 * board's TIM3) at 20 kHz from timer_hz, into the bridge's IN1/IN2 (the
 * board has clocked the timer and routed its pins); before any drive or
 * coast. */
void pwm_bridge_start(uint32_t timer_base, uint32_t timer_hz);
/* Signed duty, Q15: positive drives IN1, negative IN2. */
void pwm_bridge_drive(int16_t duty_q15);
/* Both inputs low: the bridge's outputs float (coast). */
void pwm_bridge_coast(void);

/* The independent watchdog: the main loop must come round within
 * IWDG_TIMEOUT_MS at the LSI's nominal 40 kHz. Its longest pass is one page
 * erase, which stalls the CPU up to 40 ms (tERASE, DS5319 and DS9773; one
 * erase a pass, servo_store.c), plus the pass itself (under 0.1 ms); the
 * LSI may run at up to 60 kHz (DS5319; 50 kHz DS9773), which shortens the
 * timeout to 48 ms, still 8 ms over the erase; at its slowest, 30 kHz, a
 * hung loop leaves the output driven for 96 ms. */
#define IWDG_TIMEOUT_MS 72u
void iwdg_start(void);
void iwdg_kick(void);

/* The 96-bit unique ID at uid_addr folded to the 32-bit serial number
 * (data ID 8). */
uint32_t unique_id_serial_at(uint32_t uid_addr);

#endif
