/* servo_sim's command line: which servos, where the bus and the control port
 * are, where the flash files live, the plant, the supply and the ambient. */
#ifndef SIM_OPTIONS_H
#define SIM_OPTIONS_H

#include <stdbool.h>
#include <stdint.h>

#include "ports/host/plant_model.h"
#include "sim_bus.h"
#include "sim_cpu.h"
#include "sim_usb.h"

struct sim_options {
    uint8_t ids[SIM_MAX_SERVOS];
    uint8_t units[SIM_MAX_SERVOS]; /* earlier servos given the same ID */
    unsigned id_count;
    int tcp_port;          /* -1: a pseudo-terminal; 0: any free port */
    int control_port;      /* 0: any free port */
    const char *link;      /* symlink to the pty */
    const char *state_dir;
    struct plant_model plant; /* --plant's file, or the reference servo */
    double supply_v;          /* --supply, else the plant's */
    double ambient_c;
    bool rx_interrupt;
    const struct sim_cpu *cpu;
    struct sim_usb host_link; /* the host's adapter (--host-link), usb by default */
    bool paced;               /* --clock paced: the host's waits alone move the clock */
};

/* Parses argv; prints the usage and exits on --help or a bad option. */
void sim_options_parse(int argc, char **argv, struct sim_options *o);

#endif
