/* The STM32G0's internal flash (RM0444 3: 2 KB pages erased by number,
 * programmed 64 bits at a time with 8 ECC bits) as a hal_flash whose
 * write block is 8 bytes: the config store, the fault history and the slot
 * writer write whole 8-byte blocks in order, the CRC last, so a power cut
 * leaves at most one torn double word, which reads back as an ECC double
 * error. That raises the NMI (RM0444 3.3.9): flash_g0_nmi_ecc takes it, and a
 * read that met one returns zeros, a record whose CRC fails, rather than
 * the torn bytes or a fault. The CPU stalls while it programs or erases;
 * every operation is verified by reading back. */
#ifndef STM32G0_FLASH_G0_H
#define STM32G0_FLASH_G0_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_flash.h"

/* The flash array: its base, erase unit and number of pages (board.h). */
struct flash_g0 {
    uint32_t base;
    uint32_t page_size;
    uint32_t pages;
};

/* f: the two pages page0 and page1 of chip's flash, 8 bytes a program step. */
void flash_g0_init(struct hal_flash *f, struct flash_g0 *chip, uint32_t page0, uint32_t page1);
/* hal_flash.read: memory-mapped; zeros where an ECC double error was met. */
void flash_g0_read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len);
/* Whether the last flash_g0_read met an ECC double error (a double word
 * a power cut left torn): its zeros are not what the flash holds. */
bool flash_g0_read_failed(void);
/* From the NMI: true if it was the flash's ECC double error (then cleared
 * and counted), false for any other cause (a fault). */
bool flash_g0_nmi_ecc(void);
/* ECC double errors met since start-up. */
uint32_t flash_g0_ecc_errors(void);

#endif
