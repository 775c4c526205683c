/* The config store: loads, saves only on change, and survives a power cut at
 * every single erase or program step with the old or the new config. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "storage/config_peek.h"
#include "storage/config_store.h"
#include "runtime/crc32.h"
#include "doubles/flash_double.h"
#include "registers/data_table.h"

static struct flash_double flash;
/* Bytes one program step writes: the STM32F1's half-word, or 8 for parts
 * that write double words (test_power_cut_at_every_step_in_8_byte_blocks). */
static uint32_t write_block = 2;

static void fresh_flash(void)
{
    flash_double_init(&flash, 1024);
    flash.hal.write_block = write_block;
}

static int setup(void **state)
{
    (void)state;
    write_block = 2;
    fresh_flash();
    return 0;
}

/* A valid config that differs from factory in a way n determines. */
static struct user_config config_n(unsigned n)
{
    struct user_config c;
    user_config_factory(&c);
    c.stall_power_mw = (uint16_t)(n * 7u + 1u);
    c.soft_start_ms = (uint16_t)(n ^ 0x5A5Au);
    c.servo_id = (uint8_t)(n % 254u);
    return c;
}

/* The user and the drive areas alike. */
static void assert_config_equal(const struct user_config *a, const struct user_config *b)
{
    assert_memory_equal(a, b, sizeof *a);
}

static struct user_config boot(struct config_store *s)
{
    struct user_config c;
    flash_double_power_on(&flash);
    config_store_load(s, &flash.hal, &c);
    return c;
}

static void test_blank_store_boots_factory(void **state)
{
    (void)state;
    struct config_store s;
    struct user_config c, factory;
    user_config_factory(&factory);
    assert_false(config_store_load(&s, &flash.hal, &c));
    assert_config_equal(&c, &factory);
}

static void test_garbage_store_boots_factory(void **state)
{
    (void)state;
    srand(7);
    for (size_t i = 0; i < sizeof flash.mem; i++) {
        ((uint8_t *)flash.mem)[i] = (uint8_t)rand();
    }
    struct config_store s;
    struct user_config c, factory;
    user_config_factory(&factory);
    assert_false(config_store_load(&s, &flash.hal, &c));
    assert_config_equal(&c, &factory);
    /* And it can still save: the garbage page gets erased first. */
    struct user_config n = config_n(1);
    assert_int_equal(config_store_save(&s, &n, 0), CONFIG_SAVED);
    struct user_config back = boot(&s);
    assert_config_equal(&back, &n);
    assert_false(flash.misuse);
}

static void test_save_round_trip_and_only_on_change(void **state)
{
    (void)state;
    struct config_store s;
    struct user_config c = boot(&s);
    /* Factory values are what a blank store boots with: nothing to write. */
    assert_int_equal(config_store_save(&s, &c, 0), CONFIG_UNCHANGED);
    assert_int_equal(flash.steps, 0);
    struct user_config n = config_n(5);
    assert_int_equal(config_store_save(&s, &n, 0), CONFIG_SAVED);
    long steps = flash.steps;
    assert_int_equal(config_store_save(&s, &n, 0), CONFIG_UNCHANGED);
    assert_int_equal(flash.steps, steps);
    struct user_config back = boot(&s);
    assert_config_equal(&back, &n);
}

static void test_record_with_invalid_values_is_ignored(void **state)
{
    (void)state;
    struct config_store s;
    boot(&s);
    struct user_config good = config_n(1);
    assert_int_equal(config_store_save(&s, &good, 0), CONFIG_SAVED);
    /* A newer record, correctly framed and CRC'd, but with 39 >= 40: it is
     * written through the store with validation bypassed by the test. */
    struct user_config bad = config_n(2);
    bad.low_voltage_mv = 9000;
    bad.high_voltage_mv = 8000;
    assert_false(user_config_valid(&bad));
    assert_int_equal(config_store_save(&s, &bad, 0), CONFIG_SAVED);
    struct user_config back = boot(&s);
    assert_config_equal(&back, &good);
}

static void test_pages_alternate_and_wear_evenly(void **state)
{
    (void)state;
    struct config_store s;
    boot(&s);
    uint16_t slots = config_store_slots_per_page(&s);
    assert_int_equal(slots, 1024 / CONFIG_RECORD_SIZE);
    unsigned saves = 10u * 2u * slots;
    for (unsigned i = 1; i <= saves; i++) {
        struct user_config n = config_n(i);
        assert_int_equal(config_store_save(&s, &n, 0), CONFIG_SAVED);
    }
    struct user_config back = boot(&s);
    struct user_config last = config_n(saves);
    assert_config_equal(&back, &last);
    /* One erase per page-full of records, shared by both pages. */
    assert_in_range(flash.erases[0], 9, 11);
    assert_in_range(flash.erases[1], 9, 11);
    assert_false(flash.misuse);
}

