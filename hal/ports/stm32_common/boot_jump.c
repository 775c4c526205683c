#include "ports/stm32_common/boot_jump.h"

#include "ports/stm32_common/stm32_core_regs.h"

#define SCB_VTOR REG32(0xE000ED08u)

/* Whether the part has a VTOR is a part fact (hal/ports/parts.toml, vtor),
 * not the architecture's: ARMv6-M makes it optional (the F030's M0 has
 * none, the G031's M0+ has one). The bootloader, the one caller, is built
 * with its board's (cmake/arm-image.cmake); the libraries' copy, which no
 * application calls, falls back to the architecture's. */
#ifndef SERVO_PART_VTOR
#if defined(__ARM_ARCH_7M__)
#define SERVO_PART_VTOR 1
#else
#define SERVO_PART_VTOR 0
#endif
#endif

/* The F1's 68 interrupt lines take two words of ICER/ICPR; ARMv6-M has 32
 * lines at most, and one word (the next is reserved: ARMv6-M ARM, B3.4). */
#if defined(__ARM_ARCH_7M__)
#define NVIC_LINE_WORDS 2u
#else
#define NVIC_LINE_WORDS 1u
#endif

void boot_restart_with(uint32_t addr, uint32_t word)
{
    REG32(addr) = word;
    __asm__ volatile("dsb" ::: "memory");
    SCB_AIRCR = SCB_AIRCR_RESET;
    for (;;) {
    }
}

uint32_t boot_take_word(uint32_t addr)
{
    uint32_t word = REG32(addr);
    REG32(addr) = 0;
    return word;
}

void boot_jump(uint32_t vector_table)
{
    uint32_t sp = REG32(vector_table);
    uint32_t entry = REG32(vector_table + 4u);
    __asm__ volatile("cpsid i" ::: "memory");
    SYSTICK_CTRL = 0;
    for (uint32_t n = 0; n < NVIC_LINE_WORDS; n++) {
        NVIC_ICER(n) = 0xFFFFFFFFu;
        NVIC_ICPR(n) = 0xFFFFFFFFu;
    }
#if SERVO_PART_VTOR
    SCB_VTOR = vector_table;
#endif /* a part without a VTOR (the F030's M0): the image's startup maps its table (startup_stm32f030.c) */
    __asm__ volatile("dsb\n"
                     "isb\n"
                     "msr msp, %0\n"
                     "cpsie i\n"
                     "bx %1\n"
                     :
                     : "r"(sp), "r"(entry)
                     : "memory");
    __builtin_unreachable();
}
