/* The data table against docs/protocol.md (the items, their factory values
 * and "Reading and writing items"): every item. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "registers/data_table.h"

static struct registers regs;
static struct user_config before; /* what a write changed */

static int setup(void **state)
{
    (void)state;
    memset(&regs, 0, sizeof regs);
    user_config_factory(&regs.user);
    return 0;
}

/* Factory values as docs/protocol.md lists them, on the wire (ReadBatchData). */
static const uint8_t factory_block[USER_AREA_SIZE] = {
    1,    /* 32 check flag */
    0,    /* 33 control response */
    0,    /* 34 servo ID */
    0,    /* 35 reserved */
    5,    /* 36 baud 115200 */
    0,    /* 37 stall protection */
    0x10, 0x27, /* 38 10000 mW */
    0xA0, 0x0F, /* 39 4000 mV */
    0xD0, 0x20, /* 40 8400 mV */
    0x8B, 0x02, /* 41 651 */
    0x10, 0x27, /* 42 10000 mW */
    0xA0, 0x0F, /* 43 4000 mA */
    0,    /* 44 */
    0,    /* 45 */
    0,    /* 46 */
    0,    /* 47 */
    1,    /* 48 */
    1,    /* 49 */
    0xB8, 0x0B, /* 50 3000 ms */
    0x46, 0x05, /* 51 1350 */
    0xBA, 0xFA, /* 52 -1350 */
    0x00, 0x00, /* 53 */
};

static void test_factory_block_is_the_documented_one(void **state)
{
    (void)state;
    uint8_t block[USER_AREA_SIZE];
    user_config_encode(&regs.user, block);
    assert_memory_equal(block, factory_block, USER_AREA_SIZE);
}

static void test_every_user_item_reads_its_factory_bytes(void **state)
{
    (void)state;
    unsigned pos = 0;
    for (uint8_t id = 32; id <= 53; id++) {
        const struct data_item *it = data_table_find(id);
        assert_non_null(it);
        uint8_t out[DATA_ITEM_MAX_SIZE];
        uint8_t n = data_table_read(&regs, id, out);
        if (id == 35 || id == 45) {
            assert_int_equal(n, 0); /* reserved: not public */
        } else {
            assert_int_equal(n, data_item_size(it));
            assert_memory_equal(out, &factory_block[pos], n);
        }
        pos += data_item_size(it);
    }
    assert_int_equal(pos, USER_AREA_SIZE);
}

static void test_status_items_read_live_values(void **state)
{
    (void)state;
    regs.status = (struct status_area){
        .voltage_mv = 7400,
        .current_ma = 350,
        .power_mw = 2590,
        .temperature_adc = 2048,
        .status = 0x41,
        .model = 0x0F00,
        .firmware_version = 0x0010,
        .serial_number = 0xA1B2C3D4,
    };
    const struct {
        uint8_t id;
        uint8_t size;
        uint8_t bytes[4];
    } expect[] = {
        {1, 2, {0xE8, 0x1C}}, {2, 2, {0x5E, 0x01}}, {3, 2, {0x1E, 0x0A}},
        {4, 2, {0x00, 0x08}}, {5, 1, {0x41}},       {6, 2, {0x00, 0x0F}},
        {7, 2, {0x10, 0x00}}, {8, 4, {0xD4, 0xC3, 0xB2, 0xA1}},
    };
    for (size_t i = 0; i < sizeof expect / sizeof expect[0]; i++) {
        uint8_t out[DATA_ITEM_MAX_SIZE];
        assert_int_equal(data_table_read(&regs, expect[i].id, out), expect[i].size);
        assert_memory_equal(out, expect[i].bytes, expect[i].size);
    }
}

static void test_unknown_ids_read_nothing(void **state)
{
    (void)state;
    const uint8_t unknown[] = {0, 9, 20, 31, 54, 100, 255};
    for (size_t i = 0; i < sizeof unknown; i++) {
        uint8_t out[DATA_ITEM_MAX_SIZE];
        assert_null(data_table_find(unknown[i]));
        assert_int_equal(data_table_read(&regs, unknown[i], out), 0);
    }
}

static void test_status_and_reserved_items_refuse_writes(void **state)
{
    (void)state;
    const uint8_t four[4] = {1, 2, 3, 4};
    for (uint8_t id = 1; id <= 8; id++) {
        const struct data_item *it = data_table_find(id);
        assert_int_equal(data_table_write(&regs, id, four, data_item_size(it), &before), DATA_WRITE_REFUSED);
    }
    assert_int_equal(data_table_write(&regs, 35, four, 1, &before), DATA_WRITE_REFUSED);
    assert_int_equal(data_table_write(&regs, 45, four, 1, &before), DATA_WRITE_REFUSED);
    assert_int_equal(data_table_write(&regs, 54, four, 1, &before), DATA_WRITE_REFUSED);
    test_factory_block_is_the_documented_one(state);
}

