/* The application image in its flash slot: a 256-byte header, then the
 * application's vector table and code. The bootloader starts an image only
 * when the header and the CRC over the whole image check, so a slot half
 * erased or half written (a power cut during an update) is never started.
 *
 *   offset  size  field
 *   0       4     magic "SVAP" (0x50415653, little-endian)
 *   4       2     format (1)
 *   6       2     board (an image for another board is refused)
 *   8       4     image size: bytes from offset 256 on
 *   12      4     CRC-32 of those bytes
 *   16      2     firmware version (data item 7)
 *   18      6     reserved, 0
 *   24      4     CRC-32 of bytes 0-23
 *   28      228   0xFF (the vector table must sit 256-byte aligned)
 *
 * bootloader/servo_image writes the same layout. */
#ifndef BOOTLOADER_APP_IMAGE_H
#define BOOTLOADER_APP_IMAGE_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_flash.h"
#include "hal/must_check.h"

#define APP_IMAGE_MAGIC 0x50415653u
#define APP_IMAGE_FORMAT 1u
#define APP_HEADER_SIZE 256u  /* the vector table follows */
#define APP_HEADER_CHECKED 24u /* bytes the header's own CRC covers */
#define APP_HEADER_VERSION_AT 16u

/* The flash the application lives in: whole pages of `flash` from base. */
struct app_slot {
    const struct hal_flash *flash; /* page_size, write_block, erase, program, read */
    uint32_t base;
    uint32_t pages;
    /* Whether flash->read's last read met bytes that cannot be read (the
     * G0: a double word a power cut left torn, read as zeros); NULL on a
     * part where none can be. */
    bool (*read_failed)(void);
};

struct app_image_info {
    uint32_t size;    /* after the header */
    uint32_t crc;
    uint16_t version;
    uint16_t board;
};

enum app_image_verdict {
    APP_IMAGE_VALID,
    APP_IMAGE_NO_HEADER,   /* erased, or not an image */
    APP_IMAGE_BAD_HEADER,  /* header CRC, format or size wrong */
    APP_IMAGE_WRONG_BOARD,
    APP_IMAGE_BAD_CRC,     /* the image itself does not match its CRC */
};

uint32_t app_slot_size(const struct app_slot *slot);

/* The header for `size` bytes of code (size even), as bootloader/servo_image
 * writes it; for the simulator's factory image and the tests. */
void app_image_make_header(uint8_t header[APP_HEADER_SIZE], const uint8_t *code, uint32_t size,
                           uint16_t version, uint16_t board);

/* Reads and checks the image in the slot; info is filled from the header
 * whenever it checks (also when the image's CRC does not), and all 0 when
 * it does not. */
MUST_CHECK enum app_image_verdict app_image_check(const struct app_slot *slot, uint16_t board,
                                       struct app_image_info *info);

/* The version in the header at slot_base of memory-mapped flash, 0 if no
 * image header is there: what the application the bootloader started from
 * that slot reports as data item 7 (the bootloader checked the header). */
static inline uint16_t app_image_version_in_place(uintptr_t slot_base)
{
    const volatile uint32_t *magic = (const volatile uint32_t *)slot_base;
    const volatile uint16_t *version = (const volatile uint16_t *)(slot_base + APP_HEADER_VERSION_AT);
    return *magic == APP_IMAGE_MAGIC ? *version : 0u;
}

#endif
