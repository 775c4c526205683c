/* The whole servo core, bytes on the wire in, exact bytes out (or silence):
 * the data packets end to end, the wire rules, link changes after the
 * response, persistence, and sync Monitor turn-taking. Motion packets:
 * test_motion_packets.c. */
#include <setjmp.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "registers/data_table.h"
#include "support/by_name.h"
#include "support/servo_harness.h"

static int setup(void **state)
{
    (void)state;
    harness_init();
    return 0;
}

static void test_ping_exact_bytes(void **state)
{
    (void)state;
    /* 12 4C 01 01 00 60 -> 05 1C 01 01 00 23 (checksums by hand) */
    const uint8_t ping[] = {0x12, 0x4C, 0x01, 0x01, 0x00, 0x60};
    harness_feed(ping, sizeof ping);
    harness_poll(2);
    const uint8_t reply[] = {0x05, 0x1C, 0x01, 0x01, 0x00, 0x23};
    harness_assert_sent(reply, sizeof reply);
}

static void test_silence_for_others_broadcast_and_bad_checksum(void **state)
{
    (void)state;
    REQUEST(PKT_PING, 5);
    EXPECT_SILENCE();
    REQUEST(PKT_PING, 0xFF);
    EXPECT_SILENCE();
    const uint8_t bad[] = {0x12, 0x4C, 0x01, 0x01, 0x00, 0x61};
    hal_double_clear_sent(&hal);
    harness_feed(bad, sizeof bad);
    harness_poll(2);
    EXPECT_SILENCE();
    assert_int_equal(servo.rx.stats.checksum_errors, 1);
    assert_int_equal(servo.regs.status.status & STATUS_COMMAND_ERROR, 0);
}

static void test_read_data_every_item(void **state)
{
    (void)state;
    uint8_t block[USER_AREA_SIZE];
    user_config_encode(&servo.regs.user, block);
    unsigned pos = 0;
    for (uint8_t id = 32; id <= 53; id++) {
        const struct data_item *it = data_table_find(id);
        REQUEST(PKT_READ_DATA, 0, id);
        uint8_t content[8] = {0, id};
        uint8_t n = 2;
        if (id != 35 && id != 45) {
            memcpy(&content[2], &block[pos], data_item_size(it));
            n = (uint8_t)(n + data_item_size(it));
        }
        uint8_t frame[16];
        size_t fn = make_response(frame, 3, content, n);
        harness_assert_sent(frame, fn);
        pos += data_item_size(it);
    }
    /* Status area: model, version, serial from the port. */
    REQUEST(PKT_READ_DATA, 0, ITEM_MODEL);
    EXPECT_ITEM(0, ITEM_MODEL, 0xf00);
    REQUEST(PKT_READ_DATA, 0, ITEM_FIRMWARE_VERSION);
    EXPECT_ITEM(0, ITEM_FIRMWARE_VERSION, 0x10);
    REQUEST(PKT_READ_DATA, 0, ITEM_SERIAL_NUMBER);
    EXPECT_ITEM(0, ITEM_SERIAL_NUMBER, 0x12345678);
    REQUEST(PKT_READ_DATA, 0, 200);
    EXPECT_RESPONSE(PKT_READ_DATA, 0, 200);
}

static void test_write_data_and_failures(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_SOFT_START_MS, 1000);
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_SOFT_START_MS, 1);
    REQUEST(PKT_READ_DATA, 0, ITEM_SOFT_START_MS);
    EXPECT_ITEM(0, ITEM_SOFT_START_MS, 1000);
    WRITE_ITEM(0, ITEM_VOLTAGE_MV, 0); /* read-only */
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_VOLTAGE_MV, 0);
    REQUEST(PKT_WRITE_DATA, 0, ITEM_SOFT_START_MS, 0xE8); /* wrong size */
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_SOFT_START_MS, 0);
    WRITE_ITEM(0, ITEM_CENTER_OFFSET_DECIDEG, 1801); /* 1801: out of range */
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_CENTER_OFFSET_DECIDEG, 0);
    assert_true(servo.regs.status.status & STATUS_COMMAND_ERROR);
    REQUEST(PKT_READ_DATA, 0, ITEM_STATUS);
    EXPECT_RESPONSE(PKT_READ_DATA, 0, ITEM_STATUS, STATUS_COMMAND_ERROR);
}

static void test_batch_read_write_and_reset(void **state)
{
    (void)state;
    uint8_t block[1 + USER_AREA_SIZE] = {0};
    user_config_encode(&servo.regs.user, &block[1]);
    REQUEST(PKT_READ_BATCH_DATA, 0);
    uint8_t frame[64];
    size_t n = make_response(frame, 5, block, sizeof block);
    harness_assert_sent(frame, n);

    block[1 + 1] = 1;    /* control response */
    block[1 + 3] = 0x42; /* reserved 35 kept as given */
    block[1 + 28] = 0x10; /* 52 = -1520 (0xFA10) */
    harness_request(PKT_WRITE_BATCH_DATA, block, sizeof block);
    EXPECT_RESPONSE(PKT_WRITE_BATCH_DATA, 0, 1);
    REQUEST(PKT_READ_BATCH_DATA, 0);
    n = make_response(frame, 5, block, sizeof block);
    harness_assert_sent(frame, n);

    block[1 + 4] = 0; /* invalid baud index: all or nothing */
    block[1 + 1] = 0;
    harness_request(PKT_WRITE_BATCH_DATA, block, sizeof block);
    EXPECT_RESPONSE(PKT_WRITE_BATCH_DATA, 0, 0);
    assert_int_equal(servo.regs.user.control_response, 1);

    REQUEST(PKT_RESET_USER_DATA, 0);
    EXPECT_RESPONSE(PKT_RESET_USER_DATA, 0, 1);
    assert_int_equal(servo.regs.user.control_response, 0);
    assert_int_equal(servo.regs.user.reserved_35, 0);
}

