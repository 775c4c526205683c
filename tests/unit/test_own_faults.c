/* The servo core after a reset it did not plan (what the board read at
 * start-up, hal_port.reset): the fault history's entry, with a firmware
 * fault's frame in place of the readings; item 73's counts; safe mode
 * after three fault resets in a row, which holds the output off and
 * answers the bus; the stack's unused depth (item 74). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "app/servo_safety.h"
#include "storage/fault_record.h"
#include "support/by_name.h"
#include "support/servo_harness.h"

static struct hal_reset reset;
static volatile uint16_t unused_bytes = 612;

static int setup(void **state)
{
    (void)state;
    harness_init();
    harness_ideal_tracking();
    WRITE_ITEM(0, ITEM_SOFT_START_ON, 0);
    harness_run_ms(20);
    return 0;
}

static int32_t read_item(enum data_item_id item)
{
    REQUEST(PKT_READ_DATA, 0, (uint8_t)item);
    assert_true(hal.sent_length >= 8u);
    return ANSWER_FIELD(PKT_READ_DATA, 2, hal.sent_length - 7u, 0);
}

/* A restart whose cause the board read as r. */
static void restart_after(struct hal_reset r)
{
    reset = r;
    hal.port.reset = &reset;
    hal.port.stack_unused = &unused_bytes;
    harness_restart();
    harness_run_ms(20);
}

static struct hal_reset firmware_fault(uint8_t in_row)
{
    return (struct hal_reset){.kind = HAL_RESET_FIRMWARE_FAULT, .in_row = in_row, .counts = {in_row, 0, 0, 0},
                              .sp_offset = 0x0ED8, .pc = 0x08003A52u, .lr = 0x08003A11u,
                              .mm_bus_status = 0x8200, .exception = 5, .usage_status = 0x80};
}

static void test_a_firmware_fault_is_logged_with_its_frame(void **state)
{
    (void)state;
    restart_after(firmware_fault(1));
    REQUEST(PKT_READ_FAULTS, 0, 0);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_COUNT), 1);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_WHAT), FAULT_FIRMWARE);
    /* struct fault_code in the readings' bytes: pc, lr, sp, CFSR low half,
     * exception and the usage byte. */
    assert_int_equal((uint32_t)ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_ANGLE), 0x08003A52u);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_VOLTAGE), 0x3A11);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_CURRENT), 0x0800);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_POWER), 0x0ED8);
    assert_int_equal((uint16_t)ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_WINDING), 0x8200);
    assert_int_equal((uint16_t)ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_CASE), 0x8005);
    assert_int_equal(read_item(ITEM_RESET_COUNTS), 1);
    assert_int_equal(read_item(ITEM_SAFE_MODE), 0);
    harness_run_ms(100); /* a sample of the heat round copies the stack's figure */
    assert_int_equal(read_item(ITEM_STACK_UNUSED), 612);
}

static void test_other_resets_are_logged_by_kind_and_counted(void **state)
{
    (void)state;
    restart_after((struct hal_reset){.kind = HAL_RESET_WATCHDOG, .in_row = 1, .counts = {2, 1, 0, 3}});
    REQUEST(PKT_READ_FAULTS, 0, 0);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_WHAT), FAULT_RESET_WATCHDOG);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_ANGLE), 0);
    assert_int_equal(read_item(ITEM_RESET_COUNTS), 0x03000102);
    restart_after((struct hal_reset){.kind = HAL_RESET_PLANNED});
    REQUEST(PKT_READ_FAULTS, 0, 0);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_COUNT), 1); /* no entry for it */
}

static void test_three_in_a_row_hold_the_output_off_and_answer(void **state)
{
    (void)state;
    restart_after(firmware_fault(SAFE_MODE_RESETS));
    assert_int_equal(read_item(ITEM_SAFE_MODE), 1);
    hal.max_abs_duty = 0;
    REQUEST(PKT_MOVE_ANGLE, 0, 0x84, 0x03, 0x64, 0x00, 0x00, 0x00); /* 90.0 in 100 ms */
    harness_run_ms(300);
    assert_int_equal(hal.max_abs_duty, 0);
    assert_true(hal.coasting);
    assert_int_equal(read_item(ITEM_LIMITER), 7); /* a monitor holds it: ReadFaults says which */
    restart_after(firmware_fault(SAFE_MODE_RESETS + 1u)); /* a boot loop: counted, not logged */
    REQUEST(PKT_READ_FAULTS, 0, 0);
    assert_int_equal(ANSWER_FIELD(PKT_READ_FAULTS, ANSWER_READ_FAULTS_COUNT), 1);
    assert_int_equal(read_item(ITEM_RESET_COUNTS), SAFE_MODE_RESETS + 1u);
    restart_after((struct hal_reset){.kind = HAL_RESET_POWER_ON});
    assert_int_equal(read_item(ITEM_SAFE_MODE), 0);
    REQUEST(PKT_MOVE_ANGLE, 0, 0x84, 0x03, 0x64, 0x00, 0x00, 0x00);
    harness_run_ms(300);
    assert_true(hal.max_abs_duty > 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_a_firmware_fault_is_logged_with_its_frame, setup),
        cmocka_unit_test_setup(test_other_resets_are_logged_by_kind_and_counted, setup),
        cmocka_unit_test_setup(test_three_in_a_row_hold_the_output_off_and_answer, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
