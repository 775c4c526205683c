/* Registers the STM32F0 and STM32F1 families share, and nothing more: the
 * Cortex-M core's SysTick, NVIC and SCB (ARMv6-M and ARMv7-M place them
 * alike), and at the same addresses with the same bits the RCC's first
 * registers, the flash interface (RM0008 3, RM0360 3), DMA1 (RM0008 13,
 * RM0360 10), TIM3 and the IWDG. The STM32G0 shares the core, DMA1's
 * channels, TIM3 and the IWDG (RM0444 10, 22, 24) at the same addresses. Our own minimal definitions: no vendor
 * library. */
#ifndef STM32_CORE_REGS_H
#define STM32_CORE_REGS_H

#include <stdint.h>

#define REG32(addr) (*(volatile uint32_t *)(uintptr_t)(addr))

/* Core */
#define SYSTICK_CTRL REG32(0xE000E010u)
#define SYSTICK_LOAD REG32(0xE000E014u)
#define SYSTICK_VAL REG32(0xE000E018u)
#define SYSTICK_ENABLE_CORE_CLOCK_IRQ 7u /* ENABLE | TICKINT | CLKSOURCE=core */
#define NVIC_ISER(n) REG32(0xE000E100u + 4u * (n))
#define NVIC_ICER(n) REG32(0xE000E180u + 4u * (n))
#define NVIC_ICPR(n) REG32(0xE000E280u + 4u * (n))
#define SCB_ICSR REG32(0xE000ED04u)
#define SCB_ICSR_PENDSTSET (1u << 26)
#define SCB_AIRCR REG32(0xE000ED0Cu)
#define SCB_AIRCR_RESET (0x05FA0000u | (1u << 2)) /* VECTKEY, SYSRESETREQ */
/* ARMv7-M only (B3.2): fault enables and status, and the MPU (B3.5) */
#define SCB_SHCSR REG32(0xE000ED24u)
#define SCB_SHCSR_FAULTS_OWN (7u << 16) /* MemManage, BusFault, UsageFault taken as themselves */
#define SCB_CFSR REG32(0xE000ED28u)
#define SCB_HFSR REG32(0xE000ED2Cu)
#define MPU_CTRL REG32(0xE000ED94u)
#define MPU_RNR REG32(0xE000ED98u)
#define MPU_RBAR REG32(0xE000ED9Cu)
#define MPU_RASR REG32(0xE000EDA0u)
#define MPU_CTRL_ON_DEFAULT_MAP 5u /* ENABLE, PRIVDEFENA: the default map elsewhere */

#ifndef STM32_FAMILY_G0
/* RCC: the registers and bits both families place alike (not the G0's,
 * whose RCC and flash interface are laid out anew: ports/stm32g0/stm32g0_regs.h;
 * a G0 build, STM32_FAMILY_G0, leaves these out so none is used by mistake) */
#define RCC_BASE 0x40021000u
#define RCC_CR REG32(RCC_BASE + 0x00u)
#define RCC_CFGR REG32(RCC_BASE + 0x04u)
#define RCC_AHBENR REG32(RCC_BASE + 0x14u)
#define RCC_APB2ENR REG32(RCC_BASE + 0x18u)
#define RCC_APB1ENR REG32(RCC_BASE + 0x1Cu)
#define RCC_CSR REG32(RCC_BASE + 0x24u)
/* RCC_CSR's reset flags (RM0008 7.3.10; RM0360, RCC_CSR) and the bit that clears them */
#define RCC_CSR_RMVF (1u << 24)
#define RCC_CSR_PINRSTF (1u << 26)
#define RCC_CSR_PORRSTF (1u << 27)
#define RCC_CSR_SFTRSTF (1u << 28)
#define RCC_CSR_IWDGRSTF (1u << 29)
#define RCC_CSR_WWDGRSTF (1u << 30)
#define RCC_CSR_LPWRRSTF (1u << 31)
#define RCC_CR_HSEON (1u << 16)
#define RCC_CR_HSERDY (1u << 17)
#define RCC_CR_PLLON (1u << 24)
#define RCC_CR_PLLRDY (1u << 25)
#define RCC_CFGR_SW_PLL 2u
#define RCC_CFGR_SWS_MASK (3u << 2)
#define RCC_CFGR_SWS_PLL (2u << 2)
#define RCC_CFGR_PLLSRC_HSE (1u << 16) /* F1: HSE; F0: HSE / PREDIV (1 after reset) */
#define RCC_AHBENR_DMA1 (1u << 0)
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
#endif /* STM32_FAMILY_G0 */

/* DMA1: the interrupt flags, and channel n's registers from 1 */
#define DMA1_ISR REG32(0x40020000u)
#define DMA1_IFCR REG32(0x40020004u)
#define DMA1_CCR_ADDR(n) (0x40020008u + 20u * ((n) - 1u))
#define DMA1_FLAGS(n) (0xFu << (4u * ((n) - 1u))) /* GIF, TCIF, HTIF, TEIF */
#define DMA_CCR(ch) REG32((ch) + 0x0u)
#define DMA_CNDTR(ch) REG32((ch) + 0x4u)
#define DMA_CPAR(ch) REG32((ch) + 0x8u)
#define DMA_CMAR(ch) REG32((ch) + 0xCu)
/* MINC | CIRC | PSIZE 16 | MSIZE 16 | EN: an ADC scan into RAM */
#define DMA_CCR_ADC_CIRCULAR ((1u << 7) | (1u << 5) | (1u << 8) | (1u << 10) | (1u << 0))

/* TIM3 (the H-bridge PWM on CH1/CH2), the same timer on F0 and F1 */
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

/* Independent watchdog (40 kHz LSI on both) */
#define IWDG_KR REG32(0x40003000u)
#define IWDG_PR REG32(0x40003004u)
#define IWDG_RLR REG32(0x40003008u)
#define IWDG_KEY_START 0xCCCCu
#define IWDG_KEY_ACCESS 0x5555u
#define IWDG_KEY_RELOAD 0xAAAAu

#endif
