/* The motion layer as the dispatcher sees it: decoded motion commands in,
 * position and state out. Units are the protocol's (0.1 degree, ms, mW). */
#ifndef MOTION_MOTION_H
#define MOTION_MOTION_H

#include <stdbool.h>
#include <stdint.h>

#include "protocol/registers.h"

enum motion_kind {
    MOTION_ANGLE,    /* packets 8, 11-15 */
    MOTION_WHEEL,    /* packet 7 */
    MOTION_DAMPING,  /* packet 9 */
    MOTION_STOP,     /* packet 24 */
};

enum motion_profile {
    PROFILE_INTERVAL, /* cruise velocity derived from interval_ms */
    PROFILE_VELOCITY, /* cruise time derived from velocity_decideg_s */
};

/* One motion request as it arrived, fields not yet clamped. */
struct motion_command {
    uint8_t packet;           /* request packet number, for the finish answer */
    uint8_t kind;             /* enum motion_kind */
    uint8_t profile;          /* enum motion_profile */
    uint8_t multi_turn;       /* packets 13-15 */
    uint8_t answer_when_done; /* control response on, sent to this servo alone */
    uint8_t method;           /* wheel: direction | action; stop: 0x10-0x12 */
    int32_t angle_decideg;
    uint32_t interval_ms;
    uint16_t acc_ms;
    uint16_t dec_ms;
    uint16_t velocity_decideg_s;
    uint16_t wheel_speed_deg_s;
    uint16_t wheel_value;     /* turns or ms, by method */
    uint16_t power_mw;
};

enum motion_submit_result {
    MOTION_ACCEPTED,
    MOTION_QUEUE_FULL, /* control response on and the queue is full */
};

struct motion_angle {
    int32_t multi_turn_decideg;  /* ReadMultiTurnAngle / Monitor angle */
    int16_t turns;               /* whole turns in multi_turn_decideg */
    int16_t single_turn_decideg; /* ReadAngle: within -1800..1800 */
};

#include "motion/motion_state.h"

void motion_init(struct motion *m, const struct user_config *cfg);
enum motion_submit_result motion_submit(struct motion *m, const struct motion_command *cmd);
bool motion_is_released(const struct motion *m);
void motion_read_angle(const struct motion *m, struct motion_angle *out);
/* ResetMultiTurnAngle (17), SetOriginPoint (23): false unless released. */
bool motion_reset_multi_turn(struct motion *m);
bool motion_set_origin(struct motion *m);
void motion_begin_async(struct motion *m);
void motion_end_async(struct motion *m, bool cancel);
/* Packet number of a finished move that must be answered, 0 if none. */
uint8_t motion_take_finished(struct motion *m);
/* True while a motion command runs (status bit 0). */
bool motion_is_executing(const struct motion *m);

#endif
