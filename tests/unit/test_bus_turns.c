/* Three servo cores on one half-duplex wire: unsolicited answers (a move
 * finished, control response on) take turns in their ID's slot, with each
 * other, with answers to the host and with a Sync Monitor round. The wire
 * here is the simulator's rule made exact: a byte reaches every other
 * station one byte time after it starts, and a station that starts sending
 * while another's bytes are on the wire is a collision. Each servo's main
 * loop runs every 250 us (the simulator's step), at its own phase. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "support/frames.h"
#include "doubles/hal_double.h"
#include "doubles/ideal_encoder.h"
#include "app/servo.h"

enum {
    NODES = 3,
    BYTE_US = 87, /* 115200 baud */
    STEP_US = 10,
    LOOP_US = 250,
    HOST = NODES,
    WIRE_MAX = 8192,
};

struct node {
    struct hal_double hal;
    struct servo servo;
    size_t sent_seen;
    uint64_t tx_end;
    uint32_t phase_us;
};

struct wire_byte {
    uint64_t at; /* when its stop bit ends */
    uint8_t byte;
    uint8_t sender;
};

static struct node nodes[NODES];
static struct wire_byte wire[WIRE_MAX];
static size_t wire_head, wire_count;
static uint64_t now, wire_until, servo_until;
static unsigned collisions;
static uint8_t heard[WIRE_MAX]; /* what the host received */
static size_t heard_count;

/* The encoder follows the setpoint while under control: an ideal servo. */
static uint16_t ideal_encoder(void *model)
{
    struct node *n = model;
    const struct motion *m = &n->servo.motion;
    if (m->mode == MODE_POSITION) {
        n->hal.encoder_raw = ideal_encoder_raw(m);
    }
    return n->hal.encoder_raw;
}

static void put_on_wire(unsigned sender, const uint8_t *bytes, size_t n)
{
    uint64_t t = now > wire_until ? now : wire_until;
    for (size_t i = 0; i < n && wire_count < WIRE_MAX; i++) {
        t += BYTE_US;
        wire[(wire_head + wire_count++) % WIRE_MAX] =
            (struct wire_byte){.at = t, .byte = bytes[i], .sender = (uint8_t)sender};
    }
    wire_until = t;
}

static void host_sends(uint8_t code, const uint8_t *content, size_t length)
{
    uint8_t frame[64];
    size_t n = make_request(frame, code, content, length);
    put_on_wire(HOST, frame, n);
}

static void step(void)
{
    now += STEP_US;
    while (wire_count > 0 && wire[wire_head].at <= now) {
        const struct wire_byte *b = &wire[wire_head];
        for (unsigned i = 0; i < NODES; i++) {
            if (i != b->sender) {
                servo_on_rx_byte(&nodes[i].servo, b->byte, (uint32_t)b->at);
            }
        }
        if (b->sender != HOST && heard_count < WIRE_MAX) {
            heard[heard_count++] = b->byte;
        }
        wire_head = (wire_head + 1) % WIRE_MAX;
        wire_count--;
    }
    for (unsigned i = 0; i < NODES; i++) {
        struct node *n = &nodes[i];
        n->hal.now_us = (uint32_t)now;
        n->hal.tx_busy = now < n->tx_end;
        if ((now + n->phase_us) % LOOP_US != 0) {
            continue;
        }
        servo_poll(&n->servo);
        if (n->hal.sent_length > n->sent_seen) {
            if (now < wire_until) {
                collisions++; /* someone's bytes are still on the wire */
            }
            put_on_wire(i, &n->hal.sent[n->sent_seen], n->hal.sent_length - n->sent_seen);
            n->sent_seen = n->hal.sent_length;
            n->tx_end = wire_until;
            servo_until = wire_until;
            n->hal.tx_busy = true;
        }
    }
}

static void run_us(uint64_t us)
{
    for (uint64_t end = now + us; now < end;) {
        step();
    }
}

/* Servos with IDs 1..3 at different main-loop phases, soft start off. */
static int setup(void **state)
{
    (void)state;
    memset(nodes, 0, sizeof nodes);
    wire_head = wire_count = heard_count = 0;
    now = 10000;
    wire_until = servo_until = 0;
    collisions = 0;
    for (unsigned i = 0; i < NODES; i++) {
        struct node *n = &nodes[i];
        hal_double_init(&n->hal);
        n->hal.now_us = (uint32_t)now;
        n->hal.encoder_model = ideal_encoder;
        n->hal.model = n;
        n->phase_us = (uint32_t)(i * 70u) / STEP_US * STEP_US;
        servo_init(&n->servo, &n->hal.port);
        n->servo.regs.user.servo_id = (uint8_t)(i + 1);
        n->servo.link_settings_pending = 1; /* set directly, not by a request */
        n->servo.regs.user.soft_start_on = 0;
        n->servo.regs.user.control_response = 1;
        n->servo.regs.user.power_limit_mw = 0xFFFF;
        n->servo.regs.user.current_limit_ma = 0xFFFF;
    }
    run_us(5000); /* the new IDs take effect */
    heard_count = 0;
    return 0;
}

