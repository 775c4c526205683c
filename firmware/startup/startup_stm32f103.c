/* Reset handler and vector table for the STM32F103 (Cortex-M3). */
#include <stdint.h>

#include "startup/board_mark.h"
#include "startup/startup_memory.h"

int main(void);
void Reset_Handler(void);
void Default_Handler(void);
void SysTick_Handler(void) __attribute__((weak, alias("Default_Handler")));
void USART1_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));
void DMA1_Channel5_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));

void Reset_Handler(void)
{
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

enum { CORE_VECTORS = 16, DMA1_CHANNEL5_IRQ = 15, USART1_IRQ = 37 };

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
    [0] = (void (*)(void))(uintptr_t)&_estack,
    [1] = Reset_Handler,
    [2] = Default_Handler,  /* NMI */
    [3] = Default_Handler,  /* HardFault */
    [4] = Default_Handler,  /* MemManage */
    [5] = Default_Handler,  /* BusFault */
    [6] = Default_Handler,  /* UsageFault */
    [BOARD_MARK_VECTOR] = BOARD_MARK,
    [11] = Default_Handler, /* SVCall */
    [14] = Default_Handler, /* PendSV */
    [15] = SysTick_Handler,
    [CORE_VECTORS + DMA1_CHANNEL5_IRQ] = DMA1_Channel5_IRQHandler,
#ifndef STARTUP_BOOTLOADER
    [CORE_VECTORS + USART1_IRQ] = USART1_IRQHandler,
#endif
};
