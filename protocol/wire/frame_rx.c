#include "protocol/frame_rx.h"

#include <stddef.h>

#include "protocol/frame_rx_states.h"
#include "protocol/packet_codes.h"
#include "protocol/wire.h"

/* The bursts' fast paths (a header, a run of content or garbage at once,
 * the hot helpers inlined) buy the receive path its budget. FRAME_RX_SMALL
 * (the Cortex-M0 application, every bootloader) takes bytes one by one, for
 * size; FRAME_RX_NO_SYNC (the bootloaders only, which answer no
 * SyncCommand) skips SyncCommand by its length. */
#ifdef FRAME_RX_SMALL
#define INLINE_IN_FAST_BUILD static
#else
#define INLINE_IN_FAST_BUILD static inline __attribute__((always_inline))
#endif

/* SyncCommand content: cmd, record_len, count, then the records. */
enum { SYNC_HEADER_SIZE = 3 };

static struct rx_frame *work_slot(struct frame_rx *rx)
{
    return &rx->slots[rx->head];
}

/* The rest of a frame not kept, its checksum included, goes by its length. */
static void skip(struct frame_rx *rx, uint32_t bytes)
{
    rx->skip_left = bytes;
    rx->state = RX_SKIP;
}

INLINE_IN_FAST_BUILD void start_content(struct frame_rx *rx, uint16_t length)
{
    rx->remaining = length;
    rx->position = 0;
    if (!rx->is_request || rx->discard) {
        skip(rx, (uint32_t)length + 1u);
        return;
    }
    struct rx_frame *f = work_slot(rx);
    f->length = length;
    f->flags = 0;
    f->stored = 0;
    f->sync_index = FRAME_SYNC_NO_RECORD;
    rx->sync_capturing = 0;
    rx->state = length ? RX_CONTENT : RX_CHECKSUM;
}

#ifndef FRAME_RX_NO_SYNC
/* A byte of SyncCommand content: keep the 3-byte header and, of the records,
 * only the first one that starts with this servo's ID. */
static void sync_content_byte(struct frame_rx *rx, struct rx_frame *f, uint8_t byte)
{
    if (rx->position < SYNC_HEADER_SIZE) {
        f->content[rx->position] = byte;
        f->stored = (uint8_t)(rx->position + 1u);
        if (rx->position == SYNC_HEADER_SIZE - 1) {
            rx->sync_record_len = f->content[1];
            rx->sync_record_pos = 0;
            rx->sync_record_index = 0;
            uint32_t expected = SYNC_HEADER_SIZE + (uint32_t)f->content[1] * f->content[2];
            if (f->content[1] == 0u || f->content[1] > FRAME_SYNC_RECORD_MAX ||
                expected != f->length) {
                f->flags |= FRAME_BAD_SYNC;
            }
        }
        return;
    }
    if (f->flags & FRAME_BAD_SYNC) {
        return; /* consumed by length only */
    }
    if (rx->sync_record_pos == 0u && f->sync_index == FRAME_SYNC_NO_RECORD &&
        byte == *rx->own_id) {
        rx->sync_capturing = 1;
        f->sync_index = rx->sync_record_index;
    }
    if (rx->sync_capturing) {
        f->content[SYNC_HEADER_SIZE + rx->sync_record_pos] = byte;
        f->stored = (uint8_t)(SYNC_HEADER_SIZE + rx->sync_record_pos + 1u);
    }
    rx->sync_record_pos++;
    if (rx->sync_record_pos == rx->sync_record_len) {
        rx->sync_record_pos = 0;
        rx->sync_record_index++;
        rx->sync_capturing = 0;
    }
}
#endif

/* A request addressed to another servo (unknown packets count as
 * addressed, as in the dispatcher): nothing of it is kept. */
static bool for_another_servo(const struct frame_rx *rx, uint8_t code, uint8_t id)
{
    return id != *rx->own_id && id != WIRE_BROADCAST_ID && packet_is_addressed(code);
}

static void content_byte(struct frame_rx *rx, uint8_t byte)
{
    struct rx_frame *f = work_slot(rx);
    if (f->code == PKT_SYNC_COMMAND) {
#ifdef FRAME_RX_NO_SYNC
        skip(rx, rx->remaining);
        return;
#else
        sync_content_byte(rx, f, byte);
#endif
    } else if (rx->position == 0u && for_another_servo(rx, f->code, byte)) {
        skip(rx, rx->remaining); /* the rest and the checksum */
        return;
    } else if (rx->position < FRAME_CONTENT_MAX) {
        f->content[rx->position] = byte;
        f->stored = (uint8_t)(rx->position + 1u);
    } else {
        f->flags |= FRAME_TRUNCATED;
    }
    rx->position++;
    rx->remaining--;
    if (rx->remaining == 0u) {
        rx->state = RX_CHECKSUM;
    }
}

