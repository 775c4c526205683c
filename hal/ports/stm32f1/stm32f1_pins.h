/* A servo board's pins on an STM32F1, from its declaration (its board.h,
 * included before this file), each as a number 0xPN: port P (0 A, 1 B,
 * 2 C, 3 D), pin N, so PA9 is 0x09 and PB10 0x1A:
 *   BOARD_BUS_TX_PIN       the bus USART's TX, the single wire; its remap
 *                          (AFIO_MAPR) follows from the pin (RM0008 9.3.8)
 *   BOARD_BRIDGE_TIMER     2, 3 or 4: the timer whose CH1 and CH2 drive the
 *                          bridge's IN1 and IN2 (board_common.h)
 *   BOARD_BRIDGE_IN1_PIN, BOARD_BRIDGE_IN2_PIN  those channels' pins, the
 *                          timer's without a remap (RM0008 9.3.7)
 *   BOARD_ADC_SUPPLY, BOARD_ADC_CURRENT, BOARD_ADC_NTC, BOARD_ADC_POSITION
 *                          the ADC1 channels of the scan's four inputs,
 *                          0-9: IN0-IN7 on PA0-PA7, IN8-IN9 on PB0-PB1
 *                          (DS5319, pin definitions)
 * A pin that is not its function's stops the build here, naming the fact;
 * a pin the part's package lacks stops it when the board is configured
 * (hal/ports/parts.toml's pins, servo_image/board_facts.py). What follows
 * is constants for the board's own code: every choice is made at compile
 * time. */
#ifndef STM32F1_PINS_H
#define STM32F1_PINS_H

#include "ports/stm32f1/stm32f1_regs.h"

#if !defined(BOARD_BUS_TX_PIN) || !defined(BOARD_BRIDGE_TIMER) || !defined(BOARD_BRIDGE_IN1_PIN) || \
    !defined(BOARD_BRIDGE_IN2_PIN) || !defined(BOARD_ADC_SUPPLY) || !defined(BOARD_ADC_CURRENT) ||   \
    !defined(BOARD_ADC_NTC) || !defined(BOARD_ADC_POSITION)
#error "board.h declares its pins: BOARD_BUS_TX_PIN, BOARD_BRIDGE_TIMER and _IN1_PIN/_IN2_PIN, BOARD_ADC_* (docs/building.md)"
#endif

/* A pin's port, its configuration register (CRL pins 0-7, CRH 8-15) and
 * its nibble there (RM0008 9.2.1, 9.2.2); its port's clock. */
#define PIN_CR_INDEX(pin) ((uint32_t)(pin) >> 3)    /* port x 2 + (CRH ? 1 : 0) */
#define PIN_SHIFT(pin) (4u * ((uint32_t)(pin) & 7u))
#define PIN_CR(pin) REG32(GPIOA_BASE + 0x400u * ((uint32_t)(pin) >> 4) + 4u * (((uint32_t)(pin) >> 3) & 1u))
#define PIN_CLOCK(pin) (RCC_APB2ENR_GPIOA << ((uint32_t)(pin) >> 4))
_Static_assert(GPIOB_BASE == GPIOA_BASE + 0x400u && GPIOD_BASE == GPIOA_BASE + 0xC00u,
               "GPIOA-D are 1 KB apart (RM0008 memory map)");
_Static_assert(RCC_APB2ENR_GPIOD == RCC_APB2ENR_GPIOA << 3, "IOPAEN-IOPDEN are in a row (RM0008 7.3.7)");
#define PIN_VALID(pin) ((pin) >= 0 && (pin) <= 0x3F)

/* The bus: a USART's TX, with or without its remap (RM0008 9.3.8:
 * USART1 PA9, remapped PB6; USART2 PA2, remapped PD5; USART3 PB10,
 * partly remapped PC10, fully PD8). */
#define BUS_TX_OK                                                                                   \
    (BOARD_BUS_USART == 1   ? BOARD_BUS_TX_PIN == 0x09 || BOARD_BUS_TX_PIN == 0x16                  \
     : BOARD_BUS_USART == 2 ? BOARD_BUS_TX_PIN == 0x02 || BOARD_BUS_TX_PIN == 0x35                  \
                            : BOARD_BUS_TX_PIN == 0x1A || BOARD_BUS_TX_PIN == 0x2A || BOARD_BUS_TX_PIN == 0x38)
_Static_assert(BUS_TX_OK, "board.h: BOARD_BUS_TX_PIN is not its USART's TX (RM0008 9.3.8: USART1 PA9 0x09 "
                          "or PB6 0x16, USART2 PA2 0x02 or PD5 0x35, USART3 PB10 0x1A, PC10 0x2A or PD8 0x38)");
