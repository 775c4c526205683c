/* An STM32F103 board's clock tree, bus pin, H-bridge PWM pins and timer
 * and the ADC channels it scans, the F1 boards' shared code: the pins and
 * instances are the board's board.h's (ports/stm32f1/stm32f1_pins.h); a
 * board with another clock tree or front end brings its own (docs/building.md). */
#ifndef BOARDS_COMMON_STM32F1_BOARD_IO_H
#define BOARDS_COMMON_STM32F1_BOARD_IO_H

#include <stdint.h>

#include "ports/stm32_common/board_common.h" /* the bridge PWM, the ADC scan, the watchdog */

#define F103_CORE_HZ 72000000u
#define F103_PCLK2_HZ 72000000u /* USART1, ADC (through /6), TIM on APB2 */
#define F103_PCLK1_HZ 36000000u

/* 8 MHz crystal, PLL x9: 72 MHz core, APB2 72 MHz, APB1 36 MHz, ADC 12 MHz.
 * Gives up (stays on the 8 MHz HSI) if the crystal does not start. */
void clock_f103_init(void);

/* The bus: its TX pin's port, AFIO and its USART clocked, the pin
 * remapped if it is the remapped one and made the open-drain wire (the
 * application and the bootloader alike). */
void bus_pins_init(void);

/* The bridge timer's CH1/CH2 (the reference board's TIM3, PA6/PA7) at
 * 20 kHz into the bridge's IN1/IN2. */
void pwm_bridge_init(void);

/* ADC1 scans the board's four channels (the reference board's 0-3) into
 * adc_scan_values[] (board_common.h). */
void adc_scan_init(void);

/* The 96-bit unique ID folded to the 32-bit serial number (data ID 8). */
uint32_t unique_id_serial(void *ctx); /* a hal_port's serial_number (ctx unused) */

#endif
