#include "protocol/frame_rx.h"

#include <stdatomic.h>
#include <stddef.h>

#include "protocol/packet_codes.h"
#include "protocol/wire.h"

enum rx_state {
    RX_HDR0,
    RX_HDR1,
    RX_CODE,
    RX_LENGTH,
    RX_LENGTH_LO, /* extended length, low byte */
    RX_LENGTH_HI,
    RX_CONTENT,
    RX_CHECKSUM,
};

/* SyncCommand content: cmd, record_len, count, then the records. */
enum { SYNC_HEADER_SIZE = 3 };

static uint8_t next_slot(uint8_t i)
{
    return (uint8_t)((i + 1u) % FRAME_QUEUE_SLOTS);
}

void frame_rx_init(struct frame_rx *rx, const volatile uint8_t *own_id,
                   uint32_t idle_timeout_us)
{
    *rx = (struct frame_rx){0};
    rx->own_id = own_id;
    rx->idle_timeout_us = idle_timeout_us;
    rx->state = RX_HDR0;
}

void frame_rx_set_idle_timeout(struct frame_rx *rx, uint32_t idle_timeout_us)
{
    rx->idle_timeout_us = idle_timeout_us;
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

static struct rx_frame *work_slot(struct frame_rx *rx)
{
    return &rx->slots[rx->head];
}

static void start_content(struct frame_rx *rx, uint16_t length)
{
    rx->remaining = length;
    rx->position = 0;
    if (!rx->is_request) {
        rx->state = length ? RX_CONTENT : RX_CHECKSUM;
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

static void content_byte(struct frame_rx *rx, uint8_t byte)
{
    if (rx->is_request && !rx->discard) {
        struct rx_frame *f = work_slot(rx);
        if (f->code == PKT_SYNC_COMMAND) {
            sync_content_byte(rx, f, byte);
        } else if (rx->position < FRAME_CONTENT_MAX) {
            f->content[rx->position] = byte;
            f->stored = (uint8_t)(rx->position + 1u);
        } else {
            f->flags |= FRAME_TRUNCATED;
        }
    }
    rx->position++;
    rx->remaining--;
    if (rx->remaining == 0u) {
        rx->state = RX_CHECKSUM;
    }
}

static void finish_frame(struct frame_rx *rx, uint8_t checksum)
{
    rx->state = RX_HDR0;
    if (!rx->is_request) {
        rx->stats.responses_skipped++;
        return;
    }
    if (checksum != rx->checksum) {
        rx->stats.checksum_errors++;
        return;
    }
    if (rx->discard) {
        rx->stats.queue_overflows++;
        return;
    }
    work_slot(rx)->responses_seen = rx->stats.responses_skipped;
    /* Publish the slot only after its contents are written. */
    atomic_signal_fence(memory_order_release);
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

void frame_rx_feed(struct frame_rx *rx, uint8_t byte, uint32_t now_us)
{
    /* Signed: a clock that stepped back a little (an emulated SysTick can)
     * is no idle line. */
    int32_t gap = (int32_t)(now_us - rx->last_byte_us);
    if (rx->state != RX_HDR0 && gap > (int32_t)rx->idle_timeout_us) {
        rx->stats.idle_timeouts++;
        rx->state = RX_HDR0;
    }
    rx->last_byte_us = now_us;

    switch (rx->state) {
    case RX_HDR0:
        if (!header_start(rx, byte)) {
            rx->stats.garbage_bytes++;
        }
        return;
    case RX_HDR1: {
        uint8_t want = rx->is_request ? WIRE_REQUEST_HDR1 : WIRE_RESPONSE_HDR1;
        if (byte == want) {
            rx->checksum = (uint8_t)(rx->checksum + byte);
            rx->state = RX_CODE;
        } else {
            /* Not a header after all: the byte may begin the real one. */
            rx->stats.garbage_bytes++;
            rx->state = RX_HDR0;
            if (!header_start(rx, byte)) {
                rx->stats.garbage_bytes++;
            }
        }
        return;
    }
    case RX_CODE:
        rx->checksum = (uint8_t)(rx->checksum + byte);
        if (rx->is_request) {
            rx->discard = next_slot(rx->head) == rx->tail;
            work_slot(rx)->code = byte;
        }
        rx->state = RX_LENGTH;
        return;
    case RX_LENGTH:
        rx->checksum = (uint8_t)(rx->checksum + byte);
        /* Only requests use the extended length (extensions.md). */
        if (rx->is_request && byte == WIRE_EXTENDED_LENGTH) {
            rx->state = RX_LENGTH_LO;
        } else {
            start_content(rx, byte);
        }
        return;
    case RX_LENGTH_LO:
        rx->checksum = (uint8_t)(rx->checksum + byte);
        rx->remaining = byte;
        rx->state = RX_LENGTH_HI;
        return;
    case RX_LENGTH_HI:
        rx->checksum = (uint8_t)(rx->checksum + byte);
        start_content(rx, (uint16_t)(rx->remaining | (uint16_t)((uint16_t)byte << 8)));
        return;
    case RX_CONTENT:
        rx->checksum = (uint8_t)(rx->checksum + byte);
        content_byte(rx, byte);
        return;
    case RX_CHECKSUM:
        finish_frame(rx, byte);
        return;
    default:
        rx->state = RX_HDR0;
        return;
    }
}

const struct rx_frame *frame_rx_peek(struct frame_rx *rx)
{
    if (rx->tail == rx->head) {
        return NULL;
    }
    atomic_signal_fence(memory_order_acquire);
    return &rx->slots[rx->tail];
}

void frame_rx_release(struct frame_rx *rx)
{
    if (rx->tail != rx->head) {
        atomic_signal_fence(memory_order_release);
        rx->tail = next_slot(rx->tail);
    }
}
