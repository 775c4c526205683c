/* The fault history in flash (storage/fault_log.c) on the flash double:
 * order, fields, page changes, clears, wear rules and power cuts at every
 * step. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "doubles/flash_double.h"
#include "storage/fault_log.h"

static struct flash_double flash;
static struct fault_log log_;

static struct fault_entry fault(uint8_t what, uint32_t seconds)
{
    return (struct fault_entry){.what = what, .op_seconds = seconds, .voltage_mv = 7400,
                                .current_ma = (uint16_t)(100u + seconds), .power_mw = 5000,
                                .winding_decic = 812, .case_decic = -35,
                                .angle_decideg = -(int32_t)seconds * 1000};
}

/* Runs the log's flash work as the main loop would: steps, and the erase
 * when it must go on elsewhere. False when the flash refused (or died). */
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

/* n faults of one kind, 20 s apart, each logged and settled. */
static void log_faults(uint8_t what, uint32_t count)
{
    for (uint32_t n = 1; n <= count; n++) {
        struct fault_entry e = fault(what, 20u * n);
        assert_true(fault_log_add(&log_, &e));
        assert_true(settle());
    }
}

static int setup(void **state)
{
    (void)state;
    flash_double_init(&flash, 1024);
    fault_log_load(&log_, &flash.hal);
    return 0;
}

static bool read_entry(uint8_t index, struct fault_entry *e)
{
    *e = (struct fault_entry){0};
    return fault_log_read(&log_, index, (uint8_t *)e);
}

static void reload(void)
{
    flash_double_power_on(&flash);
    fault_log_load(&log_, &flash.hal);
}

/* The history shows numbers newest..newest-count+1 in order, each intact. */
static void assert_history(uint32_t newest, uint8_t count)
{
    assert_int_equal(log_.shown_count, count);
    for (uint8_t i = 0; i < count; i++) {
        struct fault_entry e;
        assert_true(read_entry(i, &e));
        assert_int_equal(e.number, newest - i);
        struct fault_entry want = fault(e.what, e.op_seconds);
        assert_int_equal(e.current_ma, want.current_ma);
        assert_int_equal(e.angle_decideg, want.angle_decideg);
        assert_int_equal(e.winding_decic, 812);
        assert_int_equal(e.case_decic, -35);
    }
    struct fault_entry none;
    assert_false(read_entry(count, &none));
}

static void test_faults_read_back_newest_first_after_a_power_cycle(void **state)
{
    (void)state;
    assert_int_equal(log_.shown_count, 0);
    assert_true(fault_log_add(&log_, &(struct fault_entry){0}) || true);
    setup(NULL);
    for (uint32_t i = 1; i <= 3; i++) {
        struct fault_entry e = fault((uint8_t)(1u + i), 100u * i);
        assert_true(fault_log_add(&log_, &e));
    }
    assert_true(settle());
    assert_history(3, 3);
    struct fault_entry e;
    assert_true(read_entry(0, &e));
    assert_int_equal(e.what, 4);
    assert_int_equal(e.op_seconds, 300);
    reload();
    assert_history(3, 3);
}

static void test_the_history_keeps_the_newest_16_across_pages(void **state)
{
    (void)state;
    for (uint32_t n = 1; n <= 100; n++) { /* three page changes, two erases */
        struct fault_entry e = fault(FAULT_STALL, 20u * n);
        assert_true(fault_log_add(&log_, &e));
        assert_true(settle());
        uint8_t count = (uint8_t)(n < FAULT_HISTORY ? n : FAULT_HISTORY);
        assert_history(n, count);
    }
    assert_int_equal(flash.erases[0] + flash.erases[1], 2); /* page 1 was blank */
    reload();
    assert_history(100, FAULT_HISTORY);
    assert_false(flash.misuse);
}

static void test_a_clear_hides_the_older_faults(void **state)
{
    (void)state;
    log_faults(FAULT_OVER_POWER, 5);
    struct fault_entry clear = {.what = FAULT_CLEARED, .op_seconds = 200};
    assert_true(fault_log_add(&log_, &clear));
    assert_true(settle());
    assert_int_equal(log_.shown_count, 0);
    reload();
    assert_int_equal(log_.shown_count, 0);
    struct fault_entry e = fault(FAULT_WATCHDOG, 300);
    assert_true(fault_log_add(&log_, &e));
    assert_true(settle());
    reload();
    assert_history(7, 1);
}

static void test_repeats_and_the_wear_budget_are_counted_not_written(void **state)
{
    (void)state;
    struct fault_entry early = fault(FAULT_STALL, 0); /* in the first second of operation */
    assert_true(fault_log_add(&log_, &early));
    assert_false(fault_log_add(&log_, &early));
    struct fault_entry e = fault(FAULT_OVER_CURRENT, 1000);
    assert_true(fault_log_add(&log_, &e));
    e.op_seconds = 1009; /* the same kind within 10 s */
    assert_false(fault_log_add(&log_, &e));
    e.what = FAULT_LOW_VOLTAGE; /* another kind */
    assert_true(fault_log_add(&log_, &e));
    assert_true(settle());
    assert_int_equal(log_.not_logged, 2);
    /* Past the budget: 1000 records plus one per 547 s of operation. */
    log_.newest = FAULT_ALLOWANCE + 2u;
    e = fault(FAULT_STALL, 1093);
    assert_false(fault_log_add(&log_, &e));
    e.op_seconds = 2000; /* 3 more allowed by now */
    assert_true(fault_log_add(&log_, &e));
    assert_int_equal(log_.not_logged, 3);
}

