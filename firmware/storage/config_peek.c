#include "config_peek.h"

#include "config_store.h"
#include "crc32.h"
#include "protocol/wire.h"

/* Format 2 of config_store.c: magic u16, format u8, length u8, sequence
 * u32, operating time u32, user area (the ID its byte 2, the baud index
 * byte 4), CRC-32. The application rewrites a format-1 store in format 2
 * when it boots (servo.c), so the bootloader reads format 2 only. */
enum { MAGIC = 0xC0F1, FORMAT = 2, PAYLOAD = 12, AREA = 32, AREA_ID = 2, AREA_BAUD = 4 };
/* Magic, format and length in one little-endian word. */
#define HEADER ((uint32_t)MAGIC | (uint32_t)FORMAT << 16 | (uint32_t)AREA << 24)

void config_peek_link(const struct hal_flash *flash, uint8_t *id, uint8_t *baud_index)
{
    uint32_t newest = 0;
    *id = 0;
    *baud_index = 5;
    for (unsigned page = 0; page < 2u; page++) {
        for (uint32_t at = 0; at + CONFIG_RECORD_SIZE <= flash->page_size; at += CONFIG_RECORD_SIZE) {
            uint8_t rec[CONFIG_RECORD_SIZE];
            flash->read(flash->ctx, flash->page_addr[page] + at, rec, CONFIG_RECORD_SIZE);
            uint32_t seq = wire_get_u32(&rec[4]);
            uint8_t record_id = rec[PAYLOAD + AREA_ID];
            uint8_t record_baud = rec[PAYLOAD + AREA_BAUD];
            if (wire_get_u32(&rec[0]) == HEADER &&
                seq > newest && wire_get_u32(&rec[PAYLOAD + AREA]) == crc32(rec, PAYLOAD + AREA) &&
                record_id <= 254u && record_baud >= 1u && record_baud <= 8u) {
                newest = seq;
                *id = record_id;
                *baud_index = record_baud;
            }
        }
    }
}
