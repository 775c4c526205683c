#include "storage/flash_erased.h"

bool flash_erased(const struct hal_flash *flash, uint32_t addr, uint32_t len)
{
    uint8_t piece[16];
    for (uint32_t at = 0; at < len; at += sizeof piece) {
        uint32_t n = len - at < sizeof piece ? len - at : (uint32_t)sizeof piece;
        flash->read(flash->ctx, addr + at, piece, n);
        for (uint32_t i = 0; i < n; i++) {
            if (piece[i] != 0xFFu) {
                return false;
            }
        }
    }
    return true;
}
