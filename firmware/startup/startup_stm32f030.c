/* Reset handler and vector table for the STM32F030 (Cortex-M0). ARMv6-M
 * has no VTOR: the core takes its vectors from address 0, which is the
 * bootloader's flash. The application copies its table to the start of RAM
 * and maps RAM there (SYSCFG MEM_MODE, RM0360 9.1.1) before any interrupt
 * is enabled; the linker script keeps those 192 bytes out of .data/.bss.
 * The bootloader (STARTUP_BOOTLOADER) is what sits at address 0: its table
 * stays in flash, and ends at DMA1 channel 2/3, since it sends without the
 * USART's interrupt (84 bytes of its 4 KB shorter). */
#include <stdint.h>

#include "startup/core_vectors.h"
#include "ports/stm32f0/stm32f0_regs.h"

void DMA1_Channel2_3_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));

#ifdef STARTUP_BOOTLOADER
#define LAST_IRQ DMA1_CH3_IRQ
#else
#define LAST_IRQ USART1_IRQ
#endif
enum { VECTORS = CORE_VECTORS + LAST_IRQ + 1 };

__attribute__((section(".isr_vector"), used))
static void (*const vector_table[VECTORS])(void) = {
    CORE_VECTOR_ENTRIES,
    [CORE_VECTORS + DMA1_CH3_IRQ] = DMA1_Channel2_3_IRQHandler,
#ifndef STARTUP_BOOTLOADER
    [CORE_VECTORS + USART1_IRQ] = USART1_IRQHandler,
#endif
};

void Reset_Handler(void)
{
#ifndef STARTUP_BOOTLOADER
    extern uint32_t _ram_vectors;
    uint32_t *ram = &_ram_vectors;
    for (uint32_t i = 0; i < VECTORS; i++) {
        ram[i] = (uint32_t)(uintptr_t)vector_table[i];
    }
    RCC_APB2ENR |= RCC_APB2ENR_SYSCFG;
    SYSCFG_CFGR1 = SYSCFG_CFGR1_MEM_MODE_SRAM;
#endif
    startup_memory();
    (void)main();
    for (;;) {
    }
}

void Default_Handler(void)
{
    for (;;) {
    }
}
