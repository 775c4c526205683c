/* The config store's record, little-endian, one layout for the store
 * (config_store.c) and the bootloader's reader (config_peek.c).
 *
 * Format 2: magic u16, format u8, payload length u8, sequence u32, operating
 * time u32, the user area (USER_AREA_SIZE bytes, its own wire image), CRC-32
 * over everything before it. Format 1 (older firmware) has no operating
 * time; the store still loads it, the bootloader reads format 2 only. */
#ifndef STORAGE_CONFIG_RECORD_H
#define STORAGE_CONFIG_RECORD_H

#include <stddef.h>

#include "registers/registers.h"

/* The header, the user area and its CRC, in whole 8-byte write blocks (the
 * largest a part programs at once); padding after the CRC is written
 * erased (0xFF). 48 bytes for the maker's 32-byte user area. */
#define CONFIG_RECORD_UNPADDED (12u + USER_AREA_SIZE + 4u)
#define CONFIG_RECORD_SIZE ((CONFIG_RECORD_UNPADDED + 7u) / 8u * 8u)

enum {
    REC_MAGIC = 0,      /* u16 */
    REC_FORMAT = 2,     /* u8 */
    REC_LENGTH = 3,     /* u8: payload bytes */
    REC_SEQUENCE = 4,   /* u32 */
    REC_OP_SECONDS = 8, /* u32, format 2 */
    REC_PAYLOAD = 12,   /* USER_AREA_SIZE bytes */
    REC_CRC = REC_PAYLOAD + USER_AREA_SIZE, /* u32 over bytes 0..REC_CRC-1 */
    RECORD_MAGIC = 0xC0F1,
    RECORD_FORMAT = 2,
    V1_PAYLOAD = 8,
    V1_CRC = V1_PAYLOAD + USER_AREA_SIZE,
    V1_RECORD_SIZE = V1_CRC + 4,
    V1_FORMAT = 1,
    /* Where the link settings are in a format-2 record. */
    REC_SERVO_ID = REC_PAYLOAD + offsetof(struct user_config, servo_id),
    REC_BAUD_INDEX = REC_PAYLOAD + offsetof(struct user_config, baud_index),
};

/* Magic, format and length: a format-2 record's first word. */
#define RECORD_HEADER_WORD                                                                   \
    ((uint32_t)RECORD_MAGIC | (uint32_t)RECORD_FORMAT << 16 | (uint32_t)USER_AREA_SIZE << 24)

_Static_assert(REC_CRC + 4 == CONFIG_RECORD_UNPADDED, "record layout");
_Static_assert(CONFIG_RECORD_SIZE % 8 == 0, "a record is whole write blocks of 2, 4 or 8 bytes");

#endif