#define BUS_TX_REMAP                                                                                \
    (BOARD_BUS_TX_PIN == 0x16   ? AFIO_MAPR_USART1_REMAP                                            \
     : BOARD_BUS_TX_PIN == 0x35 ? AFIO_MAPR_USART2_REMAP                                            \
     : BOARD_BUS_TX_PIN == 0x2A ? AFIO_MAPR_USART3_REMAP_PARTIAL                                    \
     : BOARD_BUS_TX_PIN == 0x38 ? AFIO_MAPR_USART3_REMAP_FULL                                       \
                                : 0u)

/* The bridge: CH1 and CH2 of TIM2 (PA0, PA1), TIM3 (PA6, PA7) or TIM4
 * (PB6, PB7), on APB1 (RM0008 9.3.7, 7.3.8). */
_Static_assert(BOARD_BRIDGE_TIMER >= 2 && BOARD_BRIDGE_TIMER <= 4,
               "board.h: BOARD_BRIDGE_TIMER is 2, 3 or 4 on an STM32F1 (a general-purpose timer, RM0008 15)");
#define BRIDGE_CH1_PIN (BOARD_BRIDGE_TIMER == 2 ? 0x00 : BOARD_BRIDGE_TIMER == 3 ? 0x06 : 0x16)
_Static_assert(BOARD_BRIDGE_IN1_PIN == BRIDGE_CH1_PIN && BOARD_BRIDGE_IN2_PIN == BRIDGE_CH1_PIN + 1,
               "board.h: BOARD_BRIDGE_IN1_PIN and _IN2_PIN are not its timer's CH1 and CH2 (RM0008 9.3.7: "
               "TIM2 PA0 0x00 and PA1 0x01, TIM3 PA6 0x06 and PA7 0x07, TIM4 PB6 0x16 and PB7 0x17)");
#define BRIDGE_TIM_BASE (BOARD_BRIDGE_TIMER == 2 ? TIM2_BASE : BOARD_BRIDGE_TIMER == 3 ? TIM3_BASE : TIM4_BASE)
#define BRIDGE_TIM_CLOCK                                                                            \
    (BOARD_BRIDGE_TIMER == 2 ? RCC_APB1ENR_TIM2 : BOARD_BRIDGE_TIMER == 3 ? RCC_APB1ENR_TIM3 : RCC_APB1ENR_TIM4)

/* The ADC scan: the four channels, in the scan's order (board_common.h). */
#define ADC_PIN(ch) ((ch) < 8 ? (ch) : 0x10 + (ch) - 8)
#define ADC_CH_OK(ch) ((ch) >= 0 && (ch) <= 9)
_Static_assert(ADC_CH_OK(BOARD_ADC_SUPPLY) && ADC_CH_OK(BOARD_ADC_CURRENT) && ADC_CH_OK(BOARD_ADC_NTC) &&
                   ADC_CH_OK(BOARD_ADC_POSITION),
               "board.h: a BOARD_ADC_* channel is not 0-9 (ADC1 IN0-IN9 on PA0-PA7, PB0-PB1: DS5319)");
/* Sample times, 3 bits a channel in SMPR2 (channels 0-9); the sequence,
 * 5 bits a place in SQR3 (RM0008 11.12.5, 11.12.11). */
#define ADC_SMPR2_ALL(cycles)                                                                       \
    (((uint32_t)(cycles) << (3u * BOARD_ADC_SUPPLY)) | ((uint32_t)(cycles) << (3u * BOARD_ADC_CURRENT)) | \
     ((uint32_t)(cycles) << (3u * BOARD_ADC_NTC)) | ((uint32_t)(cycles) << (3u * BOARD_ADC_POSITION)))
#define ADC_SQR3_SCAN                                                                               \
    ((uint32_t)BOARD_ADC_SUPPLY | ((uint32_t)BOARD_ADC_CURRENT << 5) | ((uint32_t)BOARD_ADC_NTC << 10) | \
     ((uint32_t)BOARD_ADC_POSITION << 15))

/* No pin two things. */
#define PIN_ONE_OF(pin, a, b, c, d, e, f) ((pin) == (a) || (pin) == (b) || (pin) == (c) || (pin) == (d) || \
                                           (pin) == (e) || (pin) == (f))
_Static_assert(!PIN_ONE_OF(BOARD_BUS_TX_PIN, BOARD_BRIDGE_IN1_PIN, BOARD_BRIDGE_IN2_PIN, ADC_PIN(BOARD_ADC_SUPPLY),
                           ADC_PIN(BOARD_ADC_CURRENT), ADC_PIN(BOARD_ADC_NTC), ADC_PIN(BOARD_ADC_POSITION)) &&
                   !PIN_ONE_OF(ADC_PIN(BOARD_ADC_SUPPLY), BOARD_BRIDGE_IN1_PIN, BOARD_BRIDGE_IN2_PIN,
                               ADC_PIN(BOARD_ADC_CURRENT), ADC_PIN(BOARD_ADC_NTC), ADC_PIN(BOARD_ADC_POSITION), -1) &&
                   !PIN_ONE_OF(ADC_PIN(BOARD_ADC_CURRENT), BOARD_BRIDGE_IN1_PIN, BOARD_BRIDGE_IN2_PIN,
                               ADC_PIN(BOARD_ADC_NTC), ADC_PIN(BOARD_ADC_POSITION), -1, -1) &&
                   !PIN_ONE_OF(ADC_PIN(BOARD_ADC_NTC), BOARD_BRIDGE_IN1_PIN, BOARD_BRIDGE_IN2_PIN,
                               ADC_PIN(BOARD_ADC_POSITION), -1, -1, -1) &&
                   !PIN_ONE_OF(ADC_PIN(BOARD_ADC_POSITION), BOARD_BRIDGE_IN1_PIN, BOARD_BRIDGE_IN2_PIN, -1, -1, -1, -1),
               "board.h: two of the bus, the bridge and the ADC inputs are on one pin");

