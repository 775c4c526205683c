/* Flash kept in a file, with the STM32F1's rules (erase to 0xFF, program
 * half-words that are erased), so what the servo wrote survives a restart:
 * the config store's two pages, and the application slot.
 *
 * It also keeps the time the CPU would have stalled: the F1 fetches code
 * from the flash it is writing, so nothing runs, the main loop and the
 * interrupts alike, while a page erases or a half-word programs. The
 * datasheet's longest times are used (DS5319, "Flash memory
 * characteristics": tERASE 20-40 ms, tPROG 40-70 us, 52.5 us typical). */
#ifndef HOST_SIM_FLASH_H
#define HOST_SIM_FLASH_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_flash.h"

#define SIM_FLASH_PAGE 1024u
#define SIM_FLASH_ERASE_US 40000u
#define SIM_FLASH_PROGRAM_US 70u

struct sim_flash {
    struct hal_flash hal;
    uint8_t *mem;      /* the caller's, pages x SIM_FLASH_PAGE bytes */
    uint32_t base;     /* address of mem[0] */
    uint32_t size;
    int fd; /* the file, kept open; each erase or program writes through */
    uint32_t stall_us; /* CPU stall owed by erases and programs since last taken */
    bool created;      /* the file was new (or short): a blank chip */
    /* Injected faults: this many of the next erases, or half-word programs,
     * fail as a worn page does (FLASH_SR's PGERR or a read-back that does
     * not match): the cells keep what they held, the driver gets false. */
    uint32_t fail_erases;
    uint32_t fail_programs;
};

/* Opens (or creates, erased) the file holding `pages` pages at `base`, kept
 * in mem; false with errno on failure. hal.page_addr names the first two
 * pages (the config store's). */
bool sim_flash_open(struct sim_flash *f, const char *path, uint32_t base, uint32_t pages,
                    uint8_t *mem);

#endif
