/* 64-bit division for planning, without the C library's general 64/64
 * routine (about 150 Thumb-2 instructions a call on the Cortex-M3, many
 * more on the M0). The planner's divisors are tick counts and small
 * quantities: when one fits 32 bits, two 32-bit hardware divisions do it
 * (Knuth's algorithm D on 16-bit digits, as in Hacker's Delight, divlu);
 * a divisor beyond 32 bits takes one of them and a correction. So no image
 * links the library's 64-bit division (408 bytes on the Cortex-M0). */
#ifndef MOTION_DIV64_H
#define MOTION_DIV64_H

#include <stdint.h>

/* n / d, exactly. */
uint64_t div64_u(uint64_t n, uint64_t d);
/* num / den rounded to nearest, halves away from zero; den > 0. */
int64_t div64_round(int64_t num, int64_t den);

#endif
