/* Writing a new image into the application slot, as the update packets
 * ask: erase a page, program bytes at an offset after checking their CRC,
 * read them back. Nothing here decides whether the slot holds a valid
 * image: app_image_check() does, from the header and the image's CRC, so
 * a power cut at any step leaves an image that is either whole or refused. */
#ifndef BOOTLOADER_SLOT_WRITE_H
#define BOOTLOADER_SLOT_WRITE_H

#include <stdint.h>

#include "app_image.h"

enum slot_write_result {
    SLOT_WRITE_OK = 0,
    SLOT_WRITE_BAD_CRC = 1,     /* the data does not match its CRC: damaged on the wire */
    SLOT_WRITE_OUT_OF_SLOT = 2, /* beyond the slot, or not whole write blocks */
    SLOT_WRITE_FLASH_FAILED = 3, /* the flash refused (not erased, worn) */
    SLOT_WRITE_READ_BACK = 4,   /* programmed, but reads back otherwise */
};

/* Erases page `page` of the slot. */
enum slot_write_result slot_erase_page(const struct app_slot *slot, uint32_t page);

/* Programs len bytes at offset into the slot if crc32(data) == crc. */
enum slot_write_result slot_write(const struct app_slot *slot, uint32_t offset,
                                  const uint8_t *data, uint32_t len, uint32_t crc);

#endif
