/* The STM32F1 registers this port uses, and nothing more (RM0008). Our own
 * minimal definitions: no vendor library. */
#ifndef STM32F1_REGS_H
#define STM32F1_REGS_H

#include <stdint.h>

#define REG32(addr) (*(volatile uint32_t *)(uintptr_t)(addr))

/* Core */
#define SYSTICK_CTRL REG32(0xE000E010u)
#define SYSTICK_LOAD REG32(0xE000E014u)
#define SYSTICK_VAL REG32(0xE000E018u)
#define NVIC_ISER(n) REG32(0xE000E100u + 4u * (n))
#define SYSTICK_ENABLE_CORE_CLOCK_IRQ 7u /* ENABLE | TICKINT | CLKSOURCE=core */

/* RCC */
#define RCC_BASE 0x40021000u
#define RCC_CR REG32(RCC_BASE + 0x00u)
#define RCC_CFGR REG32(RCC_BASE + 0x04u)
#define RCC_AHBENR REG32(RCC_BASE + 0x14u)
#define RCC_APB2ENR REG32(RCC_BASE + 0x18u)
#define RCC_APB1ENR REG32(RCC_BASE + 0x1Cu)
#define RCC_CSR REG32(RCC_BASE + 0x24u)
#define RCC_CR_HSEON (1u << 16)
#define RCC_CR_HSERDY (1u << 17)
#define RCC_CR_PLLON (1u << 24)
#define RCC_CR_PLLRDY (1u << 25)
#define RCC_CFGR_SW_PLL 2u
#define RCC_CFGR_SWS_MASK (3u << 2)
#define RCC_CFGR_SWS_PLL (2u << 2)
#define RCC_CFGR_PPRE1_DIV2 (4u << 8)
#define RCC_CFGR_ADCPRE_DIV6 (2u << 14)
#define RCC_CFGR_PLLSRC_HSE (1u << 16)
#define RCC_CFGR_PLLMUL9 (7u << 18)
#define RCC_AHBENR_DMA1 (1u << 0)
#define RCC_APB2ENR_AFIO (1u << 0)
#define RCC_APB2ENR_GPIOA (1u << 2)
#define RCC_APB2ENR_ADC1 (1u << 9)
#define RCC_APB2ENR_USART1 (1u << 14)
#define RCC_APB1ENR_TIM3 (1u << 1)

/* Flash interface */
#define FLASH_BASE_REG 0x40022000u
#define FLASH_ACR REG32(FLASH_BASE_REG + 0x00u)
#define FLASH_KEYR REG32(FLASH_BASE_REG + 0x04u)
#define FLASH_SR REG32(FLASH_BASE_REG + 0x0Cu)
#define FLASH_CR REG32(FLASH_BASE_REG + 0x10u)
#define FLASH_AR REG32(FLASH_BASE_REG + 0x14u)
#define FLASH_ACR_LATENCY_2 2u
#define FLASH_ACR_PRFTBE (1u << 4)
#define FLASH_KEY1 0x45670123u
#define FLASH_KEY2 0xCDEF89ABu
#define FLASH_SR_BSY (1u << 0)
#define FLASH_SR_PGERR (1u << 2)
#define FLASH_SR_WRPRTERR (1u << 4)
#define FLASH_SR_EOP (1u << 5)
#define FLASH_CR_PG (1u << 0)
#define FLASH_CR_PER (1u << 1)
#define FLASH_CR_STRT (1u << 6)
#define FLASH_CR_LOCK (1u << 7)

/* GPIOA */
#define GPIOA_CRL REG32(0x40010800u)
#define GPIOA_CRH REG32(0x40010804u)
/* 4-bit pin configurations (MODE | CNF << 2) */
#define GPIO_ANALOG 0x0u
#define GPIO_AF_PUSH_PULL_50MHZ 0xBu
#define GPIO_AF_OPEN_DRAIN_50MHZ 0xFu

