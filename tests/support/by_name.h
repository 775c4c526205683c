/* Requests built and answers read by packet and item name (the names
 * protocol/servo_schema gives them), for the servo harness's tests. */
#ifndef TEST_BY_NAME_H
#define TEST_BY_NAME_H

#include <stddef.h>
#include <stdint.h>

#include "protocol/packet_codes.h"
#include "protocol/packet_fields.h"
#include "registers/schema_items.h"

/* WriteData of value to item, at the item's size (the data table's). */
void harness_write_item(uint8_t servo_id, enum data_item_id item, int32_t value);
/* The ReadData answer of item holding value must be exactly what was sent. */
void harness_expect_item(uint8_t servo_id, enum data_item_id item, int32_t value);
/* A field of the answer last sent, which must be one whole answer of
 * packet code: ANSWER_FIELD(PKT_MONITOR, ANSWER_MONITOR_ANGLE). */
int32_t harness_answer_field(uint8_t code, size_t offset, size_t size, int is_signed);

#define WRITE_ITEM(servo_id, item, value) harness_write_item((servo_id), (item), (value))
#define EXPECT_ITEM(servo_id, item, value) harness_expect_item((servo_id), (item), (value))
#define ANSWER_FIELD(code, ...) harness_answer_field((code), __VA_ARGS__)

#endif
