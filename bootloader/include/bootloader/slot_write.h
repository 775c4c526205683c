/* Writing a new image into the application slot, as the update packets
 * ask: erase a page, program bytes at an offset after checking their CRC,
 * read them back. Nothing here decides whether the slot holds a valid
 * image: app_image_check() does, from the header and the image's CRC, so
 * a power cut at any step leaves an image that is either whole or refused. */
#ifndef BOOTLOADER_SLOT_WRITE_H
#define BOOTLOADER_SLOT_WRITE_H

#include <stdint.h>

#include "bootloader/app_image.h"
#include "hal/must_check.h"

enum slot_write_result {
    SLOT_WRITE_OK = 0,
    SLOT_WRITE_BAD_CRC = 1,     /* the data does not match its CRC: damaged on the wire */
    SLOT_WRITE_OUT_OF_SLOT = 2, /* beyond the slot, or not whole write blocks */
    /* the flash refused (worn), or the block reads back otherwise
     * (hal_flash.program says which it did) */
    SLOT_WRITE_FLASH_FAILED = 3,
    /* a block holds neither its bytes nor the erased state (a program step
     * cut short, or other bytes): nothing programmed; erase its page and
     * write the page again */
    SLOT_WRITE_NOT_ERASED = 5,
};

/* Erases page `page` of the slot. */
MUST_CHECK enum slot_write_result slot_erase_page(const struct app_slot *slot, uint32_t page);

/* Programs len bytes at offset into the slot if crc32(data) == crc; blocks
 * that already hold their bytes are skipped, so a repeated write succeeds;
 * one neither erased nor holding them refuses the write (NOT_ERASED). */
MUST_CHECK enum slot_write_result slot_write(const struct app_slot *slot, uint32_t offset,
                                  const uint8_t *data, uint32_t len, uint32_t crc);

#endif