/* USART1 */
#define USART1_BASE 0x40013800u
#define USART_SR(b) REG32((b) + 0x00u)
#define USART_DR(b) REG32((b) + 0x04u)
#define USART_BRR(b) REG32((b) + 0x08u)
#define USART_CR1(b) REG32((b) + 0x0Cu)
#define USART_CR3(b) REG32((b) + 0x14u)
#define USART_SR_RXNE (1u << 5)
#define USART_SR_TC (1u << 6)
#define USART_SR_TXE (1u << 7)
#define USART_SR_ORE (1u << 3)
#define USART_CR3_DMAR (1u << 6)
#define USART_CR1_RE (1u << 2)
#define USART_CR1_TE (1u << 3)
#define USART_CR1_RXNEIE (1u << 5)
#define USART_CR1_TCIE (1u << 6)
#define USART_CR1_TXEIE (1u << 7)
#define USART_CR1_UE (1u << 13)
#define USART_CR3_HDSEL (1u << 3)
#define USART1_IRQ 37u

/* TIM3 (H-bridge PWM on CH1/CH2) */
#define TIM3_BASE 0x40000400u
#define TIM_CR1(b) REG32((b) + 0x00u)
#define TIM_EGR(b) REG32((b) + 0x14u)
#define TIM_CCMR1(b) REG32((b) + 0x18u)
#define TIM_CCER(b) REG32((b) + 0x20u)
#define TIM_PSC(b) REG32((b) + 0x28u)
#define TIM_ARR(b) REG32((b) + 0x2Cu)
#define TIM_CCR1(b) REG32((b) + 0x34u)
#define TIM_CCR2(b) REG32((b) + 0x38u)
#define TIM_CCMR1_PWM1_BOTH ((6u << 4) | (1u << 3) | (6u << 12) | (1u << 11))
#define TIM_CCER_CC1E_CC2E ((1u << 0) | (1u << 4))

/* ADC1 with DMA1 channel 1 */
#define ADC1_BASE 0x40012400u
#define ADC_SR REG32(ADC1_BASE + 0x00u)
#define ADC_CR1 REG32(ADC1_BASE + 0x04u)
#define ADC_CR2 REG32(ADC1_BASE + 0x08u)
#define ADC_SMPR2 REG32(ADC1_BASE + 0x10u)
#define ADC_SQR1 REG32(ADC1_BASE + 0x2Cu)
#define ADC_SQR3 REG32(ADC1_BASE + 0x34u)
#define ADC_DR_ADDR (ADC1_BASE + 0x4Cu)
#define ADC_CR1_SCAN (1u << 8)
#define ADC_CR2_ADON (1u << 0)
#define ADC_CR2_CONT (1u << 1)
#define ADC_CR2_CAL (1u << 2)
#define ADC_CR2_DMA (1u << 8)
#define ADC_CR2_EXTSEL_SWSTART (7u << 17)
#define ADC_CR2_EXTTRIG (1u << 20)
#define ADC_CR2_SWSTART (1u << 22)
#define DMA1_CCR1 REG32(0x40020008u)
#define DMA1_CNDTR1 REG32(0x4002000Cu)
#define DMA1_CPAR1 REG32(0x40020010u)
#define DMA1_CMAR1 REG32(0x40020014u)
/* DMA1 channel 5 serves USART1_RX (RM0008 table 78); its CCR, and its
 * flags in DMA1_ISR / DMA1_IFCR (bits 16-19: GIF, TCIF, HTIF, TEIF). */
#define DMA1_ISR REG32(0x40020000u)
#define DMA1_IFCR REG32(0x40020004u)
#define DMA1_CCR5_ADDR 0x40020058u
#define DMA1_CH5_FLAGS (0xFu << 16)
#define DMA1_CH5_IRQ 15u
/* MINC | CIRC | PSIZE 16 | MSIZE 16 | EN */
#define DMA_CCR_ADC_CIRCULAR ((1u << 7) | (1u << 5) | (1u << 8) | (1u << 10) | (1u << 0))

/* Independent watchdog */
#define IWDG_KR REG32(0x40003000u)
#define IWDG_PR REG32(0x40003004u)
#define IWDG_RLR REG32(0x40003008u)
#define IWDG_KEY_START 0xCCCCu
#define IWDG_KEY_ACCESS 0x5555u
#define IWDG_KEY_RELOAD 0xAAAAu

/* 96-bit unique device ID (F103) */
#define UID_ADDR 0x1FFFF7E8u

#endif
