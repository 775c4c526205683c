/* Benchmark (not a test): instructions spent by the receive path, framer and
 * dispatcher. Run it through tests/bench/target/run_target_bench.py (the
 * Thumb-2 build under QEMU).
 *
 * The servo receives and sends as on the reference board: the STM32F1
 * port's code (usart_hd.c, dma_rx.c; answers by DMA, dma_tx.h) on registers
 * in RAM. The benchmark plays the DMA channels (bytes into the ring, the
 * counter down, a lap interrupt per ring); what the CPU runs is counted: the lap interrupt and the main loop
 * (the port raises no receive interrupt). Each reading of the clock runs
 * the port's SysTick clock too (QEMU has SysTick), though the benchmark's
 * own clock is what the servo sees.
 *
 * Regions (bench_region.h; a name measured many times is summed):
 *   stream      a realistic mixed bus stream: requests for this servo and for
 *               others, other servos' responses, garbage; after each
 *               message the interrupts it raised and one main-loop pass
 *               (no control tick falls due: bench_motion counts those)
 *   idle_poll   one main-loop pass with nothing to do
 *   answer_*    every packet that is answered: from the request's last byte
 *               (in the ring by DMA) to its answer handed to the UART (the
 *               main-loop pass that takes it)
 *   request_*   every packet that is not: the main-loop pass that takes it */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/bench_region.h"
#include "registers/data_table.h"
#include "ports/stm32_common/dma_rx.h"
#include "ports/stm32_common/flash_f0f1.h"
#include "support/frames.h"
#include "doubles/hal_double.h"
#include "doubles/ideal_encoder.h"
#include "app/servo.h"
#include "ports/stm32f1/stm32f1_regs.h"
#include "ports/stm32_common/systick_clock.h"
#include "ports/stm32f1/usart_hd.h"

#define OWN_ID 1u
#ifndef BENCH_MESSAGES
#define BENCH_MESSAGES 4000u /* the target build has 64 KB of RAM: fewer */
#endif
#define MESSAGES BENCH_MESSAGES

static struct hal_double hal;
static struct servo servo;
/* The USART's and the DMA channel's registers, in RAM. */
static uint32_t usart_regs[8];
static uint32_t dma_regs[4];
static uint32_t dma_tx_regs[4];
static struct usart_hd usart;
static struct dma_rx dma;
static unsigned laps_due; /* transfer-complete interrupts the DMA raised */
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

static uint32_t clock_us(void)
{
    return hal.now_us;
}

/* What reading the reference board's clock costs, at the time the
 * benchmark says. */
static uint32_t port_now_us(void *ctx)
{
    (void)ctx;
    (void)systick_now_us();
    return hal.now_us;
}

/* Set: the region under way ends once the answer is handed to the UART
 * (named split_name), and the rest of the pass's begins. */
static bool split_at_send;
static const char *split_name;

static void port_uart_send(void *ctx, const uint8_t *data, uint16_t len)
{
    (void)ctx;
    usart_hd_send_dma(&usart, data, len);
    if (split_at_send) {
        split_at_send = false;
        bench_end(split_name);
        bench_begin();
    }
}

static bool port_uart_tx_done(void *ctx)
{
    (void)ctx;
    return usart_hd_tx_done(&usart);
}

/* The hardware's part, not counted: the DMA channel writes the bytes. */
static void dma_writes(const uint8_t *bytes, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        hal.now_us += 87u;
        uint32_t left = dma_regs[1];
        hal.rx.data[hal_rx_ring_size(&hal.rx) - left] = bytes[i];
        dma_regs[1] = left == 1u ? hal_rx_ring_size(&hal.rx) : left - 1u;
        laps_due += left == 1u;
    }
}

/* The USART's part, not counted: the frame left the wire. */
static void transmission_ends(void)
{
    usart.tx_busy = 0;
    usart_regs[3] = (usart_regs[3] & ~(USART_CR1_TXEIE | USART_CR1_TCIE)) | USART_CR1_RE;
}

/* What the CPU runs after a message: the interrupts it raised, then a
 * main-loop pass. */
