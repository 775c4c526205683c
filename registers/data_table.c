#include "registers/data_table.h"

#include <stddef.h>
#include <string.h>

/* A row: its access with the size above it, where its field is, and its
 * range and factory value (the ID is the row's place, data_table_find). */
#define ROW(size_, access_, area_, field_, min_, max_, factory_)                   \
    {(uint8_t)((access_) | (size_) << DATA_SIZE_SHIFT), (uint8_t)offsetof(area_, field_), \
     (uint16_t)(min_), (uint16_t)(max_), (uint16_t)(factory_)}
#define RO_STATUS(id_, field_, size_) ROW(size_, DATA_READ, struct status_area, field_, 0, 0, 0)
#define USER(id_, field_, size_, access_, min_, max_, factory_)                    \
    ROW(size_, (access_) | DATA_USER, struct user_config, field_, min_, max_, factory_)
#define FIRMWARE(id_, field_, size_, access_, min_, max_, factory_)                \
    ROW(size_, (access_) | DATA_FIRMWARE, struct firmware_area, field_, min_, max_, factory_)
#define RO DATA_READ
#define RO_SIGNED (DATA_READ | DATA_SIGNED)
#define RW (DATA_READ | DATA_WRITE)
#define RW_SIGNED (DATA_READ | DATA_WRITE | DATA_SIGNED)
#define RESERVED 0u /* kept in the batch block, hidden from ReadData/WriteData */
#define RESERVED_SIGNED DATA_SIGNED

/* Rows in ID order; status area first, then the user area in wire order,
 * then the firmware area, then the drive area (protocol/servo_schema). */
static const struct data_item items[] = {DATA_ITEM_ROWS};

enum {
    ITEM_COUNT = sizeof items / sizeof items[0],
    USER_ROW = STATUS_LAST - STATUS_FIRST + 1,
    FIRMWARE_ROW = USER_ROW + (USER_LAST - USER_FIRST + 1),
    DRIVE_ROW = FIRMWARE_ROW + (FIRMWARE_LAST - FIRMWARE_FIRST + 1),
};

_Static_assert(ITEM_COUNT == DRIVE_ROW + (DRIVE_LAST - DRIVE_FIRST + 1), "table rows");
/* struct user_config is laid out as its wire image: every item at its own
 * size, in ID order, no padding (test_data_table checks each row's offset
 * against its wire position). On a little-endian CPU the wire bytes are
 * then a copy of the struct, and ReadBatchData answers at memcpy speed. */
_Static_assert(sizeof(struct user_config) == USER_AREA_SIZE + DRIVE_AREA_SIZE,
               "the user and drive areas are their wire image");
_Static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the wire and the CPU are little-endian");

const struct data_item *data_table_find(uint8_t id)
{
    if (id >= STATUS_FIRST && id <= STATUS_LAST) {
        return &items[id - STATUS_FIRST];
    }
    if (id >= USER_FIRST && id <= USER_LAST) {
        return &items[USER_ROW + (id - USER_FIRST)];
    }
    if (id >= FIRMWARE_FIRST && id <= FIRMWARE_LAST) {
        return &items[FIRMWARE_ROW + (id - FIRMWARE_FIRST)];
    }
    if (id >= DRIVE_FIRST && id <= DRIVE_LAST) {
        return &items[DRIVE_ROW + (id - DRIVE_FIRST)];
    }
    return NULL;
}

static const uint8_t *field_of(const struct registers *regs, const struct data_item *it)
{
    const uint8_t *base = (it->access & DATA_USER)       ? (const uint8_t *)&regs->user
                          : (it->access & DATA_FIRMWARE) ? (const uint8_t *)&regs->firmware
                                                         : (const uint8_t *)&regs->status;
    return base + it->offset;
}

/* Fields are naturally aligned members (offset a multiple of size, checked
 * by test_data_table): plain loads and stores, where a memcpy of unknown
 * alignment is a call on the size-first Cortex-M0 build. */

/* The value of a field as a signed 32-bit number (u32 items are never
 * range-checked, so their reinterpretation is harmless). */
static int32_t field_get(const uint8_t *field, const struct data_item *it)
{
    const void *at = field;
    switch (data_item_size(it)) {
    case 1:
        return *field;
    case 2:
        return (it->access & DATA_SIGNED) ? *(const int16_t *)at : *(const uint16_t *)at;
    default:
        return (int32_t)*(const uint32_t *)at;
    }
}

/* Only user-area (drive-area) and firmware-area items are ever written:
 * area is the item's struct. */
static void field_set(void *area, const struct data_item *it, int32_t value)
{
    void *field = (uint8_t *)area + it->offset;
    if (data_item_size(it) == 1) {
        *(uint8_t *)field = (uint8_t)value;
    } else if (data_item_size(it) == 2) {
        *(uint16_t *)field = (uint16_t)value;
    }
}

