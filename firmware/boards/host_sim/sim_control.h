/* servo_sim's control port: line commands that change the models (supply,
 * load, heat, a mechanical stop, flash faults, power cycles) and read the
 * servos' state and the simulated clock. `servo_sim --help` lists them. */
#ifndef SIM_CONTROL_H
#define SIM_CONTROL_H

#include <poll.h>
#include <stddef.h>
#include <stdint.h>

#include "sim_bus.h"
#include "sim_servo.h"

#define SIM_CONTROL_CLIENTS 8

struct sim_control_client {
    int fd; /* -1: a free slot */
    char line[256];
    size_t used;
};

struct sim_control {
    int listen_fd;
    int port;
    struct sim_control_client clients[SIM_CONTROL_CLIENTS];
    struct sim_bus *bus;
    struct sim_servo *servos; /* the bus's stations, in order */
    const uint64_t *most_behind_us; /* furthest the bus clock fell behind the wall clock */
};

/* Listens on 127.0.0.1:port (0: any free port; c->port says which). */
void sim_control_open(struct sim_control *c, int port, struct sim_bus *bus,
                      struct sim_servo *servos, const uint64_t *most_behind_us);
/* The descriptors to poll: the listening socket, then every client slot. */
enum { SIM_CONTROL_FDS = 1 + SIM_CONTROL_CLIENTS };
void sim_control_fds(const struct sim_control *c, struct pollfd fds[SIM_CONTROL_FDS]);
/* Accepts, reads and answers what the poll found. */
void sim_control_serve(struct sim_control *c, const struct pollfd fds[SIM_CONTROL_FDS]);

#endif
