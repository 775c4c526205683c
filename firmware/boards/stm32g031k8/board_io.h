/* The STM32G031K8 board's own use of the part (64 MHz, 64 KB flash, 8 KB
 * RAM): clock tree, the bus pin, H-bridge pins, the ADC channels it scans.
 * A board on other pins changes this file. */
#ifndef BOARD_IO_H
#define BOARD_IO_H

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

/* TIM3 CH1/CH2 (PA6/PA7, AF1) at 20 kHz into the bridge's IN1/IN2. */
void pwm_bridge_init(void);

/* The ADC scans channels 0-3 (PA0-PA3) into adc_scan_values[] by DMA1
 * channel 1 (DMAMUX request 5). */
void adc_scan_init(void);

/* The 96-bit unique ID folded to the 32-bit serial number (data ID 8). */
uint32_t unique_id_serial(void *ctx);

#endif