static inline __attribute__((always_inline)) void lap_interrupts(void)
{
    for (; laps_due > 0u; laps_due--) {
        dma_rx_lap(&dma);
    }
}

static inline __attribute__((always_inline)) void cpu_runs(void)
{
    lap_interrupts();
    servo_poll(&servo);
}

static void __attribute__((noinline)) run_stream(void)
{
    size_t pos = 0;
    for (unsigned m = 0; m < messages; m++) {
        dma_writes(&stream[pos], message_end[m] - pos);
        pos = message_end[m];
        hal.now_us += 2000u; /* a gap: noise never joins the next frame */
        bench_begin();
        cpu_runs();
        bench_end("stream");
        transmission_ends();
    }
}

/* The fault history's reads run the board's code (flash_f0f1.c), on the
 * double's pages: where a page lies in RAM is the harness's part. */
static void port_flash_read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len)
{
    struct flash_double *f = ctx;
    uintptr_t in_ram = (uintptr_t)&f->mem[0][0] + (addr - f->hal.page_addr[0]);
    flash_f0f1_read(NULL, (uint32_t)in_ram, dst, len);
}

static void fresh_servo(void)
{
    hal_double_init(&hal);
    hal.now_us = 1000u;
    memset(usart_regs, 0, sizeof usart_regs);
    usart_hd_init(&usart, (uintptr_t)usart_regs, 72000000u, 115200u, true, &hal.rx, clock_us);
    dma_rx_start(&dma, (uintptr_t)dma_regs, (uintptr_t)&usart_regs[1], &hal.rx);
    usart_hd_rx_dma(&usart);
    usart_hd_tx_dma(&usart, (uintptr_t)dma_tx_regs);
    laps_due = 0;
    hal.port.bus.now_us = port_now_us;
    hal.port.bus.rx_sync = dma_rx_sync;
    hal.port.rx_ctx = &dma;
    hal.port.bus.send = port_uart_send;
    hal.port.bus.tx_done = port_uart_tx_done;
    _Static_assert(FLASH_DOUBLE_PAGE_MAX == 1024u, "the double's pages lie end to end");
    hal.flash.hal.read = port_flash_read;
    hal.fault_flash.hal.read = port_flash_read;
    servo_init(&servo, &hal.port);
    servo.regs.user.servo_id = OWN_ID;
    servo.link_settings_pending = 1; /* set directly, not by a request */
    servo_poll(&servo); /* applies the ID */
}

/* One request: all but its last byte outside the measurement. The image
 * must keep it (the framer hands it on) and answer it exactly when the
 * protocol says it answers: a packet dropped by this CPU's build of the
 * framer or dispatcher stops the benchmark. */
static void latency(const char *name, uint8_t code, const uint8_t *content, size_t length,
                    bool answers)
{
    uint8_t frame[80];
    size_t n = make_request(frame, code, content, length);
    uint32_t frames_before = servo.rx.stats.frames;
    /* run_target_bench.py checks these against protocol/servo_schema: every
     * packet measured, and answered exactly where the schema says. */
    printf("packet %u %s\n", code, answers ? "answer" : "quiet");
    dma_writes(frame, n - 1u);
    cpu_runs(); /* the main loop takes all but the last byte */
    dma_writes(&frame[n - 1u], 1);
    lap_interrupts(); /* rare (one a ring), and not the answer's path */
    servo.next_tick_us = hal.now_us + 0x7FFFFFFFu;
    tick_scheduled(&servo); /* no control tick inside */
    bench_begin();
    servo_poll(&servo);
    bench_end(name);
    if (servo.rx.stats.frames != frames_before + 1u) {
        fprintf(stderr, "%s: the framer dropped packet %u\n", name, code);
        exit(1);
    }
    if (answers != (usart.tx_busy != 0u)) {
        fprintf(stderr, "%s: %s\n", name, answers ? "no response was sent" : "answered a packet that has no answer");
        exit(1);
    }
    if (!answers && (servo.regs.status.status & STATUS_COMMAND_ERROR)) {
        fprintf(stderr, "%s: refused (command error)\n", name);
        exit(1);
    }
    transmission_ends();
    servo_poll(&servo);
}