/* The configuration word of register r (PIN_CR_INDEX) with the front end's
 * pins set: analogue inputs, the bridge's alternate-function push-pull
 * outputs, and the bus's open drain where it shares the register; the
 * rest at their reset value, floating inputs (RM0008 9.2.1). */
#define PIN_SET(word, pin, r, cfg)                                                                  \
    (PIN_CR_INDEX(pin) == (r) ? ((word) & ~(0xFu << PIN_SHIFT(pin))) | ((uint32_t)(cfg) << PIN_SHIFT(pin)) : (word))
#define FRONT_END_IN(r)                                                                             \
    (PIN_CR_INDEX(BOARD_BRIDGE_IN1_PIN) == (r) || PIN_CR_INDEX(BOARD_BRIDGE_IN2_PIN) == (r) ||     \
     PIN_CR_INDEX(ADC_PIN(BOARD_ADC_SUPPLY)) == (r) || PIN_CR_INDEX(ADC_PIN(BOARD_ADC_CURRENT)) == (r) || \
     PIN_CR_INDEX(ADC_PIN(BOARD_ADC_NTC)) == (r) || PIN_CR_INDEX(ADC_PIN(BOARD_ADC_POSITION)) == (r))
#define FRONT_END_WORD(r)                                                                           \
    PIN_SET(PIN_SET(PIN_SET(PIN_SET(PIN_SET(PIN_SET(PIN_SET(0x44444444u, BOARD_BUS_TX_PIN, r,          \
        GPIO_AF_OPEN_DRAIN_50MHZ), ADC_PIN(BOARD_ADC_SUPPLY), r, GPIO_ANALOG), ADC_PIN(BOARD_ADC_CURRENT), r, \
        GPIO_ANALOG), ADC_PIN(BOARD_ADC_NTC), r, GPIO_ANALOG), ADC_PIN(BOARD_ADC_POSITION), r, GPIO_ANALOG), \
        BOARD_BRIDGE_IN1_PIN, r, GPIO_AF_PUSH_PULL_50MHZ), BOARD_BRIDGE_IN2_PIN, r, GPIO_AF_PUSH_PULL_50MHZ)
/* The ports' clocks the front end needs. */
#define FRONT_END_CLOCKS                                                                            \
    (PIN_CLOCK(BOARD_BRIDGE_IN1_PIN) | PIN_CLOCK(ADC_PIN(BOARD_ADC_SUPPLY)) |                        \
     PIN_CLOCK(ADC_PIN(BOARD_ADC_CURRENT)) | PIN_CLOCK(ADC_PIN(BOARD_ADC_NTC)) |                    \
     PIN_CLOCK(ADC_PIN(BOARD_ADC_POSITION)))
/* Register r (0-7: GPIOA CRL, CRH, GPIOB CRL, ...) written whole, if the
 * front end has a pin in it: a constant store, or nothing. */
#define FRONT_END_SET(r)                                                                            \
    do {                                                                                            \
        if (FRONT_END_IN(r)) {                                                                      \
            REG32(GPIOA_BASE + 0x400u * ((r) >> 1) + 4u * ((r) & 1u)) = FRONT_END_WORD(r);         \
        }                                                                                           \
    } while (0)
/* The front end's pins after the bus's (bus_pins_init, which clocked the
 * bus pin's port and AFIO): the other ports' clocks, then every register
 * with a front-end pin. */
#define FRONT_END_PINS_INIT()                                                                       \
    do {                                                                                            \
        if ((FRONT_END_CLOCKS & ~PIN_CLOCK(BOARD_BUS_TX_PIN)) != 0u) {                              \
            RCC_APB2ENR |= FRONT_END_CLOCKS;                                                        \
        }                                                                                           \
        FRONT_END_SET(0u);                                                                          \
        FRONT_END_SET(1u);                                                                          \
        FRONT_END_SET(2u);                                                                          \
        FRONT_END_SET(3u);                                                                          \
        FRONT_END_SET(4u);                                                                          \
        FRONT_END_SET(5u);                                                                          \
        FRONT_END_SET(6u);                                                                          \
        FRONT_END_SET(7u);                                                                          \
    } while (0)

#endif