static void test_a_refused_program_spends_a_slot_not_the_history(void **state)
{
    (void)state;
    log_faults(FAULT_STALL, 3);
    flash.mem[0][3 * FAULT_RECORD_SIZE] = 0x00; /* the next slot is not erased: the program fails */
    struct fault_entry e = fault(FAULT_STALL, 100);
    assert_true(fault_log_add(&log_, &e));
    assert_true(settle());
    assert_int_equal(log_.failures, 1);
    e = fault(FAULT_STALL, 200);
    assert_true(fault_log_add(&log_, &e));
    assert_true(settle());
    reload();
    assert_int_equal(log_.shown_count, 4); /* number 4 was spent */
    static const uint32_t numbers[] = {5, 3, 2, 1};
    for (uint8_t i = 0; i < 4u; i++) {
        struct fault_entry got;
        assert_true(read_entry(i, &got));
        assert_int_equal(got.number, numbers[i]);
    }
}

/* A power cut at every erase and program step of 40 faults, in every way
 * a step can be cut: what was done before the cut is all there, in order,
 * and the log goes on. */
static void test_a_power_cut_at_any_step_loses_at_most_the_record_in_flight(void **state)
{
    (void)state;
    for (int mode = 0; mode < CUT_MODES; mode++) {
        for (long cut = 0; cut < 40 * 16 + 2; cut += 7) {
            setup(NULL);
            flash.cut_at = cut;
            flash.cut_mode = (enum cut_mode)mode;
            uint32_t done = 0;
            for (uint32_t n = 1; n <= 40 && !flash.dead; n++) {
                struct fault_entry e = fault(FAULT_STALL, 20u * n);
                assert_true(fault_log_add(&log_, &e));
                if (settle() && !flash.dead) {
                    done = n;
                }
            }
            reload();
            assert_true(log_.newest >= done);
            uint8_t count = (uint8_t)(log_.newest < FAULT_HISTORY ? log_.newest : FAULT_HISTORY);
            if (log_.newest > done) { /* the cut record landed whole */
                assert_true(log_.newest == done + 1u);
            }
            assert_history(log_.newest, count);
            struct fault_entry e = fault(FAULT_OVER_POWER, 5000);
            assert_true(fault_log_add(&log_, &e));
            assert_true(settle());
            assert_true(log_.newest > done);
            struct fault_entry got;
            assert_true(read_entry(0, &got));
            assert_int_equal(got.what, FAULT_OVER_POWER);
        }
    }
}

/* Steps only: the flash work of a servo whose output is driven, where no
 * erase may stall the CPU. */
static void step_without_erase(void)
{
    while (fault_log_step(&log_)) {
    }
}

/* A clear is promised within milliseconds: where its record would wait for
 * an erase (the page in use full, the spare not erased: a driven servo),
 * it is refused, not queued and lost. Faults wait for the erase
 * in RAM, in order, and are written after it. */
static void test_a_clear_that_would_wait_for_an_erase_is_refused(void **state)
{
    (void)state;
    flash.mem[1][5] = 0x00; /* page 1 not blank: it needs an erase before use */
    reload();
    for (uint32_t n = 1; n <= 32; n++) { /* page 0 fills */
        struct fault_entry e = fault(FAULT_STALL, 20u * n);
        assert_true(fault_log_add(&log_, &e));
        step_without_erase();
    }
    assert_int_equal(log_.newest, 32);
    struct fault_entry late = fault(FAULT_OVER_POWER, 700);
    assert_true(fault_log_add(&log_, &late)); /* waits in RAM */
    step_without_erase();
    assert_int_equal(log_.newest, 32);
    struct fault_entry clear = {.what = FAULT_CLEARED, .op_seconds = 701};
    assert_false(fault_log_add(&log_, &clear));
    assert_true(fault_log_spare_dirty(&log_));
    assert_true(fault_log_erase_spare(&log_)); /* released and quiet */
    assert_true(fault_log_add(&log_, &clear));
    assert_true(settle());
    assert_int_equal(log_.newest, 34); /* the fault, then the clear */
    assert_int_equal(log_.shown_count, 0);
    reload();
    assert_int_equal(log_.shown_count, 0);
    assert_false(flash.misuse);
}

/* A clear with records queued before it, and no erased spare, could wait
 * behind them: refused until they are written (a moment), then taken. */
static void test_a_clear_behind_queued_records_waits_for_them(void **state)
{
    (void)state;
    flash.mem[1][5] = 0x00;
    reload();
    for (uint32_t n = 1; n <= 31; n++) {
        struct fault_entry e = fault(FAULT_STALL, 20u * n);
        assert_true(fault_log_add(&log_, &e));
        step_without_erase();
    }
    struct fault_entry e = fault(FAULT_OVER_POWER, 700);
    assert_true(fault_log_add(&log_, &e)); /* the last slot */
    struct fault_entry clear = {.what = FAULT_CLEARED, .op_seconds = 701};
    assert_false(fault_log_add(&log_, &clear));
    step_without_erase();
    assert_false(fault_log_add(&log_, &clear)); /* the page is full now */
}