static void test_new_id_takes_effect_after_the_response(void **state)
{
    (void)state;
    hal.tx_busy = true; /* the response is still on the wire */
    WRITE_ITEM(0, ITEM_SERVO_ID, 7);
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_SERVO_ID, 1); /* answered with the old ID */
    harness_poll(2);
    assert_int_equal(servo.active_id, 0); /* not while the response is on the wire */
    /* The host's next request, to the new ID, follows the last stop bit at
     * once: the pass that finds the line free takes the new ID before it
     * reads the request. */
    hal.tx_busy = false;
    uint8_t wire[8];
    size_t n = make_request(wire, 1, (const uint8_t[]){7}, 1);
    hal_double_clear_sent(&hal);
    harness_feed(wire, n);
    harness_poll(2);
    assert_int_equal(servo.active_id, 7);
    EXPECT_RESPONSE(PKT_PING, 7);
    REQUEST(PKT_PING, 7);
    EXPECT_RESPONSE(PKT_PING, 7);
    REQUEST(PKT_PING, 0);
    EXPECT_SILENCE();
}

static void test_new_baud_takes_effect_after_the_response(void **state)
{
    (void)state;
    assert_int_equal(hal.baud, 115200);
    hal.tx_busy = true;
    WRITE_ITEM(0, ITEM_BAUD_INDEX, 8);
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_BAUD_INDEX, 1);
    assert_int_equal(hal.baud, 115200);
    hal.tx_busy = false;
    harness_poll(2);
    assert_int_equal(hal.baud, 1000000);
    assert_int_equal(servo.rx_idle_us, 1000);
}

/* The line idle for the idle time (1 ms at 115200) between two passes of
 * the main loop drops a partial frame; a shorter pause does not. */
static void feed_ping_in_two(uint32_t pause_us)
{
    uint8_t wire[8];
    size_t n = make_request(wire, 1, (const uint8_t[]){0}, 1);
    hal_double_clear_sent(&hal);
    harness_feed(wire, 3);
    harness_poll(1);
    hal.now_us += pause_us;
    harness_poll(1);
    harness_feed(wire + 3, n - 3);
    harness_poll(2);
}

static void test_an_idle_line_drops_a_partial_frame(void **state)
{
    (void)state;
    feed_ping_in_two(servo.rx_idle_us);
    EXPECT_SILENCE();
    assert_int_equal(servo.rx.stats.idle_timeouts, 1);
    REQUEST(PKT_PING, 0); /* the next frame is whole */
    EXPECT_RESPONSE(PKT_PING, 0);
}

static void test_a_pause_within_the_idle_time_keeps_the_frame(void **state)
{
    (void)state;
    feed_ping_in_two(servo.rx_idle_us - 1u - HARNESS_BYTE_US);
    EXPECT_RESPONSE(PKT_PING, 0);
    assert_int_equal(servo.rx.stats.idle_timeouts, 0);
}

static void test_the_idle_time_survives_the_clock_wrap(void **state)
{
    (void)state;
    hal.now_us = 0xFFFFFFFFu - 3u * HARNESS_BYTE_US;
    servo.next_tick_us = hal.now_us;
    tick_scheduled(&servo);
    feed_ping_in_two(100);
    EXPECT_RESPONSE(PKT_PING, 0);
    assert_int_equal(servo.rx.stats.idle_timeouts, 0);
}

static void test_a_clock_stepping_back_is_no_idle_line(void **state)
{
    (void)state;
    /* An emulated SysTick can read a little earlier than the byte's stamp. */
    uint8_t wire[8];
    size_t n = make_request(wire, 1, (const uint8_t[]){0}, 1);
    hal_double_clear_sent(&hal);
    harness_feed(wire, 3);
    hal.now_us -= 1000u;
    harness_poll(1);
    harness_feed(wire + 3, n - 3);
    harness_poll(2);
    EXPECT_RESPONSE(PKT_PING, 0);
    assert_int_equal(servo.rx.stats.idle_timeouts, 0);
}

static void test_config_survives_restart(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_SERVO_ID, 9);
    WRITE_ITEM(9, ITEM_CURRENT_LIMIT_MA, 2000);
    EXPECT_RESPONSE(PKT_WRITE_DATA, 9, ITEM_CURRENT_LIMIT_MA, 1);
    /* In flash before the answer: a power cut right after it keeps it. */
    harness_restart();
    REQUEST(PKT_READ_DATA, 9, ITEM_CURRENT_LIMIT_MA);
    EXPECT_ITEM(9, ITEM_CURRENT_LIMIT_MA, 2000);
    /* Writing the same value again writes no flash. */
    long steps = hal.flash.steps;
    WRITE_ITEM(9, ITEM_CURRENT_LIMIT_MA, 2000);
    EXPECT_RESPONSE(PKT_WRITE_DATA, 9, ITEM_CURRENT_LIMIT_MA, 1);
    harness_run_ms(100);
    assert_int_equal(hal.flash.steps, steps);
}

/* AssignId (0x42): only the servo with the serial number takes the ID and
 * answers, whatever its ID; the ID is durable as WriteData's; an ID above
 * 254 is refused. */
static void test_assign_id_by_serial_number(void **state)
{
    (void)state;
    REQUEST(PKT_ASSIGN_ID, 0xFF, 0x79, 0x56, 0x34, 0x12, 7); /* another servo's serial number */
    EXPECT_SILENCE();
    assert_int_equal(servo.regs.user.servo_id, 0);
    assert_int_equal(servo.regs.status.status & STATUS_COMMAND_ERROR, 0);
    REQUEST(PKT_ASSIGN_ID, 0xFF, 0x78, 0x56, 0x34, 0x12, 255);
    EXPECT_RESPONSE(PKT_ASSIGN_ID, 0, 0);
    REQUEST(PKT_ASSIGN_ID, 0xFF, 0x78, 0x56, 0x34, 0x12, 7);
    EXPECT_RESPONSE(PKT_ASSIGN_ID, 7, 1);
    harness_restart();
    REQUEST(PKT_PING, 7);
    EXPECT_RESPONSE(PKT_PING, 7);
    REQUEST(PKT_ASSIGN_ID, 0x07, 0x78, 0x56, 0x34, 0x12, 9); /* to its own ID: taken too */
    EXPECT_RESPONSE(PKT_ASSIGN_ID, 9, 1);
    REQUEST(PKT_ASSIGN_ID, 0xFF, 0x78, 0x56, 0x34, 0x12); /* short: a malformed frame, no answer */
    EXPECT_SILENCE();
}

