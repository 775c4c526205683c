/* libFuzzer harness over the whole servo: receive path, framer,
 * dispatcher, register file, motion, protection and config store, with the
 * input driving the wire, the clock, the horn, the sensors, the flash and
 * the power.
 *
 * Input: a setup byte, then operations (docs in make_corpus.py, which
 * writes the seeds):
 *   setup  bits 0-1 flash image (blank; used; used, its page one record from
 *          full; used, answering moves), bits 2-3 bytes between main-loop
 *          passes (1, 2, 4, 8), bit 4 a UART slow to finish
 *   op     low 3 bits what, high 5 bits n:
 *          0, 7  n+1 bytes on the wire follow
 *          1     (n & 15) + 1 ms pass, a main-loop pass (and tick) each, or
 *                with n bit 4 a pass each 100 us (a finished move's answer
 *                waits for a 300 us window of its own)
 *          2     the horn: next byte, as int8 counts per tick; n bit 0: the
 *                encoder follows the setpoint instead; n bit 1: it is held
 *          3     sensors: next 3 bytes are supply (x 40 mV), current
 *                (x 20 mA) and NTC (x 16 counts)
 *          4     flash: n bit 0 every write fails (the config store's and the
 *                fault history's); n bit 1 the power is cut
 *                at the write step the next byte names
 *          5     power cycle: the servo boots again from its flash (3 at most);
 *                n bits 0-2 the reset the board reports (0 a power-on, then
 *                firmware fault, watchdog, software, brown-out, pin, low
 *                power, planned), bits 3-4 its place in a row less one
 *          6     (n+1) x 50 ms pass at once (the main loop was stalled)
 * Every servo starts from a snapshot taken once per flash image, so an
 * input costs no init. After each main-loop pass: everything sent is a
 * well-formed response frame as the DMA reads it, a changed user area is
 * valid, the multi-turn reading is in range and its turn count agrees. */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "doubles/hal_double.h"
#include "doubles/ideal_encoder.h"
#include "registers/data_table.h"
#include "app/servo.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

enum { IMAGES = 4, BYTE_US = 87, MAX_SIM_MS = 1150, MAX_BOOTS = 3 };

struct world {
    struct hal_double hal;
    struct servo servo;
};

static struct world live;
static struct world snapshots[IMAGES];
static struct user_config last_valid;
static int32_t spin_per_tick;
static int encoder_mode; /* 0 spin, 1 follow the setpoint, 2 held */
static int32_t encoder_counts;
/* What a board reads at start-up (hal_reset.h): a record of a firmware
 * fault, the reset counts, and a stack check and depth as the boards have. */
static struct hal_reset reset_seen;
static uint16_t stack_unused_bytes;

#define CHECK(cond)              \
    do {                         \
        if (!(cond)) {           \
            __builtin_trap();    \
        }                        \
    } while (0)

static uint16_t encoder_model(void *model)
{
    (void)model;
    const struct motion *m = &live.servo.motion;
    if (encoder_mode == 1 && m->mode == MODE_POSITION) {
        encoder_counts = ideal_encoder_counts(m);
    } else if (encoder_mode == 0) {
        encoder_counts += spin_per_tick;
    }
    return (uint16_t)(encoder_counts & (ENCODER_COUNTS - 1));
}

/* Every byte sent must belong to a complete, correct response frame. */
static void check_sent(void)
{
    const struct hal_double *h = &live.hal;
    size_t i = 0;
    while (i < h->sent_length) {
        CHECK(h->sent_length - i >= 5);
        CHECK(h->sent[i] == 0x05 && h->sent[i + 1] == 0x1C);
        size_t n = 4u + h->sent[i + 3] + 1u;
        CHECK(h->sent_length - i >= n);
        uint8_t sum = 0;
        for (size_t k = 0; k + 1 < n; k++) {
            sum = (uint8_t)(sum + h->sent[i + k]);
        }
        CHECK(sum == h->sent[i + n - 1]);
        i += n;
    }
    hal_double_clear_sent(&live.hal);
}

/* Only what can have changed: the user area is revalidated when it did;
 * the angle only moves with ticks (checked after time passes). */
static void check_invariants(void)
{
    const struct servo *s = &live.servo;
    if (memcmp(&s->regs.user, &last_valid, sizeof last_valid) != 0) {
        CHECK(user_config_valid(&s->regs.user));
        last_valid = s->regs.user;
    }
    CHECK(s->active_id != 0xFF);
    CHECK(!live.hal.flash.misuse);
    CHECK(s->rx.head < FRAME_QUEUE_SLOTS && s->rx.tail < FRAME_QUEUE_SLOTS);
    if (live.hal.sent_length != 0u) {
        check_sent();
    }
}

