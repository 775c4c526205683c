#include "boards/common/stm32g0/board_io.h"

#include "board.h"
#include "ports/stm32g0/stm32g0_pins.h"
#include "ports/stm32g0/stm32g0_regs.h"

void clock_g031_init(void)
{
    /* Two wait states before the clock rises (RM0444 3.3.4), read back. */
    G0_FLASH_ACR = G0_FLASH_ACR_LATENCY_2 | G0_FLASH_ACR_PRFTEN | G0_FLASH_ACR_ICEN;
    while ((G0_FLASH_ACR & G0_FLASH_ACR_LATENCY_MASK) != G0_FLASH_ACR_LATENCY_2) {
    }
    G0_RCC_PLLCFGR = G0_RCC_PLLCFGR_64MHZ_FROM_HSI16;
    G0_RCC_CR |= G0_RCC_CR_PLLON;
    while (!(G0_RCC_CR & G0_RCC_CR_PLLRDY)) {
    }
    G0_RCC_CFGR = G0_RCC_CFGR_SW_PLLR;
    while ((G0_RCC_CFGR & G0_RCC_CFGR_SWS_MASK) != G0_RCC_CFGR_SWS_PLLR) {
    }
}

/* The application sets its pins through one copy of these (called at each
 * pin); the bootloader, which sets one, inlines them. */
#ifdef STARTUP_BOOTLOADER
#define PIN_HELPER static
#else
#define PIN_HELPER __attribute__((noinline)) static
#endif

/* Two bits a pin in MODER, four in AFR (RM0444 7.4). */
PIN_HELPER void pin_mode(uint32_t pin, uint32_t mode)
{
    G0_GPIOA_MODER = (G0_GPIOA_MODER & ~(3u << (2u * pin))) | (mode << (2u * pin));
}

PIN_HELPER void pin_af1(uint32_t pin)
{
    volatile uint32_t *afr = pin < 8u ? &G0_GPIOA_AFRL : &G0_GPIOA_AFRH;
    uint32_t shift = 4u * (pin % 8u);
    *afr = (*afr & ~(0xFu << shift)) | (1u << shift);
    pin_mode(pin, G0_GPIO_MODE_AF);
}

void bus_pins_init(void)
{
    G0_RCC_IOPENR |= G0_RCC_IOPENR_GPIOA;
#if BOARD_BUS_USART == 1
    G0_RCC_APBENR2 |= G0_RCC_APBENR2_USART1;
#else
    G0_RCC_APBENR1 |= G0_RCC_APBENR1_USART2;
#endif
    uint32_t tx = BUS_TX_PA; /* the TX pin board.h names, AF1 (stm32g0_pins.h) */
    /* Open drain: the single bus wire (external pull-up). */
    G0_GPIOA_OTYPER |= 1u << tx;
    G0_GPIOA_OSPEEDR |= 3u << (2u * tx);
    pin_af1(tx);
}

void pwm_bridge_init(void)
{
    G0_RCC_APBENR1 |= G0_RCC_APBENR1_TIM3;
    pin_af1((uint32_t)BOARD_BRIDGE_IN1_PIN); /* TIM3 CH1 and CH2, as board.h names them */
    pin_af1((uint32_t)BOARD_BRIDGE_IN2_PIN);
    pwm_bridge_start(TIM3_BASE, G031_PCLK_HZ);
}

void adc_scan_init(void)
{
    G0_RCC_AHBENR |= G0_RCC_AHBENR_DMA1;
    G0_RCC_APBENR2 |= G0_RCC_APBENR2_ADC;
    for (uint32_t pin = ADC_FIRST_PIN; pin <= ADC_LAST_PIN; pin++) { /* the inputs board.h names */
        if (ADC_PINS_IN_A_ROW || ((ADC_PIN_MASK >> pin) & 1u) != 0u) {
            pin_mode(pin, G0_GPIO_MODE_ANALOG);
        }
    }
    G0_DMAMUX_CCR(1u) = G0_DMAMUX_REQ_ADC;
    uintptr_t ch = DMA1_CCR_ADDR(1u);
    DMA_CPAR(ch) = G0_ADC_DR_ADDR;
    DMA_CMAR(ch) = (uint32_t)(uintptr_t)adc_scan_values;
    DMA_CNDTR(ch) = ADC_CHANNELS;
    DMA_CCR(ch) = DMA_CCR_ADC_CIRCULAR;
    /* PCLK / 4 = 16 MHz (CKMODE 2). The regulator first, 20 us before
     * calibrating (RM0444 15.3.2, tADCVREG_STUP), then calibrate with the
     * ADC off (15.3.3), then enable it (15.3.4). */
    G0_ADC_CFGR2 = G0_ADC_CFGR2_CKMODE_PCLK_4;
    G0_ADC_CR = G0_ADC_CR_ADVREGEN;
    for (volatile uint32_t i = 0; i < G031_CORE_HZ / 1000000u * 20u; i++) {
    }
    G0_ADC_CR = G0_ADC_CR_ADVREGEN | G0_ADC_CR_ADCAL;
    while (G0_ADC_CR & G0_ADC_CR_ADCAL) {
    }
    G0_ADC_CR = G0_ADC_CR_ADVREGEN | G0_ADC_CR_ADEN;
    while (!(G0_ADC_ISR & G0_ADC_ISR_ADRDY)) {
    }
    /* 79.5 cycles a channel (SMP1 6): 4 x 5.8 us at 16 MHz, near the F1's. */
    G0_ADC_SMPR = 6u;
    G0_ADC_CHSELR = ADC_PIN_MASK; /* scanned in ascending order: board.h's (stm32g0_pins.h) */
    while (!(G0_ADC_ISR & G0_ADC_ISR_CCRDY)) { /* the channel set taken (15.3.8) */
    }
    G0_ADC_CFGR1 = G0_ADC_CFGR1_DMAEN | G0_ADC_CFGR1_DMACFG | G0_ADC_CFGR1_CONT;
    G0_ADC_CR = G0_ADC_CR_ADVREGEN | G0_ADC_CR_ADEN | G0_ADC_CR_ADSTART;
}

uint32_t unique_id_serial(void *ctx)
{
    (void)ctx;
    return unique_id_serial_at(G0_UID_ADDR);
}
