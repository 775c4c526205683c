#include "sim_bus.h"

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <unistd.h>

void sim_bus_init(struct sim_bus *b, uint64_t now_us)
{
    *b = (struct sim_bus){.host_fd = -1, .last_sender = -1, .now_us = now_us, .host_baud = 115200u};
}

uint64_t sim_bus_step_to(const struct sim_bus *b, uint64_t wall_us)
{
    uint64_t limit = b->now_us + SIM_BUS_STEP_US;
    return wall_us < limit ? wall_us : limit;
}

/* Bytes go on the one wire one byte time apart, after whatever is on it,
 * so the queue's times never run backwards. */
static uint64_t enqueue(struct sim_bus *b, uint8_t sender, const uint8_t *data, unsigned len,
                        uint32_t baud, uint64_t now_us)
{
    uint64_t byte_us = baud ? (10000000u + baud - 1u) / baud : 87u;
    uint64_t t = now_us > b->wire_until_us ? now_us : b->wire_until_us;
    struct sim_bus_span *last = &b->spans[(b->span_count - 1u) % SIM_BUS_SPANS];
    if (b->span_count == 0u || last->sender != sender || last->end_us != t) {
        last = &b->spans[b->span_count++ % SIM_BUS_SPANS];
        *last = (struct sim_bus_span){.start_us = t, .end_us = t, .sender = sender};
    }
    for (unsigned i = 0; i < len; i++) {
        if (b->count == SIM_BUS_QUEUE) {
            b->dropped++; /* never on the wire: it takes no wire time */
            continue;
        }
        t += byte_us;
        b->queue[(b->head + b->count) % SIM_BUS_QUEUE] =
            (struct sim_bus_byte){.at_us = t, .baud = baud, .byte = data[i], .sender = sender};
        b->count++;
    }
    b->wire_until_us = t;
    last->end_us = t;
    last->bytes = (uint16_t)(last->bytes + len);
    return t;
}

uint64_t sim_bus_send(struct sim_bus *b, unsigned sender, const uint8_t *data, unsigned len,
                      uint32_t baud, uint64_t now_us)
{
    if (now_us < b->servo_until_us && b->last_sender != (int)sender) {
        b->collisions++;
        fprintf(stderr, "servo_sim: collision: servo %u started while servo %d was sending\n",
                b->stations[sender].log_id, b->stations[b->last_sender].log_id);
    }
    uint64_t t = enqueue(b, (uint8_t)sender, data, len, baud, now_us);
    b->servo_until_us = t;
    b->last_sender = (int)sender;
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
    }
}

/* What the host's adapter hands over by now_us goes to the host. */
static void hand_over(struct sim_bus *b, uint64_t now_us)
{
    uint8_t out[256];
    unsigned n;
    while ((n = sim_usb_take(&b->usb, now_us, out, sizeof out)) > 0u) {
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
            if (s != e->sender && *st->baud == e->baud) {
                st->receive(st->ctx, e->byte, e->at_us);
                received = true;
            }
        }
        if (e->sender != SIM_HOST && b->host_baud == e->baud) {
            received = true;
            sim_usb_hold(&b->usb, e->byte, e->at_us, e->baud);
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

void sim_bus_from_host(struct sim_bus *b, const uint8_t *data, unsigned len, uint64_t now_us)
{
    (void)enqueue(b, SIM_HOST, data, len, b->host_baud, now_us);
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
