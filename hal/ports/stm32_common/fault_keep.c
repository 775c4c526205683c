#include "ports/stm32_common/fault_keep.h"

#include <stdbool.h>

#include "ports/stm32_common/kept_ram.h"
#include "ports/stm32_common/stm32_core_regs.h"

/* The linker's (hal/ports/stm32_common/linker): the stack's bottom and top, RAM's start. */
extern uint32_t _sstack, _estack, _ram_start;

/* The bottom of the stack an overflow must not pass unseen: larger than
 * any one frame the images' functions take at once (config_store_load's
 * 200 B on the F103 and the G031, the largest; the build's .su files), so no
 * frame can step over it. */
#define GUARD_BYTES 256u
#if defined(__ARM_ARCH_7M__)
/* The MPU's region over it, aligned to its size (ARMv7-M B3.5.8: the
 * linker aligns the stack so, BOARD_STACK_ALIGN), no access, never
 * executed: an overflow faults at the first store into it. */
#define GUARD_AT (((uint32_t)(uintptr_t)&_sstack + GUARD_BYTES - 1u) & ~(GUARD_BYTES - 1u))
#define WATCH_FROM ((uint32_t *)(uintptr_t)(GUARD_AT + GUARD_BYTES))
#define RASR_XN (1u << 28)
#define RASR_SIZE_256 (7u << 1) /* 2^(SIZE+1) bytes */
#else
/* The M0 has no MPU: the word at the bottom is checked every tick, and the
 * band above it by the depth scan (a word a tick, from the bottom up). */
#define WATCH_FROM (&_sstack + 1)
#define BAND_TOP ((uint32_t *)(uintptr_t)((uintptr_t)&_sstack + GUARD_BYTES))
#endif

/* Control ticks without a fault reset after which the next one is the
 * first in a row again (safe mode: app/servo_safety.h): 10 s at 1 kHz. */
#define HEALTHY_TICKS 10000u

volatile uint16_t stack_unused_bytes;
static uint32_t *scan_at;
static uint32_t *lowest_used;
static uint16_t ticks_run;

void fault_keep(const uint32_t *frame, uint32_t ipsr)
{
    struct hal_reset *r = &_kept_ram.reset;
#if defined(__ARM_ARCH_7M__)
    MPU_CTRL = 0; /* the frame may lie in the guard */
    uint32_t cfsr = SCB_CFSR;
    uint32_t hfsr = SCB_HFSR;
    r->mm_bus_status = (uint16_t)cfsr;
    r->usage_status = (uint8_t)(((cfsr >> 16) & 0xFu) | ((cfsr >> 20) & 0x30u) | ((hfsr << 5) & 0x40u) |
                                ((hfsr >> 23) & 0x80u));
#endif
    uint32_t at = (uint32_t)(uintptr_t)frame;
    bool readable = at >= (uint32_t)(uintptr_t)&_ram_start && at <= (uint32_t)(uintptr_t)&_estack - 32u;
    r->pc = readable ? frame[6] : 0u;
    r->lr = readable ? frame[5] : 0u;
    r->sp_offset = (uint16_t)(at - (uint32_t)(uintptr_t)&_ram_start);
    r->exception = (uint8_t)ipsr;
    _kept_ram.note = KEPT_FAULT;
    struct kept_ram *k = &_kept_ram;
    kept_seal(k);
    __asm__ volatile("dsb" ::: "memory");
    SCB_AIRCR = SCB_AIRCR_RESET;
    for (;;) {
    }
}

void stack_guard_start(void)
{
#if defined(__ARM_ARCH_7M__)
    MPU_RNR = 0;
    MPU_RBAR = GUARD_AT;
    MPU_RASR = RASR_XN | RASR_SIZE_256 | 1u; /* AP 0: no access */
    MPU_CTRL = MPU_CTRL_ON_DEFAULT_MAP;
    SCB_SHCSR |= SCB_SHCSR_FAULTS_OWN;
    __asm__ volatile("dsb\n isb" ::: "memory");
#endif
    scan_at = WATCH_FROM;
    lowest_used = &_estack;
}

void stack_watch_pass(void)
{
#if !defined(__ARM_ARCH_7M__)
    if (_sstack != STACK_PAINT || lowest_used < BAND_TOP) {
        /* The stack reached its bottom band: the bridge off first, as a
         * fault handler would, then the record (no frame: this pass's SP). */
        extern uint32_t _bridge_off;
        *(volatile uint32_t *)(uintptr_t)&_bridge_off = 0u;
        uint32_t sp;
        __asm__ volatile("mov %0, sp" : "=r"(sp));
        fault_keep((const uint32_t *)(uintptr_t)sp, HAL_FAULT_STACK_GUARD);
    }
#endif
    if (ticks_run < HEALTHY_TICKS && ++ticks_run == HEALTHY_TICKS) {
        kept_healthy();
    }
    uint32_t *at = scan_at;
    if (*at != STACK_PAINT) {
        lowest_used = at;
        stack_unused_bytes = (uint16_t)((uint32_t)(uintptr_t)at - (uint32_t)(uintptr_t)&_sstack);
        at = WATCH_FROM;
    } else if (++at >= lowest_used) {
        at = WATCH_FROM;
    }
    scan_at = at;
}
