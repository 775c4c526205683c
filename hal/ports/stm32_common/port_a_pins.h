/* What the F0 and G0 boards' pin headers share (stm32f0_pins.h,
 * stm32g0_pins.h): their code drives port A alone, so a board's pins are
 * port A's numbers; the four ADC inputs as the mask CHSELR takes, and no
 * pin two things. The family's header checks each against its datasheet. */
#ifndef STM32_PORT_A_PINS_H
#define STM32_PORT_A_PINS_H

#include <stdint.h>

#if !defined(BOARD_BUS_TX_PIN) || !defined(BOARD_BRIDGE_TIMER) || !defined(BOARD_BRIDGE_IN1_PIN) || \
    !defined(BOARD_BRIDGE_IN2_PIN) || !defined(BOARD_ADC_SUPPLY) || !defined(BOARD_ADC_CURRENT) ||   \
    !defined(BOARD_ADC_NTC) || !defined(BOARD_ADC_POSITION)
#error "board.h declares its pins: BOARD_BUS_TX_PIN, BOARD_BRIDGE_TIMER and _IN1_PIN/_IN2_PIN, BOARD_ADC_* (docs/building.md)"
#endif

#define ADC_PIN_MASK                                                                                \
    ((1u << BOARD_ADC_SUPPLY) | (1u << BOARD_ADC_CURRENT) | (1u << BOARD_ADC_NTC) | (1u << BOARD_ADC_POSITION))
#define ADC_FIRST_PIN ((uint32_t)BOARD_ADC_SUPPLY)
#define ADC_LAST_PIN ((uint32_t)BOARD_ADC_POSITION)
/* All the pins from the first to the last: the loop sets each. */
#define ADC_PINS_IN_A_ROW (BOARD_ADC_POSITION - BOARD_ADC_SUPPLY == 3)

/* No pin two things: the bus, the bridge and the inputs are on port A. */
_Static_assert((ADC_PIN_MASK & ((1u << BOARD_BUS_TX_PIN) | (1u << BOARD_BRIDGE_IN1_PIN) |
                                (1u << BOARD_BRIDGE_IN2_PIN))) == 0u &&
                   BOARD_BUS_TX_PIN != BOARD_BRIDGE_IN1_PIN && BOARD_BUS_TX_PIN != BOARD_BRIDGE_IN2_PIN,
               "board.h: two of the bus, the bridge and the ADC inputs are on one pin");

#endif
