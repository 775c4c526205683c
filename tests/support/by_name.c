#include "support/by_name.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>

#include <cmocka.h>

#include "registers/data_table.h"
#include "support/servo_harness.h"

static const struct data_item *item_row(enum data_item_id item)
{
    const struct data_item *row = data_table_find((uint8_t)item);
    assert_non_null(row);
    return row;
}

/* value's size low bytes, little-endian, after two bytes (servo ID, item). */
static size_t put_item(uint8_t *out, uint8_t servo_id, enum data_item_id item, int32_t value)
{
    const struct data_item *row = item_row(item);
    out[0] = servo_id;
    out[1] = (uint8_t)item;
    for (size_t k = 0; k < data_item_size(row); k++) {
        out[2 + k] = (uint8_t)((uint32_t)value >> (8u * k));
    }
    return 2u + data_item_size(row);
}

void harness_write_item(uint8_t servo_id, enum data_item_id item, int32_t value)
{
    uint8_t content[2 + DATA_ITEM_MAX_SIZE];
    harness_request(PKT_WRITE_DATA, content, put_item(content, servo_id, item, value));
}

void harness_expect_item(uint8_t servo_id, enum data_item_id item, int32_t value)
{
    uint8_t content[2 + DATA_ITEM_MAX_SIZE];
    uint8_t frame[64];
    size_t n = make_response(frame, PKT_READ_DATA, content, put_item(content, servo_id, item, value));
    harness_assert_sent(frame, n);
}

int32_t harness_answer_field(uint8_t code, size_t offset, size_t size, int is_signed)
{
    /* header (2), code, length, content, checksum: the frame the content
     * makes must be the one sent */
    assert_true(hal.sent_length >= 5u);
    size_t length = hal.sent[3];
    assert_true(offset + size <= length && 5u + length <= 64u);
    uint8_t frame[64];
    harness_assert_sent(frame, make_response(frame, code, &hal.sent[4], length));
    uint32_t v = 0;
    for (size_t k = 0; k < size; k++) {
        v |= (uint32_t)hal.sent[4u + offset + k] << (8u * k);
    }
    if (is_signed && size < 4u && (v >> (8u * size - 1u)) != 0u) {
        v |= ~0u << (8u * size);
    }
    return (int32_t)v;
}
