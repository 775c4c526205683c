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
#include "hal/hal_rx_ring.h"
#include "hal/hal_sensors.h"

struct hal_port {
    void *ctx;
    /* Free-running microsecond clock; wraps at 2^32. */
    uint32_t (*now_us)(void *ctx);
    /* Starts sending len bytes and returns at once; data stays valid until
     * uart_tx_done() says true. The port turns the half-duplex line around. */
    void (*uart_send)(void *ctx, const uint8_t *data, uint16_t len);
    /* True once the last stop bit of the last send has left the wire. */
    bool (*uart_tx_done)(void *ctx);
    void (*uart_set_baud)(void *ctx, uint32_t baud);
    /* Received bytes, in the ring the port owns and fills. */
    struct hal_rx_ring *rx;
    /* Brings rx->written and rx->heard_us up to date, for a port whose DMA
     * fills the ring (called with rx_ctx); NULL when its receive interrupt
     * does. */
    void (*rx_sync)(void *rx_ctx, uint32_t now_us);
    void *rx_ctx;
    /* H-bridge: signed duty, Q15 (32767 = full supply; positive turns the
     * output towards increasing angle, counter-clockwise seen from the horn). */
    void (*motor_drive)(void *ctx, int16_t duty_q15);
    /* Both bridge halves off: the output turns freely (release). */
    void (*motor_coast)(void *ctx);
    /* Output-shaft angle from the 12-bit absolute magnetic encoder, 0..4095,
     * increasing counter-clockwise. */
    uint16_t (*encoder_read)(void *ctx);
    /* Samples the analogue sensors (called once per control tick). */
    void (*sensors_read)(void *ctx, struct sensor_raw *out);
    const struct sensor_calibration *calibration;
    const struct hal_flash *flash;
    /* Data ID 8: derived by the port from the MCU's unique ID; read once,
     * at start. An operation, so a board's hal_port can be all constant. */
    uint32_t (*serial_number)(void *ctx);
    /* Restarts into the bootloader, which then stays (UpdateEnter); NULL
     * where there is none. Does not return on silicon. */
    void (*enter_bootloader)(void *ctx);
    /* The board images are built for (the update image header's board). */
    uint16_t board;
    /* Longest gap between the bytes of one frame the link can produce, in
     * us; 0 for a real UART (the framer's own rule, frame_rx_idle_us). An
     * emulated UART delivers bytes with the host's scheduling jitter. */
    uint32_t rx_gap_tolerance_us;
};

/* Brings the receive ring up to date (a port whose DMA fills it). */
static inline void hal_rx_sync(const struct hal_port *h, uint32_t now_us)
{
    if (h->rx_sync != NULL) {
        h->rx_sync(h->rx_ctx, now_us);
    }
}

/* UpdateEnter's restart; nothing where the board has no bootloader. */
static inline void hal_enter_bootloader(const struct hal_port *h)
{
    if (h->enter_bootloader != NULL) {
        h->enter_bootloader(h->ctx);
    }
}

#endif
