/* The STM32G031 registers this port uses, and nothing more (RM0444, the
 * STM32G0x1 reference manual; addresses and bits as ST's STM32G031 SVD
 * has them). The core, DMA1's channels, TIM3 and the IWDG are where the
 * F0 and F1 have them (stm32_core_regs.h); the RCC, the flash interface,
 * GPIO, the ADC and the DMAMUX are the G0's own. A G0 build defines
 * STM32_FAMILY_G0, which leaves the F0/F1 RCC and flash out of
 * stm32_core_regs.h. */
#ifndef STM32G0_REGS_H
#define STM32G0_REGS_H

#include "ports/stm32_common/stm32_core_regs.h"

/* RCC (RM0444 5.4: register map 5.4.27) */
#define G0_RCC_BASE 0x40021000u
#define G0_RCC_CR REG32(G0_RCC_BASE + 0x00u)
#define G0_RCC_CFGR REG32(G0_RCC_BASE + 0x08u)
#define G0_RCC_PLLCFGR REG32(G0_RCC_BASE + 0x0Cu)
#define G0_RCC_IOPENR REG32(G0_RCC_BASE + 0x34u)
#define G0_RCC_AHBENR REG32(G0_RCC_BASE + 0x38u)
#define G0_RCC_APBENR1 REG32(G0_RCC_BASE + 0x3Cu)
#define G0_RCC_APBENR2 REG32(G0_RCC_BASE + 0x40u)
#define RCC_CSR REG32(G0_RCC_BASE + 0x60u)
#define G0_RCC_CR_PLLON (1u << 24)
#define G0_RCC_CR_PLLRDY (1u << 25)
/* PLLCFGR (RM0444 5.4.4): HSI16 in (PLLSRC 2), M = 1 (PLLM 0), N = 8,
 * R = 2 (PLLR 1) enabled: 16 MHz x 8 / 2 = 64 MHz, the VCO at 128 MHz. */
#define G0_RCC_PLLCFGR_64MHZ_FROM_HSI16 ((2u << 0) | (0u << 4) | (8u << 8) | (1u << 28) | (1u << 29))
#define G0_RCC_CFGR_SW_PLLR 2u          /* SW: PLLRCLK (RM0444 5.4.3) */
#define G0_RCC_CFGR_SWS_MASK (7u << 3)
#define G0_RCC_CFGR_SWS_PLLR (2u << 3)
#define G0_RCC_IOPENR_GPIOA (1u << 0)
#define G0_RCC_AHBENR_DMA1 (1u << 0)
#define G0_RCC_APBENR1_TIM3 (1u << 1)
#define G0_RCC_APBENR1_USART2 (1u << 17)
#define G0_RCC_APBENR2_USART1 (1u << 14)
#define G0_RCC_APBENR2_ADC (1u << 20)
/* RCC_CSR (RM0444 5.4.26): the reset flags sit where the F0/F1 have them
 * (kept_ram.c reads them so); the bit that clears them is 23, not 24. */
#define RCC_CSR_RMVF (1u << 23)
#define RCC_CSR_PINRSTF (1u << 26)
#define RCC_CSR_PORRSTF (1u << 27) /* PWRRSTF: BOR or POR */
#define RCC_CSR_SFTRSTF (1u << 28)
#define RCC_CSR_IWDGRSTF (1u << 29)
#define RCC_CSR_WWDGRSTF (1u << 30)
#define RCC_CSR_LPWRRSTF (1u << 31)

/* The IWDG's counts a millisecond at PR 0 (LSI / 4): the G031's LSI is
 * 32 kHz typical (DS12992; parts.toml lsi_hz), so 72 ms is 576 counts. */
#define IWDG_COUNTS_PER_MS 8u

/* Flash interface (RM0444 3.7) */
#define G0_FLASH_BASE_REG 0x40022000u
#define G0_FLASH_ACR REG32(G0_FLASH_BASE_REG + 0x00u)
#define G0_FLASH_KEYR REG32(G0_FLASH_BASE_REG + 0x08u)
#define G0_FLASH_SR REG32(G0_FLASH_BASE_REG + 0x10u)
#define G0_FLASH_CR REG32(G0_FLASH_BASE_REG + 0x14u)
#define G0_FLASH_ECCR REG32(G0_FLASH_BASE_REG + 0x18u)
#define G0_FLASH_KEY1 0x45670123u /* RM0444 3.3.6 (key values) */
#define G0_FLASH_KEY2 0xCDEF89ABu
/* ACR: 2 wait states up to 64 MHz in range 1 (RM0444 3.3.4), prefetch, cache */
#define G0_FLASH_ACR_LATENCY_MASK 7u
#define G0_FLASH_ACR_LATENCY_2 2u
#define G0_FLASH_ACR_PRFTEN (1u << 8)
#define G0_FLASH_ACR_ICEN (1u << 9)
#define G0_FLASH_SR_EOP (1u << 0)
#define G0_FLASH_SR_OPERR (1u << 1)
#define G0_FLASH_SR_PROGERR (1u << 3)
#define G0_FLASH_SR_WRPERR (1u << 4)
#define G0_FLASH_SR_PGAERR (1u << 5)
#define G0_FLASH_SR_SIZERR (1u << 6)
#define G0_FLASH_SR_PGSERR (1u << 7)
#define G0_FLASH_SR_MISERR (1u << 8)
#define G0_FLASH_SR_FASTERR (1u << 9)
#define G0_FLASH_SR_RDERR (1u << 14)
#define G0_FLASH_SR_OPTVERR (1u << 15)
#define G0_FLASH_SR_BSY1 (1u << 16)
#define G0_FLASH_SR_CFGBSY (1u << 18)
/* every error flag (write 1 to clear, RM0444 3.7.5) */
#define G0_FLASH_SR_ERRORS                                                                   \
    (G0_FLASH_SR_OPERR | G0_FLASH_SR_PROGERR | G0_FLASH_SR_WRPERR | G0_FLASH_SR_PGAERR |     \
     G0_FLASH_SR_SIZERR | G0_FLASH_SR_PGSERR | G0_FLASH_SR_MISERR | G0_FLASH_SR_FASTERR |    \
     G0_FLASH_SR_RDERR | G0_FLASH_SR_OPTVERR)
