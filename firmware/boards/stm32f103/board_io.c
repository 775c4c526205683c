#include "board_io.h"
#include "board.h"
#include "ports/stm32f1/stm32f1_bus.h"

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
    RCC_APB1ENR |= RCC_APB1ENR_TIM3;
    pwm_bridge_start(TIM3_BASE, 2u * F103_PCLK1_HZ); /* the timer runs at 2 x PCLK1 */
}

void adc_scan_init(void)
{
    RCC_AHBENR |= RCC_AHBENR_DMA1;
    RCC_APB2ENR |= RCC_APB2ENR_ADC1;
    DMA_CPAR(DMA1_CCR_ADDR(1u)) = ADC_DR_ADDR;
    DMA_CMAR(DMA1_CCR_ADDR(1u)) = (uint32_t)(uintptr_t)adc_scan_values;
    DMA_CNDTR(DMA1_CCR_ADDR(1u)) = ADC_CHANNELS;
    DMA_CCR(DMA1_CCR_ADDR(1u)) = DMA_CCR_ADC_CIRCULAR;
    /* Channels 0-3 (PA0-PA3), 55.5 cycles each: 4 x 5.8 us at 12 MHz. */
    ADC_SMPR2 = 5u | (5u << 3) | (5u << 6) | (5u << 9);
    ADC_SQR1 = (uint32_t)(ADC_CHANNELS - 1) << 20;
    ADC_SQR3 = 0u | (1u << 5) | (2u << 10) | (3u << 15);
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
    RCC_APB2ENR |= RCC_APB2ENR_GPIOA | RCC_APB2ENR_AFIO;
    BUS_USART_CLOCK_ON(); /* the USART board.h names */
    /* PA9 USART1 TX, open drain: the single bus wire (external pull-up).
     * A bus on another USART needs its TX pin here (RM0008 Table 5:
     * USART2 PA2, USART3 PB10): the pins are this file's, not data yet. */
    GPIOA_CRH = (GPIOA_CRH & ~(0xFu << 4)) | (GPIO_AF_OPEN_DRAIN_50MHZ << 4);
}