INLINE_IN_FAST_BUILD void finish_skipped(struct frame_rx *rx)
{
    rx->state = RX_HDR0;
    if (!rx->is_request) {
        rx->stats.responses_skipped++;
        return;
    }
    rx->stats.requests_seen++;
    if (rx->discard) {
        rx->stats.queue_overflows++;
    }
}

INLINE_IN_FAST_BUILD void finish_frame(struct frame_rx *rx, uint8_t checksum)
{
    rx->state = RX_HDR0;
    rx->stats.requests_seen++;
    if (checksum != rx->checksum) {
        rx->stats.checksum_errors++;
        return;
    }
    work_slot(rx)->responses_seen = rx->stats.responses_skipped;
    rx->head = next_slot(rx->head);
    rx->stats.frames++;
}

/* Header byte 0 seen: which kind of frame may be starting. */
static bool header_start(struct frame_rx *rx, uint8_t byte)
{
    if (byte == WIRE_REQUEST_HDR0 || byte == WIRE_RESPONSE_HDR0) {
        rx->is_request = byte == WIRE_REQUEST_HDR0;
        rx->checksum = byte;
        rx->state = RX_HDR1;
        return true;
    }
    return false;
}

/* One byte through the state machine. Every byte from the second header
 * byte to the last of the content counts in the checksum: summed here
 * once, for all those states (a second header byte that is not one
 * restarts the sum anyway). */
INLINE_IN_FAST_BUILD void step(struct frame_rx *rx, uint8_t byte)
{
    if (rx->state >= RX_HDR1 && rx->state <= RX_CONTENT) {
        rx->checksum = (uint8_t)(rx->checksum + byte);
    }
    switch (rx->state) {
    case RX_HDR1:
        if (byte == (rx->is_request ? WIRE_REQUEST_HDR1 : WIRE_RESPONSE_HDR1)) {
            rx->state = RX_CODE;
            return;
        }
        /* Not a header after all: the byte may begin the real one. */
        rx->stats.garbage_bytes++;
        rx->state = RX_HDR0;
        /* fall through */
    case RX_HDR0:
        if (!header_start(rx, byte)) {
            rx->stats.garbage_bytes++;
        }
        return;
    case RX_CODE:
        if (rx->is_request) {
            rx->discard = next_slot(rx->head) == rx->tail;
            work_slot(rx)->code = byte;
        }
        rx->state = RX_LENGTH;
        return;
    case RX_LENGTH:
        /* Only requests use the extended length (docs/protocol.md). */
        if (rx->is_request && byte == WIRE_EXTENDED_LENGTH) {
            rx->state = RX_LENGTH_LO;
        } else {
            start_content(rx, byte);
        }
        return;
    case RX_LENGTH_LO:
        rx->remaining = byte;
        rx->state = RX_LENGTH_HI;
        return;
    case RX_LENGTH_HI:
        start_content(rx, (uint16_t)(rx->remaining | (uint16_t)((uint16_t)byte << 8)));
        return;
    case RX_CONTENT:
        content_byte(rx, byte);
        return;
    case RX_CHECKSUM:
        finish_frame(rx, byte);
        return;
    case RX_SKIP:
        if (--rx->skip_left == 0u) {
            finish_skipped(rx);
        }
        return;
    default:
        rx->state = RX_HDR0;
        return;
    }
}

/* A kept request's plain content (not SyncCommand, past the ID, within
 * FRAME_CONTENT_MAX) in one run: copy and sum. Returns the bytes taken. */
#ifndef FRAME_RX_SMALL
INLINE_IN_FAST_BUILD uint32_t content_run(struct frame_rx *rx, const uint8_t *data, uint32_t n)
{
    struct rx_frame *f = work_slot(rx);
    if (f->code == PKT_SYNC_COMMAND || rx->position == 0u || rx->position >= FRAME_CONTENT_MAX) {
        return 0;
    }
    uint32_t take = FRAME_CONTENT_MAX - rx->position;
    take = take < n ? take : n;
    take = take < rx->remaining ? take : rx->remaining;
    uint8_t sum = rx->checksum;
    uint8_t *to = &f->content[rx->position];
    for (uint32_t i = 0; i < take; i++) {
        to[i] = data[i];
        sum = (uint8_t)(sum + data[i]);
    }
    rx->checksum = sum;
    rx->position = (uint16_t)(rx->position + take);
    rx->remaining = (uint16_t)(rx->remaining - take);
    f->stored = (uint8_t)rx->position;
    if (rx->remaining == 0u) {
        rx->state = RX_CHECKSUM;
    }
    return take;
}