#define G0_FLASH_CR_PG (1u << 0)
#define G0_FLASH_CR_PER (1u << 1)
#define G0_FLASH_CR_PNB_SHIFT 3u /* PNB[5:0]: the page's number (RM0444 3.7.6) */
#define G0_FLASH_CR_PNB_MASK (0x3Fu << 3)
#define G0_FLASH_CR_STRT (1u << 16)
#define G0_FLASH_CR_LOCK (1u << 31)
/* ECCR (RM0444 3.7.7): a corrected (ECCC) or a double error (ECCD, which
 * raises the NMI) and the double word's address. */
#define G0_FLASH_ECCR_ADDR_MASK 0x3FFFu
#define G0_FLASH_ECCR_ECCC (1u << 30)
#define G0_FLASH_ECCR_ECCD (1u << 31)

/* GPIOA on the IOPORT bus (RM0444 2.2 memory map; registers 7.4, the F0's layout) */
#define G0_GPIOA_BASE 0x50000000u
#define G0_GPIOA_MODER REG32(G0_GPIOA_BASE + 0x00u)
#define G0_GPIOA_OTYPER REG32(G0_GPIOA_BASE + 0x04u)
#define G0_GPIOA_OSPEEDR REG32(G0_GPIOA_BASE + 0x08u)
#define G0_GPIOA_AFRL REG32(G0_GPIOA_BASE + 0x20u)
#define G0_GPIOA_AFRH REG32(G0_GPIOA_BASE + 0x24u)
#define G0_GPIO_MODE_AF 2u
#define G0_GPIO_MODE_ANALOG 3u

/* USART1 and USART2 (RM0444 33.8: the F0's USART at these offsets;
 * usart_v2_hd.c drives it through ../stm32f0/stm32f0_regs.h's
 * definitions, whose offsets and bits it shares) */
#define G0_USART1_BASE 0x40013800u
#define G0_USART2_BASE 0x40004400u
#define USART_CR1(b) REG32((b) + 0x00u) /* as the F0 header has it, token for token */
#define G0_USART_RDR_OFFSET 0x24u
#define G0_USART1_IRQ 27u
#define G0_USART2_IRQ 28u

/* DMA1 (RM0444 10): channels 1-5 on the F0's registers; channel 1's own
 * interrupt, 2 and 3 share one, 4 and 5 another with the DMAMUX's overrun
 * (RM0444 12.3, the vector table). */
#define G0_DMA1_CH2_3_IRQ 10u

/* DMAMUX (RM0444 11): DMA1 channel n takes the request in CxCR, x = n - 1;
 * the request's number in DMAREQ_ID[5:0] (RM0444 11.3.2, "DMAMUX
 * requests": 5 ADC, 50/51 USART1 RX/TX, 52/53 USART2 RX/TX). */
#define G0_DMAMUX_BASE 0x40020800u
#define G0_DMAMUX_CCR(n) REG32(G0_DMAMUX_BASE + 4u * ((n) - 1u))
#define G0_DMAMUX_REQ_ADC 5u
#define G0_DMAMUX_REQ_USART1_RX 50u
#define G0_DMAMUX_REQ_USART1_TX 51u
#define G0_DMAMUX_REQ_USART2_RX 52u
#define G0_DMAMUX_REQ_USART2_TX 53u

/* ADC (RM0444 15.12) */
#define G0_ADC_BASE 0x40012400u
#define G0_ADC_ISR REG32(G0_ADC_BASE + 0x00u)
#define G0_ADC_CR REG32(G0_ADC_BASE + 0x08u)
#define G0_ADC_CFGR1 REG32(G0_ADC_BASE + 0x0Cu)
#define G0_ADC_CFGR2 REG32(G0_ADC_BASE + 0x10u)
#define G0_ADC_SMPR REG32(G0_ADC_BASE + 0x14u)
#define G0_ADC_CHSELR REG32(G0_ADC_BASE + 0x28u)
#define G0_ADC_DR_ADDR (G0_ADC_BASE + 0x40u)
#define G0_ADC_ISR_ADRDY (1u << 0)
#define G0_ADC_ISR_CCRDY (1u << 13)
#define G0_ADC_CR_ADEN (1u << 0)
#define G0_ADC_CR_ADSTART (1u << 2)
#define G0_ADC_CR_ADVREGEN (1u << 28)
#define G0_ADC_CR_ADCAL (1u << 31)
#define G0_ADC_CFGR1_DMAEN (1u << 0)
#define G0_ADC_CFGR1_DMACFG (1u << 1) /* circular */
#define G0_ADC_CFGR1_CONT (1u << 13)
#define G0_ADC_CFGR2_CKMODE_PCLK_4 (2u << 30)

/* 96-bit unique device ID (RM0444 40.1) */
#define G0_UID_ADDR 0x1FFF7590u

#endif
