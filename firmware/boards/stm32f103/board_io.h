/* The reference board's own use of the STM32F103: clock tree, the bus pin,
 * H-bridge PWM pins and timer, the ADC channels it scans. A board on other
 * pins changes this file (pin map: this folder's README.md). */
#ifndef BOARD_IO_H
#define BOARD_IO_H

#include <stdint.h>

#include "ports/stm32_common/board_common.h" /* the bridge PWM, the ADC scan, the watchdog */

#define F103_CORE_HZ 72000000u
#define F103_PCLK2_HZ 72000000u /* USART1, ADC (through /6), TIM on APB2 */
#define F103_PCLK1_HZ 36000000u

/* 8 MHz crystal, PLL x9: 72 MHz core, APB2 72 MHz, APB1 36 MHz, ADC 12 MHz.
 * Gives up (stays on the 8 MHz HSI) if the crystal does not start. */
void clock_f103_init(void);

/* The bus: GPIOA, AFIO and USART1 clocked, PA9 the open-drain wire (the
 * application and the bootloader alike). */
void bus_pins_init(void);

/* TIM3 CH1/CH2 (PA6/PA7) at 20 kHz into the bridge's IN1/IN2. */
void pwm_bridge_init(void);

/* ADC1 scans channels 0-3 into adc_scan_values[] (board_common.h). */
void adc_scan_init(void);

/* The 96-bit unique ID folded to the 32-bit serial number (data ID 8). */
uint32_t unique_id_serial(void *ctx); /* a hal_port's serial_number (ctx unused) */

#endif
