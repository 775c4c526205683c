/* An ideal servo for tests: the encoder count nearest to where the motion
 * layer's setpoint is, so the horn follows it exactly. */
#ifndef TEST_IDEAL_ENCODER_H
#define TEST_IDEAL_ENCODER_H

#include <stdint.h>

#include "motion/motion.h"

/* The encoder's multi-turn count (origin included) nearest the setpoint:
 * decideg Q8 / 225, rounded half away from zero. */
static inline int32_t ideal_encoder_counts(const struct motion *m)
{
    int32_t sp = m->setpoint_q8;
    int32_t half = DECIDEG_Q8_PER_COUNT / 2;
    return (sp >= 0 ? sp + half : sp - half) / DECIDEG_Q8_PER_COUNT + m->origin_counts;
}

/* The raw 12-bit reading of that count. */
static inline uint16_t ideal_encoder_raw(const struct motion *m)
{
    return (uint16_t)((uint32_t)ideal_encoder_counts(m) & (ENCODER_COUNTS - 1));
}

#endif