/* Bytes outside any frame up to the next that may start a header. */
INLINE_IN_FAST_BUILD uint32_t garbage_run(struct frame_rx *rx, const uint8_t *data, uint32_t n)
{
    uint32_t i = 0;
    while (i < n && data[i] != WIRE_REQUEST_HDR0 && data[i] != WIRE_RESPONSE_HDR0) {
        i++;
    }
    rx->stats.garbage_bytes += i;
    return i;
}

/* A whole plain header (both header bytes, code, a one-byte length) when
 * all four have arrived: what step() would do in four calls. */
INLINE_IN_FAST_BUILD uint32_t header_run(struct frame_rx *rx, const uint8_t *data, uint32_t n)
{
    if (n < WIRE_HEADER_SIZE) {
        return 0;
    }
    bool request = data[0] == WIRE_REQUEST_HDR0;
    if (data[1] != (request ? WIRE_REQUEST_HDR1 : WIRE_RESPONSE_HDR1) ||
        (request && data[3] == WIRE_EXTENDED_LENGTH)) {
        return 0;
    }
    rx->is_request = request;
    rx->checksum = (uint8_t)(data[0] + data[1] + data[2] + data[3]);
    if (request) {
        /* The ID has arrived too: a request for another servo goes by
         * its length from here. */
        if (n > WIRE_HEADER_SIZE && data[3] != 0u && data[2] != PKT_SYNC_COMMAND &&
            for_another_servo(rx, data[2], data[WIRE_HEADER_SIZE])) {
            rx->discard = 0;
            skip(rx, (uint32_t)data[3] + 1u);
            return WIRE_HEADER_SIZE;
        }
        rx->discard = next_slot(rx->head) == rx->tail;
        work_slot(rx)->code = data[2];
    }
    start_content(rx, data[3]);
    return WIRE_HEADER_SIZE;
}

/* Runs through the bytes; with stop_when_full, returns after the frame
 * that fills the queue. Returns the bytes taken. Specialised at each call
 * (stop_when_full a constant), so the receive path pays for the check
 * only where a frame ends. */
static inline __attribute__((always_inline)) uint32_t feed(struct frame_rx *rx, const uint8_t *data,
                                                           uint32_t n, bool stop_when_full)
{
    uint32_t left = n;
    while (left > 0u) {
        uint32_t took = 0;
        switch (rx->state) {
        case RX_SKIP:
            took = rx->skip_left < left ? rx->skip_left : left;
            rx->skip_left -= took;
            if (rx->skip_left == 0u) {
                finish_skipped(rx);
            }
            break;
        case RX_CONTENT:
            took = content_run(rx, data, left);
            break;
        case RX_HDR0:
            took = garbage_run(rx, data, left);
            if (took == 0u) {
                took = header_run(rx, data, left);
            }
            break;
        case RX_CHECKSUM:
            finish_frame(rx, *data);
            if (stop_when_full && next_slot(rx->head) == rx->tail) {
                return n - left + 1u;
            }
            took = 1;
            break;
        default:
            break;
        }
        if (took == 0u) {
            step(rx, *data);
            took = 1;
        }
        data += took;
        left -= took;
    }
    return n;
}

void frame_rx_feed_bytes(struct frame_rx *rx, const uint8_t *data, uint32_t n)
{
    (void)feed(rx, data, n, false);
}

/* The queue fills only at the end of a frame, where feed() stops: full,
 * the framer is between frames. */
uint32_t frame_rx_feed_until_full(struct frame_rx *rx, const uint8_t *data, uint32_t n)
{
    return next_slot(rx->head) == rx->tail ? 0u : feed(rx, data, n, true);
}
#else
void frame_rx_feed_bytes(struct frame_rx *rx, const uint8_t *data, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        step(rx, data[i]);
    }
}

/* Full between frames: the bytes after wait where they are (the port's
 * ring) until the dispatcher has taken a frame. */
static bool must_wait(const struct frame_rx *rx)
{
    return rx->state == RX_HDR0 && next_slot(rx->head) == rx->tail;
}

/* A byte at a time. A burst too short to fill an empty queue (nearly every
 * main-loop pass's) needs no check between its bytes. */
uint32_t frame_rx_feed_until_full(struct frame_rx *rx, const uint8_t *data, uint32_t n)
{
    uint32_t i = 0;
    if (n <= FRAME_RX_SAFE_BURST && rx->head == rx->tail) {
        for (; i < n; i++) {
            step(rx, data[i]);
        }
        return n;
    }
    for (; i < n && !must_wait(rx); i++) {
        step(rx, data[i]);
    }
    return i;
}
#endif

void frame_rx_feed(struct frame_rx *rx, uint8_t byte)
{
    frame_rx_feed_bytes(rx, &byte, 1);
}
