/* What the servo core needs of its hardware. Each board fills one in one
 * place (its main.c: one initialiser naming its ports' operations; the
 * simulator's sim_servo_start; the test double's init), and nothing
 * changes it after; the core never touches hardware otherwise. Functions
 * are called from the main loop only; the optional ones through the inline
 * wrappers at the end. */
#ifndef HAL_HAL_PORT_H
#define HAL_HAL_PORT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "hal/hal_flash.h"
#include "hal/hal_reset.h"
#include "hal/hal_rx_ring.h"
#include "hal/hal_sensors.h"

/* The servo's bus: the half-duplex UART and the clock its bytes are
 * stamped by. One port provides all of it (stm32f1_uart.h, stm32f0_uart.h:
 * one initialiser); ctx is the hal_port's. */
struct hal_bus {
    /* Free-running microsecond clock; wraps at 2^32. */
    uint32_t (*now_us)(void *ctx);
    /* Starts sending len bytes and returns at once; data stays valid until
     * tx_done() says true. The port turns the half-duplex line around. It
     * reads each byte as it goes out (DMA, an interrupt), not all at the
     * start: the M0's Sync Monitor answer is built behind its first bytes
     * (servo.c, send_ahead). */
    void (*send)(void *ctx, const uint8_t *data, uint16_t len);
    /* True once the last stop bit of the last send has left the wire. */
    bool (*tx_done)(void *ctx);
    void (*set_baud)(void *ctx, uint32_t baud);
    /* Brings rx->written and rx->heard_us up to date, for a port whose DMA
     * fills the ring (called with the hal_port's rx_ctx); NULL when its
     * receive interrupt does. Optional: hal_rx_sync(). */
    void (*rx_sync)(void *rx_ctx, uint32_t now_us);
};

/* The motor and what the servo measures of it; ctx is the hal_port's. */
struct hal_motor {
    /* H-bridge: signed duty, Q15 (32767 = full supply; positive turns the
     * output towards increasing angle, counter-clockwise seen from the horn). */
    void (*drive)(void *ctx, int16_t duty_q15);
    /* Both bridge halves off: the output turns freely (release). */
    void (*coast)(void *ctx);
    /* Output-shaft angle from the 12-bit absolute magnetic encoder, 0..4095,
     * increasing counter-clockwise. */
    uint16_t (*read_encoder)(void *ctx);
    /* Samples the analogue sensors (called once per control tick). */
    void (*read_sensors)(void *ctx, struct sensor_raw *out);
};

struct hal_port {
    void *ctx;
    struct hal_bus bus;
    /* Received bytes, in the ring the board owns and the port fills. */
    struct hal_rx_ring *rx;
    void *rx_ctx;
    struct hal_motor motor;
    const struct sensor_calibration *calibration;
    const struct hal_flash *flash;
    /* The fault history's two pages (storage/fault_log.h); NULL: none kept. */
    const struct hal_flash *fault_flash;
    /* Data ID 8: derived by the port from the MCU's unique ID; read once,
     * at start. An operation, so a board's hal_port can be all constant. */
    uint32_t (*serial_number)(void *ctx);
    /* Data ID 7: the version in the header of the update image this
     * application was started from, read once at start; 0 where there is
     * none (the core then reports the version it was built as). Optional. */
    uint16_t (*image_version)(void *ctx);
    /* Restarts into the bootloader, which then stays (UpdateEnter) and
     * answers at the ID and baud index given (the application's: its own
     * reading of the store could differ); NULL where there is none. Does
     * not return on silicon. */
    void (*enter_bootloader)(void *ctx, uint8_t id, uint8_t baud_index);
    /* Why the MCU last started (hal_reset.h), read by the board before
     * servo_init; NULL: a power-on (a port that cannot tell). */
    const struct hal_reset *reset;
    /* Bytes of stack never written since start (item 74); NULL: unknown. */
    const volatile uint16_t *stack_unused;
    /* Each control tick's pass: the stack's guard checked, its depth's scan
     * a word on (a fault when the guard is gone); NULL: none. */
    void (*stack_watch)(void);
    /* The board images are built for (the update image header's board). */
    uint16_t board;
    /* Longest gap between the bytes of one frame the link can produce, in
     * us; 0 for a real UART (the framer's own rule, frame_rx_idle_us). An
     * emulated UART delivers bytes with the host's scheduling jitter. */
    uint32_t rx_gap_tolerance_us;
    /* This CPU's longest control tick and main-loop pass together, in us
     * (the target bench's worst figures, docs/benchmark.md): a tick that
     * starts less than this before a Sync Monitor turn would delay the
     * answer, so it waits for the answer to start (servo_turns.c), as one
     * does for a request to this servo about to end (servo.c). 0: no wait
     * for a turn; for a request, its last two bytes only. */
    uint8_t tick_and_pass_us;
};

/* The fields of a host port (servo_sim's servo, the unit tests' double)
 * whose owner has rx, flash and fault_flash members and whose operations
 * have the names below; the calibration and what is optional are its own. */
#define HAL_PORT_HOST_FIELDS(owner)                                                     \
    .ctx = (owner), .rx = &(owner)->rx, .flash = &(owner)->flash.hal,                   \
    .fault_flash = &(owner)->fault_flash.hal, .serial_number = serial_number,           \
    .bus = {.now_us = now_us, .send = uart_send, .tx_done = uart_tx_done,               \
            .set_baud = uart_set_baud},                                                 \
    .motor = {.drive = motor_drive, .coast = motor_coast, .read_encoder = encoder_read, \
              .read_sensors = sensors_read}

/* Brings the receive ring up to date (a port whose DMA fills it). */
static inline void hal_rx_sync(const struct hal_port *h, uint32_t now_us)
{
    if (h->bus.rx_sync != NULL) {
        h->bus.rx_sync(h->rx_ctx, now_us);
    }
}

/* UpdateEnter's restart, on a board with a bootloader (enter_bootloader
 * set: the dispatcher refuses UpdateEnter elsewhere). */
static inline void hal_enter_bootloader(const struct hal_port *h, uint8_t id, uint8_t baud_index)
{
    h->enter_bootloader(h->ctx, id, baud_index);
}

#endif
