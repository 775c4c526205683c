/* The data table: one row per data item (ID, size, signedness, access,
 * range, factory value, storage), and the operations packets 3-6 and 2 need.
 * The code reads the table; no item has code of its own except the two
 * cross-item rules (39 < 40, 51 > 52). */
#ifndef REGISTERS_DATA_TABLE_H
#define REGISTERS_DATA_TABLE_H

#include <stdbool.h>
#include <stdint.h>

#include "registers/registers.h"

enum data_access {
    DATA_READ = 1u << 0,   /* ReadData answers the value */
    DATA_WRITE = 1u << 1,  /* WriteData may change it */
    DATA_SIGNED = 1u << 2,
    DATA_USER = 1u << 3,   /* lives in struct user_config (user and drive areas) */
    DATA_FIRMWARE = 1u << 4, /* lives in struct firmware_area; else status_area */
    DATA_SIZE_SHIFT = 5,     /* the size, 1, 2 or 4, is the bits from here */
};

struct data_item {
    uint8_t access;   /* enum data_access, and the size above DATA_SIZE_SHIFT */
    uint8_t offset;   /* offsetof() in its area's struct */
    /* The writable items are 1 or 2 bytes: these are the field's own bits
     * (signed where the access says DATA_SIGNED). */
    uint16_t min;     /* accepted range for writes, inclusive */
    uint16_t max;
    uint16_t factory; /* factory value (docs/protocol.md) */
};

/* Bytes on the wire: 1, 2 or 4. */
static inline uint8_t data_item_size(const struct data_item *it)
{
    return (uint8_t)(it->access >> DATA_SIZE_SHIFT);
}

/* Largest item: the serial number, 4 bytes. */
#define DATA_ITEM_MAX_SIZE 4u

const struct data_item *data_table_find(uint8_t id);

/* ReadData: the item's bytes into out (DATA_ITEM_MAX_SIZE); 0 when the ID is
 * unknown or not public. */
uint8_t data_table_read(const struct registers *regs, uint8_t id, uint8_t *out);

enum data_write_result {
    DATA_WRITE_REFUSED,   /* not writable, wrong size or invalid: unchanged */
    DATA_WRITE_SAME,      /* accepted; nothing to store (the item already held
                           * that value, or it is a firmware item: RAM only) */
    DATA_WRITE_CHANGED,   /* accepted and changed (a user or drive item): the
                           * store must save it */
};

/* WriteData: applies the value only if the item is writable, len matches its
 * size and the resulting configuration is valid. On DATA_WRITE_CHANGED,
 * before holds the user and drive areas as they were (to put back). */
enum data_write_result data_table_write(struct registers *regs, uint8_t id, const uint8_t *data,
                                        uint8_t len, struct user_config *before);

/* The user and drive areas at their factory values (the drive area's: the
 * reference board's). */
void user_config_factory(struct user_config *cfg);
/* The firmware area's writable items at their factory values, the rest 0. */
void firmware_area_factory(struct firmware_area *area);
/* ResetUserData: the user area's factory values except the servo ID and the
 * baud rate; the drive area (the hardware's) stays. */
void user_config_reset(struct user_config *cfg);
bool user_config_valid(const struct user_config *cfg);
/* The user area's wire image (the batch block). */
void user_config_encode(const struct user_config *cfg, uint8_t out[USER_AREA_SIZE]);
/* The first length bytes of cfg's wire image from in (USER_AREA_SIZE: the
 * batch block; sizeof *cfg: both areas), validated with the rest of cfg;
 * cfg is changed only when the result is valid. */
bool user_config_decode(struct user_config *cfg, const uint8_t *in, uint8_t length);

/* Baud rate for data ID 36's index (1-8); 0 for an invalid index. */
uint32_t baud_rate_of_index(uint8_t index);

#endif
