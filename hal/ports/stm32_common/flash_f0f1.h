/* The internal flash of an STM32F0 or F1 (one flash interface) as a
 * hal_flash: page erase and half-word programming, each verified by
 * reading back. The CPU stalls while it
 * programs (~50 us a half-word, ~20 ms a page erase): the config store only
 * writes after a change, from the main loop. */
#ifndef STM32_FLASH_F0F1_H
#define STM32_FLASH_F0F1_H

#include "hal/hal_flash.h"

/* page_addr: the two pages reserved for the config store. */
void flash_f0f1_init(struct hal_flash *f, uint32_t page_size, uint32_t page0, uint32_t page1);
/* hal_flash.read: the flash is memory-mapped (the target benchmark runs it). */
void flash_f0f1_read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len);

#endif
