#include "sim_bus.h"

#include "ports/host/wire_overlap.h"
#include "protocol/frame_tx.h"

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <unistd.h>

void sim_bus_init(struct sim_bus *b, uint64_t now_us)
{
    *b = (struct sim_bus){.host_fd = -1, .now_us = now_us, .host_baud = 115200u};
}

uint64_t sim_bus_step_to(const struct sim_bus *b, uint64_t wall_us)
{
    uint64_t limit = b->now_us + SIM_BUS_STEP_US;
    return wall_us < limit ? wall_us : limit;
}

static uint64_t byte_time_us(uint32_t baud)
{
    return baud ? (10000000u + baud - 1u) / baud : 87u;
}

static struct sim_bus_byte *queued(struct sim_bus *b, unsigned i)
{
    return &b->queue[(b->head + i) % SIM_BUS_QUEUE];
}

/* A byte that overlaps a byte of another sender already on the wire is not
 * heard as a byte of its own: the receivers, framed on the byte already
 * there, get it garbled by this one (wire_overlap.h, the virtual boards'
 * rule too). True when it overlapped. */
static bool garble(struct sim_bus *b, uint8_t sender, uint8_t byte, uint64_t start, uint64_t end)
{
    bool overlapped = false;
    bool with_servo = false;
    for (unsigned i = b->count; i-- > 0;) {
        struct sim_bus_byte *e = queued(b, i);
        if (e->at_us <= start) {
            break; /* ends are in order: nothing earlier reaches this byte */
        }
        if (e->sender != sender && e->start_us < end) {
            e->byte = wire_overlap(e->byte, byte, (int64_t)(start - e->start_us) * 1000,
                                   (int64_t)(e->at_us - e->start_us) * 1000);
            e->garbled = 1;
            overlapped = true;
            with_servo |= e->sender != SIM_HOST;
        }
    }
    b->garbled += overlapped;
    b->collisions += with_servo && sender != SIM_HOST;
    return overlapped;
}

/* Puts a byte into the queue in the order of the bytes' ends. */
static void insert(struct sim_bus *b, struct sim_bus_byte byte)
{
    unsigned i = b->count++;
    while (i > 0 && queued(b, i - 1u)->at_us > byte.at_us) {
        *queued(b, i) = *queued(b, i - 1u);
        i--;
    }
    *queued(b, i) = byte;
}

/* Bytes go on the wire one byte time apart from start_us, each garbling
 * whatever of another sender's it overlaps. */
static uint64_t enqueue(struct sim_bus *b, uint8_t sender, const uint8_t *data, unsigned len,
                        uint32_t baud, uint64_t start_us)
{
    uint64_t byte_us = byte_time_us(baud);
    uint64_t t = start_us;
    struct sim_bus_span *last = &b->spans[(b->span_count - 1u) % SIM_BUS_SPANS];
    if (b->span_count == 0u || last->sender != sender || last->end_us != t) {
        last = &b->spans[b->span_count++ % SIM_BUS_SPANS];
        *last = (struct sim_bus_span){.start_us = t, .end_us = t, .sender = sender};
    }
    for (unsigned i = 0; i < len; i++) {
        uint64_t from = t;
        t += byte_us;
        if (garble(b, sender, data[i], from, t)) {
            continue;
        }
        if (b->count == SIM_BUS_QUEUE) {
            b->dropped++;
            continue;
        }
        insert(b, (struct sim_bus_byte){.start_us = from, .at_us = t, .baud = baud,
                                        .byte = data[i], .sender = sender});
    }
    b->wire_until_us = t > b->wire_until_us ? t : b->wire_until_us;
    last->end_us = t;
    last->bytes = (uint16_t)(last->bytes + len);
    return t;
}

/* A servo's bytes go on the wire when it sends them, whatever is there: it
 * cannot hear a byte before its stop bit. */
uint64_t sim_bus_send(struct sim_bus *b, unsigned sender, const uint8_t *data, unsigned len,
                      uint32_t baud, uint64_t now_us)
{
    if (b->stations[sender].unplugged) { /* its bytes reach no wire */
        return now_us + (uint64_t)len * byte_time_us(baud);
    }
    unsigned long before = b->collisions;
    uint64_t t = enqueue(b, (uint8_t)sender, data, len, baud, now_us);
    if (b->collisions != before) {
        fprintf(stderr, "servo_sim: collision: servo %u talked over another servo's answer "
                "(%lu bytes garbled)\n", b->stations[sender].log_id, b->collisions - before);
    }
    return t;
}

