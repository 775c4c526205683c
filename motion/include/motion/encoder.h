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

static inline void encoder_update(struct encoder_track *e, uint16_t raw)
{
    raw = (uint16_t)(raw & (ENCODER_COUNTS - 1));
    int32_t delta = (int32_t)raw - (int32_t)e->last;
    if (delta >= ENCODER_COUNTS / 2) {
        delta -= ENCODER_COUNTS;
    } else if (delta < -ENCODER_COUNTS / 2) {
        delta += ENCODER_COUNTS;
    }
    e->counts += delta;
    e->last = raw;
}

#endif