/* A field of ReadStore's answer, by a request of its own:
 * store_field(ANSWER_READ_STORE_FLAGS). */
static uint32_t store_field(size_t at, size_t size, int is_signed)
{
    REQUEST(PKT_READ_STORE, 0);
    return (uint32_t)harness_answer_field(PKT_READ_STORE, at, size, is_signed);
}

/* Every flash write fails (a dead or worn page): a change is answered 0
 * and not made, so what the host reads is what the servo keeps; ReadStore
 * says why. Once the flash works again, writes are taken again. */
static void test_a_write_the_flash_refuses_is_not_made(void **state)
{
    (void)state;
    const uint16_t kept = servo.regs.user.current_limit_ma;
    hal.flash.dead = true;
    WRITE_ITEM(0, ITEM_CURRENT_LIMIT_MA, 2000);
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_CURRENT_LIMIT_MA, 0);
    assert_int_equal(servo.store.write_failures, 1);
    REQUEST(PKT_READ_DATA, 0, ITEM_CURRENT_LIMIT_MA);
    EXPECT_RESPONSE(PKT_READ_DATA, 0, ITEM_CURRENT_LIMIT_MA, (uint8_t)kept, (uint8_t)(kept >> 8));
    assert_int_equal(store_field(ANSWER_READ_STORE_FLAGS), STORE_FAILED);
    assert_int_equal(store_field(ANSWER_READ_STORE_FAILURES), 1); /* failures */
    uint8_t batch[1 + USER_AREA_SIZE] = {0};
    user_config_encode(&servo.regs.user, &batch[1]);
    batch[1 + 43 - 32] = 0xB8; /* a real change: stored or refused */
    batch[1 + 44 - 32] = 0x0B;
    harness_request(PKT_WRITE_BATCH_DATA, batch, sizeof batch);
    EXPECT_RESPONSE(PKT_WRITE_BATCH_DATA, 0, 0);
    hal.flash.dead = false;
    WRITE_ITEM(0, ITEM_CURRENT_LIMIT_MA, 3000);
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_CURRENT_LIMIT_MA, 1);
    assert_int_equal(store_field(ANSWER_READ_STORE_FLAGS), 0);
    harness_restart();
    REQUEST(PKT_READ_DATA, 0, ITEM_CURRENT_LIMIT_MA);
    EXPECT_ITEM(0, ITEM_CURRENT_LIMIT_MA, 3000);
}

/* Every accepted change is a record of its own, written before its
 * answer; a write of the value already held writes nothing. */
static void test_every_change_is_in_flash_before_its_answer(void **state)
{
    (void)state;
    const uint32_t first = servo.store.sequence;
    for (unsigned i = 0; i < 10u; i++) {
        REQUEST(PKT_WRITE_DATA, 0, ITEM_START_FORCE, (uint8_t)(100u + i));
        EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_START_FORCE, 1);
        assert_int_equal(servo.store.sequence, first + i + 1u);
    }
    long steps = hal.flash.steps;
    WRITE_ITEM(0, ITEM_START_FORCE, 109);
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_START_FORCE, 1);
    assert_int_equal(hal.flash.steps, steps);
}

/* A host toggling item 44 every 150 ms (quiet long enough for the erase),
 * for 2 hours of operation with a power cycle every 20 minutes: after the allowance the servo takes one
 * change per seconds_per_save of operating time, the budget that keeps 10
 * years of this within the pages' rated cycles, and refuses the rest
 * (result 0, ReadStore bit 1) rather than keep them in RAM. The operating
 * time recorded with each save keeps power cycles from refilling it. */
static void test_writes_in_a_loop_stay_within_the_wear_budget(void **state)
{
    (void)state;
    uint32_t per_save = servo.saving.saver.seconds_per_save;
    uint32_t records = 2u * FLASH_RATED_CYCLES * config_store_slots_per_page(&servo.store);
    /* 10 years at this rate, and the allowance, within 90 % of the rating */
    assert_true(SAVE_ALLOWANCE + SAVE_LIFE_SECONDS / per_save <= records / 10u * 9u);
    uint32_t ms = 0;
    uint32_t refused = 0;
    for (uint32_t i = 0; ms < 2u * 3600u * 1000u; i++) {
        uint8_t flip = (uint8_t)(servo.regs.user.start_force ^ 1u);
        REQUEST(PKT_WRITE_DATA, 0, ITEM_START_FORCE, flip);
        refused += ANSWER_FIELD(PKT_WRITE_DATA, ANSWER_WRITE_DATA_RESULT) == 0;
        hal.now_us += 149000u; /* no motion: ticks beyond the catch-up drop */
        harness_poll(2);
        ms += 150;
        if (i % 12000u == 11999u) { /* each 30 min: a save (1 per per_save s) comes between */
            harness_restart();
        }
        assert_true(servo.store.sequence <= save_policy_budget(&servo.saving.saver));
    }
    uint32_t op = save_policy_op_seconds(&servo.saving.saver);
    printf("# 2 h of writes every 150 ms: %u saves, %u refused, %u page erases; budget %u (1 per %u s)\n",
           (unsigned)servo.store.sequence, (unsigned)refused,
           (unsigned)config_store_page_erases(&servo.store),
           (unsigned)save_policy_budget(&servo.saving.saver), (unsigned)per_save);
    assert_true(op > 3600u && op <= 7200u);
    assert_true(refused > 40000u);
    assert_int_equal(servo.store.sequence, save_policy_budget(&servo.saving.saver));
    uint8_t held = servo.regs.user.start_force;
    REQUEST(PKT_WRITE_DATA, 0, ITEM_START_FORCE, (uint8_t)(held ^ 1u));
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_START_FORCE, 0);
    assert_int_equal(servo.regs.user.start_force, held);
    assert_int_equal(store_field(ANSWER_READ_STORE_FLAGS), STORE_OVER_BUDGET);
    assert_int_equal(store_field(ANSWER_READ_STORE_RECORDS), servo.store.sequence);
    const uint32_t per_page = config_store_slots_per_page(&servo.store); /* 14 records of 72 B */
    uint32_t pages_started = (servo.store.sequence + per_page - 1u) / per_page;
    assert_int_equal(store_field(ANSWER_READ_STORE_PAGE_ERASES), (pages_started + 1u) / 2u);
    assert_int_equal(store_field(ANSWER_READ_STORE_RATED_CYCLES), FLASH_RATED_CYCLES);
    assert_int_equal(store_field(ANSWER_READ_STORE_BUDGET), save_policy_budget(&servo.saving.saver));
    assert_int_equal(store_field(ANSWER_READ_STORE_OPERATING_TIME), op);
    assert_true(servo.store.sequence > SAVE_ALLOWANCE);
    assert_true(servo.store.sequence >= SAVE_ALLOWANCE + op / per_save - 1u);
}

