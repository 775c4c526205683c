/* servo_sim's clock for the examples (firmware/boards/host_sim/sim_clock.h
 * publishes it in a file, microseconds): a bus on it waits as the
 * simulated servos do, whatever the PC's load. */
#ifndef SERVOBUS_SIM_CLOCK_H
#define SERVOBUS_SIM_CLOCK_H

#include <stdint.h>

#include "servobus/servobus_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Why a clock file was not taken: sim_clock_why's words. */
typedef enum sim_clock_status {
    SIM_CLOCK_OK,
    SIM_CLOCK_NO_FILE,   /* cannot be opened (or mapped, or written for paced) */
    SIM_CLOCK_NOT_CLOCK, /* shorter than a simulator's clock file */
    SIM_CLOCK_USED,      /* paced: another host has used the simulator's bus */
} sim_clock_status;

const char *sim_clock_why(sim_clock_status status);

/* Maps the file; 0, or -1 (then sim_clock_us falls back to CLOCK_MONOTONIC;
 * sim_clock_last says why). */
int sim_clock_open(const char *path);
sim_clock_status sim_clock_last(void);
/* The clock, microseconds: an sb_transport's now_us. A clock that stands
 * still for 30 s of the PC's time (SB_SIM_CLOCK_STALLED_S in the
 * environment: another number; a simulator stopped or gone, or a paced one
 * whose host does not pace it) ends the program: exit 3, saying so. */
uint64_t sim_clock_us(void *ctx);

/* A paced servo_sim (--clock paced) runs only while its host waits on it:
 * what the host does between its waits takes no simulated time, however
 * loaded the PC (tests). Maps the file to write, and returns inner with
 * its reads and writes told to the simulator (the clock file's offsets
 * 8, 16 and 24) and sim_clock_us for now_us; where it cannot (*status not
 * SIM_CLOCK_OK) inner as it was. Its byte counts start at zero, so it must
 * be the simulator's first host. */
sb_transport sim_clock_paced(const char *path, sb_transport inner, sim_clock_status *status);

#ifdef __cplusplus
}
#endif

#endif
