/* The STM32F1's internal flash as a hal_flash: page erase and half-word
 * programming, each verified by reading back. The CPU stalls while it
 * programs (~50 us a half-word, ~20 ms a page erase): the config store only
 * writes after a change, from the main loop. */
#ifndef STM32F1_FLASH_F1_H
#define STM32F1_FLASH_F1_H

#include "hal/hal_flash.h"

/* page_addr: the two pages reserved for the config store. */
void flash_f1_init(struct hal_flash *f, uint32_t page_size, uint32_t page0, uint32_t page1);

#endif
