/* The shared half-duplex wire of the simulator: what one servo sends reaches
 * every other servo one byte time after another, from the moment it
 * sends it, and the host through its USB-serial adapter (sim_usb.h); the
 * host's bytes reach every servo paced the same way (a pty or socket
 * delivers them in bursts a UART never would), after
 * whatever is already on the wire. Bytes of two senders that overlap
 * garble each other, as on a real wire: a receiver framed on the byte
 * already there samples the middle of its bits while the line is low if
 * either drives it low, and gets nothing of the later byte's own framing;
 * two drivers are never in step, a bit apart at least (sim_bus.c, overlap;
 * tools/vboard/bus.py keeps the same rule). Servos at one ID answer as one
 * damaged frame, as real ones do. `garbled`
 * counts bytes that overlapped; `collisions` the bytes a servo sent over
 * another servo's, logged: answers must never do that.
 *
 * Each byte goes at its sender's baud rate and only a receiver at the same
 * rate gets it (at another rate a UART sees framing errors, dropped here).
 * The host's rate is what it set on the pty, or `hostbaud` on the control
 * port for a TCP host (115200 until then). A host that writes faster than
 * the line is held back (the simulator stops reading it), as its own UART
 * would be, so no byte is dropped and no backlog of wire time builds up.
 *
 * The servos and their models run on the bus's clock, `now_us`. It follows
 * the wall clock, but a pass of the simulator's loop moves it by at most
 * SIM_BUS_STEP_US, and it stands still while the servos run. On silicon a
 * byte's interrupt runs as it arrives and the main loop answers within
 * microseconds; a PC that preempts the simulator for milliseconds must not
 * let a servo see time it has not reacted in (it would take the line for
 * silent and talk over a Sync Monitor answer). A preempted simulator falls
 * behind the wall clock instead, and catches up at full speed, a byte time
 * at a time with the servos' main loops run between (main.c): what a servo
 * does between two bytes it does whatever the PC's load. */
#ifndef SIM_BUS_H
#define SIM_BUS_H

#include <stdint.h>

#include "sim_usb.h"

#define SIM_BUS_QUEUE 8192u
#define SIM_MAX_SERVOS 254u /* IDs 0..253, and 254 */
#define SIM_BUS_STEP_US 250u /* most the bus clock moves in one pass */
#define SIM_HOST 0xFFu /* sender of the host's bytes */

/* What the bus needs of a station (a simulated servo): its UART's rate,
 * where its received bytes go, and the ID the log names it by. The bus
 * calls stations through this, so it knows nothing of what they are. */
struct sim_station {
    void *ctx;
    const uint32_t *baud; /* the station's rate now */
    void (*receive)(void *ctx, uint8_t byte, uint64_t at_us);
    uint8_t log_id;
    bool unplugged; /* off the bus (control port: unplug): hears and sends nothing */
};

/* One sender's bytes back to back on the wire: from the first start bit
 * to the last stop bit, on the bus clock. */
struct sim_bus_span {
    uint64_t start_us;
    uint64_t end_us;
    uint16_t bytes;
    uint8_t sender; /* a station's index, or SIM_HOST */
};
#define SIM_BUS_SPANS 1024u /* the wire's log keeps the latest */

struct sim_bus_byte {
    uint64_t start_us;
    uint64_t at_us; /* its stop bit's end: the queue is in this order */
    uint32_t baud;
    uint8_t byte;
    uint8_t sender;
    uint8_t garbled; /* another sender's byte overlapped it */
};

struct sim_bus {
    struct sim_bus_byte queue[SIM_BUS_QUEUE];
    unsigned head;
    unsigned count;
    uint64_t wire_until_us;   /* end of the last byte queued, host's or servo's */
    uint64_t now_us;          /* every byte due by then has been delivered */
    int host_fd;              /* -1: no host connected */
    struct sim_usb usb;       /* the host's USB-serial adapter (sim_usb.h) */
    uint32_t host_baud;       /* the host's UART rate */
    struct sim_station stations[SIM_MAX_SERVOS];
    unsigned station_count;
    unsigned long collisions; /* servo bytes sent over another servo's */
    unsigned long garbled;    /* bytes sent over another sender's (the host's too) */
    unsigned long dropped;    /* queue overflow (servo bytes; the host is held back) */
    unsigned long baud_mismatches; /* bytes no station at that rate received */
    unsigned long host_bytes; /* bytes the host was sent */
    uint64_t (*wall_us)(void); /* the wall clock, if set: handed_wall_us */
    uint64_t handed_wall_us;  /* as the host was last handed bytes (before the write) */
    /* A servo's byte that began before this is not the connected host's:
     * it answers a client that left (sim_bus_new_host). */
    uint64_t deaf_before_us;
    struct sim_bus_span spans[SIM_BUS_SPANS];
    unsigned long span_count; /* in all: the latest SIM_BUS_SPANS are kept */
};

/* A TCP client taken in place of one that left: what answers the one
 * that left (the bytes on the wire or due on it before the next client's
 * first byte, the longest answer's time at most) is not handed to it. */
void sim_bus_new_host(struct sim_bus *b);

/* Room for this many more bytes: the host is read no faster. */
unsigned sim_bus_room(const struct sim_bus *b);

void sim_bus_init(struct sim_bus *b, uint64_t now_us);
/* Adds a station; its index is its sender number in sim_bus_send. */
void sim_bus_attach(struct sim_bus *b, struct sim_station station);
/* Queues len bytes from servo `sender`; returns when the last stop bit ends. */
uint64_t sim_bus_send(struct sim_bus *b, unsigned sender, const uint8_t *data, unsigned len,
                      uint32_t baud, uint64_t now_us);
/* Where the next pass may move the bus clock: the wall clock, or one step. */
uint64_t sim_bus_step_to(const struct sim_bus *b, uint64_t wall_us);
/* Delivers every byte due by now_us and moves the bus clock there. */
void sim_bus_deliver(struct sim_bus *b, uint64_t now_us);
void sim_bus_from_host(struct sim_bus *b, const uint8_t *data, unsigned len, uint64_t now_us);
/* Microseconds until the next queued byte, or the host adapter's next
 * hand-over, is due; -1 if none. */
int64_t sim_bus_next_due(const struct sim_bus *b, uint64_t now_us);
/* When the bus clock next has something to do on the way to until_us: the
 * next byte's time or the adapter's hand-over (not before now), or until_us. */
uint64_t sim_bus_next_at(const struct sim_bus *b, uint64_t until_us);

#endif
