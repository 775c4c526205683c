/* The time a simulated servo's CPU takes: a main-loop pass, a control tick
 * and a request's handling, on the board the simulator stands for. The
 * firmware runs on the PC in no time; these put back what the target
 * takes, so that the wire shows the turnaround and the Sync Monitor gaps
 * of the servo, not of the PC. */
#ifndef SIM_CPU_H
#define SIM_CPU_H

#include <stdbool.h>
#include <stdint.h>

struct sim_cpu {
    const char *name;
    uint32_t pass_ns;   /* a main-loop pass with nothing to do */
    uint32_t tick_ns;   /* a control tick, the longest */
    uint32_t answer_ns; /* a request to an answer ready, the longest but a durable write's */
    /* The pass that frames a Sync Monitor's checksum byte, beyond an idle
     * pass, up to the start of this servo's answer (listed first): the M3
     * builds the answer before, the M0 after (sends_ahead: servo.c,
     * send_ahead; that pass costs answer_ns in all). */
    uint32_t sync_answer_ns;
    bool sends_ahead;
    uint8_t tick_and_pass_us; /* what the board tells the firmware (hal_port.h) */
};

/* "m3" (the reference board, the default) or "m0"; NULL if neither. */
const struct sim_cpu *sim_cpu_named(const char *name);

#endif
