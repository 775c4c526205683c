#include "boards/common/stm32f0/board_io.h"

#include "board.h"
#include "ports/stm32f0/stm32f0_pins.h"
#include "ports/stm32f0/stm32f0_regs.h"

enum { HSE_STARTUP_TRIES = 100000 };

void clock_f030_init(void)
{
    uint32_t pll = RCC_CFGR_PLLSRC_HSE | RCC_CFGR_PLLMUL6;
    RCC_CR |= RCC_CR_HSEON;
    for (int i = 0; !(RCC_CR & RCC_CR_HSERDY); i++) {
        if (i == HSE_STARTUP_TRIES) {
            pll = RCC_CFGR_PLLMUL12; /* no crystal: HSI / 2, timing off over temperature */
            break;
        }
    }
    FLASH_ACR = FLASH_ACR_PRFTBE | FLASH_ACR_LATENCY_1;
    RCC_CFGR = pll;
    RCC_CR |= RCC_CR_PLLON;
    while (!(RCC_CR & RCC_CR_PLLRDY)) {
    }
    RCC_CFGR = pll | RCC_CFGR_SW_PLL;
    while ((RCC_CFGR & RCC_CFGR_SWS_MASK) != RCC_CFGR_SWS_PLL) {
    }
}

/* The application sets its pins through one copy of these (called at each
 * pin); the bootloader, which sets one, inlines them. */
#ifdef STARTUP_BOOTLOADER
#define PIN_HELPER static
#else
#define PIN_HELPER __attribute__((noinline)) static
#endif

/* Two bits a pin in MODER, four in AFR. */
PIN_HELPER void pin_mode(uint32_t pin, uint32_t mode)
{
    GPIOA_MODER = (GPIOA_MODER & ~(3u << (2u * pin))) | (mode << (2u * pin));
}

PIN_HELPER void pin_af1(uint32_t pin)
{
    volatile uint32_t *afr = pin < 8u ? &GPIOA_AFRL : &GPIOA_AFRH;
    uint32_t shift = 4u * (pin % 8u);
    *afr = (*afr & ~(0xFu << shift)) | (1u << shift);
    pin_mode(pin, GPIO_MODE_AF);
}

void bus_pins_init(void)
{
    RCC_AHBENR |= RCC_AHBENR_GPIOA;
    RCC_APB2ENR |= RCC_APB2ENR_USART1;
    /* The TX pin board.h names (stm32f0_pins.h: PA9, USART1 TX, AF1), open
     * drain: the single bus wire (external pull-up). */
    GPIOA_OTYPER |= 1u << BUS_TX_PA;
    GPIOA_OSPEEDR |= 3u << (2u * BUS_TX_PA);
    pin_af1(BUS_TX_PA);
}

void pwm_bridge_init(void)
{
    RCC_APB1ENR |= RCC_APB1ENR_TIM3;
    pin_af1((uint32_t)BOARD_BRIDGE_IN1_PIN); /* TIM3 CH1 and CH2, as board.h names them */
    pin_af1((uint32_t)BOARD_BRIDGE_IN2_PIN);
    pwm_bridge_start(TIM3_BASE, F030_PCLK_HZ);
}

void adc_scan_init(void)
{
    RCC_AHBENR |= RCC_AHBENR_DMA1;
    RCC_APB2ENR |= RCC_APB2ENR_ADC1;
    for (uint32_t pin = ADC_FIRST_PIN; pin <= ADC_LAST_PIN; pin++) { /* the inputs board.h names */
        if (ADC_PINS_IN_A_ROW || ((ADC_PIN_MASK >> pin) & 1u) != 0u) {
            pin_mode(pin, GPIO_MODE_ANALOG);
        }
    }
    uintptr_t ch = DMA1_CCR_ADDR(1u);
    DMA_CPAR(ch) = ADC_DR_ADDR;
    DMA_CMAR(ch) = (uint32_t)(uintptr_t)adc_scan_values;
    DMA_CNDTR(ch) = ADC_CHANNELS;
    DMA_CCR(ch) = DMA_CCR_ADC_CIRCULAR;
    /* PCLK / 2 = 24 MHz, above the ADC's 14 MHz: PCLK / 4 is not offered,
     * so the asynchronous 14 MHz clock (CKMODE 0) it is. Calibrate first,
     * with the ADC off (RM0360 12.4.1). */
    ADC_CFGR2 = 0;
    ADC_CR = ADC_CR_ADCAL;
    while (ADC_CR & ADC_CR_ADCAL) {
    }
    ADC_CR = ADC_CR_ADEN;
    while (!(ADC_ISR & ADC_ISR_ADRDY)) {
    }
    /* 55.5 cycles a channel (SMP 5): 4 x 4.9 us at 14 MHz, as the F1's. */
    ADC_SMPR = 5u;
    ADC_CHSELR = ADC_PIN_MASK; /* scanned in ascending order: board.h's (stm32f0_pins.h) */
    ADC_CFGR1 = ADC_CFGR1_DMAEN | ADC_CFGR1_DMACFG | ADC_CFGR1_CONT;
    ADC_CR = ADC_CR_ADEN | ADC_CR_ADSTART;
}

uint32_t unique_id_serial(void *ctx)
{
    (void)ctx;
    return unique_id_serial_at(UID_ADDR);
}