/* Safe mode, entered at start-up after HAL_SAFE_MODE_RESETS fault resets
 * in a row, holds until the next start: nothing drives the bridge. */
static void check_safe_mode(void)
{
    const struct servo *s = &live.servo;
    if (reset_seen.in_row >= HAL_SAFE_MODE_RESETS) {
        CHECK(s->regs.firmware.safe_mode == 1u);
    }
    if (s->regs.firmware.safe_mode != 0u) {
        /* The guard takes it at the first tick (one may wait for a request's end). */
        CHECK(live.hal.coasting && (s->motion.inhibit || s->guard_seen != s->protection.act_changes));
    }
}

static void check_angle(void)
{
    struct motion_angle a;
    motion_read_angle(&live.servo.motion, &a);
    CHECK(a.multi_turn_decideg >= -3686400 && a.multi_turn_decideg <= 3686400);
    CHECK(a.turns == a.multi_turn_decideg / 3600);
}

/* A frame the UART is still sending (tx_busy, the slow UART's passes): its
 * bytes as they were read, which no later pass may change under it. */
static struct {
    const uint8_t *data;
    uint16_t length;
    uint8_t read[HAL_DOUBLE_SENT_MAX];
} flight;

/* The DMA reads a frame as its bytes go out: one sent ahead of its build
 * (servo.c, send_ahead) is read once the pass has built it, and what the
 * UART had taken by then must not have changed; nor may a frame still
 * going out change in the passes after. */
static void pass(void)
{
    struct hal_double *h = &live.hal;
    if (!h->tx_busy) {
        flight.data = NULL; /* the UART finished before this pass */
    }
    servo_poll(&live.servo);
    if (flight.data != NULL) {
        CHECK(memcmp(flight.data, flight.read, flight.length) == 0);
    }
    if (h->sending != NULL) {
        size_t at = h->sending_at;
        size_t head = h->sending_length < sizeof h->head_at_send ? h->sending_length : sizeof h->head_at_send;
        flight.data = h->sending;
        flight.length = h->sending_length < sizeof flight.read ? h->sending_length : (uint16_t)sizeof flight.read;
        memcpy(flight.read, h->sending, flight.length);
        hal_double_dma_reads(h);
        CHECK(at + head > h->sent_length || memcmp(h->head_at_send, &h->sent[at], head) == 0);
    }
}

static void poll(void)
{
    pass();
    check_invariants();
}


static void stack_watch(void)
{
    /* The boards' guard check: nothing to check on the host. */
}

static void boot(void)
{
    flash_double_power_on(&live.hal.flash);
    live.hal.port.reset = &reset_seen;
    live.hal.port.stack_unused = &stack_unused_bytes;
    live.hal.port.stack_watch = stack_watch;
    servo_init(&live.servo, &live.hal.port);
    last_valid = live.servo.regs.user;
}

static void write_item(uint8_t item, uint16_t value, uint8_t size)
{
    uint8_t content[4] = {live.servo.active_id, item, (uint8_t)value, (uint8_t)(value >> 8)};
    struct rx_frame f = {.code = 4, .length = (uint16_t)(2u + size), .stored = (uint8_t)(2u + size)};
    memcpy(f.content, content, sizeof content);
    struct response r;
    struct dispatch_result res;
    dispatch(&live.servo.dispatcher, &f, &r, &res); /* written through to flash */
}

static void run_ms(uint32_t ms)
{
    for (uint32_t i = 0; i < 4u * ms; i++) {
        live.hal.now_us += 250u;
        poll();
    }
}

/* The flash images: a store that has been used, and one whose page is a
 * record from full, so the second change after it needs the other page. */
static void make_snapshot(int image)
{
    memset(&live, 0, sizeof live);
    hal_double_init(&live.hal);
    live.hal.now_us = 5000;
    live.hal.encoder_model = encoder_model;
    boot();
    if (image != 0) {
        /* Every record a change: soft start times, then soft start off. */
        unsigned records = image == 2 ? 20u : 5u;
        for (unsigned k = 0; k + 1u < records; k++) {
            write_item(50, (uint16_t)(1000u + k), 2);
            run_ms(60);
        }
        write_item(49, 0, 1);
        run_ms(60);
        if (image == 3) {
            write_item(33, 1, 1);   /* control response on */
            write_item(42, 0xFFFF, 2);
            run_ms(60);
        }
        boot();
    }
    hal_double_clear_sent(&live.hal);
    snapshots[image] = live;
}

