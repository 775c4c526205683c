/* The STM32G0 flash driver's arithmetic, apart from its registers so that
 * the host's unit tests run it (tests/unit/test_flash_g0.c): which page an
 * erase names (PNB, by number, not by address as on the F0/F1), the double
 * word a program step writes (RM0444 3.3.7: 64 bits, the first word then
 * the second, at an 8-byte aligned address), and which status flags mean
 * the operation failed. */
#ifndef STM32G0_FLASH_G0_LOGIC_H
#define STM32G0_FLASH_G0_LOGIC_H

#include <stdbool.h>
#include <stdint.h>

#define FLASH_G0_UNIT 8u /* the program unit: a double word with its 8 ECC bits */

/* The page at addr, into *page: false unless addr is a page's first byte
 * within pages pages of flash from base (page_size a power of two). */
static inline bool flash_g0_page_of(uint32_t base, uint32_t page_size, uint32_t pages, uint32_t addr,
                                    uint32_t *page)
{
    uint32_t off = addr - base;
    if (addr < base || (off & (page_size - 1u)) != 0u) {
        return false;
    }
    uint32_t n = 0;
    for (uint32_t size = page_size; size > 1u; size >>= 1) {
        n++;
    }
    *page = off >> n;
    return *page < pages;
}

/* The two words of a double word, little-endian as the flash reads them. */
static inline uint32_t flash_g0_word(const uint8_t *data)
{
    return (uint32_t)data[0] | (uint32_t)data[1] << 8 | (uint32_t)data[2] << 16 | (uint32_t)data[3] << 24;
}

/* A program step's address: on a double word. */
static inline bool flash_g0_unit_aligned(uint32_t addr)
{
    return (addr & (FLASH_G0_UNIT - 1u)) == 0u;
}

/* Whether a finished operation's status (FLASH_SR) says it failed: any
 * error flag (RM0444 3.7.5), given the mask of them. */
static inline bool flash_g0_failed(uint32_t sr, uint32_t errors)
{
    return (sr & errors) != 0u;
}

#endif
