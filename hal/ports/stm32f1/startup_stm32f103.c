/* Reset handler and vector table for the STM32F103 (Cortex-M3). */
#include <stdint.h>

#include "ports/stm32_common/core_vectors.h"

/* The interrupts a board's bus may name (ports/stm32f1/stm32f1_bus.h:
 * USART1-3 and DMA1's channels, RM0008 Table 78), each weak: a board
 * defines the two its board.h names, by these names; the others fall to
 * the fault handler. */
#define WEAK_DEFAULT __attribute__((weak, alias("Default_Handler")))
void DMA1_Channel1_IRQHandler(void) WEAK_DEFAULT;
void DMA1_Channel2_IRQHandler(void) WEAK_DEFAULT;
void DMA1_Channel3_IRQHandler(void) WEAK_DEFAULT;
void DMA1_Channel4_IRQHandler(void) WEAK_DEFAULT;
void DMA1_Channel5_IRQHandler(void) WEAK_DEFAULT;
void DMA1_Channel6_IRQHandler(void) WEAK_DEFAULT;
void DMA1_Channel7_IRQHandler(void) WEAK_DEFAULT;
void USART2_IRQHandler(void) WEAK_DEFAULT;
void USART3_IRQHandler(void) WEAK_DEFAULT;

void Reset_Handler(void)
{
    startup_memory();
    (void)main();
    for (;;) {
    }
}

/* RM0008's vector table: DMA1 channel n is interrupt 10 + n; USART1-3 are
 * 37-39. */
enum { DMA1_CHANNEL1_IRQ = 11, DMA1_CHANNEL7_IRQ = 17, USART1_IRQ = 37, USART3_IRQ = 39 };

/* Core exceptions, then device interrupts up to USART3; the bootloader,
 * which sends without interrupts, stops at DMA1 channel 7 (its table is
 * 88 bytes of its 4 KB shorter). */
#ifdef STARTUP_BOOTLOADER
#define LAST_IRQ DMA1_CHANNEL7_IRQ
#else
#define LAST_IRQ USART3_IRQ
#endif
__attribute__((section(".isr_vector"), used))
static void (*const vector_table[CORE_VECTORS + LAST_IRQ + 1])(void) = {
    CORE_VECTOR_ENTRIES,
    [4] = Default_Handler, /* MemManage */
    [5] = Default_Handler, /* BusFault */
    [6] = Default_Handler, /* UsageFault */
    [CORE_VECTORS + DMA1_CHANNEL1_IRQ] = DMA1_Channel1_IRQHandler,
    [CORE_VECTORS + DMA1_CHANNEL1_IRQ + 1] = DMA1_Channel2_IRQHandler,
    [CORE_VECTORS + DMA1_CHANNEL1_IRQ + 2] = DMA1_Channel3_IRQHandler,
    [CORE_VECTORS + DMA1_CHANNEL1_IRQ + 3] = DMA1_Channel4_IRQHandler,
    [CORE_VECTORS + DMA1_CHANNEL1_IRQ + 4] = DMA1_Channel5_IRQHandler,
    [CORE_VECTORS + DMA1_CHANNEL1_IRQ + 5] = DMA1_Channel6_IRQHandler,
    [CORE_VECTORS + DMA1_CHANNEL7_IRQ] = DMA1_Channel7_IRQHandler,
#ifndef STARTUP_BOOTLOADER
    [CORE_VECTORS + USART1_IRQ] = USART1_IRQHandler,
    [CORE_VECTORS + USART1_IRQ + 1] = USART2_IRQHandler,
    [CORE_VECTORS + USART3_IRQ] = USART3_IRQHandler,
#endif
};
