/* The STM32F030 registers this port uses, and nothing more (RM0360); what
 * the F0 shares with the F1 is in stm32_core_regs.h. */
#ifndef STM32F0_REGS_H
#define STM32F0_REGS_H

#include "ports/stm32_common/stm32_core_regs.h"

/* RCC (RM0360 6.4) */
#define RCC_CFGR_PLLMUL6 (4u << 18)
#define RCC_CFGR_PLLMUL12 (10u << 18)
#define RCC_AHBENR_GPIOA (1u << 17)
#define RCC_APB2ENR_SYSCFG (1u << 0)

#define FLASH_ACR_LATENCY_1 1u /* 24 < SYSCLK <= 48 MHz */

/* SYSCFG: MEM_MODE 3 maps SRAM at 0, where the core looks for vectors */
#define SYSCFG_CFGR1 REG32(0x40010000u)
#define SYSCFG_CFGR1_MEM_MODE_SRAM 3u

/* GPIOA (RM0360 8.4) */
#define GPIOA_BASE 0x48000000u
#define GPIOA_MODER REG32(GPIOA_BASE + 0x00u)
#define GPIOA_OTYPER REG32(GPIOA_BASE + 0x04u)
#define GPIOA_OSPEEDR REG32(GPIOA_BASE + 0x08u)
#define GPIOA_AFRL REG32(GPIOA_BASE + 0x20u)
#define GPIOA_AFRH REG32(GPIOA_BASE + 0x24u)
#define GPIO_MODE_AF 2u
#define GPIO_MODE_ANALOG 3u

/* USART1 (RM0360 23.7) */
#define USART1_BASE 0x40013800u
#define USART_CR1(b) REG32((b) + 0x00u)
#define USART_CR3(b) REG32((b) + 0x08u)
#define USART_BRR(b) REG32((b) + 0x0Cu)
#define USART_ISR(b) REG32((b) + 0x1Cu)
#define USART_ICR(b) REG32((b) + 0x20u)
#define USART_RDR_OFFSET 0x24u
#define USART_TDR_OFFSET 0x28u
#define USART_TDR(b) REG32((b) + USART_TDR_OFFSET)
#define USART_CR1_UE (1u << 0)
#define USART_CR1_RE (1u << 2)
#define USART_CR1_TE (1u << 3)
#define USART_CR1_IDLEIE (1u << 4)
#define USART_CR1_TCIE (1u << 6)
#define USART_CR3_HDSEL (1u << 3)
#define USART_CR3_DMAR (1u << 6)
#define USART_CR3_DMAT (1u << 7)
#define USART_CR3_OVRDIS (1u << 12)
#define USART_ISR_IDLE (1u << 4)
#define USART_ISR_TC (1u << 6)
#define USART_ISR_TXE (1u << 7)
#define USART_ICR_CLEAR 0x5Fu /* PE, FE, NF, ORE, IDLE, TC */
#define USART_ICR_IDLECF (1u << 4)
#define USART_ICR_TCCF (1u << 6)
#define USART1_IRQ 27u


/* ADC (RM0360 12.11), into DMA1 channel 1 */
#define ADC_BASE 0x40012400u
#define ADC_ISR REG32(ADC_BASE + 0x00u)
#define ADC_CR REG32(ADC_BASE + 0x08u)
#define ADC_CFGR1 REG32(ADC_BASE + 0x0Cu)
#define ADC_CFGR2 REG32(ADC_BASE + 0x10u)
#define ADC_SMPR REG32(ADC_BASE + 0x14u)
#define ADC_CHSELR REG32(ADC_BASE + 0x28u)
#define ADC_DR_ADDR (ADC_BASE + 0x40u)
#define ADC_ISR_ADRDY (1u << 0)
#define ADC_CR_ADEN (1u << 0)
#define ADC_CR_ADSTART (1u << 2)
#define ADC_CR_ADCAL (1u << 31)
#define ADC_CFGR1_DMAEN (1u << 0)
#define ADC_CFGR1_DMACFG (1u << 1) /* circular */
#define ADC_CFGR1_CONT (1u << 13)

/* DMA1 channel 2 serves USART1_TX, channel 3 USART1_RX (RM0360 table 26,
 * no remap); the two share one interrupt. */
#define DMA1_CCR2_ADDR DMA1_CCR_ADDR(2u)
#define DMA1_CH3_IRQ 10u


/* 96-bit unique device ID (RM0360 29.1) */
#define UID_ADDR 0x1FFFF7ACu

#endif
