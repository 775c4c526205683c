/* The STM32G0 flash driver (hal/ports/stm32g0/flash_g0.c, compiled for the
 * host against the model in doubles/flash_g0_model.c): pages erased by
 * number, whole double words at 8-byte boundaries, and a double word torn
 * by a power cut, which reads back as an ECC double error: the config
 * store and the fault log see no record there, the one before it wins, and
 * both go on past it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "bootloader/slot_write.h"
#include "doubles/flash_g0_model.h"
#include "ports/stm32g0/flash_g0.h"
#include "ports/stm32g0/flash_g0_logic.h"
#include "ports/stm32g0/stm32g0_regs.h"
#include "registers/data_table.h"
#include "runtime/crc32.h"
#include "storage/config_store.h"
#include "storage/fault_log.h"

static struct g0_flash_model m;
static struct flash_g0 chip;
static struct hal_flash hal;

/* The whole array erased; the store's pages the last two, as the board's. */
static int setup(void **state)
{
    (void)state;
    if (!g0_model_init(&m)) {
        return -1;
    }
    chip = (struct flash_g0){.base = m.base, .page_size = G0_MODEL_PAGE, .pages = G0_MODEL_PAGES};
    flash_g0_init(&hal, &chip, g0_model_addr(&m, 30, 0), g0_model_addr(&m, 31, 0));
    return 0;
}

static const uint8_t DATA[8] = {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};

static void test_a_page_is_erased_by_its_number(void **state)
{
    (void)state;
    uint32_t page = 99;
    assert_true(flash_g0_page_of(0x08000000u, 2048, 32, 0x08000000u, &page));
    assert_int_equal(page, 0);
    assert_true(flash_g0_page_of(0x08000000u, 2048, 32, 0x08000800u, &page));
    assert_int_equal(page, 1);
    assert_true(flash_g0_page_of(0x08000000u, 2048, 32, 0x0800F800u, &page));
    assert_int_equal(page, 31);
    assert_false(flash_g0_page_of(0x08000000u, 2048, 32, 0x08010000u, &page)); /* past the end */
    assert_false(flash_g0_page_of(0x08000000u, 2048, 32, 0x08000808u, &page)); /* inside a page */
    assert_false(flash_g0_page_of(0x08000000u, 2048, 32, 0x07FFF800u, &page)); /* below */

    /* Through the driver: data on pages 29-31, page 30 erased, only it. */
    for (uint32_t p = 29; p < 32; p++) {
        assert_true(hal.program(hal.ctx, g0_model_addr(&m, p, 8), DATA));
    }
    assert_true(hal.erase_page(hal.ctx, hal.page_addr[0]));
    for (uint32_t p = 0; p < G0_MODEL_PAGES; p++) {
        assert_int_equal(m.erases[p], p == 30u);
    }
    assert_memory_equal(&m.mem[29 * G0_MODEL_PAGE + 8], DATA, 8);
    assert_memory_equal(&m.mem[31 * G0_MODEL_PAGE + 8], DATA, 8);
    assert_int_equal(m.mem[30 * G0_MODEL_PAGE + 8], 0xFF);
    /* Not a page's first byte, or past the array: refused, nothing erased. */
    assert_false(hal.erase_page(hal.ctx, hal.page_addr[1] + 8u));
    assert_false(hal.erase_page(hal.ctx, g0_model_addr(&m, G0_MODEL_PAGES, 0)));
    assert_int_equal(m.erases[31], 0);
    assert_false(m.misuse);
}