static void test_reset_keeps_link(void **state)
{
    (void)state;
    WRITE_ITEM(0, ITEM_SERVO_ID, 4);
    harness_poll(2);
    REQUEST(PKT_RESET_USER_DATA, 4);
    EXPECT_RESPONSE(PKT_RESET_USER_DATA, 4, 1);
    REQUEST(PKT_PING, 4);
    EXPECT_RESPONSE(PKT_PING, 4);
}





/* Servo `id` sends its Monitor response on the shared wire. */
static void other_servo_answers(uint8_t id)
{
    uint8_t frame[32];
    uint8_t content[16] = {id};
    size_t n = make_response(frame, 22, content, sizeof content);
    harness_feed(frame, n);
    harness_poll(3);
}

/* Sync Monitor: servo 0 is third in the list, so it lets two responses go
 * by first. */
static void test_sync_monitor_waits_its_turn(void **state)
{
    (void)state;
    const uint8_t sync[] = {22, 1, 4, 5, 6, 0, 9};
    harness_request(PKT_SYNC_COMMAND, sync, sizeof sync);
    EXPECT_SILENCE();
    other_servo_answers(5);
    EXPECT_SILENCE();
    other_servo_answers(6);
    assert_int_equal(ANSWER_FIELD(PKT_MONITOR, ANSWER_MONITOR_ID), 0);
}

static void test_sync_monitor_passes_a_silent_servo(void **state)
{
    (void)state;
    const uint8_t sync[] = {22, 1, 3, 5, 6, 0};
    harness_request(PKT_SYNC_COMMAND, sync, sizeof sync);
    other_servo_answers(5);
    EXPECT_SILENCE();
    /* Servo 6 never answers: after the documented silence, servo 0 goes. */
    hal.now_us += SYNC_SLOT_SILENCE_US - 1;
    harness_poll(3);
    EXPECT_SILENCE();
    hal.now_us += 2;
    harness_poll(3);
    assert_int_equal(hal.sent_length, 21);
}

/* At 1 Mbaud, bytes 10 us apart, as a port stamps them. */
static void feed_at_1mbaud(const uint8_t *bytes, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        hal.now_us += 10u;
        servo_on_rx_byte(&servo, bytes[i], hal.now_us);
    }
}

/* Servo 0 second in a Sync Monitor at 1 Mbaud on a CPU whose tick and
 * pass take 46 us (the M0's): servo 5's answer is on the line, all but its
 * last `left` bytes received, and the control tick falls due. Returns
 * the tick's schedule as it was. */
static uint32_t tick_due_near_the_turn(uint8_t tick_and_pass_us, size_t left, uint8_t frame[32],
                                       size_t *n)
{
    hal.port.tick_and_pass_us = tick_and_pass_us;
    servo.regs.user.baud_index = 8; /* 1 Mbaud */
    servo.link_settings_pending = 1;
    harness_poll(1);
    const uint8_t sync[] = {22, 1, 2, 5, 0};
    harness_request(PKT_SYNC_COMMAND, sync, sizeof sync);
    uint8_t content[16] = {5};
    *n = make_response(frame, 22, content, sizeof content);
    while (servo.next_tick_us - hal.now_us <= 10u * (*n - left)) { /* time only goes on */
        hal.now_us = servo.next_tick_us;
        harness_poll(1);
    }
    hal.now_us = servo.next_tick_us - 10u * (*n - left) - 1u;
    feed_at_1mbaud(frame, *n - left);
    harness_poll(1); /* the framer sees `left` bytes to come */
    uint32_t due = servo.next_tick_us;
    hal.now_us = due;
    harness_poll(1);
    return due;
}

/* The tick that falls due 3 byte times before this servo's turn waits: the
 * answer starts in the pass after the line frees, the tick in the next, on
 * its schedule. */
static void test_a_tick_waits_for_a_sync_turn_a_tick_away(void **state)
{
    (void)state;
    uint8_t frame[32];
    size_t n;
    uint32_t due = tick_due_near_the_turn(46, 3, frame, &n);
    assert_int_equal(servo.turn_guard_bytes, 4);
    assert_int_equal(servo.next_tick_us, due); /* held */
    EXPECT_SILENCE();
    feed_at_1mbaud(&frame[n - 3], 3);
    harness_poll(1);
    assert_int_equal(hal.sent_length, 21); /* 30 us after the tick was due */
    assert_int_equal(servo.next_tick_us, due);
    harness_poll(1);
    assert_int_equal(servo.next_tick_us, due + CONTROL_TICK_US);
}

/* Further from the turn, or on a CPU whose tick is shorter than a byte
 * time, the tick runs when due; and a turn that does not come holds it
 * back by a tick and a pass at most. */
