#include "bootloader/app_image.h"

#include <string.h>

#include "runtime/crc32.h"
#include "protocol/wire.h"

void app_image_make_header(uint8_t header[APP_HEADER_SIZE], const uint8_t *code, uint32_t size,
                           uint16_t version, uint16_t board)
{
    memset(header, 0xFF, APP_HEADER_SIZE);
    le_put_u32(&header[0], APP_IMAGE_MAGIC);
    le_put_u16(&header[4], APP_IMAGE_FORMAT);
    le_put_u16(&header[6], board);
    le_put_u32(&header[8], size);
    le_put_u32(&header[12], crc32(code, size));
    le_put_u16(&header[16], version);
    memset(&header[18], 0, 6);
    le_put_u32(&header[APP_HEADER_CHECKED], crc32(header, APP_HEADER_CHECKED));
}

uint32_t app_slot_size(const struct app_slot *slot)
{
    return slot->pages * slot->flash->page_size;
}

enum app_image_verdict app_image_check(const struct app_slot *slot, uint16_t board,
                                       struct app_image_info *info)
{
    const struct hal_flash *f = slot->flash;
    *info = (struct app_image_info){0}; /* what a refused header tells: nothing */
    uint8_t h[APP_HEADER_CHECKED + 4u];
    f->read(f->ctx, slot->base, h, sizeof h);
    if (le_get_u32(&h[0]) != APP_IMAGE_MAGIC) {
        return APP_IMAGE_NO_HEADER;
    }
    uint32_t size = le_get_u32(&h[8]);
    if (le_get_u32(&h[APP_HEADER_CHECKED]) != crc32(h, APP_HEADER_CHECKED) ||
        le_get_u16(&h[4]) != APP_IMAGE_FORMAT || size == 0u ||
        size > app_slot_size(slot) - APP_HEADER_SIZE) {
        return APP_IMAGE_BAD_HEADER;
    }
    *info = (struct app_image_info){.size = size, .crc = le_get_u32(&h[12]),
                                    .version = le_get_u16(&h[16]), .board = le_get_u16(&h[6])};
    if (info->board != board) {
        return APP_IMAGE_WRONG_BOARD;
    }
    uint32_t state = CRC32_START;
    uint8_t chunk[64];
    for (uint32_t at = 0; at < size; at += sizeof chunk) {
        uint32_t n = size - at < sizeof chunk ? size - at : (uint32_t)sizeof chunk;
        f->read(f->ctx, slot->base + APP_HEADER_SIZE + at, chunk, n);
        state = crc32_update(state, chunk, n);
    }
    return ~state == info->crc ? APP_IMAGE_VALID : APP_IMAGE_BAD_CRC;
}
