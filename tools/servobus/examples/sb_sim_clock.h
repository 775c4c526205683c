/* servo_sim's clock for the examples (firmware/boards/host_sim/sim_clock.h
 * publishes it in a file, microseconds): a bus on it waits as the
 * simulated servos do, whatever the PC's load. */
#ifndef SERVOBUS_SIM_CLOCK_H
#define SERVOBUS_SIM_CLOCK_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Maps the file; 0, or -1 (then sim_clock_us falls back to CLOCK_MONOTONIC). */
int sim_clock_open(const char *path);
/* The clock, microseconds: an sb_transport's now_us. */
uint64_t sim_clock_us(void *ctx);

#ifdef __cplusplus
}
#endif

#endif
