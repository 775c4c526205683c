/* The shared half-duplex wire of the simulator: what one servo sends reaches
 * the host and every other servo one byte time after another, after whatever
 * is already on the wire; the host's bytes reach every servo paced the same
 * way (a pty or socket delivers them in bursts a UART never would). A
 * servo that starts sending while another's bytes are on the wire is a
 * collision, counted and logged: on a real bus it would garble both. */
#ifndef SIM_BUS_H
#define SIM_BUS_H

#include <stdint.h>

#define SIM_BUS_QUEUE 8192u
#define SIM_MAX_SERVOS 16u
#define SIM_HOST 0xFFu /* sender of the host's bytes */

struct sim_servo;

struct sim_bus_byte {
    uint64_t at_us;
    uint8_t byte;
    uint8_t sender;
};

struct sim_bus {
    struct sim_bus_byte queue[SIM_BUS_QUEUE];
    unsigned head;
    unsigned count;
    uint64_t wire_until_us;   /* end of the last byte queued, host's or servo's */
    uint64_t servo_until_us;  /* end of the last servo byte queued */
    int last_sender;          /* servo that queued it */
    int host_fd;              /* -1: no host connected */
    struct sim_servo *servos[SIM_MAX_SERVOS];
    unsigned servo_count;
    unsigned long collisions;
    unsigned long dropped;    /* queue overflow */
};

void sim_bus_init(struct sim_bus *b);
/* Queues len bytes from servo `sender`; returns when the last stop bit ends. */
uint64_t sim_bus_send(struct sim_bus *b, unsigned sender, const uint8_t *data, unsigned len,
                      uint32_t baud, uint64_t now_us);
/* Delivers every byte whose time has come. */
void sim_bus_deliver(struct sim_bus *b, uint64_t now_us);
void sim_bus_from_host(struct sim_bus *b, const uint8_t *data, unsigned len, uint64_t now_us);
/* Microseconds until the next queued byte is due; -1 if none. */
int64_t sim_bus_next_due(const struct sim_bus *b, uint64_t now_us);

#endif
