#include "support/servo_harness.h"

#include "doubles/ideal_encoder.h"

#include <setjmp.h>
#include <stdarg.h>
#include <string.h>

#include <cmocka.h>

struct hal_double hal;
struct servo servo;

static uint16_t held_raw;

void harness_init(void)
{
    hal_double_init(&hal);
    hal.now_us = 5000;
    servo_init(&servo, &hal.port);
}

void harness_restart(void)
{
    flash_double_power_on(&hal.flash);
    flash_double_power_on(&hal.fault_flash);
    servo_init(&servo, &hal.port);
}

void harness_poll(unsigned n)
{
    for (unsigned i = 0; i < n; i++) {
        servo_poll(&servo);
        hal_double_dma_reads(&hal);
    }
}

/* The main loop takes what the port received long before its ring is
 * full: a pass whenever it would be. */
void harness_feed(const uint8_t *bytes, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (hal.rx.written - hal.rx.read == hal_rx_ring_size(&hal.rx)) {
            servo_poll(&servo);
            hal_double_dma_reads(&hal);
        }
        hal.now_us += HARNESS_BYTE_US;
        servo_on_rx_byte(&servo, bytes[i], hal.now_us);
    }
}

void harness_request(uint8_t code, const uint8_t *content, size_t length)
{
    static uint8_t wire[4096];
    size_t n = make_request(wire, code, content, length);
    hal_double_clear_sent(&hal);
    harness_feed(wire, n);
    harness_poll(4);
}

void harness_run_ms(uint32_t ms)
{
    for (uint32_t i = 0; i < 4u * ms; i++) {
        hal.now_us += 250u;
        servo_poll(&servo);
        hal_double_dma_reads(&hal);
    }
}

static uint16_t ideal_encoder(void *model)
{
    (void)model;
    const struct motion *m = &servo.motion;
    if (m->mode == MODE_POSITION) {
        held_raw = ideal_encoder_raw(m);
    }
    return held_raw;
}

void harness_ideal_tracking(void)
{
    held_raw = (uint16_t)(servo.motion.encoder.counts & (ENCODER_COUNTS - 1));
    hal.encoder_model = ideal_encoder;
}

void harness_assert_sent(const uint8_t *frame, size_t n)
{
    assert_int_equal(hal.sent_length, n);
    assert_memory_equal(hal.sent, frame, n);
}