/* The horn follows the setpoint exactly (for the move below). */
static uint16_t follow(void *model)
{
    (void)model;
    return servo.motion.mode == MODE_POSITION ? ideal_encoder_raw(&servo.motion) : hal.encoder_raw;
}

/* A move's answer when it has finished (item 33 on): the main-loop pass
 * that sends it, in the servo's slot on a quiet line, no control tick in
 * it (bench_motion counts those). The move runs first, unmeasured. */
static void finished_move_answer(void)
{
    uint8_t frame[80];
    size_t n = make_request(frame, 8, (const uint8_t[]){OWN_ID, 0x10, 0x00, 0x0A, 0x00, 0, 0}, 7);
    dma_writes(frame, n);
    printf("packet 8 finished\n");
    hal.encoder_model = follow;
    servo.next_tick_us = hal.now_us;
    tick_scheduled(&servo); /* the control loop runs again */
    for (unsigned ms = 0; !motion_has_finished(&servo.motion); ms++) {
        if (ms == 10000u) {
            fprintf(stderr, "answer_move_finished: the move did not finish\n");
            exit(1);
        }
        hal.now_us += 1000u;
        cpu_runs();
    }
    uint32_t until = hal.now_us + 0x7FFFFFFFu;
    while (usart.tx_busy == 0u) {
        if ((int32_t)(hal.now_us - until) >= 0) {
            fprintf(stderr, "answer_move_finished: no answer was sent\n");
            exit(1);
        }
        hal.now_us += 50u;
        servo.next_tick_us = hal.now_us + 0x7FFFFFFFu;
        tick_scheduled(&servo); /* no control tick inside */
        bench_begin();
        servo_poll(&servo);
        bench_end(usart.tx_busy != 0u ? "answer_move_finished" : "waiting_for_the_slot");
    }
    transmission_ends();
    servo_poll(&servo);
    hal.encoder_model = NULL;
}

#define ID OWN_ID
#define BYTES(...) (const uint8_t[]){__VA_ARGS__}, sizeof((const uint8_t[]){__VA_ARGS__})
/* A packet the protocol answers, and one it does not. */
#define ANSWER(name, code, ...) latency("answer_" name, code, BYTES(__VA_ARGS__), true)
#define QUIET(name, code, ...) latency("request_" name, code, BYTES(__VA_ARGS__), false)

/* Every packet of docs/protocol.md, in
 * the order a session might send them. */