static void reset_at(unsigned n)
{
    static const uint8_t kinds[8] = {
        HAL_RESET_POWER_ON, HAL_RESET_FIRMWARE_FAULT, HAL_RESET_WATCHDOG, HAL_RESET_SOFTWARE,
        HAL_RESET_BROWN_OUT, HAL_RESET_PIN, HAL_RESET_LOW_POWER, HAL_RESET_PLANNED,
    };
    memset(&reset_seen, 0, sizeof reset_seen);
    reset_seen.kind = kinds[n & 7u];
    reset_seen.in_row = reset_seen.kind >= HAL_RESET_FIRMWARE_FAULT ? (uint8_t)((n >> 3 & 3u) + 1u) : 0u;
    reset_seen.counts[HAL_COUNT_FIRMWARE_FAULT] = reset_seen.in_row;
    reset_seen.pc = 0x08001234u + n;
    reset_seen.lr = 0xFFFFFFF9u;
    reset_seen.sp_offset = (uint16_t)(0x0F00u - n);
    reset_seen.exception = (uint8_t)(3u + (n & 3u));
    stack_unused_bytes = (uint16_t)(700u - 16u * n);
}

static void feed(uint8_t byte, unsigned *fed, unsigned poll_every)
{
    live.hal.now_us += BYTE_US;
    servo_on_rx_byte(&live.servo, byte, live.hal.now_us);
    if (++*fed % poll_every == 0u) {
        poll();
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static bool ready;
    if (!ready) {
        for (int i = 0; i < IMAGES; i++) {
            make_snapshot(i);
        }
        ready = true;
    }
    if (size == 0) {
        return 0;
    }
    uint8_t setup = data[0];
    live = snapshots[setup & 3u];
    reset_at(0);
    flight.data = NULL;
    last_valid = live.servo.regs.user;
    spin_per_tick = 0;
    encoder_mode = 1;
    encoder_counts = live.servo.motion.encoder.counts + live.servo.motion.origin_counts;
    unsigned poll_every = 1u << ((setup >> 2) & 3u);
    bool slow_uart = setup & 0x10u;
    unsigned fed = 0;
    unsigned boots = 0;
    uint32_t sim_ms = 0;

    size_t i = 1;
    while (i < size) {
        uint8_t op = data[i++];
        unsigned n = op >> 3;
        switch (op & 7u) {
        case 1:
            /* A pass per tick: the main loop's other jobs are reached by
             * the wire bytes' passes. */
            if (sim_ms + (n & 15u) + 1u <= MAX_SIM_MS) {
                sim_ms += (n & 15u) + 1u;
                unsigned per_ms = (n & 16u) ? 10u : 1u;
                for (unsigned k = 0; k < ((n & 15u) + 1u) * per_ms; k++) {
                    live.hal.now_us += 1000u / per_ms;
                    live.hal.tx_busy = slow_uart && (k & 1u);
                    pass();
                    if (live.hal.sent_length != 0u) {
                        check_sent();
                    }
                }
                live.hal.tx_busy = false;
                check_invariants();
                check_angle();
                check_safe_mode();
            }
            break;
        case 2:
            encoder_mode = (n & 1u) ? 1 : (n & 2u) ? 2 : 0;
            spin_per_tick = i < size ? (int8_t)data[i++] : 0;
            break;
        case 3:
            if (size - i >= 3) {
                live.hal.sensors.supply = (uint16_t)(data[i] * 40u);
                live.hal.sensors.current = (uint16_t)(data[i + 1] * 20u);
                live.hal.sensors.ntc = (uint16_t)(data[i + 2] * 16u);
                i += 3;
            }
            break;
        case 4:
            live.hal.flash.dead = n & 1u;
            live.hal.fault_flash.dead = n & 1u; /* the fault history's pages too */
            if ((n & 2u) && i < size) {
                live.hal.flash.cut_at = live.hal.flash.steps + data[i++];
                live.hal.flash.cut_mode = (enum cut_mode)(n >> 2 & 3u);
            }
            break;
        case 5:
            if (boots++ < MAX_BOOTS) {
                reset_at(n);
                boot();
            }
            break;
        case 6:
            live.hal.now_us += (n + 1u) * 50000u;
            poll();
            break;
        default:
            for (unsigned k = 0; k <= n && i < size; k++) {
                feed(data[i++], &fed, poll_every);
            }
            break;
        }
    }
    for (int k = 0; k < 3; k++) {
        live.hal.now_us += 5000u; /* lets sync turn-taking time out */
        poll();
    }
    check_angle();
    return 0;
}
