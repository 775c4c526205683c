/* Saturation to a power of two, private to the motion layer. */
#ifndef MOTION_SATURATE_H
#define MOTION_SATURATE_H

#include <stdint.h>

/* v within [-limit, limit - 1], limit a power of two: one SSAT on the
 * Cortex-M3. */
static inline int32_t sat_q(int32_t v, int32_t limit)
{
    return v > limit - 1 ? limit - 1 : v < -limit ? -limit : v;
}

#endif
