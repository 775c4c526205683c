/* Why the servo last started, as the STM32 boards read it at start-up
 * (ports/stm32_common/kept_ram.c): the reset flags and the record kept in
 * RAM, into the kinds the fault history logs, the counts of item 73 and
 * the fault resets in a row that make safe mode. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "ports/stm32_common/kept_ram.c"

struct kept_ram _kept_ram; /* the linker's on the boards */

static struct kept_ram kept;

static const struct hal_reset *start(uint32_t csr)
{
    reset_classify(csr, &kept);
    return &kept.reset;
}

/* What RAM holds after a power-on: whatever the cells settled to. */
static void power_on_ram(void)
{
    memset(&kept, 0xA7, sizeof kept);
}

/* What a fault handler leaves (fault_keep.c, fault_keep). */
static void fault_taken(uint32_t pc, uint8_t exception)
{
    kept.reset.pc = pc;
    kept.reset.lr = 0x08001235u;
    kept.reset.sp_offset = 0x0F00u;
    kept.reset.mm_bus_status = 0x8200u;
    kept.reset.exception = exception;
    kept.note = KEPT_FAULT;
    kept_seal(&kept);
}

static void test_a_power_on_is_no_fault_and_counts_from_zero(void **state)
{
    (void)state;
    power_on_ram();
    const struct hal_reset *r = start(RCC_CSR_PORRSTF | RCC_CSR_PINRSTF);
    assert_int_equal(r->kind, HAL_RESET_POWER_ON);
    assert_int_equal(r->in_row, 0);
    assert_memory_equal(r->counts, (uint8_t[HAL_RESET_COUNTS]){0}, HAL_RESET_COUNTS);
    assert_int_equal(kept.magic, KEPT_MAGIC); /* the next start finds it held */
}

static void test_a_fault_is_reported_once_with_its_frame(void **state)
{
    (void)state;
    power_on_ram();
    start(RCC_CSR_PORRSTF | RCC_CSR_PINRSTF);
    fault_taken(0x08002468u, 5);
    const struct hal_reset *r = start(RCC_CSR_SFTRSTF | RCC_CSR_PINRSTF);
    assert_int_equal(r->kind, HAL_RESET_FIRMWARE_FAULT);
    assert_int_equal(r->pc, 0x08002468u);
    assert_int_equal(r->lr, 0x08001235u);
    assert_int_equal(r->sp_offset, 0x0F00u);
    assert_int_equal(r->mm_bus_status, 0x8200u);
    assert_int_equal(r->exception, 5);
    assert_int_equal(r->counts[HAL_COUNT_FIRMWARE_FAULT], 1);
    assert_int_equal(r->in_row, 1);
    /* The software reset the handler asked for is not one of its own. */
    assert_int_equal(r->counts[HAL_COUNT_OTHER], 0);
    r = start(RCC_CSR_PINRSTF); /* then the reset pin: the fault is not told twice */
    assert_int_equal(r->kind, HAL_RESET_PIN);
    assert_int_equal(r->pc, 0);
    assert_int_equal(r->exception, 0);
    assert_int_equal(r->counts[HAL_COUNT_FIRMWARE_FAULT], 1);
    assert_int_equal(r->counts[HAL_COUNT_OTHER], 1);
}

static void test_the_flags_name_the_rest(void **state)
{
    (void)state;
    static const struct {
        uint32_t csr;
        uint8_t kind;
        uint8_t count;
    } cases[] = {
        {RCC_CSR_IWDGRSTF | RCC_CSR_PINRSTF, HAL_RESET_WATCHDOG, HAL_COUNT_WATCHDOG},
        {RCC_CSR_WWDGRSTF | RCC_CSR_PINRSTF, HAL_RESET_WATCHDOG, HAL_COUNT_WATCHDOG},
        {RCC_CSR_SFTRSTF | RCC_CSR_PINRSTF, HAL_RESET_SOFTWARE, HAL_COUNT_OTHER},
        {RCC_CSR_LPWRRSTF | RCC_CSR_PINRSTF, HAL_RESET_LOW_POWER, HAL_COUNT_OTHER},
        {RCC_CSR_PORRSTF | RCC_CSR_PINRSTF, HAL_RESET_BROWN_OUT, HAL_COUNT_BROWN_OUT},
        {RCC_CSR_PINRSTF, HAL_RESET_PIN, HAL_COUNT_OTHER},
    };
    for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        power_on_ram();
        start(RCC_CSR_PORRSTF | RCC_CSR_PINRSTF);
        const struct hal_reset *r = start(cases[i].csr);
        assert_int_equal(r->kind, cases[i].kind);
        for (unsigned c = 0; c < HAL_RESET_COUNTS; c++) {
            assert_int_equal(r->counts[c], c == cases[i].count);
        }
    }
}