static void test_a_tick_waits_only_for_a_turn_it_would_delay(void **state)
{
    (void)state;
    uint8_t frame[32];
    size_t n;
    uint32_t due = tick_due_near_the_turn(46, 5, frame, &n);
    assert_int_equal(servo.next_tick_us, due + CONTROL_TICK_US);
    harness_init();
    due = tick_due_near_the_turn(9, 3, frame, &n);
    assert_int_equal(servo.turn_guard_bytes, 0);
    assert_int_equal(servo.next_tick_us, due + CONTROL_TICK_US);
    harness_init();
    due = tick_due_near_the_turn(46, 3, frame, &n);
    hal.now_us = due + 45u;
    harness_poll(1);
    assert_int_equal(servo.next_tick_us, due);
    hal.now_us = due + 46u;
    harness_poll(1);
    assert_int_equal(servo.next_tick_us, due + CONTROL_TICK_US);
    EXPECT_SILENCE();
}

/* Listed after 251 absent servos, this one would wait 251 x 3 ms for its
 * turn. A request meanwhile (to it or to anyone) means the host has given
 * up on the round: the servo drops its Sync Monitor answer and serves the
 * requests at once, none of them lost. */
static void test_a_new_request_ends_the_wait_for_a_sync_turn(void **state)
{
    (void)state;
    uint8_t sync[3 + 252] = {22, 1, 252};
    for (int i = 0; i < 251; i++) {
        sync[3 + i] = (uint8_t)(1 + i);
    }
    sync[3 + 251] = 0;
    harness_request(PKT_SYNC_COMMAND, sync, sizeof sync);
    hal.now_us += 10000;
    harness_poll(3);
    EXPECT_SILENCE(); /* still waiting: 3 of 251 turns gone */
    static const uint8_t six[][1] = {{7}, {0}, {0}, {9}, {0}, {0}};
    uint8_t wire[64 * 6];
    size_t n = 0;
    for (int i = 0; i < 6; i++) {
        n += make_request(&wire[n], 1, six[i], 1); /* pings, two to others */
    }
    hal_double_clear_sent(&hal);
    uint32_t sent_at = hal.now_us;
    for (size_t i = 0; i < n; i++) {
        harness_feed(&wire[i], 1);
        harness_poll(1);
    }
    harness_poll(3);
    uint8_t pong[16];
    size_t one = make_response(pong, 1, (const uint8_t[]){0}, 1);
    assert_int_equal(hal.sent_length, 4 * one); /* the four pings to servo 0 */
    for (int i = 0; i < 4; i++) {
        assert_memory_equal(&hal.sent[i * one], pong, one);
    }
    assert_true(hal.now_us - sent_at < 10000); /* not 750 ms later */
    assert_int_equal(servo.sync_turns_abandoned, 1);
    hal.now_us += 1000000; /* and the dropped answer never comes */
    harness_poll(3);
    assert_int_equal(hal.sent_length, 4 * one);
}

/* A page erase stalls the CPU for 20-40 ms, so the other page is erased
 * only while the output is released and the line is quiet. With both
 * pages full, a change made while the servo moves or holds is refused
 * (ReadStore bit 3) and not made; once the servo is released and the line
 * quiet, the erase runs and the same change is taken. */
static void test_the_flash_is_erased_only_while_released(void **state)
{
    (void)state;
    harness_ideal_tracking();
    WRITE_ITEM(0, ITEM_SOFT_START_ON, 0); /* soft start off: the move starts at once */
    const unsigned slots = config_store_slots_per_page(&servo.store);
    const uint32_t first = servo.store.sequence;
    for (unsigned i = 0; servo.store.sequence < first + 2u * slots - 1u; i++) {
        REQUEST(PKT_WRITE_DATA, 0, ITEM_CURRENT_LIMIT_MA, (uint8_t)(100u + i), 0x07); /* a new value each time */
        EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_CURRENT_LIMIT_MA, 1);
        harness_run_ms(70); /* too short a pause for an erase */
    }
    uint32_t erases = hal.flash.erases[0] + hal.flash.erases[1];
    /* A 1 s move to 100 degrees; a change during it, and while it holds. */
    REQUEST(PKT_MOVE_ANGLE_BY_INTERVAL, 0, 0xE8, 0x03, 0xE8, 0x03, 0x64, 0, 0xC8, 0, 0, 0);
    const uint16_t kept = servo.regs.user.current_limit_ma;
    WRITE_ITEM(0, ITEM_CURRENT_LIMIT_MA, 1621);
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_CURRENT_LIMIT_MA, 0);
    assert_int_equal(servo.regs.user.current_limit_ma, kept);
    assert_int_equal(store_field(ANSWER_READ_STORE_FLAGS), STORE_AWAITS_ERASE);
    harness_run_ms(2000); /* the move ends and holds; the line is quiet */
    assert_int_equal(hal.flash.erases[0] + hal.flash.erases[1], erases);
    WRITE_ITEM(0, ITEM_CURRENT_LIMIT_MA, 1621);
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_CURRENT_LIMIT_MA, 0);
    REQUEST(PKT_STOP_ON_CONTROL_MODE, 0, 0x10, 0, 0); /* released */
    harness_run_ms(150);
    assert_int_equal(hal.flash.erases[0] + hal.flash.erases[1], erases + 1u);
    assert_false(config_store_spare_dirty(&servo.store));
    assert_int_equal(store_field(ANSWER_READ_STORE_FLAGS), 0);
    WRITE_ITEM(0, ITEM_CURRENT_LIMIT_MA, 1621);
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_CURRENT_LIMIT_MA, 1);
    harness_restart();
    REQUEST(PKT_READ_DATA, 0, ITEM_CURRENT_LIMIT_MA);
    EXPECT_ITEM(0, ITEM_CURRENT_LIMIT_MA, 1621);
}

/* A WriteData that arrives in the ring while an erase stalls the CPU. */
static void write_arrives_during_erase(void *ctx)
{
    (void)ctx;
    uint8_t wire[16];
    size_t n = make_request(wire, 4, (const uint8_t[]){0, 38, 0xD2, 0x04}, 4);
    for (size_t i = 0; i < n; i++) {
        servo_on_rx_byte(&servo, wire[i], hal.now_us + 1000u + 87u * (uint32_t)i);
    }
    hal.now_us += 40000u;
}

