/* Reset handler and vector table for the STM32F030 (Cortex-M0). ARMv6-M
 * has no VTOR: the core takes its vectors from address 0, which is the
 * bootloader's flash. The application builds its table at the start of RAM
 * and maps RAM there (SYSCFG MEM_MODE, RM0360 9.1.1) before any interrupt
 * is enabled; the linker script keeps those 192 bytes out of .data/.bss.
 * The bootloader (STARTUP_BOOTLOADER) is what sits at address 0: its table
 * stays in flash, and ends at DMA1 channel 2/3, since it sends without the
 * USART's interrupt (84 bytes of its 4 KB shorter). */
#include <stdint.h>

#include "ports/stm32_common/core_vectors.h"
#include "ports/stm32f0/stm32f0_regs.h"

void DMA1_Channel2_3_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));

#ifdef STARTUP_BOOTLOADER
#define LAST_IRQ DMA1_CH3_IRQ
#else
#define LAST_IRQ USART1_IRQ
#endif
enum { VECTORS = CORE_VECTORS + LAST_IRQ + 1 };

#ifdef STARTUP_BOOTLOADER
__attribute__((section(".isr_vector"), used))
static void (*const vector_table[VECTORS])(void) = {
    CORE_VECTOR_ENTRIES,
    [CORE_VECTORS + DMA1_CH3_IRQ] = DMA1_Channel2_3_IRQHandler,
};
#else
/* The application's table in flash holds only what is read there: the
 * stack's top and the reset handler (the bootloader's jump) and the board's
 * mark (servoctl image). The table the core uses is built in RAM: every
 * vector the fault handler, then the few the application has. */
__attribute__((section(".isr_vector"), used))
static void (*const vector_table[BOARD_MARK_VECTOR + 1])(void) = {
    [0] = (void (*)(void))(uintptr_t)&_estack,
    [1] = Reset_Handler,
    [BOARD_MARK_VECTOR] = BOARD_MARK,
};
#endif

void Reset_Handler(void)
{
#ifndef STARTUP_BOOTLOADER
    extern void (*_ram_vectors[VECTORS])(void);
    for (uint32_t i = 0; i < VECTORS; i++) {
        _ram_vectors[i] = Default_Handler;
    }
    _ram_vectors[CORE_VECTORS - 1] = SysTick_Handler;
    _ram_vectors[CORE_VECTORS + DMA1_CH3_IRQ] = DMA1_Channel2_3_IRQHandler;
    _ram_vectors[CORE_VECTORS + USART1_IRQ] = USART1_IRQHandler;
    RCC_APB2ENR |= RCC_APB2ENR_SYSCFG;
    SYSCFG_CFGR1 = SYSCFG_CFGR1_MEM_MODE_SRAM;
#endif
    startup_memory();
    (void)main();
    for (;;) {
    }
}