static void test_an_update_restart_is_no_fault(void **state)
{
    (void)state;
    power_on_ram();
    start(RCC_CSR_PORRSTF | RCC_CSR_PINRSTF);
    start(RCC_CSR_IWDGRSTF | RCC_CSR_PINRSTF);
    kept.note = KEPT_PLANNED; /* kept_note_planned, on this record */
    kept_seal(&kept);
    const struct hal_reset *r = start(RCC_CSR_SFTRSTF | RCC_CSR_PINRSTF);
    assert_int_equal(r->kind, HAL_RESET_PLANNED);
    assert_int_equal(r->in_row, 0);
    assert_int_equal(r->counts[HAL_COUNT_WATCHDOG], 1);
    assert_int_equal(r->counts[HAL_COUNT_OTHER], 0);
}

/* UpdateEnter's restart hands its bootloader the ID and baud index the
 * application answered at, in the kept record: only a record of a planned
 * restart hands them, and the application's next start takes it back. */
static void test_a_planned_restart_hands_the_bootloader_its_link(void **state)
{
    (void)state;
    memset(&_kept_ram, 0xA5, sizeof _kept_ram); /* what a power-on leaves */
    uint8_t id = 0;
    uint8_t baud_index = 0;
    assert_false(kept_link(&id, &baud_index));
    kept_note_planned(7, 8);
    assert_true(kept_link(&id, &baud_index));
    assert_int_equal(id, 7);
    assert_int_equal(baud_index, 8);
    _kept_ram.magic ^= 1u; /* no record */
    assert_false(kept_link(&id, &baud_index));
    kept_note_planned(7, 8);
    reset_classify(RCC_CSR_SFTRSTF | RCC_CSR_PINRSTF, &_kept_ram); /* the application started */
    assert_false(kept_link(&id, &baud_index));
    kept_note_planned(7, 8);
    _kept_ram.note = KEPT_FAULT;
    kept_seal(&_kept_ram); /* a fault's record, not a planned restart */
    assert_false(kept_link(&id, &baud_index));
}

static void test_own_faults_count_in_a_row_the_supplys_do_not(void **state)
{
    (void)state;
    power_on_ram();
    start(RCC_CSR_PORRSTF | RCC_CSR_PINRSTF);
    fault_taken(0x08003000u, 3);
    assert_int_equal(start(RCC_CSR_SFTRSTF)->in_row, 1);
    assert_int_equal(start(RCC_CSR_IWDGRSTF)->in_row, 2);
    assert_int_equal(start(RCC_CSR_PORRSTF)->in_row, 2); /* a brown-out: not the firmware's */
    assert_int_equal(start(RCC_CSR_PINRSTF)->in_row, 2);
    _kept_ram = kept; /* kept_healthy works on the linker's record */
    kept_healthy(); /* a healthy run: the next is the first in a row again */
    assert_int_equal(_kept_ram.reset.in_row, 0);
    assert_int_equal(_kept_ram.crc, crc32((const uint8_t *)&_kept_ram, offsetof(struct kept_ram, crc)));
    assert_int_equal(start(RCC_CSR_SFTRSTF)->in_row, 3);
    _kept_ram = kept;
    kept_healthy(); /* in safe mode a quiet run proves nothing */
    assert_int_equal(_kept_ram.reset.in_row, HAL_SAFE_MODE_RESETS);
    assert_int_equal(start(RCC_CSR_IWDGRSTF)->in_row, 4);
    assert_int_equal(start(RCC_CSR_SFTRSTF | RCC_CSR_PINRSTF)->in_row, 5);
    kept.note = KEPT_PLANNED; /* an update's restart ends it */
    kept_seal(&kept);
    assert_int_equal(start(RCC_CSR_SFTRSTF)->in_row, 0);
}

static void test_a_record_cut_or_corrupt_is_a_power_on(void **state)
{
    (void)state;
    power_on_ram();
    start(RCC_CSR_PORRSTF | RCC_CSR_PINRSTF);
    fault_taken(0x08003000u, 3);
    kept.reset.pc ^= 1u; /* a bit the CRC no longer covers */
    const struct hal_reset *r = start(RCC_CSR_PORRSTF | RCC_CSR_PINRSTF);
    assert_int_equal(r->kind, HAL_RESET_POWER_ON);
    assert_int_equal(r->pc, 0);
    assert_int_equal(r->counts[HAL_COUNT_FIRMWARE_FAULT], 0);
}

static void test_counts_stop_at_255(void **state)
{
    (void)state;
    power_on_ram();
    start(RCC_CSR_PORRSTF | RCC_CSR_PINRSTF);
    for (unsigned i = 0; i < 300u; i++) {
        start(RCC_CSR_IWDGRSTF);
    }
    assert_int_equal(kept.reset.counts[HAL_COUNT_WATCHDOG], 255);
    assert_int_equal(kept.reset.in_row, 255);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_a_power_on_is_no_fault_and_counts_from_zero),
        cmocka_unit_test(test_a_fault_is_reported_once_with_its_frame),
        cmocka_unit_test(test_the_flags_name_the_rest),
        cmocka_unit_test(test_an_update_restart_is_no_fault),
        cmocka_unit_test(test_a_planned_restart_hands_the_bootloader_its_link),
        cmocka_unit_test(test_own_faults_count_in_a_row_the_supplys_do_not),
        cmocka_unit_test(test_a_record_cut_or_corrupt_is_a_power_on),
        cmocka_unit_test(test_counts_stop_at_255),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