/* Both config pages filled, then the line left quiet until the spare
 * page's erase runs, with arrive() putting bytes in the ring during it;
 * the answers sent so far cleared. */
static void erase_with_bytes_arriving(void (*arrive)(void *ctx))
{
    const unsigned slots = config_store_slots_per_page(&servo.store);
    for (unsigned i = 0; i < 2u * slots; i++) {
        REQUEST(PKT_WRITE_DATA, 0, ITEM_CURRENT_LIMIT_MA, (uint8_t)(100u + i), 0x07);
        harness_run_ms(70);
    }
    uint32_t erases = hal.flash.erases[0] + hal.flash.erases[1];
    hal.flash.during_erase = arrive;
    hal_double_clear_sent(&hal);
    while (hal.flash.erases[0] + hal.flash.erases[1] == erases) {
        hal.now_us += 250u; /* the line quiet until the erase runs */
        servo_poll(&servo);
    }
    hal.flash.during_erase = NULL;
}

/* A request that arrives while a page erase stalls the CPU is carried out
 * right after it, but not answered: 20-40 ms late, the answer could fall
 * in another servo's slot. ReadStore counts it; the next request is
 * answered as usual. The control loop resumes on a fresh schedule: the
 * output is released, and no tick counts as dropped. */
static void test_an_answer_that_would_leave_late_is_dropped(void **state)
{
    (void)state;
    uint32_t dropped_ticks = servo.ticks_dropped;
    erase_with_bytes_arriving(write_arrives_during_erase);
    harness_poll(4);
    assert_int_equal(hal.sent_length, 0u);       /* not answered */
    assert_int_equal(servo.regs.user.stall_power_mw, 1234); /* but carried out */
    assert_int_equal(servo.answers_dropped, 1u);
    assert_int_equal(servo.ticks_dropped, dropped_ticks);
    harness_run_ms(2);
    assert_int_equal(store_field(ANSWER_READ_STORE_ANSWERS_DROPPED), 1u);       /* ReadStore: answers dropped */
    assert_int_equal(store_field(ANSWER_READ_STORE_BYTES_LOST), 0u);       /* bytes lost */
    REQUEST(PKT_PING, 0);
    EXPECT_RESPONSE(PKT_PING, 0);
}

/* 90 ReadData (540 bytes) and a WriteData in the ring while an erase
 * stalls the CPU: at 1 Mbaud more than a 512-byte ring's lap. */
static void a_lap_arrives_during_erase(void *ctx)
{
    (void)ctx;
    uint8_t wire[16];
    uint32_t at = hal.now_us + 1000u;
    for (int i = 0; i < 90; i++) {
        size_t n = make_request(wire, 3, (const uint8_t[]){0, 38}, 2);
        for (size_t k = 0; k < n; k++) {
            servo_on_rx_byte(&servo, wire[k], at += 10u);
        }
    }
    size_t n = make_request(wire, 4, (const uint8_t[]){0, 38, 0xD2, 0x04}, 4);
    for (size_t k = 0; k < n; k++) {
        servo_on_rx_byte(&servo, wire[k], at += 10u);
    }
    hal.now_us += 40000u;
}

/* A ring that cannot hold an erase's worth of bytes at the baud rate (512
 * bytes at 1 Mbaud: 5 ms of a 40 ms erase) and wrapped during it: the DMA
 * laps in a stall go uncounted, so nothing that came is trusted. It is
 * dropped, counted as lost (ReadStore), and not carried out; the next
 * request is answered as usual. */
static void test_a_ring_that_wrapped_during_an_erase_is_dropped_and_counted(void **state)
{
    (void)state;
    assert_int_equal(hal_rx_ring_size(&hal.rx), 512u);
    WRITE_ITEM(0, ITEM_BAUD_INDEX, 8); /* 1 Mbaud */
    harness_poll(2);
    assert_int_equal(hal.baud, 1000000);
    const uint16_t stall_power = servo.regs.user.stall_power_mw;
    erase_with_bytes_arriving(a_lap_arrives_during_erase);
    harness_poll(20);
    assert_int_equal(hal.sent_length, 0u);
    assert_int_equal(servo.regs.user.stall_power_mw, stall_power); /* not carried out */
    assert_true(servo.rx_lost >= 512u);
    assert_int_equal(servo.answers_dropped, 0u);
    REQUEST(PKT_PING, 0);
    EXPECT_RESPONSE(PKT_PING, 0);
}

/* Six ReadData and a WriteData arrive in the ring while an erase stalls
 * the CPU: more frames than the framer's queue holds. */
static void a_burst_arrives_during_erase(void *ctx)
{
    (void)ctx;
    uint8_t wire[96];
    size_t n = 0;
    for (int i = 0; i < 6; i++) {
        n += make_request(wire + n, 3, (const uint8_t[]){0, 38}, 2);
    }
    n += make_request(wire + n, 4, (const uint8_t[]){0, 38, 0xD2, 0x04}, 4);
    for (size_t i = 0; i < n; i++) {
        servo_on_rx_byte(&servo, wire[i], hal.now_us + 1000u + 87u * (uint32_t)i);
    }
    hal.now_us += 40000u;
}

/* The ring holds what the framer's queue cannot: every frame of the burst
 * is carried out (the write, last, too), and none is answered late, the
 * ones framed passes after the erase included. */
static void test_a_burst_during_an_erase_is_carried_out_and_never_answered_late(void **state)
{
    (void)state;
    erase_with_bytes_arriving(a_burst_arrives_during_erase);
    harness_poll(20);
    assert_int_equal(hal.sent_length, 0u);
    assert_int_equal(servo.regs.user.stall_power_mw, 1234);
    assert_int_equal(servo.answers_dropped, 7u);
    assert_int_equal(servo.rx.stats.queue_overflows, 0u);
    assert_int_equal(servo.rx_lost, 0u);
    REQUEST(PKT_PING, 0);
    EXPECT_RESPONSE(PKT_PING, 0);
}

