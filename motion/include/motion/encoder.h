/* Multi-turn tracking of the 12-bit absolute encoder: the shaft cannot turn
 * half a revolution between two control ticks, so the shortest way from the
 * last reading is the way it went. */
#ifndef MOTION_ENCODER_H
#define MOTION_ENCODER_H

#include <stdint.h>

#define ENCODER_COUNTS 4096
/* counts x 225 = decidegrees Q8, exactly: 3600 / 4096 = 225 / 256. */
#define DECIDEG_Q8_PER_COUNT 225

struct encoder_track {
    int32_t counts; /* multi-turn position */
    uint16_t last;  /* last raw reading */
};

static inline void encoder_start(struct encoder_track *e, uint16_t raw)
{
    e->last = (uint16_t)(raw & (ENCODER_COUNTS - 1));
    e->counts = e->last;
}

/* Takes a raw reading; returns the counts moved since the last one,
 * -2048..2047. */
static inline int32_t encoder_update(struct encoder_track *e, uint16_t raw)
{
    raw = (uint16_t)(raw & (ENCODER_COUNTS - 1));
    uint32_t forward = ((uint32_t)raw - e->last + ENCODER_COUNTS / 2) & (ENCODER_COUNTS - 1);
    int32_t delta = (int32_t)forward - ENCODER_COUNTS / 2;
    e->counts += delta;
    e->last = raw;
    return delta;
}

#endif
