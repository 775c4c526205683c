/* A servo board's pins on an STM32G031, from its declaration (its board.h,
 * included before this file), each as a number 0xPN: port P (0 A, 1 B,
 * 2 C), pin N, as on the F1 (ports/stm32f1/stm32f1_pins.h):
 *   BOARD_BUS_TX_PIN       the bus USART's TX, the single wire
 *   BOARD_BRIDGE_TIMER     the timer whose CH1 and CH2 drive the bridge's
 *                          IN1 and IN2 (board_common.h)
 *   BOARD_BRIDGE_IN1_PIN, BOARD_BRIDGE_IN2_PIN  those channels' pins
 *   BOARD_ADC_SUPPLY, BOARD_ADC_CURRENT, BOARD_ADC_NTC, BOARD_ADC_POSITION
 *                          the ADC channels of the scan's four inputs
 * The G0 boards' code sets port A's pins, each on its alternate function
 * AF1 or as an analogue input, so it takes, of DS12992's alternate-function
 * tables ("Port A alternate function mapping"): USART1_TX on PA9 (AF1; not
 * PB6, AF0), USART2_TX on PA2 or PA14 (AF1), TIM3_CH1/CH2 on PA6/PA7 (AF1;
 * not PB4/PB5 or PC6/PC7) and ADC_IN0-IN7 on PA0-PA7 (DS12992, pin
 * definitions). A pin that is not its function's stops the build here,
 * naming the fact. What follows is constants: every choice is made at
 * compile time. */
#ifndef STM32G0_PINS_H
#define STM32G0_PINS_H

#include <stdint.h>

#include "ports/stm32_common/port_a_pins.h"

/* The bus: its USART's TX (DS12992, port A's AF1). */
_Static_assert(BOARD_BUS_USART == 1 ? BOARD_BUS_TX_PIN == 0x09
                                    : BOARD_BUS_TX_PIN == 0x02 || BOARD_BUS_TX_PIN == 0x0E,
               "board.h: BOARD_BUS_TX_PIN is not its USART's TX on port A's AF1 (DS12992, port A alternate "
               "functions: USART1 PA9 0x09, USART2 PA2 0x02 or PA14 0x0E)");
#define BUS_TX_PA ((uint32_t)BOARD_BUS_TX_PIN) /* its pin in GPIOA */

/* The bridge: TIM3's CH1 and CH2, PA6 and PA7 (AF1). */
_Static_assert(BOARD_BRIDGE_TIMER == 3,
               "board.h: BOARD_BRIDGE_TIMER is 3 on the G0 boards (TIM3, a general-purpose timer, RM0444 22)");
_Static_assert(BOARD_BRIDGE_IN1_PIN == 0x06 && BOARD_BRIDGE_IN2_PIN == 0x07,
               "board.h: BOARD_BRIDGE_IN1_PIN and _IN2_PIN are not TIM3's CH1 and CH2 on port A's AF1 (DS12992, "
               "port A alternate functions: PA6 0x06 and PA7 0x07)");

/* The ADC scan: ADC_IN0-IN7 on PA0-PA7. Without a sequence (CHSELRMOD
 * 0) the ADC converts the channels CHSELR selects in ascending order
 * (RM0444 15.3.8), so the four are the scan's order (board_common.h:
 * supply, current, NTC, encoder) in ascending channels. */
#define ADC_CH_OK(ch) ((ch) >= 0 && (ch) <= 7)
_Static_assert(ADC_CH_OK(BOARD_ADC_SUPPLY) && ADC_CH_OK(BOARD_ADC_CURRENT) && ADC_CH_OK(BOARD_ADC_NTC) &&
                   ADC_CH_OK(BOARD_ADC_POSITION),
               "board.h: a BOARD_ADC_* channel is not 0-7 (ADC_IN0-IN7 on PA0-PA7: DS12992, pin definitions)");
_Static_assert(BOARD_ADC_SUPPLY < BOARD_ADC_CURRENT && BOARD_ADC_CURRENT < BOARD_ADC_NTC &&
                   BOARD_ADC_NTC < BOARD_ADC_POSITION,
               "board.h: the G0's ADC scans its channels in ascending order (RM0444 15.3.8): BOARD_ADC_SUPPLY < "
               "_CURRENT < _NTC < _POSITION");

#endif
