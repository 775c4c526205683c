/* One servo core on the HAL double, driven by request bytes, for cmocka
 * tests that check exact response bytes (or silence). */
#ifndef TEST_SERVO_HARNESS_H
#define TEST_SERVO_HARNESS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "support/frames.h"
#include "doubles/hal_double.h"
#include "app/servo.h"

#define HARNESS_BYTE_US 87u

extern struct hal_double hal;
extern struct servo servo;

/* A fresh servo (blank flash) at time 5 ms. */
void harness_init(void);
/* Power cycle: same flash, new servo. */
void harness_restart(void);
void harness_feed(const uint8_t *bytes, size_t n);
void harness_poll(unsigned n);
/* Clears what was sent, sends a request, runs a few main-loop passes. */
void harness_request(uint8_t code, const uint8_t *content, size_t length);
/* Lets ms milliseconds pass, one main-loop pass every 250 us. */
void harness_run_ms(uint32_t ms);
/* The encoder follows the setpoint exactly while the servo is under
 * control, and stays put while released: an ideal servo. */
void harness_ideal_tracking(void);
void harness_assert_sent(const uint8_t *frame, size_t n);

#define REQUEST(code, ...)                                  \
    do {                                                    \
        const uint8_t c_[] = {__VA_ARGS__};                 \
        harness_request((code), c_, sizeof c_);             \
    } while (0)

/* The response frame for code/content must be exactly what was sent. */
#define EXPECT_RESPONSE(code, ...)                          \
    do {                                                    \
        const uint8_t e_[] = {__VA_ARGS__};                 \
        uint8_t f_[64];                                     \
        size_t n_ = make_response(f_, (code), e_, sizeof e_); \
        harness_assert_sent(f_, n_);                        \
    } while (0)

#define EXPECT_SILENCE() assert_int_equal(hal.sent_length, 0)

#endif
