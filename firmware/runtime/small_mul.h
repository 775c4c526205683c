/* 64-bit multiplication from 16 x 16 products (small_mul.c). Built with
 * SMALL_MUL_AEABI, the file also provides the run-time ABI's __aeabi_lmul,
 * which is how the Cortex-M0 image uses it; the host test calls it against
 * C's *. */
#ifndef RUNTIME_SMALL_MUL_H
#define RUNTIME_SMALL_MUL_H

#include <stdint.h>

uint64_t small_lmul(uint64_t a, uint64_t b);

#endif