/* The spare is erased as soon as it shows no fault (16 newer ones are in
 * the page in use), not when that page is full: a page that fills while
 * the output is driven finds the next one erased. Still one erase a page
 * change. */
static void test_the_spare_is_erased_ahead_once_it_shows_nothing(void **state)
{
    (void)state;
    log_faults(FAULT_STALL, 40); /* page 0 full, 8 on page 1 */
    assert_false(fault_log_spare_dirty(&log_)); /* page 0 still shows 8 */
    for (uint32_t n = 41; n <= 48; n++) {
        struct fault_entry e = fault(FAULT_STALL, 20u * n);
        assert_true(fault_log_add(&log_, &e));
        step_without_erase();
    }
    assert_true(fault_log_spare_dirty(&log_)); /* 16 on page 1: page 0 shows none */
    assert_true(fault_log_erase_spare(&log_));
    for (uint32_t n = 49; n <= 80; n++) { /* driven from here: no erase */
        struct fault_entry e = fault(FAULT_STALL, 20u * n);
        assert_true(fault_log_add(&log_, &e));
        step_without_erase();
    }
    assert_int_equal(log_.newest, 80);
    assert_history(80, FAULT_HISTORY);
    assert_int_equal(flash.erases[0] + flash.erases[1], 1);
    reload();
    assert_history(80, FAULT_HISTORY);
}

/* The repeat rule holds across a power cycle: each kind's last record
 * sets it again at power-up. */
static void test_a_repeat_is_a_repeat_after_a_power_cycle(void **state)
{
    (void)state;
    struct fault_entry e = fault(FAULT_LOW_VOLTAGE, 100);
    assert_true(fault_log_add(&log_, &e));
    e = fault(FAULT_STALL, 103);
    assert_true(fault_log_add(&log_, &e));
    assert_true(settle());
    reload();
    e = fault(FAULT_LOW_VOLTAGE, 105);
    assert_false(fault_log_add(&log_, &e));
    e = fault(FAULT_STALL, 112);
    assert_false(fault_log_add(&log_, &e));
    e = fault(FAULT_LOW_VOLTAGE, 110);
    assert_true(fault_log_add(&log_, &e));
    assert_int_equal(log_.not_logged, 2);
}

/* The firmware's own resets are logged however close (the application
 * stops at three in a row); a brown-out or the pin, which a weak supply can
 * repeat at every start, keep the repeat rule, across a power cycle too. */
static void test_resets_own_ones_logged_the_supplys_held_back(void **state)
{
    (void)state;
    assert_true(fault_log_add(&log_, &(struct fault_entry){.what = FAULT_FIRMWARE, .op_seconds = 100}));
    assert_true(fault_log_add(&log_, &(struct fault_entry){.what = FAULT_FIRMWARE, .op_seconds = 101}));
    assert_true(fault_log_add(&log_, &(struct fault_entry){.what = FAULT_BROWN_OUT, .op_seconds = 102}));
    assert_true(settle());
    fault_log_load(&log_, &flash.hal); /* the next start */
    assert_false(fault_log_add(&log_, &(struct fault_entry){.what = FAULT_BROWN_OUT, .op_seconds = 104}));
    assert_false(fault_log_add(&log_, &(struct fault_entry){.what = FAULT_RESET_PIN, .op_seconds = 105}));
    assert_true(fault_log_add(&log_, &(struct fault_entry){.what = FAULT_RESET_WATCHDOG, .op_seconds = 105}));
    assert_true(fault_log_add(&log_, &(struct fault_entry){.what = FAULT_BROWN_OUT, .op_seconds = 120}));
    assert_int_equal(log_.not_logged, 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_faults_read_back_newest_first_after_a_power_cycle, setup),
        cmocka_unit_test_setup(test_the_history_keeps_the_newest_16_across_pages, setup),
        cmocka_unit_test_setup(test_a_clear_hides_the_older_faults, setup),
        cmocka_unit_test_setup(test_repeats_and_the_wear_budget_are_counted_not_written, setup),
        cmocka_unit_test_setup(test_a_refused_program_spends_a_slot_not_the_history, setup),
        cmocka_unit_test_setup(test_a_power_cut_at_any_step_loses_at_most_the_record_in_flight, setup),
        cmocka_unit_test_setup(test_a_clear_that_would_wait_for_an_erase_is_refused, setup),
        cmocka_unit_test_setup(test_a_clear_behind_queued_records_waits_for_them, setup),
        cmocka_unit_test_setup(test_the_spare_is_erased_ahead_once_it_shows_nothing, setup),
        cmocka_unit_test_setup(test_a_repeat_is_a_repeat_after_a_power_cycle, setup),
        cmocka_unit_test_setup(test_resets_own_ones_logged_the_supplys_held_back, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