/* Range of every writable item: its limits accepted, one past refused. */
static void test_every_item_range(void **state)
{
    (void)state;
    const struct {
        uint8_t id;
        int32_t min, max;
    } ranges[] = {
        {32, 1, 1},         {33, 0, 1},         {34, 0, 254},       {36, 1, 8},
        {37, 0, 1},         {38, 0, 65535},     {39, 0, 8399},      {40, 4001, 65535},
        {41, 0, 65535},     {42, 0, 65535},     {43, 0, 65535},     {44, 0, 255},
        {46, 0, 1},         {47, 0, 1},         {48, 0, 2},         {49, 0, 1},
        {50, 0, 65535},     {51, -1349, 1800},  {52, -1800, 1349},  {53, -1800, 1800},
    };
    for (size_t i = 0; i < sizeof ranges / sizeof ranges[0]; i++) {
        const struct data_item *it = data_table_find(ranges[i].id);
        assert_non_null(it);
        int32_t probes[] = {ranges[i].min - 1, ranges[i].min, ranges[i].max, ranges[i].max + 1};
        for (size_t p = 0; p < 4; p++) {
            int32_t v = probes[p];
            bool representable = data_item_size(it) == 1 ? (v >= 0 && v <= 255)
                                 : (it->access & DATA_SIGNED) ? (v >= -32768 && v <= 32767)
                                                              : (v >= 0 && v <= 65535);
            if (!representable) {
                continue;
            }
            setup(NULL);
            uint8_t bytes[2] = {(uint8_t)((uint32_t)v & 0xFF), (uint8_t)(((uint32_t)v >> 8) & 0xFF)};
            bool ok = data_table_write(&regs, ranges[i].id, bytes, data_item_size(it), &before) != DATA_WRITE_REFUSED;
            bool in_range = v >= ranges[i].min && v <= ranges[i].max;
            assert_int_equal(ok, in_range);
            uint8_t out[DATA_ITEM_MAX_SIZE];
            assert_int_equal(data_table_read(&regs, ranges[i].id, out), data_item_size(it));
            if (ok) {
                assert_memory_equal(out, bytes, data_item_size(it));
            }
        }
    }
}

static void test_wrong_data_length_is_refused(void **state)
{
    (void)state;
    const uint8_t bytes[4] = {1, 0, 0, 0};
    assert_int_equal(data_table_write(&regs, 33, bytes, 2, &before), DATA_WRITE_REFUSED); /* 1-byte item */
    assert_int_equal(data_table_write(&regs, 38, bytes, 1, &before), DATA_WRITE_REFUSED); /* 2-byte item */
    assert_int_equal(data_table_write(&regs, 38, bytes, 3, &before), DATA_WRITE_REFUSED);
    assert_int_equal(data_table_write(&regs, 33, bytes, 1, &before), DATA_WRITE_CHANGED);
}

static void test_unchanged_value_is_reported_as_same(void **state)
{
    (void)state;
    const uint8_t v3000[] = {0xB8, 0x0B};
    assert_int_equal(data_table_write(&regs, 50, v3000, 2, &before), DATA_WRITE_SAME);
    const uint8_t one[] = {1};
    assert_int_equal(data_table_write(&regs, 32, one, 1, &before), DATA_WRITE_SAME);
    const uint8_t v3001[] = {0xB9, 0x0B};
    assert_int_equal(data_table_write(&regs, 50, v3001, 2, &before), DATA_WRITE_CHANGED);
    assert_int_equal(regs.user.soft_start_ms, 3001);
}

static void test_cross_item_rules(void **state)
{
    (void)state;
    /* 39 < 40: raising the low limit to the high one is refused. */
    const uint8_t v8400[] = {0xD0, 0x20};
    assert_int_equal(data_table_write(&regs, 39, v8400, 2, &before), DATA_WRITE_REFUSED);
    const uint8_t v8399[] = {0xCF, 0x20};
    assert_int_equal(data_table_write(&regs, 39, v8399, 2, &before), DATA_WRITE_CHANGED);
    /* 51 > 52 */
    const uint8_t minus1350[] = {0xBA, 0xFA};
    assert_int_equal(data_table_write(&regs, 51, minus1350, 2, &before), DATA_WRITE_REFUSED);
    const uint8_t v1350[] = {0x46, 0x05};
    assert_int_equal(data_table_write(&regs, 52, v1350, 2, &before), DATA_WRITE_REFUSED);
}

