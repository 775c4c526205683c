/* The framer's set-up and the line's idle timeout (protocol/frame_rx.h);
 * the state machine is frame_rx.c's. */
#include "protocol/frame_rx.h"
#include "protocol/frame_rx_states.h"

void frame_rx_init(struct frame_rx *rx, const volatile uint8_t *own_id)
{
    *rx = (struct frame_rx){0};
    rx->own_id = own_id;
    rx->state = RX_HDR0;
}

uint32_t frame_rx_idle_us(uint32_t baud)
{
    const uint32_t floor_us = 1000u;
    if (baud == 0u) {
        return floor_us;
    }
    /* 10 bytes of 10 bits each, rounded up. */
    uint32_t us = (100u * 1000000u + baud - 1u) / baud;
    return us > floor_us ? us : floor_us;
}

void frame_rx_line_idle(struct frame_rx *rx)
{
    if (rx->state != RX_HDR0) {
        /* A request this servo kept, cut: seen, whole or not (the count a
         * prepared answer waits for, servo.c). */
        rx->stats.requests_seen += rx->state == RX_CONTENT || rx->state == RX_CHECKSUM;
        rx->stats.idle_timeouts++;
        rx->state = RX_HDR0;
    }
}
