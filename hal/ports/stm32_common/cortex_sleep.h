#ifndef CORTEX_SLEEP_H
#define CORTEX_SLEEP_H

/* Sleep until an interrupt, without the race of checking for work and then
 * sleeping: interrupts are masked around both, and a pending interrupt ends
 * WFI whatever PRIMASK says (ARMv6-M and ARMv7-M ARM B1.5.19); its handler
 * runs once they are unmasked. may_sleep is evaluated masked. */
#define CORTEX_SLEEP_IF(may_sleep)                                                                 \
    do {                                                                                           \
        __asm__ volatile("cpsid i" ::: "memory");                                                  \
        if (may_sleep) {                                                                           \
            __asm__ volatile("wfi" ::: "memory");                                                  \
        }                                                                                          \
        __asm__ volatile("cpsie i" ::: "memory");                                                  \
    } while (0)

#endif
