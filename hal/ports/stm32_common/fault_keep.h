/* What the application does when its own code fails (docs/safety.md,
 * "The servo's own faults"). Every fault handler and unused vector of an
 * application (its startup file's Default_Handler) first turns the
 * bridge's outputs off, then calls fault_keep, which records the fault in
 * the kept RAM (kept_ram.h) and resets the chip; the next start-up logs it.
 * The stack is watched: painted at start, its bottom guarded (the M3's MPU
 * region; the M0's guard word, checked every control tick), its unused
 * depth measured a word a tick. */
#ifndef STM32_FAULT_KEEP_H
#define STM32_FAULT_KEEP_H

#include <stdint.h>

#define STACK_PAINT 0x5AC3A55Au

/* The exception's frame as the core stacked it, and IPSR: never returns. */
void fault_keep(const uint32_t *frame, uint32_t ipsr) __attribute__((noreturn));
/* Before interrupts: the M3's MPU region over the stack's bottom, and its
 * faults taken as MemManage, BusFault, UsageFault (the record says which). */
void stack_guard_start(void);
/* Each control tick's pass (hal_port.stack_watch; not every pass, so that
 * a pass with nothing to do changes nothing): the M0's guard word (a fault
 * when overwritten), a word of the unused-depth scan, and after 10 s the
 * record's fault resets in a row cleared (kept_healthy). */
void stack_watch_pass(void);
/* Bytes of stack never written since start (item 74). */
extern volatile uint16_t stack_unused_bytes;

#endif