/* Brings the store to `saved` records, the newest being config_n(saved). */
static void prepare(struct config_store *s, unsigned saved)
{
    fresh_flash();
    boot(s);
    for (unsigned i = 1; i <= saved; i++) {
        struct user_config n = config_n(i);
        assert_int_equal(config_store_save(s, &n, 0), CONFIG_SAVED);
    }
    boot(s);
}

/* The core guarantee: a cut at any step of a save, in any way the step can
 * be left, boots the old config until the very last step completes, then the
 * new one; and the store keeps working afterwards. */
static void test_power_cut_at_every_step(void **state)
{
    (void)state;
    struct config_store s;
    prepare(&s, 0);
    uint16_t slots = config_store_slots_per_page(&s);
    /* Newest record: none, first slot, mid page, last-but-one, page full
     * (the save must erase the other page), and after a page switch. */
    const unsigned histories[] = {0, 1, 5, slots - 1u, slots, slots + 1u, 2u * slots};
    unsigned cuts_checked = 0;
    for (size_t h = 0; h < sizeof histories / sizeof histories[0]; h++) {
        unsigned saved = histories[h];
        struct user_config old_cfg;
        if (saved == 0) {
            user_config_factory(&old_cfg);
        } else {
            old_cfg = config_n(saved);
        }
        struct user_config new_cfg = config_n(saved + 1000u);

        /* How many steps a clean save takes from this history. */
        prepare(&s, saved);
        assert_int_equal(config_store_save(&s, &new_cfg, 0), CONFIG_SAVED);
        long total = flash.steps;
        assert_true(total >= CONFIG_RECORD_SIZE / write_block);

        for (long cut = 0; cut < total; cut++) {
            for (int mode = 0; mode < CUT_MODES; mode++) {
                prepare(&s, saved);
                flash.cut_at = cut;
                flash.cut_mode = (enum cut_mode)mode;
                enum config_save_result cut_save = config_store_save(&s, &new_cfg, 0);
                struct user_config after = boot(&s);
                bool last_step_done = cut == total - 1 && mode == CUT_AFTER;
                /* A save the cut stopped never reports success. */
                if (!last_step_done) {
                    assert_int_not_equal(cut_save, CONFIG_SAVED);
                }
                assert_config_equal(&after, last_step_done ? &new_cfg : &old_cfg);
                /* The store recovers: the next save lands and boots. */
                struct user_config next = config_n(saved + 2000u);
                assert_int_equal(config_store_save(&s, &next, 0), CONFIG_SAVED);
                struct user_config again = boot(&s);
                assert_config_equal(&again, &next);
                assert_false(flash.misuse);
                cuts_checked++;
            }
        }
    }
    /* Every step of every history was cut in every mode. */
    assert_true(cuts_checked > 7u * CUT_MODES * (CONFIG_RECORD_SIZE / write_block));
}

/* The same guarantee on a part that programs 8 bytes at a time. */
static void test_power_cut_at_every_step_in_8_byte_blocks(void **state)
{
    write_block = 8;
    test_power_cut_at_every_step(state);
    assert_int_equal(flash.hal.write_block, 8);
}

/* Long random life: saves with cuts at random points, booting after each. */
static void test_random_cuts_over_many_saves(void **state)
{
    (void)state;
    struct config_store s;
    prepare(&s, 0);
    srand(12345);
    struct user_config current;
    user_config_factory(&current);
    for (unsigned i = 1; i <= 3000; i++) {
        struct user_config next = config_n(i);
        bool cut = rand() % 3 == 0;
        flash.cut_at = cut ? rand() % 30 : -1;
        flash.cut_mode = (enum cut_mode)(rand() % CUT_MODES);
        enum config_save_result r = config_store_save(&s, &next, 0);
        struct user_config after = boot(&s);
        if (!cut) {
            assert_int_equal(r, CONFIG_SAVED);
            assert_config_equal(&after, &next);
        } else {
            uint8_t ea[USER_AREA_SIZE], eo[USER_AREA_SIZE], en[USER_AREA_SIZE];
            user_config_encode(&after, ea);
            user_config_encode(&current, eo);
            user_config_encode(&next, en);
            assert_true(memcmp(ea, eo, USER_AREA_SIZE) == 0 ||
                        memcmp(ea, en, USER_AREA_SIZE) == 0);
        }
        current = after;
    }
    assert_false(flash.misuse);
}

