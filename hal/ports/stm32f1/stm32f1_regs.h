/* The STM32F1 registers this port uses, and nothing more (RM0008). Our own
 * minimal definitions: no vendor library. */
#ifndef STM32F1_REGS_H
#define STM32F1_REGS_H

#include "ports/stm32_common/stm32_core_regs.h"

/* RCC */
#define RCC_CFGR_PPRE1_DIV2 (4u << 8)
#define RCC_CFGR_ADCPRE_DIV6 (2u << 14)
#define RCC_CFGR_PLLMUL9 (7u << 18)
#define RCC_APB2ENR_AFIO (1u << 0)
#define RCC_APB2ENR_GPIOA (1u << 2)
#define RCC_APB2ENR_GPIOB (1u << 3)
#define RCC_APB2ENR_GPIOC (1u << 4)
#define RCC_APB2ENR_GPIOD (1u << 5)
#define RCC_APB1ENR_TIM2 (1u << 0)
#define RCC_APB1ENR_TIM4 (1u << 2)
#define RCC_APB1ENR_USART2 (1u << 17)
#define RCC_APB1ENR_USART3 (1u << 18)

/* Flash interface (the rest in stm32_core_regs.h) */
#define FLASH_ACR_LATENCY_2 2u

/* GPIOA-D: a board's pins (stm32f1_pins.h); their clocks are RCC_APB2ENR's
 * bits 2-5, one a port in order */
#define GPIOA_BASE 0x40010800u
#define GPIOB_BASE 0x40010C00u
#define GPIOC_BASE 0x40011000u
#define GPIOD_BASE 0x40011400u
#define GPIO_CRL(b) REG32((b) + 0x00u)
#define GPIO_CRH(b) REG32((b) + 0x04u)
#define GPIOA_CRL GPIO_CRL(GPIOA_BASE)
#define GPIOA_CRH GPIO_CRH(GPIOA_BASE)
/* AFIO: the USARTs' pin remaps */
#define AFIO_BASE 0x40010000u
#define AFIO_MAPR REG32(AFIO_BASE + 0x04u)
#define AFIO_MAPR_USART1_REMAP (1u << 2)
#define AFIO_MAPR_USART2_REMAP (1u << 3)
#define AFIO_MAPR_USART3_REMAP_PARTIAL (1u << 4)
#define AFIO_MAPR_USART3_REMAP_FULL (3u << 4)
/* TIM2 and TIM4: a board's bridge may take them instead of TIM3 (its
 * registers: stm32_core_regs.h's TIM_*) */
#define TIM2_BASE 0x40000000u
#define TIM4_BASE 0x40000800u
/* 4-bit pin configurations (MODE | CNF << 2) */
#define GPIO_ANALOG 0x0u
#define GPIO_AF_PUSH_PULL_50MHZ 0xBu
#define GPIO_AF_OPEN_DRAIN_50MHZ 0xFu

/* USART1-3: a board's bus names one (stm32f1_bus.h) */
#define USART1_BASE 0x40013800u
#define USART2_BASE 0x40004400u
#define USART3_BASE 0x40004800u
#define USART_SR(b) REG32((b) + 0x00u)
#define USART_DR_OFFSET 0x04u
#define USART_DR(b) REG32((b) + USART_DR_OFFSET)
#define USART_BRR(b) REG32((b) + 0x08u)
#define USART_CR1(b) REG32((b) + 0x0Cu)
#define USART_CR3(b) REG32((b) + 0x14u)
#define USART_SR_RXNE (1u << 5)
#define USART_SR_TC (1u << 6)
#define USART_SR_TXE (1u << 7)
#define USART_SR_ORE (1u << 3)
#define USART_SR_IDLE (1u << 4)
#define USART_CR3_DMAR (1u << 6)
#define USART_CR3_DMAT (1u << 7)
#define USART_CR1_RE (1u << 2)
#define USART_CR1_IDLEIE (1u << 4)
#define USART_CR1_TE (1u << 3)
#define USART_CR1_RXNEIE (1u << 5)
#define USART_CR1_TCIE (1u << 6)
#define USART_CR1_TXEIE (1u << 7)
#define USART_CR1_UE (1u << 13)
#define USART_CR3_HDSEL (1u << 3)
#define USART1_IRQ 37u
#define USART2_IRQ 38u
#define USART3_IRQ 39u


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
/* DMA1 channel 1 serves ADC1; a bus's USART its own two channels (RM0008
 * table 78, stm32f1_bus.h). Channel n's interrupt is DMA1_CH1_IRQ + n - 1. */
#define DMA1_CH1_IRQ 11u
#define DMA1_CH7_IRQ 17u


/* 96-bit unique device ID (F103) */
#define UID_ADDR 0x1FFFF7E8u

#endif
