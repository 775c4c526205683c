/* State of the stand-in motion layer: the servo reaches every target at
 * once. It keeps the control state and async buffer honest so the protocol
 * rules that depend on them can be exercised before the planner lands. */
#ifndef MOTION_MOTION_STATE_H
#define MOTION_MOTION_STATE_H

#include <stdint.h>

#define MOTION_ASYNC_MAX 1u

struct motion {
    int32_t position_decideg;  /* multi-turn, relative to the origin */
    uint8_t controlled;        /* under angle or wheel control */
    uint8_t async_open;
    uint8_t async_count;
    uint8_t finished_packet;   /* answer owed for a finished move */
    struct motion_command async_buffer[MOTION_ASYNC_MAX];
};

#endif