/* Five records of an older format in page 1, the newest holding old:
 * format 1 (44 bytes, no operating time) or 2 (48 bytes, no drive area). */
static void write_old_store(uint8_t format, const struct user_config *old)
{
    const uint32_t payload = format == 1u ? 8u : 12u, size = payload + USER_AREA_SIZE + 4u;
    for (uint32_t seq = 1; seq <= 5; seq++) {
        uint8_t *rec = &flash.mem[1][(seq - 1u) * size];
        struct user_config c = seq == 5 ? *old : config_n(seq + 40u);
        memset(rec, 0, payload);
        rec[0] = 0xF1; /* magic 0xC0F1 */
        rec[1] = 0xC0;
        rec[2] = format;
        rec[3] = USER_AREA_SIZE;
        rec[4] = (uint8_t)seq;
        user_config_encode(&c, &rec[payload]);
        uint32_t crc = crc32(rec, payload + USER_AREA_SIZE);
        for (uint32_t i = 0; i < 4u; i++) {
            rec[payload + USER_AREA_SIZE + i] = (uint8_t)(crc >> (8u * i));
        }
    }
}

/* A store written by the firmware before format 2 still loads; the first
 * save starts a fresh page in format 3 and the old page is left alone until
 * its turn to be erased. */
static void test_a_format_1_store_still_loads(void **state)
{
    (void)state;
    struct user_config old = config_n(3);
    write_old_store(1, &old);
    struct config_store s;
    struct user_config back = boot(&s);
    assert_config_equal(&back, &old);
    assert_int_equal(s.sequence, 5);
    uint8_t id, baud;
    config_peek_link(&flash.hal, &id, &baud); /* the bootloader reads format 3 only */
    assert_int_equal(id, 0);
    struct user_config n = config_n(4);
    assert_int_equal(config_store_save(&s, &n, 77), CONFIG_SAVED);
    config_peek_link(&flash.hal, &id, &baud); /* once rewritten in format 3 */
    assert_int_equal(id, n.servo_id);
    assert_int_equal(flash.erases[0], 0); /* page 0 was blank: no erase spent */
    assert_int_equal(flash.erases[1], 0);
    back = boot(&s);
    assert_config_equal(&back, &n);
    assert_int_equal(s.sequence, 6);
    assert_int_equal(s.op_seconds, 77);
    assert_false(flash.misuse);
}

/* A save in steps: one write block a call, no erase among them; the
 * other page is erased only when asked, ahead of need, and a save that
 * would need it says so instead of erasing. */
static void test_a_save_goes_in_steps_and_erases_only_ahead(void **state)
{
    (void)state;
    struct config_store s;
    boot(&s);
    const uint16_t slots = config_store_slots_per_page(&s);
    unsigned n = 1;
    for (unsigned page = 0; page < 2; page++) {
        for (uint16_t slot = 0; slot < slots; slot++) {
            struct user_config c = config_n(n++);
            assert_int_equal(config_store_begin(&s, &c, 0), CONFIG_STARTED);
            long erases = flash.erases[0] + flash.erases[1];
            for (unsigned b = 1; b < CONFIG_RECORD_SIZE / write_block; b++) {
                assert_int_equal(config_store_step(&s), CONFIG_BUSY);
                /* Until the last block (the CRC) lands, a boot loads the old. */
                struct config_store other;
                struct user_config back = boot(&other);
                assert_int_equal(other.sequence, s.sequence);
                (void)back;
            }
            assert_int_equal(config_store_step(&s), CONFIG_SAVED);
            assert_int_equal(flash.erases[0] + flash.erases[1], erases);
            struct config_store other;
            struct user_config back = boot(&other);
            assert_config_equal(&back, &c);
        }
    }
    /* Both pages full: the next record needs page 0 erased first. */
    assert_true(config_store_spare_dirty(&s));
    struct user_config c = config_n(n);
    assert_int_equal(config_store_begin(&s, &c, 0), CONFIG_NEEDS_ERASE);
    assert_true(config_store_erase_spare(&s));
    assert_false(config_store_spare_dirty(&s));
    assert_int_equal(config_store_save(&s, &c, 0), CONFIG_SAVED);
    struct user_config back = boot(&s);
    assert_config_equal(&back, &c);
    assert_false(flash.misuse);
}

