#include "bootloader/slot_write.h"

#include <stddef.h>
#include <string.h>

#include "runtime/crc32.h"

enum slot_write_result slot_erase_page(const struct app_slot *slot, uint32_t page)
{
    const struct hal_flash *f = slot->flash;
    if (page >= slot->pages) {
        return SLOT_WRITE_OUT_OF_SLOT;
    }
    return f->erase_page(f->ctx, slot->base + page * f->page_size) ? SLOT_WRITE_OK
                                                                    : SLOT_WRITE_FLASH_FAILED;
}

enum slot_write_result slot_write(const struct app_slot *slot, uint32_t offset,
                                  const uint8_t *data, uint32_t len, uint32_t crc)
{
    const struct hal_flash *f = slot->flash;
    uint32_t block = f->write_block;
    if (crc32(data, len) != crc) {
        return SLOT_WRITE_BAD_CRC;
    }
    /* A write block is a power of two up to 8 bytes: a mask finds what is
     * off it (no division on the M0). */
    if (len == 0u || block == 0u || block > 8u || (block & (block - 1u)) != 0u ||
        ((offset | len) & (block - 1u)) != 0u ||
        offset > app_slot_size(slot) || len > app_slot_size(slot) - offset) {
        return SLOT_WRITE_OUT_OF_SLOT;
    }
    /* A block that already holds its bytes is left alone: a write repeated
     * because its answer was lost succeeds instead of meeting flash it
     * cannot program twice. One that holds neither them nor the erased
     * state is not programmed: only erasing its page mends it. So is one
     * that cannot be read (on the G0 a double word a cut left torn, read as
     * zeros: not its bytes, though they be zeros). */
    uint8_t held[8];
    for (uint32_t i = 0; i < len; i += block) {
        uint32_t at = slot->base + offset + i;
        f->read(f->ctx, at, held, block);
        bool unreadable = slot->read_failed != NULL && slot->read_failed();
        if (!unreadable && memcmp(held, &data[i], block) == 0) {
            continue;
        }
        for (uint32_t k = 0; k < block; k++) {
            if (unreadable || held[k] != 0xFFu) {
                return SLOT_WRITE_NOT_ERASED;
            }
        }
        if (!f->program(f->ctx, at, &data[i])) {
            return SLOT_WRITE_FLASH_FAILED;
        }
    }
    return SLOT_WRITE_OK;
}
