/* 32-bit division one quotient bit a step (small_div.c): the quotient in the low
 * word, the remainder in the high. Built with SMALL_DIV_AEABI, the file
 * also provides the run-time ABI's __aeabi_[u]idiv[mod] on top of these,
 * which is how the Cortex-M0 image uses it; the host tests call these two
 * against C's / and %. */
#ifndef RUNTIME_SMALL_DIV_H
#define RUNTIME_SMALL_DIV_H

#include <stdint.h>

uint64_t small_udivmod(uint32_t n, uint32_t d);
uint64_t small_idivmod(int32_t n, int32_t d);

#endif
