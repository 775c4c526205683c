/* Saturation to a power of two, private to the motion layer. */
#ifndef MOTION_SATURATE_H
#define MOTION_SATURATE_H

#include <stdint.h>

/* v within [-limit, limit - 1], limit a power of two (a constant). On the
 * Cortex-M3 one SSAT, through GCC's builtin for ACLE's __ssat: the
 * compiler finds it for most of these, not for all (the negated one in the
 * tracker). */
static inline int32_t sat_q_inline(int32_t v, int32_t limit)
{
    return v > limit - 1 ? limit - 1 : v < -limit ? -limit : v;
}
#if defined(__ARM_FEATURE_SAT)
#define sat_q(v, limit) ((int32_t)__builtin_arm_ssat((int)(v), (unsigned)__builtin_ctz((unsigned)(limit)) + 1u))
#elif defined(SERVO_SIZE_FIRST)
/* A call where size comes first (the Cortex-M0): controller.c. */
int32_t sat_q(int32_t v, int32_t limit);
#else
#define sat_q sat_q_inline
#endif

#endif
