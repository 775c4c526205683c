/* libFuzzer harness: arbitrary byte streams through the receive path,
 * framer, dispatcher, register file and config store of one servo.
 *
 * Input: one control byte, then the bytes "on the wire". The control byte
 * picks how often the main loop runs, whether the UART is slow to finish
 * and where idle gaps fall, so timeouts and queueing are reached too.
 * Beyond the sanitizers, after every main-loop pass it checks that the
 * register file holds only valid values and that everything sent is a
 * well-formed response frame. */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "hal_double.h"
#include "protocol/data_table.h"
#include "servo.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static struct hal_double hal;
static struct servo servo;

#define CHECK(cond)              \
    do {                         \
        if (!(cond)) {           \
            __builtin_trap();    \
        }                        \
    } while (0)

/* Every byte sent must belong to a complete, correct response frame. */
static void check_sent(void)
{
    size_t i = 0;
    while (i < hal.sent_length) {
        CHECK(hal.sent_length - i >= 5);
        CHECK(hal.sent[i] == 0x05 && hal.sent[i + 1] == 0x1C);
        size_t n = 4u + hal.sent[i + 3] + 1u;
        CHECK(hal.sent_length - i >= n);
        uint8_t sum = 0;
        for (size_t k = 0; k + 1 < n; k++) {
            sum = (uint8_t)(sum + hal.sent[i + k]);
        }
        CHECK(sum == hal.sent[i + n - 1]);
        i += n;
    }
    hal_double_clear_sent(&hal);
}

static void check_invariants(void)
{
    CHECK(user_config_valid(&servo.regs.user));
    CHECK(servo.active_id != 0xFF);
    CHECK(servo.regs.status.serial_number == hal.port.serial_number);
    CHECK(!hal.flash.misuse);
    CHECK(servo.rx.head < FRAME_QUEUE_SLOTS && servo.rx.tail < FRAME_QUEUE_SLOTS);
    check_sent();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0) {
        return 0;
    }
    hal_double_init(&hal);
    servo_init(&servo, &hal.port);
    uint8_t control = data[0];
    unsigned poll_every = 1u + (control & 0x0Fu);   /* bytes between passes */
    bool slow_uart = control & 0x10u;
    unsigned gap_every = (control >> 5) ? 7u * (control >> 5) : 0u;

    for (size_t i = 1; i < size; i++) {
        hal.now_us += 87u;
        if (gap_every && i % gap_every == 0) {
            hal.now_us += 20000u; /* longer than any idle timeout */
        }
        servo_on_rx_byte(&servo, data[i], hal.now_us);
        if (i % poll_every == 0) {
            hal.tx_busy = slow_uart && (i & 1u);
            servo_poll(&servo);
            check_invariants();
        }
    }
    hal.tx_busy = false;
    for (int k = 0; k < 8; k++) {
        hal.now_us += 5000u; /* lets sync turn-taking time out */
        servo_poll(&servo);
        check_invariants();
    }
    return 0;
}
