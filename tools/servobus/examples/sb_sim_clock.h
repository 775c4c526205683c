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

/* Maps the file; 0, or -1 (then sim_clock_us falls back to CLOCK_MONOTONIC). */
int sim_clock_open(const char *path);
/* The clock, microseconds: an sb_transport's now_us. */
uint64_t sim_clock_us(void *ctx);

/* A paced servo_sim (--clock paced) runs only while its host waits on it:
 * what the host does between its waits takes no simulated time, however
 * loaded the PC (tests). Maps the file to write, and returns inner with
 * its reads and writes told to the simulator (the clock file's offsets
 * 8, 16 and 24) and sim_clock_us for now_us; *ok false (and inner as it
 * was) where the file cannot be mapped, or where another host has used
 * the simulator's bus already: the byte counts it keeps start at zero. */
sb_transport sim_clock_paced(const char *path, sb_transport inner, int *ok);

#ifdef __cplusplus
}
#endif

#endif
