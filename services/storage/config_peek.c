#include "storage/config_peek.h"

#include "storage/config_record.h"
#include "runtime/crc32.h"
#include "registers/byte_order.h"

/* The newest format-3 record whose CRC checks (config_record.h). The
 * application rewrites an older store in format 3 when it boots (servo.c),
 * so the bootloader reads format 3 only. */
void config_peek_link(const struct hal_flash *flash, uint8_t *id, uint8_t *baud_index)
{
    uint32_t newest = 0;
    *id = 0;
    *baud_index = BAUD_INDEX_FACTORY;
    for (unsigned page = 0; page < 2u; page++) {
        for (uint32_t at = 0; at + CONFIG_RECORD_SIZE <= flash->page_size; at += CONFIG_RECORD_SIZE) {
            uint8_t rec[CONFIG_RECORD_SIZE];
            flash->read(flash->ctx, flash->page_addr[page] + at, rec, CONFIG_RECORD_SIZE);
            uint32_t seq = le_get_u32(&rec[REC_SEQUENCE]);
            uint8_t record_id = rec[REC_SERVO_ID];
            uint8_t record_baud = rec[REC_BAUD_INDEX];
            if (le_get_u32(&rec[REC_MAGIC]) == RECORD_HEADER_WORD &&
                seq > newest && le_get_u32(&rec[REC_CRC]) == crc32(rec, REC_CRC) &&
                record_id <= SERVO_ID_MAX && record_baud >= BAUD_INDEX_MIN &&
                record_baud <= BAUD_INDEX_MAX) {
                newest = seq;
                *id = record_id;
                *baud_index = record_baud;
            }
        }
    }
}
