/* The reference board's peripherals on the STM32F103: clock tree, H-bridge
 * PWM, ADC scan, watchdog. Pin map: firmware/boards/stm32f103/README.md. */
#ifndef STM32F1_BOARD_F103_H
#define STM32F1_BOARD_F103_H

#include <stdint.h>

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
/* Signed duty, Q15: positive drives IN1, negative IN2. */
void pwm_bridge_drive(int16_t duty_q15);
/* Both inputs low: the bridge's outputs float (coast). */
void pwm_bridge_coast(void);

/* Scan order of ADC1, converted continuously into adc_scan_values[]. */
enum adc_channel { ADC_SUPPLY, ADC_CURRENT, ADC_NTC, ADC_POSITION, ADC_CHANNELS };
extern volatile uint16_t adc_scan_values[ADC_CHANNELS];
void adc_scan_init(void);

/* Independent watchdog, about 125 ms: the main loop must come round. */
void iwdg_start(void);
void iwdg_kick(void);

/* The 96-bit unique ID folded to the 32-bit serial number (data ID 8). */
uint32_t unique_id_serial(void);

#endif
