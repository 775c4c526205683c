/* The servo's ID and baud rate from the config store, for the bootloader:
 * the newest format-3 record whose CRC checks, without the data table's
 * full validation, so the bootloader links neither. */
#ifndef STORAGE_CONFIG_PEEK_H
#define STORAGE_CONFIG_PEEK_H

#include <stdint.h>

#include "hal/hal_flash.h"

/* Factory values (ID 0, baud index 5: 115200) when no record checks. */
void config_peek_link(const struct hal_flash *flash, uint8_t *id, uint8_t *baud_index);

#endif
