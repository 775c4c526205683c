/* The closed form of a trapezoid or a streamed segment at any tick, which
 * the tests hold the control tick's walk against (the firmware walks it:
 * motion/profile.c). */
#ifndef TEST_PROFILE_CLOSED_FORM_H
#define TEST_PROFILE_CLOSED_FORM_H

#include <stdint.h>

#include "motion/profile.h"

/* Each ramp exact at its own end: the first at the start, the last at the
 * target. */
int64_t profile_position(const struct profile *p, uint32_t tick);

#endif
