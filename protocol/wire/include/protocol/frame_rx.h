/* Request framer: fed the received bytes in bursts by the main loop (from
 * the port's receive ring), it queues complete, checksum-verified requests
 * for this servo.
 *
 * What is not kept costs nothing per byte: other servos' responses, and
 * requests addressed to another ID (from their ID byte on), are passed over
 * by their length in one step. SyncCommand (25) frames of any length are
 * never buffered: only this servo's record is kept. */
#ifndef PROTOCOL_FRAME_RX_H
#define PROTOCOL_FRAME_RX_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_rx_ring.h"
#include "protocol/packet_codes.h"

/* Largest request content kept (protocol/servo_schema). A longer request is
 * consumed by its length and delivered with FRAME_TRUNCATED so the
 * dispatcher can reject it as a length error. */
#define FRAME_CONTENT_MAX REQUEST_CONTENT_MAX
/* Largest SyncCommand record kept (packet 14: 15 bytes). */
#define FRAME_SYNC_RECORD_MAX 15u
/* Slots in the frame queue; one is always the framer's work slot. */
#define FRAME_QUEUE_SLOTS 4u
#define FRAME_SYNC_NO_RECORD 0xFFu

enum frame_flags {
    FRAME_TRUNCATED = 1u << 0,  /* content longer than FRAME_CONTENT_MAX */
    FRAME_BAD_SYNC = 1u << 1,   /* sync header inconsistent with length */
};

/* A received request. For SyncCommand, content holds cmd, record_len, count
 * and then this servo's record (if sync_index != FRAME_SYNC_NO_RECORD). */
struct rx_frame {
    uint32_t responses_seen; /* stats.responses_skipped when it completed */
    uint16_t length;      /* content length as announced on the wire */
    uint8_t code;         /* packet number */
    uint8_t flags;        /* enum frame_flags */
    uint8_t stored;       /* bytes of content[] that are valid */
    uint8_t sync_index;   /* position of this servo's record in a sync frame */
    uint8_t content[FRAME_CONTENT_MAX];
};

struct frame_rx_stats {
    uint32_t frames;            /* requests delivered */
    uint32_t requests_seen;     /* requests on the wire, to any ID, whole or not */
    uint32_t checksum_errors;   /* requests dropped for a bad checksum */
    uint32_t responses_skipped; /* other servos' response frames passed over */
    uint32_t idle_timeouts;     /* partial frames dropped after an idle gap */
    uint32_t queue_overflows;   /* requests dropped because the queue was full */
    uint32_t garbage_bytes;     /* bytes outside any frame */
};

/* The framer's state first: on the Cortex-M0 a byte field is reached by
 * an immediate offset only within the first 32 bytes. */
struct frame_rx {
    uint8_t head;               /* next slot the framer fills */
    uint8_t tail;               /* next slot the dispatcher reads */
    uint8_t state;
    uint8_t is_request;
    uint8_t checksum;
    uint8_t discard;            /* queue was full when this frame began */
    uint16_t remaining;         /* content bytes still to come */
    uint16_t position;          /* content bytes received so far */
    uint8_t sync_record_len;
    uint8_t sync_record_pos;    /* byte position within the current record */
    uint8_t sync_record_index;  /* index of the current record */
    uint8_t sync_capturing;
    uint32_t skip_left;         /* RX_SKIP: bytes to pass over, checksum included */
    const volatile uint8_t *own_id; /* the servo's active ID, for sync records */
    struct frame_rx_stats stats;
    struct rx_frame slots[FRAME_QUEUE_SLOTS];
};

/* own_id must stay valid for the framer's lifetime; the framer reads it when
 * a sync record starts. */
void frame_rx_init(struct frame_rx *rx, const volatile uint8_t *own_id);

/* Received bytes, in order, every one taken: a frame that starts while
 * the queue is full is dropped and counted (stats.queue_overflows). */
void frame_rx_feed_bytes(struct frame_rx *rx, const uint8_t *data, uint32_t n);
/* One received byte. */
void frame_rx_feed(struct frame_rx *rx, uint8_t byte);

/* Bytes that cannot fill an empty queue: a request is 5 bytes or more,
 * so 10 complete at most two frames (the one under way and one more) of
 * the FRAME_QUEUE_SLOTS - 1 it holds (the byte-by-byte framer's shortcut). */
#define FRAME_RX_SAFE_BURST 10u
/* Received bytes, in order, until the queue is full: returns how many were
 * taken, all of them unless it stopped at the end of the frame that filled
 * it. The rest waits where it is (the port's ring) for the next call. */
uint32_t frame_rx_feed_until_full(struct frame_rx *rx, const uint8_t *data, uint32_t n);


/* The line has been idle for the idle timeout (frame_rx_idle_us): a partial
 * frame is dropped. */
void frame_rx_line_idle(struct frame_rx *rx);
/* The framer's state while it passes over a frame it does not keep
 * (another servo's response): skip_left bytes are still to come. */
