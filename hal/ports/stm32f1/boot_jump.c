#include "boot_jump.h"

#include "stm32f1_regs.h"

#define SCB_VTOR REG32(0xE000ED08u)
#define SCB_AIRCR REG32(0xE000ED0Cu)
#define AIRCR_RESET (0x05FA0000u | (1u << 2)) /* VECTKEY, SYSRESETREQ */
#define NVIC_ICER(n) REG32(0xE000E180u + 4u * (n))
#define NVIC_ICPR(n) REG32(0xE000E280u + 4u * (n))

void boot_restart_with(uint32_t addr, uint32_t word)
{
    REG32(addr) = word;
    __asm__ volatile("dsb" ::: "memory");
    SCB_AIRCR = AIRCR_RESET;
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
    for (uint32_t n = 0; n < 2u; n++) { /* the F1's 68 interrupt lines */
        NVIC_ICER(n) = 0xFFFFFFFFu;
        NVIC_ICPR(n) = 0xFFFFFFFFu;
    }
    SCB_VTOR = vector_table;
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