static void every_packet(void)
{
    ANSWER("ping", 1, ID);
    ANSWER("read_status", 3, ID, 5);
    ANSWER("read_batch", 5, ID);
    ANSWER("monitor", 22, ID);
    ANSWER("read_angle", 10, ID);
    ANSWER("read_multi_turn", 16, ID);
    ANSWER("read_motion", 0x40, ID);
    ANSWER("read_store", 0x41, ID);
    /* A fault in the history to read (it is written before the stream). */
    const struct fault_entry stall = {.what = FAULT_STALL, .op_seconds = 60, .voltage_mv = 7400};
    if (fault_log_add(&servo.faults, &stall)) {
        while (fault_log_step(&servo.faults)) {
        }
    }
    ANSWER("read_faults", 0x43, ID, 0);
    ANSWER("update_status", 0x55, ID);
    /* A change is programmed before its answer (docs/decisions.md); the
     * same value again writes nothing. */
    ANSWER("write_data", 4, ID, 50, 0xE8, 0x03);
    ANSWER("write_same", 4, ID, 50, 0xE8, 0x03);
    uint8_t batch[1u + USER_AREA_SIZE] = {ID};
    user_config_encode(&servo.regs.user, &batch[1]);
    batch[1u + 50u - 32u] = 0xD0; /* item 50 (2 bytes) 1000 -> 2000 */
    batch[2u + 50u - 32u] = 0x07;
    latency("answer_write_batch", 6, batch, sizeof batch, true);
    /* Valid while released. */
    QUIET("set_origin", 23, ID, 0);
    QUIET("reset_multi_turn", 17, ID);
    QUIET("move_angle", 8, ID, 0x84, 0x03, 0xF4, 0x01, 0, 0);
    /* Under position control ReadMotion has more to say (its flags). */
    ANSWER("read_motion_moving", 0x40, ID);
    QUIET("move_interval", 11, ID, 0x08, 0x07, 0xE8, 0x03, 0x64, 0, 0x64, 0, 0, 0);
    QUIET("move_velocity", 12, ID, 0x84, 0x03, 0xE8, 0x03, 0x64, 0, 0x64, 0, 0, 0);
    QUIET("move_multi_turn", 13, ID, 0x10, 0x0E, 0, 0, 0xE8, 0x03, 0, 0, 0, 0);
    QUIET("move_multi_interval", 14, ID, 0x20, 0x1C, 0, 0, 0xD0, 0x07, 0, 0, 0x64, 0, 0x64, 0, 0, 0);
    QUIET("move_multi_velocity", 15, ID, 0x10, 0x0E, 0, 0, 0xE8, 0x03, 0x64, 0, 0x64, 0, 0, 0);
    QUIET("move_wheel", 7, ID, 0x01, 0x64, 0, 0, 0);
    QUIET("move_damping", 9, ID, 0xE8, 0x03);
    QUIET("stop", 24, ID, 0x11, 0, 0);
    /* A host's stream: a setpoint 20 ms on (item 69 learns the period). */
    QUIET("stream_setpoint", 0x45, ID, 0x84, 0x03, 0, 0, 0x64, 0, 0x14, 0);
    latency("request_begin_async", 18, NULL, 0, false);
    QUIET("move_angle_async", 8, ID, 0x00, 0x00, 0xF4, 0x01, 0, 0);
    QUIET("end_async", 19, 0);
    /* SyncCommand: a move for another servo and this one; Sync Monitor
     * with this servo first (it answers at once). */
    QUIET("sync_move", 25, 8, 7, 2, 9, 0x84, 0x03, 0xF4, 0x01, 0, 0, ID, 0x84, 0x03, 0xF4, 0x01, 0, 0);
    ANSWER("sync_monitor", 25, 22, 1, 2, ID, 9);
    QUIET("start_monitor", 20, 0);
    QUIET("stop_monitor", 21, 0);
    /* The bootloader's update packets: an application keeps them unanswered. */
    QUIET("update_erase", 0x51, ID, 0);
    QUIET("update_write", 0x52, ID, 0);
    QUIET("update_verify", 0x53, ID, 0);
    QUIET("update_boot", 0x54, ID, 0);
    /* Open loop for 100 ms: the bridge at a tenth of the supply. */
    QUIET("drive_duty", 0x46, ID, 0xCD, 0x0C, 0x64, 0);
    ANSWER("reset_user_data", 2, ID);
    uint32_t serial = servo.regs.status.serial_number;
    ANSWER("assign_id", 0x42, 0xFF, (uint8_t)serial, (uint8_t)(serial >> 8), (uint8_t)(serial >> 16),
        (uint8_t)(serial >> 24), ID);
    ANSWER("clear_faults", 0x44, ID);
    /* Item 33 on: moves are answered when they have finished. */
    ANSWER("write_control_response", 4, ID, 33, 1);
    finished_move_answer();
    ANSWER("write_control_response_off", 4, ID, 33, 0);
    /* Refused while the servo holds, but answered. */
    ANSWER("update_enter", 0x50, ID);
}

/* Ends the region pass_to_ring at a pass's reading of the ring (the
 * harness's part, not counted), once. */
static bool ring_marked;
static void rx_sync_marked(void *rx_dma, uint32_t now_us)
{
    if (ring_marked) {
        ring_marked = false;
        bench_end("pass_to_ring");
    }
    dma_rx_sync(rx_dma, now_us);
}

/* A Sync Monitor round of six servos, as a robot loop's host sends it
 * (docs/sleep.md, "The first answer"): the main loop, awake while the
 * line is in use, frames the request as its bytes land. Listed first, this servo sends its
 * answer in the pass that frames the checksum byte (sync_first_pass, up to
 * the UART's start; on the M0 the rest of the answer is built behind its
 * first bytes, sync_first_build: the rest of the pass); listed second,
 * it sends in the pass that frames the first one's answer's last byte
 * (sync_next_pass); listed first of two, the pass that frames the other
 * record and the checksum (sync_first_pass_of_two). run_target_bench.py
 * adds the idle pass that may have
 * just missed the byte, and judges the sum against 2 byte times. */
