/* Between the bootloader and the application on an STM32F0 or F1: the word in
 * RAM that asks the bootloader to stay, the restart that leaves it, and
 * the jump into an image. */
#ifndef STM32_BOOT_JUMP_H
#define STM32_BOOT_JUMP_H

#include <stdint.h>

/* The last word of RAM: both images' linker scripts leave it out, and a
 * system reset keeps it. */
#define BOOT_STAY_WORD_ADDR(ram_end) ((ram_end) - 4u)

/* Leaves `word` at addr and restarts the MCU (SCB AIRCR). */
void boot_restart_with(uint32_t addr, uint32_t word);
/* Reads the word at addr and clears it. */
uint32_t boot_take_word(uint32_t addr);
/* Starts the image whose vector table is at vector_table: interrupts off
 * and cleared, SysTick stopped, VTOR (ARMv7-M), MSP, reset handler. */
void boot_jump(uint32_t vector_table) __attribute__((noreturn));

#endif