/* UpdateEnter (0x50): refused without a bootloader, and while the output
 * is driven (a move, holding its end, damping, a buffered move), each with
 * its reason; a released servo answers, and the restart waits for the
 * answer to leave and for the user area to be in flash. UpdateStatus says
 * the application answers, with its version. */
static void test_update_enter_restarts_into_the_bootloader(void **state)
{
    (void)state;
    REQUEST(PKT_UPDATE_ENTER, 0);
    EXPECT_RESPONSE(PKT_UPDATE_ENTER, 0, 0, 2); /* no bootloader on this port */
    hal.port.enter_bootloader = hal_double_enter_bootloader;
    hal.port.board = 0x0103;
    servo_init(&servo, &hal.port);
    harness_ideal_tracking();
    REQUEST(PKT_UPDATE_STATUS, 0);
    uint16_t version = servo.regs.status.firmware_version;
    EXPECT_RESPONSE(PKT_UPDATE_STATUS, 0, 0, 0, 0, 0, (uint8_t)version, (uint8_t)(version >> 8), 0x03, 0x01, 0, 0, 0, 0, 0, 0, 0);
    WRITE_ITEM(0, ITEM_SOFT_START_ON, 0); /* soft start off: the move starts at once */
    REQUEST(PKT_MOVE_ANGLE_BY_INTERVAL, 0, 0xE8, 0x03, 0xE8, 0x03, 0x64, 0, 0xC8, 0, 0, 0);
    REQUEST(PKT_UPDATE_ENTER, 0);
    EXPECT_RESPONSE(PKT_UPDATE_ENTER, 0, 0, 1); /* a move runs */
    harness_run_ms(1200);
    REQUEST(PKT_UPDATE_ENTER, 0);
    EXPECT_RESPONSE(PKT_UPDATE_ENTER, 0, 0, 1); /* it holds the end: a load would fall */
    REQUEST(PKT_MOVE_DAMPING, 0, 0xF4, 0x01);
    REQUEST(PKT_UPDATE_ENTER, 0);
    EXPECT_RESPONSE(PKT_UPDATE_ENTER, 0, 0, 1); /* damping */
    REQUEST(PKT_STOP_ON_CONTROL_MODE, 0, 0x10, 0, 0); /* released */
    harness_request(PKT_BEGIN_ASYNC, NULL, 0); /* a move buffered for EndAsync */
    REQUEST(PKT_MOVE_ANGLE_BY_INTERVAL, 0, 0xE8, 0x03, 0xE8, 0x03, 0x64, 0, 0xC8, 0, 0, 0);
    REQUEST(PKT_UPDATE_ENTER, 0);
    EXPECT_RESPONSE(PKT_UPDATE_ENTER, 0, 0, 1);
    REQUEST(PKT_END_ASYNC, 1); /* the buffer dropped */
    WRITE_ITEM(0, ITEM_CURRENT_LIMIT_MA, 1621); /* in flash before its answer */
    hal.tx_busy = true;
    REQUEST(PKT_UPDATE_ENTER, 0);
    EXPECT_RESPONSE(PKT_UPDATE_ENTER, 0, 1, 0);
    harness_poll(4);
    assert_int_equal(hal.bootloader_entries, 0); /* the answer is still on the wire */
    hal.tx_busy = false;
    harness_poll(2);
    assert_int_equal(hal.bootloader_entries, 1);
    /* The bootloader is told where the application answered: ID 0 at
     * 115 200 (index 5), whatever it would read from the store. */
    assert_int_equal(hal.bootloader_link, 0 | 5 << 8);
    harness_restart();
    REQUEST(PKT_READ_DATA, 0, ITEM_CURRENT_LIMIT_MA);
    EXPECT_ITEM(0, ITEM_CURRENT_LIMIT_MA, 1621);
}

static void test_garbage_between_frames_and_responses_of_others(void **state)
{
    (void)state;
    uint8_t wire[128];
    size_t n = 0;
    const uint8_t junk[] = {0x00, 0x12, 0x99, 0x05, 0x4C};
    memcpy(wire, junk, sizeof junk);
    n += sizeof junk;
    const uint8_t inner[] = {0x12, 0x4C, 0x01, 0x01, 0x00, 0x60}; /* a ping to 0 */
    n += make_response(wire + n, 3, inner, sizeof inner);
    const uint8_t ping[] = {0};
    n += make_request(wire + n, 1, ping, 1);
    hal_double_clear_sent(&hal);
    harness_feed(wire, n);
    harness_poll(4);
    EXPECT_RESPONSE(PKT_PING, 0); /* exactly one answer: the inner ping was skipped */
}

/* kt ratio x 57.19 / V (the back-EMF duty of 1 decideg per tick): the
 * reference check on controller.c's fixed-point derivation, in doubles. */
static int32_t kv_expected(double kt_un_m_per_a, double ratio, double supply_mv)
{
    return (int32_t)(kt_un_m_per_a * 1e-6 * ratio * 1.745329 / (supply_mv * 1e-3) * 32768.0);
}

/* The drive train and the gains are data (items 80-89): the factory ones
 * give the reference servo's feed-forward, a write changes what the
 * controller uses at once, and both survive a restart and ResetUserData. */
