/* The config store's record, little-endian, one layout for the store
 * (config_store.c) and the bootloader's reader (config_peek.c).
 *
 * Format 3: magic u16, format u8, payload length u8, sequence u32, operating
 * time u32, the user area (USER_AREA_SIZE bytes, its own wire image), the
 * drive area (DRIVE_AREA_SIZE bytes, likewise), 0xFF up to the record's
 * last 4 bytes, and there CRC-32 over everything before it: the CRC is in
 * the last write block, whatever the block's size, so it lands last. Format 2 (older firmware) has no drive area, format 1 no
 * operating time either; the store still loads both (the drive area then
 * at its factory values), the bootloader reads format 3 only. */
#ifndef STORAGE_CONFIG_RECORD_H
#define STORAGE_CONFIG_RECORD_H

#include <stddef.h>

#include "registers/registers.h"

/* What a record keeps: the user area, then the drive area. */
#define STORED_SIZE (USER_AREA_SIZE + DRIVE_AREA_SIZE)

/* The header, the payload and the CRC, in whole 8-byte write blocks (the
 * largest a part programs at once): 72 bytes for the 32-byte user area and
 * the 24-byte drive area. */
#define CONFIG_RECORD_UNPADDED (12u + STORED_SIZE + 4u)
#define CONFIG_RECORD_SIZE ((CONFIG_RECORD_UNPADDED + 7u) / 8u * 8u)

enum {
    REC_MAGIC = 0,      /* u16 */
    REC_FORMAT = 2,     /* u8 */
    REC_LENGTH = 3,     /* u8: payload bytes */
    REC_SEQUENCE = 4,   /* u32 */
    REC_OP_SECONDS = 8, /* u32, formats 2 and 3 */
    REC_PAYLOAD = 12,   /* STORED_SIZE bytes: the user area, then the drive area */
    REC_PADDING = REC_PAYLOAD + STORED_SIZE, /* 0xFF up to the CRC */
    REC_CRC = CONFIG_RECORD_SIZE - 4, /* u32 over bytes 0..REC_CRC-1 */
    RECORD_MAGIC = 0xC0F1,
    RECORD_FORMAT = 3,
    V2_CRC = REC_PAYLOAD + USER_AREA_SIZE,
    V2_RECORD_SIZE = V2_CRC + 4,
    V2_FORMAT = 2,
    V1_PAYLOAD = 8,
    V1_CRC = V1_PAYLOAD + USER_AREA_SIZE,
    V1_RECORD_SIZE = V1_CRC + 4,
    V1_FORMAT = 1,
    /* Where the link settings are in a format-3 record. */
    REC_SERVO_ID = REC_PAYLOAD + offsetof(struct user_config, servo_id),
    REC_BAUD_INDEX = REC_PAYLOAD + offsetof(struct user_config, baud_index),
};

/* Magic, format and length: a format-3 record's first word. */
#define RECORD_HEADER_WORD                                                                   \
    ((uint32_t)RECORD_MAGIC | (uint32_t)RECORD_FORMAT << 16 | (uint32_t)STORED_SIZE << 24)

_Static_assert(REC_PADDING <= REC_CRC, "record layout");
_Static_assert(CONFIG_RECORD_SIZE % 8 == 0, "a record is whole write blocks of 2, 4 or 8 bytes");
_Static_assert(STORED_SIZE <= 255, "the payload length is a byte");

#endif
