/* What the servo core needs of its hardware. Each port (MCU, host
 * simulator, test double) fills one; the core never touches hardware
 * otherwise. Functions are called from the main loop only, except now_us,
 * which the receive interrupt also uses. */
#ifndef HAL_HAL_PORT_H
#define HAL_HAL_PORT_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_flash.h"

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
    const struct hal_flash *flash;
    /* Data ID 8: derived by the port from the MCU's unique ID. */
    uint32_t serial_number;
};

#endif