/* What the bootloader reads: the newest record's ID and baud rate, and
 * factory values on a blank store. */
static void test_the_bootloader_peeks_the_link_settings(void **state)
{
    (void)state;
    uint8_t id = 99, baud = 99;
    config_peek_link(&flash.hal, &id, &baud);
    assert_int_equal(id, 0);
    assert_int_equal(baud, 5);
    struct config_store s;
    boot(&s);
    for (unsigned n = 1; n <= 30; n++) { /* across a page change */
        struct user_config c = config_n(n);
        c.baud_index = (uint8_t)(1u + n % 8u);
        assert_int_equal(config_store_save(&s, &c, 0), CONFIG_SAVED);
        config_peek_link(&flash.hal, &id, &baud);
        assert_int_equal(id, c.servo_id);
        assert_int_equal(baud, c.baud_index);
    }
}

static void test_failed_flash_write_is_reported(void **state)
{
    (void)state;
    struct config_store s;
    boot(&s);
    flash.cut_at = 3; /* the flash stops answering mid-record */
    struct user_config n = config_n(1);
    assert_int_equal(config_store_save(&s, &n, 0), CONFIG_WRITE_FAILED);
    assert_int_equal(s.write_failures, 1);
    assert_true(s.failed);
}

/* Format 2 (the user area alone) loads with the drive area at its factory
 * values, and the first save writes both in format 3. */
static void test_a_format_2_store_loads_with_the_factory_drive_area(void **state)
{
    (void)state;
    struct user_config old = config_n(6); /* its drive area: factory */
    write_old_store(2, &old);
    struct config_store s;
    struct user_config back = boot(&s);
    assert_config_equal(&back, &old);
    assert_true(s.legacy);
    back.gain_kd = 1234;
    assert_int_equal(config_store_save(&s, &back, 5), CONFIG_SAVED);
    struct user_config again = boot(&s);
    assert_false(s.legacy);
    assert_config_equal(&again, &back);
    uint8_t id, baud;
    config_peek_link(&flash.hal, &id, &baud);
    assert_int_equal(id, old.servo_id);
}

/* The drive area is kept with the user area: a change to it alone is a
 * new record, and a record whose drive item is out of range is not loaded
 * (the one before it is). */
static void test_the_drive_area_is_kept_and_checked(void **state)
{
    (void)state;
    struct config_store s;
    struct user_config c = boot(&s);
    c.resistance_mohm = 6400;
    c.gear_ratio = 300;
    assert_int_equal(config_store_save(&s, &c, 0), CONFIG_SAVED);
    assert_int_equal(config_store_save(&s, &c, 0), CONFIG_UNCHANGED);
    struct user_config back = boot(&s);
    assert_config_equal(&back, &c);
    struct user_config bad = c;
    bad.gain_kp = 5000; /* above item 86's 1023 */
    assert_false(user_config_valid(&bad));
    assert_int_equal(config_store_save(&s, &bad, 0), CONFIG_SAVED);
    back = boot(&s);
    assert_config_equal(&back, &c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_blank_store_boots_factory, setup),
        cmocka_unit_test_setup(test_garbage_store_boots_factory, setup),
        cmocka_unit_test_setup(test_save_round_trip_and_only_on_change, setup),
        cmocka_unit_test_setup(test_record_with_invalid_values_is_ignored, setup),
        cmocka_unit_test_setup(test_pages_alternate_and_wear_evenly, setup),
        cmocka_unit_test_setup(test_power_cut_at_every_step, setup),
        cmocka_unit_test_setup(test_power_cut_at_every_step_in_8_byte_blocks, setup),
        cmocka_unit_test_setup(test_random_cuts_over_many_saves, setup),
        cmocka_unit_test_setup(test_a_format_1_store_still_loads, setup),
        cmocka_unit_test_setup(test_a_save_goes_in_steps_and_erases_only_ahead, setup),
        cmocka_unit_test_setup(test_the_bootloader_peeks_the_link_settings, setup),
        cmocka_unit_test_setup(test_failed_flash_write_is_reported, setup),
        cmocka_unit_test_setup(test_a_format_2_store_loads_with_the_factory_drive_area, setup),
        cmocka_unit_test_setup(test_the_drive_area_is_kept_and_checked, setup),
    };
    return cmocka_run_group_tests_name("config_store", tests, NULL, NULL);
}
