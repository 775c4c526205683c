/* Bytes off the wire, in arrival order, from the port to the main loop.
 *
 * The port writes: its DMA channel, whose counter is the write position
 * (the STM32F1 port; hal_port.bus.rx_sync turns it into `written`), or its
 * receive interrupt, one byte at a time (hal_rx_ring_put). The main loop
 * takes what has arrived in bursts, so no code runs per byte in interrupt
 * context, and a main loop held up (a flash program step) loses nothing
 * while the ring has room. Its size is the board's (BOARD_RX_RING_BYTES in
 * its board.h): enough for every byte a flash page erase can bring in at
 * the rates the board's RAM can cover (docs/decisions.md).
 *
 * One producer, one consumer; the counters run free and wrap at 2^32, so
 * written - read is what waits, even across the wrap. */
#ifndef HAL_HAL_RX_RING_H
#define HAL_HAL_RX_RING_H

#include <stdint.h>

struct hal_rx_ring {
    uint8_t *data;              /* mask + 1 bytes, a power of two: the board's */
    uint32_t mask;
    volatile uint32_t written;  /* bytes the port has put, ever */
    volatile uint32_t read;     /* bytes the main loop has taken, ever */
    volatile uint32_t heard_us; /* when the line was last heard busy */
    volatile uint32_t overruns; /* bytes lost: the UART's overrun, or a full ring */
};

/* A ring over `storage`, an array whose size is a power of two. */
#define HAL_RX_RING_OVER(storage) {.data = (storage), .mask = sizeof(storage) - 1u}

static inline uint32_t hal_rx_ring_size(const struct hal_rx_ring *r)
{
    return r->mask + 1u;
}

/* A receive interrupt's byte, at now_us. A full ring keeps what it holds. */
static inline void hal_rx_ring_put(struct hal_rx_ring *r, uint8_t byte, uint32_t now_us)
{
    uint32_t w = r->written;
    if (w - r->read > r->mask) {
        r->overruns++;
    } else {
        r->data[w & r->mask] = byte;
        r->written = w + 1u;
    }
    r->heard_us = now_us;
}

#endif
