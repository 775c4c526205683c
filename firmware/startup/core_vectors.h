/* What the STM32 startup files share: the handlers every image has, and the
 * vector table's core entries common to ARMv6-M and ARMv7-M (B1.5.2 of
 * both): the stack's top, reset, NMI, HardFault, the board's mark in the
 * reserved vector 7, SVCall, PendSV, SysTick. Each startup file defines
 * Reset_Handler and Default_Handler and lists its device interrupts. */
#ifndef STARTUP_CORE_VECTORS_H
#define STARTUP_CORE_VECTORS_H

#include <stdint.h>

#include "startup/board_mark.h"
#include "startup/startup_memory.h"

int main(void);
void Reset_Handler(void);
void Default_Handler(void);
void SysTick_Handler(void) __attribute__((weak, alias("Default_Handler")));
void USART1_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));

enum { CORE_VECTORS = 16 };

#define CORE_VECTOR_ENTRIES                            \
    [0] = (void (*)(void))(uintptr_t)&_estack,         \
    [1] = Reset_Handler,                               \
    [2] = Default_Handler, /* NMI */                   \
    [3] = Default_Handler, /* HardFault */             \
    [BOARD_MARK_VECTOR] = BOARD_MARK,                  \
    [11] = Default_Handler, /* SVCall */               \
    [14] = Default_Handler, /* PendSV */               \
    [15] = SysTick_Handler

#endif
