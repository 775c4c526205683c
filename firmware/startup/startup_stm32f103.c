/* Reset handler and vector table for the STM32F103 (Cortex-M3). */
#include <stdint.h>

#include "startup/core_vectors.h"

void DMA1_Channel5_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));

void Reset_Handler(void)
{
    startup_memory();
    (void)main();
    for (;;) {
    }
}

enum { DMA1_CHANNEL5_IRQ = 15, USART1_IRQ = 37 };

/* Core exceptions, then device interrupts up to USART1; the bootloader,
 * which sends without interrupts, stops at DMA1 channel 5 (its table is
 * 88 bytes of its 4 KB shorter). */
#ifdef STARTUP_BOOTLOADER
#define LAST_IRQ DMA1_CHANNEL5_IRQ
#else
#define LAST_IRQ USART1_IRQ
#endif
__attribute__((section(".isr_vector"), used))
static void (*const vector_table[CORE_VECTORS + LAST_IRQ + 1])(void) = {
    CORE_VECTOR_ENTRIES,
    [4] = Default_Handler,  /* MemManage */
    [5] = Default_Handler,  /* BusFault */
    [6] = Default_Handler,  /* UsageFault */
    [CORE_VECTORS + DMA1_CHANNEL5_IRQ] = DMA1_Channel5_IRQHandler,
#ifndef STARTUP_BOOTLOADER
    [CORE_VECTORS + USART1_IRQ] = USART1_IRQHandler,
#endif
};
