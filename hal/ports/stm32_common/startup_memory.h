/* What every reset handler does before main: .data from its flash copy,
 * .bss cleared, and in an application the stack painted below the reset
 * handler's own frame, so the main loop can find how deep it has ever
 * reached and whether it reached its bottom (ports/stm32_common/fault_keep.h;
 * symbols from hal/ports/stm32_common/linker/sections_stm32.ld). */
#ifndef STARTUP_MEMORY_H
#define STARTUP_MEMORY_H

#include <stdint.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _sstack, _estack;

#define STARTUP_STACK_PAINT 0x5AC3A55Au /* fault_keep.h's STACK_PAINT */
#define STARTUP_FRAME_WORDS 32u         /* the reset handler's own, at the top */

static inline void startup_memory(void)
{
    uint32_t *src = &_sidata;
    for (uint32_t *dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0;
    }
#ifndef STARTUP_BOOTLOADER
    uint32_t *painted_end = (uint32_t *)((uintptr_t)&_estack - 4u * STARTUP_FRAME_WORDS);
    for (uint32_t *dst = &_sstack; dst < painted_end;) {
        *dst++ = STARTUP_STACK_PAINT;
    }
#endif
}

#endif