#define FRAME_RX_SKIPPING 8u
/* A frame passed over ends within `bytes` more bytes. */
static inline bool frame_rx_skip_ends_within(const struct frame_rx *rx, uint32_t bytes)
{
    return rx->state == FRAME_RX_SKIPPING && rx->skip_left <= bytes;
}
/* The framer's states while it keeps a request for this servo: its
 * content, then its checksum. */
#define FRAME_RX_CONTENT 6u
#define FRAME_RX_CHECKSUM 7u
/* A request this servo keeps is under way (in the work slot,
 * frame_rx_under_way) and ends within `bytes` more bytes, its checksum's
 * among them. */
static inline bool frame_rx_kept_ends_within(const struct frame_rx *rx, uint32_t bytes)
{
    /* In FRAME_RX_CHECKSUM no content remains. */
    return (uint8_t)(rx->state - FRAME_RX_CONTENT) <= FRAME_RX_CHECKSUM - FRAME_RX_CONTENT &&
           rx->remaining < bytes;
}
/* The request under way: whole up to what has arrived, its checksum not
 * yet checked. */
static inline const struct rx_frame *frame_rx_under_way(const struct frame_rx *rx)
{
    return &rx->slots[rx->head];
}
/* A frame has begun and not ended. */
static inline bool frame_rx_in_frame(const struct frame_rx *rx)
{
    return rx->state != 0u; /* RX_HDR0 */
}

/* The oldest complete frame, or NULL. The frame stays valid until
 * frame_rx_release(). */
static inline const struct rx_frame *frame_rx_peek(const struct frame_rx *rx)
{
    return rx->tail == rx->head ? (const struct rx_frame *)0 : &rx->slots[rx->tail];
}
static inline void frame_rx_release(struct frame_rx *rx)
{
    if (rx->tail != rx->head) {
        rx->tail = (uint8_t)((rx->tail + 1u) % FRAME_QUEUE_SLOTS);
    }
}
/* Complete frames waiting for frame_rx_peek. */
static inline uint8_t frame_rx_pending(const struct frame_rx *rx)
{
    return (uint8_t)((rx->head + FRAME_QUEUE_SLOTS - rx->tail) % FRAME_QUEUE_SLOTS);
}

/* What waits in the port's ring, framed: false when nothing was. A full
 * frame queue leaves the rest in the ring for the next pass, after the
 * dispatcher has taken a frame: a burst of frames is kept, not dropped.
 * Bytes the port wrote over before they were taken (its DMA lapped the
 * reader) are added to *lost. Inline: it runs every main-loop pass. */
static inline __attribute__((always_inline)) bool frame_rx_take_ring(struct frame_rx *rx,
                                                                      struct hal_rx_ring *ring,
                                                                      uint32_t *lost)
{
    uint32_t written = ring->written;
    uint32_t read = ring->read;
    uint32_t waiting = written - read;
    if (waiting == 0u) {
        return false;
    }
    uint32_t size = ring->mask + 1u;
    if (waiting > size) {
        *lost += waiting - size;
        read = written - size;
        waiting = size;
    }
    uint32_t at = read & ring->mask;
    uint32_t first = size - at < waiting ? size - at : waiting;
    uint32_t took = frame_rx_feed_until_full(rx, &ring->data[at], first);
    if (waiting > first && took == first) { /* the rest, from the ring's start */
        took += frame_rx_feed_until_full(rx, ring->data, waiting - first);
    }
    ring->read = read + took;
    return true;
}

/* The documented idle timeout for a baud rate: ten byte times (10 bits each),
 * but never below 1 ms so that gaps inside one write by a USB serial adapter
 * do not cut a frame. */
uint32_t frame_rx_idle_us(uint32_t baud);

/* The idle timeout a port uses: the documented one (idle_us), or the
 * port's own gap tolerance where that is longer (hal_port.rx_gap_tolerance_us). */
static inline uint32_t frame_rx_port_idle_us(uint32_t idle_us, uint32_t gap_tolerance_us)
{
    return idle_us > gap_tolerance_us ? idle_us : gap_tolerance_us;
}

/* A main-loop pass's receiving, the application's and the bootloader's
 * alike: the ring framed, and a partial frame dropped once the line has
 * been silent for idle_us, so no byte sequence leaves the framer waiting
 * for bytes that never come. */
static inline __attribute__((always_inline)) void frame_rx_receive(struct frame_rx *rx,
                                                                   struct hal_rx_ring *ring,
                                                                   uint32_t *lost, uint32_t now_us,
                                                                   uint32_t idle_us)
{
    if (!frame_rx_take_ring(rx, ring, lost) && frame_rx_in_frame(rx) &&
        (int32_t)(now_us - ring->heard_us) >= (int32_t)idle_us) {
        frame_rx_line_idle(rx);
    }
}

#endif
