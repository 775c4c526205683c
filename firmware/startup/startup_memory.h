/* What every reset handler does before main: .data from its flash copy,
 * .bss cleared (symbols from firmware/linker/sections_stm32.ld). */
#ifndef STARTUP_MEMORY_H
#define STARTUP_MEMORY_H

#include <stdint.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;

static inline void startup_memory(void)
{
    uint32_t *src = &_sidata;
    for (uint32_t *dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0;
    }
}

#endif