static void test_the_drive_train_is_data(void **state)
{
    (void)state;
    const struct drive_limits *lim = &servo.motion.drive;
    uint16_t v = servo.motion.drive_inputs.supply_mv;
    assert_true(v >= 6000u);
    assert_int_equal(lim->kp, 546);
    assert_int_equal(lim->kd, 3000);
    assert_true(abs(lim->kv - kv_expected(3714, 345, v)) <= 1);
    /* ka: 1 g cm^2 x 345 x 1745.3 rad/s^2 / kt x R / V, as Q15 duty */
    double ka = 1e-7 * 345 * 1745.329 / 3.714e-3 * 2.741 / (v * 1e-3) * 32768.0;
    assert_true(fabs(lim->ka - ka) <= ka * 1e-4 + 1.0);
    /* The micro-servo's motor, its inertia first: with the reference's
     * (item 83, 1000), kt 1324 would make ka 2.8 x and the factory ki
     * unstable (drive_items_stable). */
    WRITE_ITEM(0, ITEM_INERTIA_MG_CM2, 51);
    WRITE_ITEM(0, ITEM_KT_UN_M_PER_A, 1324);
    WRITE_ITEM(0, ITEM_GEAR_RATIO, 300);
    WRITE_ITEM(0, ITEM_GAIN_KP, 300);
    assert_true(abs(lim->kv - kv_expected(1324, 300, v)) <= 1);
    assert_int_equal(lim->kp, 300);
    REQUEST(PKT_RESET_USER_DATA, 0);
    EXPECT_RESPONSE(PKT_RESET_USER_DATA, 0, 1);
    harness_restart();
    assert_int_equal(servo.regs.user.gain_kp, 300);
    assert_int_equal(servo.regs.user.gear_ratio, 300);
    assert_int_equal(servo.motion.drive.kp, 300);
    assert_true(abs(servo.motion.drive.kv - kv_expected(1324, 300, servo.motion.drive_inputs.supply_mv)) <= 1);
    WRITE_ITEM(0, ITEM_GAIN_KP, 1024); /* above its most: refused */
    EXPECT_RESPONSE(PKT_WRITE_DATA, 0, ITEM_GAIN_KP, 0);
    assert_int_equal(servo.motion.drive.kp, 300);
}

/* The calibration items (82's sign, 90, 91) are taken: the zero at
 * power-up, the bridge driven the other way, the current's zero off every
 * reading; item 71 is the encoder's raw count. */
static void test_the_calibration_items_are_taken(void **state)
{
    (void)state;
    hal.encoder_raw = 1000;
    harness_run_ms(5); /* a tick reads it */
    REQUEST(PKT_READ_DATA, 0, ITEM_ENCODER_COUNT);
    EXPECT_ITEM(0, ITEM_ENCODER_COUNT, 1000);
    WRITE_ITEM(0, ITEM_ENCODER_ZERO, 1000);
    harness_restart();
    struct motion_angle angle;
    motion_read_angle(&servo.motion, &angle);
    assert_int_equal(angle.single_turn_decideg, 0); /* 1000 counts is angle 0 from power-up */
    hal.sensors.current = 40;
    harness_run_ms(100);
    assert_true(servo.regs.status.current_ma > 0);
    WRITE_ITEM(0, ITEM_CURRENT_ZERO_COUNTS, 40);
    harness_run_ms(100);
    assert_int_equal(servo.regs.status.current_ma, 0);
    REQUEST(PKT_DRIVE_DUTY, 0, 0xE8, 0x03, 100, 0); /* +1000 of 32767 for 100 ms */
    harness_run_ms(10);
    assert_true(hal.duty > 0);
    WRITE_ITEM(0, ITEM_GEAR_RATIO, -345);
    REQUEST(PKT_DRIVE_DUTY, 0, 0xE8, 0x03, 100, 0);
    harness_run_ms(10);
    assert_true(hal.duty < 0); /* the same command, the bridge the other way */
    assert_int_equal(servo.motion.drive.kv, kv_expected(3714, 345, servo.motion.drive_inputs.supply_mv));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_ping_exact_bytes, setup),
        cmocka_unit_test_setup(test_silence_for_others_broadcast_and_bad_checksum, setup),
        cmocka_unit_test_setup(test_read_data_every_item, setup),
        cmocka_unit_test_setup(test_write_data_and_failures, setup),
        cmocka_unit_test_setup(test_batch_read_write_and_reset, setup),
        cmocka_unit_test_setup(test_new_id_takes_effect_after_the_response, setup),
        cmocka_unit_test_setup(test_new_baud_takes_effect_after_the_response, setup),
        cmocka_unit_test_setup(test_an_idle_line_drops_a_partial_frame, setup),
        cmocka_unit_test_setup(test_a_pause_within_the_idle_time_keeps_the_frame, setup),
        cmocka_unit_test_setup(test_the_idle_time_survives_the_clock_wrap, setup),
        cmocka_unit_test_setup(test_a_clock_stepping_back_is_no_idle_line, setup),
        cmocka_unit_test_setup(test_config_survives_restart, setup),
        cmocka_unit_test_setup(test_reset_keeps_link, setup),
        cmocka_unit_test_setup(test_sync_monitor_waits_its_turn, setup),
        cmocka_unit_test_setup(test_sync_monitor_passes_a_silent_servo, setup),
        cmocka_unit_test_setup(test_a_tick_waits_for_a_sync_turn_a_tick_away, setup),
        cmocka_unit_test_setup(test_a_tick_waits_only_for_a_turn_it_would_delay, setup),
        cmocka_unit_test_setup(test_a_new_request_ends_the_wait_for_a_sync_turn, setup),
        cmocka_unit_test_setup(test_a_write_the_flash_refuses_is_not_made, setup),
        cmocka_unit_test_setup(test_every_change_is_in_flash_before_its_answer, setup),
        cmocka_unit_test_setup(test_writes_in_a_loop_stay_within_the_wear_budget, setup),
        cmocka_unit_test_setup(test_the_flash_is_erased_only_while_released, setup),
        cmocka_unit_test_setup(test_an_answer_that_would_leave_late_is_dropped, setup),
        cmocka_unit_test_setup(test_a_burst_during_an_erase_is_carried_out_and_never_answered_late, setup),
        cmocka_unit_test_setup(test_a_ring_that_wrapped_during_an_erase_is_dropped_and_counted, setup),
        cmocka_unit_test_setup(test_update_enter_restarts_into_the_bootloader, setup),
        cmocka_unit_test_setup(test_garbage_between_frames_and_responses_of_others, setup),
        cmocka_unit_test_setup(test_assign_id_by_serial_number, setup),
        cmocka_unit_test_setup(test_the_drive_train_is_data, setup),
        cmocka_unit_test_setup(test_the_calibration_items_are_taken, setup),
    };
    return cmocka_run_group_tests_name("servo", tests, NULL, NULL);
}