static void sync_monitor_round(void)
{
    uint8_t frame[80];
    size_t n = make_request(frame, 25, (const uint8_t[]){22, 1, 6, OWN_ID, 9, 10, 11, 12, 13}, 9);
    servo.next_tick_us = hal.now_us + 0x7FFFFFFFu;
    tick_scheduled(&servo); /* no control tick inside */
    dma_writes(frame, n - 7u);
    cpu_runs();
    dma_writes(&frame[n - 7u], 1); /* this servo's record */
    servo_poll(&servo);
    for (size_t i = n - 6u; i < n - 1u; i++) {
        dma_writes(&frame[i], 1);
        cpu_runs();
    }
    dma_writes(&frame[n - 1u], 1); /* the checksum */
    split_name = "sync_first_pass";
    split_at_send = true;
    bench_begin();
    servo_poll(&servo);
    bench_end("sync_first_build");
    bool first = usart.tx_busy != 0u;
    transmission_ends();
    servo_poll(&servo);
    n = make_request(frame, 25, (const uint8_t[]){22, 1, 2, 9, OWN_ID}, 5);
    dma_writes(frame, n);
    cpu_runs();
    bool waits = servo.tx.waiting && !usart.tx_busy;
    uint8_t content[16] = {9};
    size_t m = make_response(frame, 22, content, sizeof content); /* servo 9's answer */
    dma_writes(frame, m - 1u);
    cpu_runs();
    dma_writes(&frame[m - 1u], 1);
    bench_begin();
    servo_poll(&servo);
    bench_end("sync_next_pass");
    bool sent = usart.tx_busy != 0u;
    transmission_ends();
    servo_poll(&servo);
    /* The main loop's round while the line is in use, nothing to do: a pass
     * and the question whether it may sleep (app_start.h's loop). */
    bench_begin();
    servo_poll(&servo);
    bool slept = servo_may_sleep(&servo);
    bench_end("awake_loop");
    /* What of a pass comes before it reads the ring: a byte that lands
     * just after that read waits a round, then the rest of a pass. */
    hal.port.bus.rx_sync = rx_sync_marked;
    ring_marked = true;
    bench_begin();
    servo_poll(&servo);
    hal.port.bus.rx_sync = dma_rx_sync;
    /* Listed first of two: the pass after the record's may find the other
     * record and the checksum landed (the worst), frame both and send. */
    n = make_request(frame, 25, (const uint8_t[]){22, 1, 2, OWN_ID, 9}, 5);
    dma_writes(frame, n - 2u);
    cpu_runs();
    dma_writes(&frame[n - 2u], 2);
    split_name = "sync_first_pass_of_two";
    split_at_send = true;
    bench_begin();
    servo_poll(&servo);
    bench_end("sync_first_build_of_two");
    first = first && usart.tx_busy != 0u;
    transmission_ends();
    servo_poll(&servo);
    if (!first || !waits || !sent || slept) {
        fprintf(stderr, "sync_monitor_round: %s\n", !first ? "the first answer was not sent"
                        : !waits ? "the second servo did not wait for its turn"
                        : !sent ? "no answer in its turn" : "it would sleep on a line in use");
        exit(1);
    }
}

int main(void)
{
    systick_clock_init(72000000u);
    build_stream();
    fresh_servo();
    bench_setup();

    /* No control tick falls due during the stream: bench_motion counts
     * those; this is the receive path, framer and dispatcher. */
    servo.next_tick_us = hal.now_us + 0x7FFFFFFFu;
    tick_scheduled(&servo);
    run_stream();
    printf("stream_bytes %lu\nstream_messages %u\nframes_for_all %u\nresponses_skipped %u\n",
           (unsigned long)stream_length, messages, (unsigned)servo.rx.stats.frames,
           (unsigned)servo.rx.stats.responses_skipped);

    bench_begin();
    servo_poll(&servo);
    bench_end("idle_poll");

    fresh_servo();
    every_packet();
    fresh_servo();
    sync_monitor_round();
    return 0;
}
