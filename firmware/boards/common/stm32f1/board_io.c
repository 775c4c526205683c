#include "boards/common/stm32f1/board_io.h"
#include "board.h"
#include "ports/stm32f1/stm32f1_bus.h"
#include "ports/stm32f1/stm32f1_pins.h"

#include "ports/stm32f1/stm32f1_regs.h"

enum { HSE_STARTUP_TRIES = 100000 };

void clock_f103_init(void)
{
    RCC_CR |= RCC_CR_HSEON;
    for (int i = 0; !(RCC_CR & RCC_CR_HSERDY); i++) {
        if (i == HSE_STARTUP_TRIES) {
            return; /* no crystal: run on HSI; the UART timing will be off */
        }
    }
    FLASH_ACR = FLASH_ACR_PRFTBE | FLASH_ACR_LATENCY_2; /* 72 MHz needs 2 wait states */
    RCC_CFGR = RCC_CFGR_PLLSRC_HSE | RCC_CFGR_PLLMUL9 | RCC_CFGR_PPRE1_DIV2 | RCC_CFGR_ADCPRE_DIV6;
    RCC_CR |= RCC_CR_PLLON;
    while (!(RCC_CR & RCC_CR_PLLRDY)) {
    }
    RCC_CFGR |= RCC_CFGR_SW_PLL;
    while ((RCC_CFGR & RCC_CFGR_SWS_MASK) != RCC_CFGR_SWS_PLL) {
    }
}

void pwm_bridge_init(void)
{
    RCC_APB1ENR |= BRIDGE_TIM_CLOCK; /* the timer board.h names */
    pwm_bridge_start(BRIDGE_TIM_BASE, 2u * F103_PCLK1_HZ); /* the timer runs at 2 x PCLK1 */
}

void adc_scan_init(void)
{
    RCC_AHBENR |= RCC_AHBENR_DMA1;
    RCC_APB2ENR |= RCC_APB2ENR_ADC1;
    DMA_CPAR(DMA1_CCR_ADDR(1u)) = ADC_DR_ADDR;
    DMA_CMAR(DMA1_CCR_ADDR(1u)) = (uint32_t)(uintptr_t)adc_scan_values;
    DMA_CNDTR(DMA1_CCR_ADDR(1u)) = ADC_CHANNELS;
    DMA_CCR(DMA1_CCR_ADDR(1u)) = DMA_CCR_ADC_CIRCULAR;
    /* The channels board.h names, 55.5 cycles each: 4 x 5.8 us at 12 MHz. */
    ADC_SMPR2 = ADC_SMPR2_ALL(5u);
    ADC_SQR1 = (uint32_t)(ADC_CHANNELS - 1) << 20;
    ADC_SQR3 = ADC_SQR3_SCAN;
    ADC_CR1 = ADC_CR1_SCAN;
    ADC_CR2 = ADC_CR2_ADON;
    ADC_CR2 = ADC_CR2_ADON | ADC_CR2_CAL;
    while (ADC_CR2 & ADC_CR2_CAL) {
    }
    ADC_CR2 = ADC_CR2_ADON | ADC_CR2_CONT | ADC_CR2_DMA | ADC_CR2_EXTSEL_SWSTART |
              ADC_CR2_EXTTRIG;
    ADC_CR2 |= ADC_CR2_SWSTART;
    /* The first scan in RAM before servo_init reads the encoder: its
     * power-up reading picks the turn the horn is in (motion_init). From
     * 0 it was tracked there, up to a turn off with a zero (item 90). */
    while (!(DMA1_ISR & DMA1_FLAGS(1u) & 2u)) { /* TCIF1 */
    }
}

uint32_t unique_id_serial(void *ctx)
{
    (void)ctx;
    return unique_id_serial_at(UID_ADDR);
}

void bus_pins_init(void)
{
    RCC_APB2ENR |= PIN_CLOCK(BOARD_BUS_TX_PIN) | RCC_APB2ENR_AFIO;
    BUS_USART_CLOCK_ON(); /* the USART board.h names */
    if (BUS_TX_REMAP != 0u) { /* its TX on the remapped pin */
        AFIO_MAPR |= BUS_TX_REMAP;
    }
    /* The TX pin board.h names, open drain: the single bus wire (external
     * pull-up). */
    PIN_CR(BOARD_BUS_TX_PIN) = (PIN_CR(BOARD_BUS_TX_PIN) & ~(0xFu << PIN_SHIFT(BOARD_BUS_TX_PIN))) |
                               (GPIO_AF_OPEN_DRAIN_50MHZ << PIN_SHIFT(BOARD_BUS_TX_PIN));
}
