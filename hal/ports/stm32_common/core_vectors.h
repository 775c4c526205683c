/* What the STM32 startup files share: the handlers every image has, the
 * vector table's core entries common to ARMv6-M and ARMv7-M (B1.5.2 of
 * both): the stack's top, reset, NMI, HardFault, the board's mark in the
 * reserved vector 7, SVCall, PendSV, SysTick; and the handler of every
 * fault and unused vector. Each startup file defines Reset_Handler and
 * lists its device interrupts. */
#ifndef STARTUP_CORE_VECTORS_H
#define STARTUP_CORE_VECTORS_H

#include <stdint.h>

#include "ports/stm32_common/board_mark.h"
#include "ports/stm32_common/startup_memory.h"

int main(void);
void Reset_Handler(void);
void Default_Handler(void);
void SysTick_Handler(void) __attribute__((weak, alias("Default_Handler")));
void USART1_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));

enum { CORE_VECTORS = 16 };

#if defined(STARTUP_BOOTLOADER) || defined(STARTUP_NO_BRIDGE)
/* A bootloader, or an image on a board without a servo's bridge (the
 * servobus example's bus master), keeps no record: a fault spins until a
 * reset. */
void Default_Handler(void)
{
    for (;;) {
    }
}
#else
/* An application's: the bridge's outputs off in the first instructions
 * (the board's register, _bridge_off, from its board.h by the linker
 * script; one store, no stack), then on a stack it can trust (its own, or
 * from the top again when the frame lies near the bottom: an overflow)
 * fault_keep records the frame and resets (ports/stm32_common/fault_keep.h). */
__attribute__((naked)) void Default_Handler(void)
{
    __asm__ volatile("ldr r0, =_bridge_off\n"
                     "movs r1, #0\n"
                     "str r1, [r0]\n"
                     "mrs r0, msp\n"
                     "ldr r2, =_stack_room\n"
                     "cmp r0, r2\n"
                     "bhs 1f\n"
                     "ldr r2, =_estack\n"
                     "mov sp, r2\n"
                     "1: mrs r1, ipsr\n"
                     "ldr r2, =fault_keep\n"
                     "bx r2\n");
}
#endif

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