static void write_host(struct sim_bus *b, const uint8_t *data, unsigned len)
{
    while (b->host_fd >= 0 && len > 0) {
        ssize_t n = write(b->host_fd, data, len);
        if (n < 0 && errno == EINTR) {
            continue;
        }
        if (n <= 0) {
            return; /* host gone or not reading: the wire does not wait */
        }
        data += n;
        len -= (unsigned)n;
        b->host_bytes += (unsigned long)n;
    }
}

/* What the host's adapter hands over by now_us goes to the host. */
static void hand_over(struct sim_bus *b, uint64_t now_us)
{
    uint8_t out[256];
    unsigned n;
    while ((n = sim_usb_take(&b->usb, now_us, out, sizeof out)) > 0u) {
        b->handed_wall_us = b->wall_us != NULL ? b->wall_us() : 0u;
        write_host(b, out, n);
    }
}

void sim_bus_deliver(struct sim_bus *b, uint64_t now_us)
{
    while (b->count > 0 && b->queue[b->head].at_us <= now_us) {
        const struct sim_bus_byte *e = &b->queue[b->head];
        /* Each byte carries the time it ended on the wire, as a receive
         * interrupt would stamp it: a stalled simulator loop does not look
         * like an idle line. The queue's times never run backwards. */
        bool received = false;
        for (unsigned s = 0; s < b->station_count; s++) {
            const struct sim_station *st = &b->stations[s];
            if (s != e->sender && !st->unplugged && *st->baud == e->baud) {
                st->receive(st->ctx, e->byte, e->at_us);
                received = true;
            }
        }
        if (e->sender != SIM_HOST && b->host_baud == e->baud) {
            received = true;
            if (e->start_us >= b->deaf_before_us) {
                sim_usb_hold(&b->usb, e->byte, e->at_us, e->baud);
            }
        }
        b->baud_mismatches += !received;
        b->head = (b->head + 1u) % SIM_BUS_QUEUE;
        b->count--;
    }
    hand_over(b, now_us);
    if (now_us > b->now_us) {
        b->now_us = now_us;
    }
}

void sim_bus_attach(struct sim_bus *b, struct sim_station station)
{
    if (b->station_count < SIM_MAX_SERVOS) {
        b->stations[b->station_count++] = station;
    }
}

/* Where the host's next byte may start: after its own bytes still queued
 * and what is on the wire by now, and the bytes that follow those back to
 * back. A servo's answer booked to start later (after a flash stall, the
 * CPU held) does not hold the host back: on a wire the host's UART sends
 * while that servo is still silent, and the two garble if they meet. */
static uint64_t host_start_us(struct sim_bus *b, uint64_t now_us)
{
    uint64_t start = now_us;
    for (unsigned i = 0; i < b->count; i++) {
        const struct sim_bus_byte *q = queued(b, i);
        if ((q->sender == SIM_HOST || q->start_us <= start) && q->at_us > start) {
            start = q->at_us;
        }
    }
    return start;
}

/* The host's bytes wait for a quiet wire (what the simulator reads of a
 * pty or socket was written before it could be put on the wire). */
void sim_bus_from_host(struct sim_bus *b, const uint8_t *data, unsigned len, uint64_t now_us)
{
    uint64_t start = host_start_us(b, now_us);
    if (start < b->deaf_before_us) {
        b->deaf_before_us = start; /* from its first byte on, answers may be its own */
    }
    (void)enqueue(b, SIM_HOST, data, len, b->host_baud, start);
}

void sim_bus_new_host(struct sim_bus *b)
{
    b->usb.count = 0; /* held for the one that left */
    uint64_t longest = (uint64_t)RESPONSE_FRAME_MAX * byte_time_us(b->host_baud) + 5000u;
    uint64_t from = b->wire_until_us > b->now_us ? b->wire_until_us : b->now_us;
    b->deaf_before_us = from + longest;
}

unsigned sim_bus_room(const struct sim_bus *b)
{
    return SIM_BUS_QUEUE - b->count;
}

/* The next byte's end on the wire, or the adapter's next hand-over. */
static uint64_t next_event(const struct sim_bus *b)
{
    uint64_t at = b->count == 0 ? SIM_USB_NONE : b->queue[b->head].at_us;
    uint64_t usb = sim_usb_due(&b->usb);
    return usb < at ? usb : at;
}

int64_t sim_bus_next_due(const struct sim_bus *b, uint64_t now_us)
{
    uint64_t at = next_event(b);
    if (at == SIM_USB_NONE) {
        return -1;
    }
    return at > now_us ? (int64_t)(at - now_us) : 0;
}

uint64_t sim_bus_next_at(const struct sim_bus *b, uint64_t until_us)
{
    uint64_t at = next_event(b);
    at = at > b->now_us ? at : b->now_us;
    return at < until_us ? at : until_us;
}