static void test_batch_decode_is_all_or_nothing(void **state)
{
    (void)state;
    uint8_t block[USER_AREA_SIZE];
    memcpy(block, factory_block, sizeof block);
    block[1] = 1;      /* control response on: valid */
    block[4] = 9;      /* baud index 9: invalid */
    assert_false(user_config_decode(&regs.user, block, USER_AREA_SIZE));
    assert_int_equal(regs.user.control_response, 0); /* nothing applied */
    block[4] = 8;
    block[3] = 0x77;   /* reserved bytes are stored as given */
    block[19] = 0x99; /* 45 */
    assert_true(user_config_decode(&regs.user, block, USER_AREA_SIZE));
    uint8_t back[USER_AREA_SIZE];
    user_config_encode(&regs.user, back);
    assert_memory_equal(back, block, USER_AREA_SIZE);
}

/* The firmware copies struct user_config as the wire's user area: each
 * item's field must sit at its wire position (sizes in ID order), and a
 * batch read must give what ReadData gives item by item. */
static void test_the_user_area_is_its_wire_image(void **state)
{
    (void)state;
    unsigned pos = 0;
    for (uint8_t id = 32; id <= 53; id++) {
        const struct data_item *it = data_table_find(id);
        assert_non_null(it);
        assert_int_equal(it->offset, pos);
        pos += data_item_size(it);
    }
    assert_int_equal(pos, USER_AREA_SIZE);
    for (unsigned seed = 0; seed < 64; seed++) {
        for (unsigned i = 0; i < sizeof regs.user; i++) {
            ((uint8_t *)&regs.user)[i] = (uint8_t)(seed * 37u + i * 11u);
        }
        uint8_t block[USER_AREA_SIZE];
        user_config_encode(&regs.user, block);
        pos = 0;
        for (uint8_t id = 32; id <= 53; id++) {
            uint8_t one[4];
            uint8_t n = data_table_read(&regs, id, one);
            if (n != 0u) {
                assert_memory_equal(one, &block[pos], n);
            }
            pos += data_item_size(data_table_find(id));
        }
    }
}

/* Fields are read and written with plain loads and stores of their size:
 * each must be naturally aligned in its area. */
static void test_every_field_is_naturally_aligned(void **state)
{
    (void)state;
    unsigned found = 0;
    for (unsigned id = 0; id <= 255u; id++) {
        const struct data_item *it = data_table_find((uint8_t)id);
        if (it != NULL) {
            found++;
            assert_int_equal(it->offset % data_item_size(it), 0);
        }
    }
    assert_true(found >= 30u);
}

static void test_reset_keeps_id_and_baud(void **state)
{
    (void)state;
    regs.user.servo_id = 7;
    regs.user.baud_index = 8;
    regs.user.control_response = 1;
    regs.user.angle_max_decideg = 900;
    regs.user.reserved_45 = 3;
    user_config_reset(&regs.user);
    assert_int_equal(regs.user.servo_id, 7);
    assert_int_equal(regs.user.baud_index, 8);
    assert_int_equal(regs.user.control_response, 0);
    assert_int_equal(regs.user.angle_max_decideg, 1350);
    assert_int_equal(regs.user.reserved_45, 0);
}

static void test_baud_rates(void **state)
{
    (void)state;
    const uint32_t rates[] = {0, 9600, 19200, 38400, 57600, 115200, 250000, 500000, 1000000, 0};
    for (uint8_t i = 0; i < 10; i++) {
        assert_int_equal(baud_rate_of_index(i), rates[i]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_factory_block_is_the_documented_one, setup),
        cmocka_unit_test_setup(test_every_user_item_reads_its_factory_bytes, setup),
        cmocka_unit_test_setup(test_status_items_read_live_values, setup),
        cmocka_unit_test_setup(test_unknown_ids_read_nothing, setup),
        cmocka_unit_test_setup(test_status_and_reserved_items_refuse_writes, setup),
        cmocka_unit_test_setup(test_every_item_range, setup),
        cmocka_unit_test_setup(test_wrong_data_length_is_refused, setup),
        cmocka_unit_test_setup(test_unchanged_value_is_reported_as_same, setup),
        cmocka_unit_test_setup(test_cross_item_rules, setup),
        cmocka_unit_test_setup(test_batch_decode_is_all_or_nothing, setup),
        cmocka_unit_test_setup(test_the_user_area_is_its_wire_image, setup),
        cmocka_unit_test_setup(test_every_field_is_naturally_aligned, setup),
        cmocka_unit_test_setup(test_reset_keeps_id_and_baud, setup),
        cmocka_unit_test_setup(test_baud_rates, setup),
    };
    return cmocka_run_group_tests_name("data_table", tests, NULL, NULL);
}