static void test_a_program_step_is_a_whole_aligned_double_word(void **state)
{
    (void)state;
    assert_int_equal(hal.write_block, FLASH_G0_UNIT);
    assert_int_equal(FLASH_G0_UNIT, 8);
    assert_true(flash_g0_unit_aligned(0x08000008u));
    assert_false(flash_g0_unit_aligned(0x08000004u));
    assert_false(flash_g0_unit_aligned(0x08000001u));
    uint32_t a = hal.page_addr[0] + 16u;
    assert_true(hal.program(hal.ctx, a, DATA));
    assert_int_equal(m.programs, 1);
    uint8_t got[16];
    hal.read(hal.ctx, a, got, 8);
    assert_memory_equal(got, DATA, 8);
    /* Half a double word, or across two: refused before the flash is touched. */
    assert_false(hal.program(hal.ctx, a + 4u, DATA));
    assert_false(hal.program(hal.ctx, a + 10u, DATA));
    assert_int_equal(m.programs, 1);
    hal.read(hal.ctx, a + 8u, got, 8);
    for (int i = 0; i < 8; i++) {
        assert_int_equal(got[i], 0xFF);
    }
    /* A double word not erased: the flash refuses it (PROGERR) and the
     * driver says so. */
    static const uint8_t other[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    assert_false(hal.program(hal.ctx, a, other));
    hal.read(hal.ctx, a, got, 8);
    assert_memory_equal(got, DATA, 8);
    assert_true(flash_g0_failed(G0_FLASH_SR_PROGERR | G0_FLASH_SR_EOP, G0_FLASH_SR_ERRORS));
    assert_false(flash_g0_failed(G0_FLASH_SR_EOP | G0_FLASH_SR_BSY1, G0_FLASH_SR_ERRORS));
    assert_false(m.misuse);
}

/* The first double word programmed, the second torn by a cut. */
static uint32_t tear_second_unit(enum g0_tear tear)
{
    setup(NULL);
    uint32_t a = hal.page_addr[1] + 64u;
    assert_true(hal.program(hal.ctx, a, DATA));
    m.cut_at = m.steps;
    m.tear = tear;
    static const uint8_t second[8] = {0xA5, 0x5A, 0x0F, 0xF0, 0x12, 0x34, 0x56, 0x78};
    assert_false(hal.program(hal.ctx, a + 8u, second));
    g0_model_power_on(&m);
    return a;
}

static void test_a_read_that_meets_a_torn_double_word_returns_zeros(void **state)
{
    (void)state;
    for (int tear = G0_TEAR_FIRST_WORD; tear <= G0_TEAR_ECC; tear++) {
        uint32_t a = tear_second_unit((enum g0_tear)tear);
        uint32_t errors = flash_g0_ecc_errors();
        uint8_t got[24];
        hal.read(hal.ctx, a, got, sizeof got);
        assert_true(m.nmis > 0u);
        assert_int_equal(flash_g0_ecc_errors(), errors + m.nmis);
        for (size_t i = 0; i < sizeof got; i++) {
            assert_int_equal(got[i], 0);
        }
        /* Its neighbours read as they are, without an error. */
        uint32_t nmis = m.nmis;
        hal.read(hal.ctx, a, got, 8);
        assert_memory_equal(got, DATA, 8);
        hal.read(hal.ctx, a + 16u, got, 8);
        assert_int_equal(got[0], 0xFF);
        assert_int_equal(m.nmis, nmis);
        /* Nor is it erased: it cannot be programmed again. */
        assert_false(hal.program(hal.ctx, a + 8u, DATA));
        assert_false(m.misuse);
    }
}

/* An update resumed after a cut: the bootloader's write of a block the cut
 * left torn is refused (the page to be erased), though the block is to
 * hold zeros, which is what the torn double word reads as. */
static void test_a_slot_write_over_a_torn_double_word_is_refused_until_erased(void **state)
{
    (void)state;
    setup(NULL);
    const struct app_slot slot = {.flash = &hal, .base = g0_model_addr(&m, 4, 0), .pages = 4,
                                  .read_failed = flash_g0_read_failed};
    uint8_t data[16] = {0};
    memcpy(data, DATA, 8);
    assert_int_equal(slot_write(&slot, 0, DATA, 8, crc32(DATA, 8)), SLOT_WRITE_OK);
    m.cut_at = m.steps;
    m.tear = G0_TEAR_ECC;
    assert_false(hal.program(hal.ctx, slot.base + 8u, &data[8])); /* zeros, torn */
    g0_model_power_on(&m);
    assert_int_equal(slot_write(&slot, 0, data, 16, crc32(data, 16)), SLOT_WRITE_NOT_ERASED);
    assert_true(flash_g0_read_failed()); /* its last read: the torn block */
    assert_int_equal(slot_write(&slot, 0, DATA, 8, crc32(DATA, 8)), SLOT_WRITE_OK);
    assert_int_equal(slot_erase_page(&slot, 0), SLOT_WRITE_OK);
    assert_int_equal(slot_write(&slot, 0, data, 16, crc32(data, 16)), SLOT_WRITE_OK);
    uint8_t got[16];
    hal.read(hal.ctx, slot.base, got, 16);
    assert_false(flash_g0_read_failed());
    assert_memory_equal(got, data, 16);
    assert_false(m.misuse);
}

static struct user_config config_n(unsigned n)
{
    struct user_config c;
    user_config_factory(&c);
    c.stall_power_mw = (uint16_t)(n * 7u + 1u);
    c.soft_start_ms = (uint16_t)(n ^ 0x5A5Au);
    c.servo_id = (uint8_t)(n % 254u);
    return c;
}

static struct user_config boot(struct config_store *s)
{
    struct user_config c;
    g0_model_power_on(&m);
    config_store_load(s, &hal, &c);
    return c;
}

static void prepare(struct config_store *s, unsigned saved)
{
    setup(NULL);
    boot(s);
    for (unsigned i = 1; i <= saved; i++) {
        struct user_config n = config_n(i);
        assert_int_equal(config_store_save(s, &n, 0), CONFIG_SAVED);
    }
    boot(s);
}

static bool any_torn(void)
{
    for (size_t u = 0; u < G0_MODEL_UNITS; u++) {
        if (m.torn[u]) {
            return true;
        }
    }
    return false;
}

/* A cut at every step of a save, either tear: the torn record is none, the
 * config before it boots, and the next saves land, round both pages. */
static void test_the_config_store_takes_a_torn_record_for_none(void **state)
{
    (void)state;
    struct config_store s;
    prepare(&s, 0);
    const unsigned slots = config_store_slots_per_page(&s);
    const unsigned histories[] = {0, 1, slots - 1u, slots};
    unsigned torn_loads = 0;
    for (int tear = G0_TEAR_FIRST_WORD; tear <= G0_TEAR_ECC; tear++) {
        for (size_t h = 0; h < sizeof histories / sizeof histories[0]; h++) {
            unsigned saved = histories[h];
            struct user_config old_cfg = config_n(saved), new_cfg = config_n(saved + 1000u);
            if (saved == 0u) {
                user_config_factory(&old_cfg);
            }
            prepare(&s, saved);
            assert_int_equal(config_store_save(&s, &new_cfg, 0), CONFIG_SAVED);
            long total = m.steps;
            for (long cut = 0; cut < total; cut++) {
                prepare(&s, saved);
                m.cut_at = cut;
                m.tear = (enum g0_tear)tear;
                assert_int_not_equal(config_store_save(&s, &new_cfg, 0), CONFIG_SAVED);
                uint32_t nmis = m.nmis;
                struct user_config after = boot(&s);
                assert_memory_equal(&after, &old_cfg, sizeof after);
                if (any_torn()) { /* read, and met as the error it is */
                    assert_true(m.nmis > nmis);
                    torn_loads++;
                }
                for (unsigned i = 1; i <= slots + 1u; i++) {
                    struct user_config next = config_n(saved + 2000u + i);
                    assert_int_equal(config_store_save(&s, &next, 0), CONFIG_SAVED);
                    struct user_config again = boot(&s);
                    assert_memory_equal(&again, &next, sizeof again);
                }
                assert_false(m.misuse);
            }
        }
    }
    assert_true(torn_loads >= 2u * 4u * (CONFIG_RECORD_SIZE / 8u));
}

static struct fault_log log_;

/* The log's flash work as the main loop does it; false when the flash
 * refused (or died). */
static bool settle(void)
{
    for (int i = 0; i < 10000; i++) {
        if (fault_log_spare_dirty(&log_)) {
            if (!fault_log_erase_spare(&log_)) {
                return false;
            }
        } else if (!fault_log_step(&log_)) {
            return true;
        }
    }
    fail_msg("the log never settles");
    return false;
}

static struct fault_entry fault(uint8_t what, uint32_t seconds)
{
    return (struct fault_entry){.what = what, .op_seconds = seconds, .current_ma = (uint16_t)seconds};
}

/* A cut at steps of 70 faults (over a page's 64), either tear: the torn
 * record is none, every fault before it reads back, and the log goes on. */
static void test_the_fault_log_takes_a_torn_record_for_none(void **state)
{
    (void)state;
    const uint32_t faults = 70;
    unsigned torn_loads = 0;
    for (int tear = G0_TEAR_FIRST_WORD; tear <= G0_TEAR_ECC; tear++) {
        for (long cut = 0; cut < (long)faults * 4 + 2; cut += 3) {
            setup(NULL);
            fault_log_load(&log_, &hal);
            m.cut_at = cut;
            m.tear = (enum g0_tear)tear;
            uint32_t done = 0;
            for (uint32_t n = 1; n <= faults && !m.dead; n++) {
                struct fault_entry e = fault(FAULT_STALL, 20u * n);
                assert_true(fault_log_add(&log_, &e));
                if (settle() && !m.dead) {
                    done = n;
                }
            }
            g0_model_power_on(&m);
            uint32_t nmis = m.nmis;
            fault_log_load(&log_, &hal);
            assert_int_equal(log_.newest, done);
            torn_loads += any_torn() && m.nmis > nmis;
            uint8_t count = (uint8_t)(done < FAULT_HISTORY ? done : FAULT_HISTORY);
            assert_int_equal(log_.shown_count, count);
            for (uint8_t i = 0; i < count; i++) {
                struct fault_entry got = {0};
                assert_true(fault_log_read(&log_, i, (uint8_t *)&got));
                assert_int_equal(got.number, done - i);
                assert_int_equal(got.op_seconds, 20u * (done - i));
            }
            struct fault_entry e = fault(FAULT_OVER_POWER, 5000);
            assert_true(fault_log_add(&log_, &e));
            assert_true(settle());
            g0_model_power_on(&m);
            fault_log_load(&log_, &hal);
            assert_int_equal(log_.newest, done + 1u);
            struct fault_entry got = {0};
            assert_true(fault_log_read(&log_, 0, (uint8_t *)&got));
            assert_int_equal(got.what, FAULT_OVER_POWER);
            assert_false(m.misuse);
        }
    }
    assert_true(torn_loads > faults);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_a_page_is_erased_by_its_number, setup),
        cmocka_unit_test_setup(test_a_program_step_is_a_whole_aligned_double_word, setup),
        cmocka_unit_test(test_a_read_that_meets_a_torn_double_word_returns_zeros),
        cmocka_unit_test(test_a_slot_write_over_a_torn_double_word_is_refused_until_erased),
        cmocka_unit_test(test_the_config_store_takes_a_torn_record_for_none),
        cmocka_unit_test(test_the_fault_log_takes_a_torn_record_for_none),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
