/* Benchmark (not a test): instructions spent by the receive path, framer and
 * dispatcher, counted by callgrind. Run it through run_bench.py.
 *
 * Regions (bench_region.h: callgrind on the host, the QEMU plugin on the
 * target):
 *   stream      a realistic mixed bus stream: requests for this servo and for
 *               others, other servos' responses, garbage; one main-loop pass
 *               after each message, as the main loop would run between them
 *               (no control tick falls due: bench_motion counts those)
 *   idle_poll   one main-loop pass with nothing to do
 *   latency_*   from a request's last byte (receive interrupt) to its
 *               response being handed to the UART (one main-loop pass) */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_region.h"
#include "frames.h"
#include "hal_double.h"
#include "servo.h"

#define OWN_ID 1u
#ifndef BENCH_MESSAGES
#define BENCH_MESSAGES 4000u /* the target build has 64 KB of RAM: fewer */
#endif
#define MESSAGES BENCH_MESSAGES

static struct hal_double hal;
static struct servo servo;
static uint8_t stream[MESSAGES * 40u];
static size_t stream_length;
static size_t message_end[MESSAGES];
static unsigned messages;

static uint32_t lcg_state = 12345u;
static uint32_t rnd(uint32_t n)
{
    lcg_state = lcg_state * 1103515245u + 12345u;
    return (lcg_state >> 8) % n;
}

static void add(const uint8_t *bytes, size_t n)
{
    memcpy(&stream[stream_length], bytes, n);
    stream_length += n;
    message_end[messages++] = stream_length;
}

/* A request of a common kind, for servo `id`. */
static size_t some_request(uint8_t *out, uint8_t id)
{
    switch (rnd(6)) {
    case 0:
        return make_request(out, 1, (uint8_t[]){id}, 1);
    case 1:
        return make_request(out, 3, (uint8_t[]){id, (uint8_t)(1 + rnd(8))}, 2);
    case 2:
        return make_request(out, 22, (uint8_t[]){id}, 1);
    case 3:
        return make_request(out, 10, (uint8_t[]){id}, 1);
    case 4: /* angle move by interval, 11 bytes */
        return make_request(out, 11, (uint8_t[]){id, 0xE8, 0x03, 0xE8, 0x03, 0x64, 0, 0xC8, 0, 0, 0}, 11);
    default: /* write of an unchanged value */
        return make_request(out, 4, (uint8_t[]){id, 44, 0}, 3);
    }
}

static void build_stream(void)
{
    uint8_t buf[64];
    while (messages < MESSAGES) {
        uint32_t kind = rnd(100);
        size_t n;
        if (kind < 25) { /* for this servo */
            n = some_request(buf, OWN_ID);
        } else if (kind < 65) { /* for another servo */
            n = some_request(buf, (uint8_t)(2 + rnd(20)));
        } else if (kind < 90) { /* another servo's response */
            uint8_t content[16] = {(uint8_t)(2 + rnd(20))};
            n = make_response(buf, 22, content, rnd(2) ? 16 : 4);
        } else { /* line noise */
            n = 1 + rnd(8);
            for (size_t i = 0; i < n; i++) {
                buf[i] = (uint8_t)rnd(256);
            }
        }
        add(buf, n);
    }
}

static void feed_range(size_t from, size_t to)
{
    for (size_t i = from; i < to; i++) {
        hal.now_us += 87u;
        servo_on_rx_byte(&servo, stream[i], hal.now_us);
    }
}

static void __attribute__((noinline)) run_stream(void)
{
    size_t pos = 0;
    for (unsigned m = 0; m < messages; m++) {
        feed_range(pos, message_end[m]);
        pos = message_end[m];
        hal.now_us += 2000u; /* a gap: noise never joins the next frame */
        servo_poll(&servo);
        hal.sent_length = 0;
    }
}

static void fresh_servo(void)
{
    hal_double_init(&hal);
    hal.now_us = 1000u;
    servo_init(&servo, &hal.port);
    hal.port.serial_number = 0;
    servo.regs.user.servo_id = OWN_ID;
    servo_poll(&servo); /* applies the ID */
}

/* One request: all but its last byte outside the measurement. */
static void latency(const char *name, uint8_t code, const uint8_t *content, size_t length)
{
    uint8_t frame[64];
    size_t n = make_request(frame, code, content, length);
    for (size_t i = 0; i + 1 < n; i++) {
        hal.now_us += 87u;
        servo_on_rx_byte(&servo, frame[i], hal.now_us);
    }
    unsigned sends = hal.sends;
    hal.now_us += 87u;
    servo.next_tick_us = hal.now_us + 0x7FFFFFFFu; /* no control tick inside */
    bench_begin();
    servo_on_rx_byte(&servo, frame[n - 1], hal.now_us);
    servo_poll(&servo);
    bench_end(name);
    if (hal.sends != sends + 1u) {
        fprintf(stderr, "%s: no response was sent\n", name);
        exit(1);
    }
    servo_poll(&servo);
}

int main(void)
{
    build_stream();
    fresh_servo();
    bench_setup();

    /* No control tick falls due during the stream: bench_motion counts
     * those; this is the receive path, framer and dispatcher. */
    servo.next_tick_us = hal.now_us + 0x7FFFFFFFu;
    bench_begin();
    run_stream();
    bench_end("stream");
    printf("stream_bytes %lu\nstream_messages %u\nframes_for_all %u\nresponses_skipped %u\n",
           (unsigned long)stream_length, messages, (unsigned)servo.rx.stats.frames,
           (unsigned)servo.rx.stats.responses_skipped);

    bench_begin();
    servo_poll(&servo);
    bench_end("idle_poll");

    fresh_servo();
    latency("latency_ping", 1, (uint8_t[]){OWN_ID}, 1);
    latency("latency_read_status", 3, (uint8_t[]){OWN_ID, 5}, 2);
    latency("latency_read_batch", 5, (uint8_t[]){OWN_ID}, 1);
    latency("latency_monitor", 22, (uint8_t[]){OWN_ID}, 1);
    latency("latency_write_data", 4, (uint8_t[]){OWN_ID, 50, 0xE8, 0x03}, 4);
    return 0;
}