/* v is within the item's range (its bounds read as its field is). */
static bool in_range(int32_t v, const struct data_item *it)
{
    bool sign = (it->access & DATA_SIGNED) != 0u;
    int32_t min = sign ? (int16_t)it->min : it->min;
    int32_t max = sign ? (int16_t)it->max : it->max;
    return v >= min && v <= max;
}

/* Little-endian wire bytes of an item, sign-extended for signed items. */
static int32_t wire_value(const uint8_t *data, const struct data_item *it)
{
    if (data_item_size(it) == 1) {
        return data[0];
    }
    uint16_t raw = (uint16_t)(data[0] | (uint16_t)(data[1] << 8));
    return (it->access & DATA_SIGNED) ? (int32_t)(int16_t)raw : (int32_t)raw;
}

static void put_wire(uint8_t *out, const struct data_item *it, int32_t value)
{
    uint32_t v = (uint32_t)value;
    for (uint8_t i = 0; i < data_item_size(it); i++) {
        out[i] = (uint8_t)(v >> (8u * i));
    }
}

uint8_t data_table_read(const struct registers *regs, uint8_t id, uint8_t *out)
{
    const struct data_item *it = data_table_find(id);
    if (it == NULL || !(it->access & DATA_READ)) {
        return 0;
    }
    put_wire(out, it, field_get(field_of(regs, it), it));
    return data_item_size(it);
}

static bool cross_item_rules_hold(const struct user_config *cfg)
{
    return cfg->low_voltage_mv < cfg->high_voltage_mv &&
           cfg->angle_max_decideg > cfg->angle_min_decideg;
}

bool user_config_valid(const struct user_config *cfg)
{
    for (const struct data_item *it = &items[USER_ROW]; it < &items[ITEM_COUNT]; it++) {
        if ((it->access & DATA_USER) &&
            !in_range(field_get((const uint8_t *)cfg + it->offset, it), it)) {
            return false; /* a user- or drive-area item out of its range */
        }
    }
    return cross_item_rules_hold(cfg);
}

enum data_write_result data_table_write(struct registers *regs, uint8_t id, const uint8_t *data,
                                        uint8_t len, struct user_config *before)
{
    const struct data_item *it = data_table_find(id);
    if (it == NULL || !(it->access & DATA_WRITE) || len != data_item_size(it)) {
        return DATA_WRITE_REFUSED;
    }
    int32_t value = wire_value(data, it);
    if (!in_range(value, it)) {
        return DATA_WRITE_REFUSED;
    }
    if (value == field_get(field_of(regs, it), it)) {
        return DATA_WRITE_SAME;
    }
    if (it->access & DATA_FIRMWARE) { /* RAM only, no rule across items */
        field_set(&regs->firmware, it, value);
        return DATA_WRITE_SAME;
    }
    /* The user area is valid before (every write comes through here or
     * user_config_decode), so only this item and the rules across items
     * need checking. */
    *before = regs->user;
    field_set(&regs->user, it, value);
    if (!cross_item_rules_hold(&regs->user)) {
        regs->user = *before;
        return DATA_WRITE_REFUSED;
    }
    return DATA_WRITE_CHANGED;
}

/* Each item of rows from..to-1 to its factory value, in area (their struct). */
static void rows_factory(void *area, uint8_t from, uint8_t to)
{
    for (const struct data_item *it = &items[from]; it < &items[to]; it++) {
        field_set(area, it, it->factory);
    }
}

void user_config_factory(struct user_config *cfg)
{
    rows_factory(cfg, USER_ROW, FIRMWARE_ROW);
    rows_factory(cfg, DRIVE_ROW, ITEM_COUNT);
}

void firmware_area_factory(struct firmware_area *area)
{
    memset(area, 0, sizeof *area);
    rows_factory(area, FIRMWARE_ROW, DRIVE_ROW);
}

void user_config_reset(struct user_config *cfg)
{
    uint8_t servo_id = cfg->servo_id;
    uint8_t baud_index = cfg->baud_index;
    rows_factory(cfg, USER_ROW, FIRMWARE_ROW); /* the drive area stays */
    cfg->servo_id = servo_id;
    cfg->baud_index = baud_index;
}

void user_config_encode(const struct user_config *cfg, uint8_t out[USER_AREA_SIZE])
{
    memcpy(out, cfg, USER_AREA_SIZE);
}

bool user_config_decode(struct user_config *cfg, const uint8_t *in, uint8_t length)
{
    struct user_config decoded = *cfg;
    memcpy(&decoded, in, length);
    if (!user_config_valid(&decoded)) {
        return false;
    }
    *cfg = decoded;
    return true;
}

uint32_t baud_rate_of_index(uint8_t index)
{
    static const uint32_t rates[] = {9600u,   19200u,  38400u,  57600u,
                                     115200u, 250000u, 500000u, 1000000u};
    if (index < 1u || index > sizeof rates / sizeof rates[0]) {
        return 0;
    }
    return rates[index - 1u];
}