/* Response frames the host heard: how many whole ones with a good checksum
 * of packet `code` from `id`; fails on any byte that is not part of one. */
static unsigned answers_from(uint8_t code, uint8_t id)
{
    unsigned found = 0;
    size_t i = 0;
    while (i < heard_count) {
        assert_true(i + 5 <= heard_count);
        assert_int_equal(heard[i], 0x05);
        assert_int_equal(heard[i + 1], 0x1C);
        size_t end = i + 4 + heard[i + 3] + 1;
        assert_true(end <= heard_count);
        uint8_t sum = 0;
        for (size_t k = i; k + 1 < end; k++) {
            sum = (uint8_t)(sum + heard[k]);
        }
        assert_int_equal(sum, heard[end - 1]);
        found += heard[i + 2] == code && heard[i + 4] == id;
        i = end;
    }
    return found;
}

static void move(uint8_t id, int16_t angle, uint16_t interval_ms)
{
    const uint8_t content[] = {id, (uint8_t)angle, (uint8_t)((uint16_t)angle >> 8),
                               (uint8_t)interval_ms, (uint8_t)(interval_ms >> 8), 0, 0};
    host_sends(8, content, sizeof content);
}

/* Servos 1 and 2 finish moves at every offset from -3.5 to +3.5 ms of each
 * other, in steps of 50 us: each answer arrives whole, once, and no two
 * stations ever talk at once. */
static void test_finishing_at_any_offset_never_collides(void **state)
{
    unsigned runs = 0;
    for (int extra_ms = -3; extra_ms <= 3; extra_ms++) {
        for (uint32_t delay_us = 0; delay_us < 1000; delay_us += 50) {
            setup(state);
            move(1, 300, 100);
            run_us(delay_us);
            move(2, 300, (uint16_t)(100 + extra_ms));
            run_us(400000);
            assert_int_equal(collisions, 0);
            assert_int_equal(answers_from(8, 1), 1);
            assert_int_equal(answers_from(8, 2), 1);
            runs++;
        }
    }
    printf("# %u runs, finishes -3.5..+3.5 ms apart: no collision\n", runs);
}

/* While the host keeps servo 3 busy (a ping every 2 ms, answered at once),
 * the line is never quiet long enough for a slot: the finished answers wait
 * for the host to pause, then go out in ID order. */
static void test_answers_wait_for_the_host_to_pause(void **state)
{
    (void)state;
    move(2, 300, 100);
    move(1, 300, 100);
    run_us(3000); /* the host waits for the line, as hosts do */
    for (int i = 0; i < 150; i++) {
        const uint8_t ping[] = {3};
        host_sends(1, ping, sizeof ping);
        run_us(2000);
    }
    assert_int_equal(answers_from(8, 1) + answers_from(8, 2), 0);
    assert_int_equal(answers_from(1, 3), 150);
    run_us(300000);
    assert_int_equal(collisions, 0);
    assert_int_equal(answers_from(8, 1), 1);
    assert_int_equal(answers_from(8, 2), 1);
    /* Servo 1's answer comes before servo 2's. */
    size_t first = 0;
    while (!(heard[first + 2] == 8 && (heard[first + 4] == 1 || heard[first + 4] == 2))) {
        first += 4u + heard[first + 3] + 1u;
    }
    assert_int_equal(heard[first + 4], 1);
}

/* A Sync Monitor round in progress (servo 3 listed after an absent ID 9, so
 * it waits 3 ms of silence for its turn) is not cut into by an answer that
 * becomes due meanwhile. */
static void test_a_sync_monitor_round_is_not_cut_into(void **state)
{
    (void)state;
    for (uint32_t lead_us = 0; lead_us < 6000; lead_us += 250) {
        setup(state);
        move(1, 300, 100);
        run_us(100000 - lead_us); /* the move finishes around now */
        const uint8_t sync[] = {22, 1, 2, 9, 3};
        host_sends(25, sync, sizeof sync);
        run_us(300000);
        assert_int_equal(collisions, 0);
        assert_int_equal(answers_from(8, 1), 1);
        assert_int_equal(answers_from(22, 3), 1);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_finishing_at_any_offset_never_collides, setup),
        cmocka_unit_test_setup(test_answers_wait_for_the_host_to_pause, setup),
        cmocka_unit_test_setup(test_a_sync_monitor_round_is_not_cut_into, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
