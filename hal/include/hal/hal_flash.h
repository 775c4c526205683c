/* Flash as the config store needs it: two erasable pages and half-word
 * programming, as on the STM32F1. A port fills one of these. */
#ifndef HAL_HAL_FLASH_H
#define HAL_HAL_FLASH_H

#include <stdbool.h>
#include <stdint.h>

struct hal_flash {
    void *ctx;
    uint32_t page_size;     /* bytes, a multiple of 2 */
    uint32_t page_addr[2];  /* the two pages given to the config store */
    /* Sets every byte of the page at addr to 0xFF. */
    bool (*erase_page)(void *ctx, uint32_t addr);
    /* Programs one half-word at an even, erased address. */
    bool (*program_u16)(void *ctx, uint32_t addr, uint16_t value);
    void (*read)(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len);
};

#endif
