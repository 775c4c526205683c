/* Reset handler and vector table for the STM32G031 (Cortex-M0+). Its core
 * has a VTOR (parts.toml vtor; ARMv6-M B3.2.5): the table stays in flash,
 * the bootloader's at address 0, the application's 256 bytes into its slot
 * (VTOR takes a table on 256 bytes: the slot's header is that long). The
 * application points VTOR at its own table first thing, so it runs the same
 * whether the bootloader (boot_jump.c, which sets it too) or a debugger
 * started it. Every interrupt of RM0444's vector table (12.3, "Interrupt
 * and exception vectors", the G031's lines) has a weak handler that a
 * driver overrides. The NMI is the flash's ECC double error first
 * (flash_g0.h): taken and returned from; any other is a fault. */
#include <stdint.h>

#include "ports/stm32_common/core_vectors.h"
#include "ports/stm32g0/flash_g0.h"
#include "ports/stm32g0/stm32g0_regs.h"

#define WEAK_HANDLER(name) void name(void) __attribute__((weak, alias("Default_Handler")))
WEAK_HANDLER(WWDG_IRQHandler);
WEAK_HANDLER(PVD_IRQHandler);
WEAK_HANDLER(RTC_TAMP_IRQHandler);
WEAK_HANDLER(FLASH_IRQHandler);
WEAK_HANDLER(RCC_IRQHandler);
WEAK_HANDLER(EXTI0_1_IRQHandler);
WEAK_HANDLER(EXTI2_3_IRQHandler);
WEAK_HANDLER(EXTI4_15_IRQHandler);
WEAK_HANDLER(DMA1_Channel1_IRQHandler);
WEAK_HANDLER(DMA1_Channel2_3_IRQHandler);
WEAK_HANDLER(DMA1_Ch4_5_DMAMUX1_OVR_IRQHandler);
WEAK_HANDLER(ADC1_IRQHandler);
WEAK_HANDLER(TIM1_BRK_UP_TRG_COM_IRQHandler);
WEAK_HANDLER(TIM1_CC_IRQHandler);
WEAK_HANDLER(TIM2_IRQHandler);
WEAK_HANDLER(TIM3_IRQHandler);
WEAK_HANDLER(LPTIM1_IRQHandler);
WEAK_HANDLER(LPTIM2_IRQHandler);
WEAK_HANDLER(TIM14_IRQHandler);
WEAK_HANDLER(TIM16_IRQHandler);
WEAK_HANDLER(TIM17_IRQHandler);
WEAK_HANDLER(I2C1_IRQHandler);
WEAK_HANDLER(I2C2_IRQHandler);
WEAK_HANDLER(SPI1_IRQHandler);
WEAK_HANDLER(SPI2_IRQHandler);
WEAK_HANDLER(USART2_IRQHandler);
WEAK_HANDLER(LPUART1_IRQHandler);
void NMI_Handler(void);

/* The bootloader's table ends at DMA1 channels 2/3, the last interrupt it
 * takes (it sends without the USART's): 84 bytes of its 4 KB, as the F030's. */
#ifdef STARTUP_BOOTLOADER
enum { DEVICE_VECTORS = 11 };
#else
enum { DEVICE_VECTORS = 32 };
#endif

__attribute__((section(".isr_vector"), used))
static void (*const vector_table[CORE_VECTORS + DEVICE_VECTORS])(void) = {
    /* core_vectors.h's CORE_VECTOR_ENTRIES, but the NMI's own handler */
    [0] = (void (*)(void))(uintptr_t)&_estack,
    [1] = Reset_Handler,
    [2] = NMI_Handler,
    [3] = Default_Handler, /* HardFault */
    [BOARD_MARK_VECTOR] = BOARD_MARK,
    [11] = Default_Handler, /* SVCall */
    [14] = Default_Handler, /* PendSV */
    [15] = SysTick_Handler,
    [CORE_VECTORS + 0] = WWDG_IRQHandler,
    [CORE_VECTORS + 1] = PVD_IRQHandler,
    [CORE_VECTORS + 2] = RTC_TAMP_IRQHandler,
    [CORE_VECTORS + 3] = FLASH_IRQHandler,
    [CORE_VECTORS + 4] = RCC_IRQHandler,
    [CORE_VECTORS + 5] = EXTI0_1_IRQHandler,
    [CORE_VECTORS + 6] = EXTI2_3_IRQHandler,
    [CORE_VECTORS + 7] = EXTI4_15_IRQHandler,
    [CORE_VECTORS + 8] = Default_Handler, /* reserved on the G031 */
    [CORE_VECTORS + 9] = DMA1_Channel1_IRQHandler,
    [CORE_VECTORS + 10] = DMA1_Channel2_3_IRQHandler,
#ifndef STARTUP_BOOTLOADER
    [CORE_VECTORS + 11] = DMA1_Ch4_5_DMAMUX1_OVR_IRQHandler,
    [CORE_VECTORS + 12] = ADC1_IRQHandler,
    [CORE_VECTORS + 13] = TIM1_BRK_UP_TRG_COM_IRQHandler,
    [CORE_VECTORS + 14] = TIM1_CC_IRQHandler,
    [CORE_VECTORS + 15] = TIM2_IRQHandler,
    [CORE_VECTORS + 16] = TIM3_IRQHandler,
    [CORE_VECTORS + 17] = LPTIM1_IRQHandler,
    [CORE_VECTORS + 18] = LPTIM2_IRQHandler,
    [CORE_VECTORS + 19] = TIM14_IRQHandler,
    [CORE_VECTORS + 20] = Default_Handler, /* reserved on the G031 */
    [CORE_VECTORS + 21] = TIM16_IRQHandler,
    [CORE_VECTORS + 22] = TIM17_IRQHandler,
    [CORE_VECTORS + 23] = I2C1_IRQHandler,
    [CORE_VECTORS + 24] = I2C2_IRQHandler,
    [CORE_VECTORS + 25] = SPI1_IRQHandler,
    [CORE_VECTORS + 26] = SPI2_IRQHandler,
    [CORE_VECTORS + 27] = USART1_IRQHandler,
    [CORE_VECTORS + 28] = USART2_IRQHandler,
    [CORE_VECTORS + 29] = LPUART1_IRQHandler,
    [CORE_VECTORS + 30] = Default_Handler, /* reserved on the G031 */
    [CORE_VECTORS + 31] = Default_Handler, /* reserved on the G031 */
#endif
};

/* The exception entry stacked r0-r3, r12 and lr: the check may use them.
 * Not the flash's: on to the fault handler with the stack as it came. */
__attribute__((naked)) void NMI_Handler(void)
{
    __asm__ volatile("push {r0, lr}\n"
                     "bl flash_g0_nmi_ecc\n"
                     "pop {r1, r2}\n"
                     "mov lr, r2\n"
                     "cmp r0, #0\n"
                     "beq 1f\n"
                     "bx lr\n"
                     "1: ldr r2, =Default_Handler\n"
                     "bx r2\n");
}

void Reset_Handler(void)
{
#ifndef STARTUP_BOOTLOADER
    REG32(0xE000ED08u) = (uint32_t)(uintptr_t)vector_table; /* SCB->VTOR (ARMv6-M B3.2.5) */
    __asm__ volatile("dsb\n isb" ::: "memory");
#endif
    startup_memory();
    (void)main();
    for (;;) {
    }
}
