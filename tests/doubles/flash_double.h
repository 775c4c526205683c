/* Two flash pages in RAM with NOR semantics (erase to 0xFF, programming
 * only clears bits) and a power cut that can be placed at any erase or
 * program step. */
#ifndef TEST_FLASH_DOUBLE_H
#define TEST_FLASH_DOUBLE_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_flash.h"

#define FLASH_DOUBLE_PAGE_MAX 1024u
#define FLASH_DOUBLE_BASE 0x0800F800u

/* What an interrupted step leaves behind. */
enum cut_mode {
    CUT_BEFORE,   /* the step never happened */
    CUT_AFTER,    /* the step completed, then the power went */
    CUT_PARTIAL,  /* erase: first half of the page; program: some bits */
    CUT_SCATTER,  /* erase: every other byte; program: other bits */
    CUT_MODES,
};

struct flash_double {
    uint8_t mem[2][FLASH_DOUBLE_PAGE_MAX];
    struct hal_flash hal;
    long steps;        /* erase and program steps performed so far */
    long cut_at;       /* step at which the power fails; -1 for never */
    enum cut_mode cut_mode;
    bool dead;         /* power is gone: nothing more changes */
    uint32_t erases[2];
    bool misuse;       /* programmed a non-erased or odd address */
    /* Called while an erase stalls the CPU: a test lets time pass and
     * bytes arrive there. */
    void (*during_erase)(void *ctx);
    void *during_erase_ctx;
};

void flash_double_init(struct flash_double *f, uint32_t page_size);
/* Power back on: the same memory, a new life. */
void flash_double_power_on(struct flash_double *f);

#endif
