/* An STM32G031 board's clock tree, bus pin, H-bridge PWM pins and the ADC
 * channels it scans (64 MHz; the reference part, the STM32G031K8: 64 KB
 * flash, 8 KB RAM), the G0 boards' shared code: the pins are the board's
 * board.h's (ports/stm32g0/stm32g0_pins.h); a board with another clock
 * tree or front end brings its own (docs/building.md). */
#ifndef BOARDS_COMMON_STM32G0_BOARD_IO_H
#define BOARDS_COMMON_STM32G0_BOARD_IO_H

#include <stdint.h>

#include "ports/stm32_common/board_common.h" /* the bridge PWM, the ADC scan, the watchdog */

#define G031_CORE_HZ 64000000u
#define G031_PCLK_HZ 64000000u /* USART1/2, TIM3, the ADC (through /4) */

/* HSI16 through the PLL (x8 / 2): 64 MHz core and APB, no crystal. The
 * HSI16 is trimmed at the factory to within 1 % at 25 C and a few % over
 * temperature (DS12992, HSI16 characteristics): within what a UART at 16x
 * oversampling tolerates, unlike the F030's HSI. */
void clock_g031_init(void);

/* The bus: GPIOA and the bus's USART clocked, its TX pin the open-drain wire. */
void bus_pins_init(void);

/* TIM3 CH1/CH2 (board.h's pins, PA6/PA7, AF1) at 20 kHz into the bridge's IN1/IN2. */
void pwm_bridge_init(void);

/* The ADC scans the board's four channels (the reference board's 0-3,
 * PA0-PA3) into adc_scan_values[] by DMA1
 * channel 1 (DMAMUX request 5). */
void adc_scan_init(void);

/* The 96-bit unique ID folded to the 32-bit serial number (data ID 8). */
uint32_t unique_id_serial(void *ctx);

#endif
