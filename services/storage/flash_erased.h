/* Whether flash reads erased (all 0xFF): a slot before a record goes into
 * it, a page before records start on it. Both logs (the config store, the
 * fault history) ask. */
#ifndef STORAGE_FLASH_ERASED_H
#define STORAGE_FLASH_ERASED_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_flash.h"

/* The len bytes from addr all read 0xFF. Reads in small pieces: a page's
 * check takes no page-sized buffer. */
bool flash_erased(const struct hal_flash *flash, uint32_t addr, uint32_t len);

#endif
