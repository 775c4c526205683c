/* The framer's states and its queue's next slot: what frame_rx.c (the
 * state machine, its fast paths) and frame_rx_queue.c (set-up, the line's
 * idle timeout, a frame's release) share. Internal to the wire layer. */
#ifndef PROTOCOL_FRAME_RX_STATES_H
#define PROTOCOL_FRAME_RX_STATES_H

#include <stdint.h>

#include "protocol/frame_rx.h"

enum rx_state {
    RX_HDR0,      /* 0: frame_rx_in_frame() knows it */
    RX_HDR1,
    RX_CODE,
    RX_LENGTH,
    RX_LENGTH_LO, /* extended length, low byte */
    RX_LENGTH_HI,
    RX_CONTENT,   /* a request this servo keeps */
    RX_CHECKSUM,
    RX_SKIP,      /* a frame not kept: remaining counts its checksum too */
};
_Static_assert(RX_SKIP == FRAME_RX_SKIPPING, "frame_rx.h names the skipping state");
_Static_assert(RX_CONTENT == FRAME_RX_CONTENT && RX_CHECKSUM == FRAME_RX_CHECKSUM,
               "frame_rx.h names the states of a kept request");

static inline uint8_t next_slot(uint8_t i)
{
    return (uint8_t)((i + 1u) % FRAME_QUEUE_SLOTS);
}

#endif
