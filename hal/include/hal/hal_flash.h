/* Flash as the config store needs it: two erasable pages, programmed a
 * write block at a time (2 bytes on the STM32F1, 4 or 8 on parts that
 * write words or double words). A port fills one of these. */
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
    uint32_t write_block;   /* bytes one program step writes: 2, 4 or 8 */
    /* Programs write_block bytes from data at an aligned, erased address;
     * true only if the block then reads back as data. */
    bool (*program)(void *ctx, uint32_t addr, const uint8_t *data);
    void (*read)(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len);
};

#endif
