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

/* Two pages from page0 on, programmed two bytes a step (the STM32F0/F1's
 * half-words), by these operations on ctx. */
static inline struct hal_flash hal_flash_two_pages(void *ctx, uint32_t page_size, uint32_t page0,
                                                   bool (*erase_page)(void *, uint32_t),
                                                   bool (*program)(void *, uint32_t, const uint8_t *),
                                                   void (*read)(void *, uint32_t, uint8_t *, uint32_t))
{
    return (struct hal_flash){.ctx = ctx, .page_size = page_size, .page_addr = {page0, page0 + page_size},
                              .erase_page = erase_page, .write_block = 2, .program = program, .read = read};
}

#endif
