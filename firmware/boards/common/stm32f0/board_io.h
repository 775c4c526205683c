/* An STM32F030 board's clock tree, bus pin, H-bridge PWM pins and the ADC
 * channels it scans (48 MHz; the reference part, the STM32F030K6: 32 KB
 * flash, 4 KB RAM), the F0 boards' shared code: the pins are the board's
 * board.h's (ports/stm32f0/stm32f0_pins.h); a board with another clock
 * tree or front end brings its own (docs/building.md). */
#ifndef BOARDS_COMMON_STM32F0_BOARD_IO_H
#define BOARDS_COMMON_STM32F0_BOARD_IO_H

#include <stdint.h>

#include "ports/stm32_common/board_common.h" /* the bridge PWM, the ADC scan, the watchdog */

#define F030_CORE_HZ 48000000u
#define F030_PCLK_HZ 48000000u /* USART1, TIM3, the ADC (through /2) */

/* 8 MHz crystal, PLL x6: 48 MHz core and APB. Without a crystal, HSI / 2
 * x 12, the same 48 MHz: the HSI may be 5 % off over temperature (the
 * F030 datasheet, DM00088500, HSI characteristics), beyond what a UART
 * tolerates, so the board has the crystal as the F103 does. */
void clock_f030_init(void);

/* The bus: GPIOA and USART1 clocked, its TX pin (PA9) the open-drain wire (AF1). */
void bus_pins_init(void);

/* TIM3 CH1/CH2 (board.h's pins, PA6/PA7, AF1) at 20 kHz into the bridge's IN1/IN2. */
void pwm_bridge_init(void);

/* ADC1 scans the board's four channels (the reference board's 0-3) into
 * adc_scan_values[] (board_common.h). */
void adc_scan_init(void);

/* The 96-bit unique ID folded to the 32-bit serial number (data ID 8). */
uint32_t unique_id_serial(void *ctx); /* a hal_port's serial_number (ctx unused) */

#endif
