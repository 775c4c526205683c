/* The UpdateStatus answer (0x55, docs/packets.md): who answers, the
 * versions, and the slot's geometry. One encoder for the application (which
 * knows only its version and board) and the bootloader (which knows it all). */
#ifndef PROTOCOL_UPDATE_STATUS_H
#define PROTOCOL_UPDATE_STATUS_H

#include <stdint.h>

#include "registers/byte_order.h"

enum {
    UPDATE_STATUS_LENGTH = 16,
    UPDATE_MODE_APPLICATION = 0,
    UPDATE_MODE_BOOTLOADER = 1,
};

/* What is not the answerer's to tell stays 0. */
struct update_status {
    uint8_t mode;
    uint8_t image_verdict;       /* enum app_image_verdict; bootloader only */
    uint8_t write_block;         /* bytes; bootloader only */
    uint16_t bootloader_version; /* bootloader only */
    uint16_t app_version;
    uint16_t board;
    uint16_t page_size;          /* bytes; bootloader only */
    uint16_t pages;              /* the slot's; bootloader only */
    uint16_t write_max;          /* UpdateWrite's most bytes; bootloader only */
};

/* The answer after its ID byte (out[0], the caller's). Returns its length. */
static inline uint8_t update_status_encode(const struct update_status *st,
                                           uint8_t out[UPDATE_STATUS_LENGTH])
{
    out[1] = st->mode;
    le_put_u16(&out[2], st->bootloader_version);
    out[4] = st->image_verdict;
    le_put_u16(&out[5], st->app_version);
    le_put_u16(&out[7], st->board);
    le_put_u16(&out[9], st->page_size);
    le_put_u16(&out[11], st->pages);
    out[13] = st->write_block;
    le_put_u16(&out[14], st->write_max);
    return UPDATE_STATUS_LENGTH;
}

#endif
