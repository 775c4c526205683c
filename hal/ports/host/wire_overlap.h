/* The half-duplex wire's rule where two drivers overlap, one model for
 * servo_sim (firmware/boards/host_sim/sim_bus.c) and the virtual boards
 * (tools/vboard/bus.py, through vboard_native). */
#ifndef WIRE_OVERLAP_H
#define WIRE_OVERLAP_H

#include <stdint.h>

/* The byte a receiver framed on `heard` gets when `other` started lag_ns
 * after it (before it, if negative): the middle of each of heard's bits
 * sampled while the line is low if either drives it low (a byte drives its
 * start bit low, its data least significant bit first, its stop bit high,
 * and leaves the line high outside its frame). Two drivers are never in
 * step (their clocks and latencies differ): one within half a bit of the
 * other is taken as a bit off. byte_ns: heard's 10 bit times. */
uint8_t wire_overlap(uint8_t heard, uint8_t other, int64_t lag_ns, int64_t byte_ns);

#endif
