/* Flash kept in a file, with the STM32F1's rules (erase to 0xFF, program
 * half-words that are erased), so the configuration survives a restart. */
#ifndef HOST_SIM_FLASH_H
#define HOST_SIM_FLASH_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_flash.h"

#define SIM_FLASH_PAGE 1024u

struct sim_flash {
    struct hal_flash hal;
    uint8_t mem[2 * SIM_FLASH_PAGE];
    int fd; /* the file, kept open; each erase or program writes through */
};

/* Opens (or creates, erased) the file; false with errno on failure. */
bool sim_flash_open(struct sim_flash *f, const char *path);

#endif
