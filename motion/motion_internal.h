/* What motion.c (commands, state) and control_tick.c (the tick) share;
 * private to the motion layer. Positions are Q32 decidegrees, speeds Q32 or
 * Q8 decidegrees per tick, as in motion.h. */
#ifndef MOTION_INTERNAL_H
#define MOTION_INTERNAL_H

#include <stdint.h>

#include "motion/motion.h"

enum {
    MULTI_TURN_LIMIT = 3686400, /* behaviour.md, "Motion" */
    DECIDEG_PER_TURN = 3600,
    SUPPLY_HYSTERESIS_MV = 128, /* the limits follow the supply past this */
    CLOCK_REAL_TIME = 256,      /* clock_rate, Q8 */
};

/* Setpoint and horn agree within these: 0.5 degree, 25 deg/s. A new profile
 * starts from the setpoint then, else from the horn; a move has arrived
 * only slower than FOLLOW_SPEED. */
#define FOLLOW_GAP_Q32 (5 * DECIDEG_Q32)
enum { FOLLOW_SPEED_Q8 = 64 };

/* The profile's clock (control_tick.c, "the profile's clock"). */
enum {
    LEAD_FREE_Q8 = 5 << 8, /* 0.5 degree */
    LEAD_SPAN_SHIFT = 3,   /* (lead - free) >> 3: 256 at 8 decideg */
    LEAD_FILTER_SHIFT = 2, /* time constant 4 ticks */
    CLOCK_SLOWING = 64,    /* the clock stops within 4 ticks */
    CLOCK_RECOVERY = 8,    /* a stopped clock is back to real time in 32 ticks */
};

static inline int64_t counts_to_q32(int32_t counts)
{
    return (int64_t)counts * DECIDEG_Q8_PER_COUNT * ((int64_t)1 << 24);
}

/* Q32 to Q8 (decideg, or decideg per tick), saturated to int32. */
static inline int32_t q32_to_q8_sat(int64_t v)
{
    int64_t q8 = v >> 24;
    return q8 > INT32_MAX ? INT32_MAX : q8 < -INT32_MAX ? -INT32_MAX : (int32_t)q8;
}

/* The center offset (53): protocol angles are measured minus this. */
static inline int64_t motion_center_offset_q32(const struct motion *m)
{
    return (int64_t)m->regs->user.center_offset_decideg * DECIDEG_Q32;
}

/* Moves the origin by counts the way the angle grows: every position the
 * motion layer holds (horn, setpoint, profile) moves with it, so a move in
 * flight goes on unchanged. The encoder's count and the origin are kept
 * within a turn of each other's whole turns, so neither outgrows int32. */
void motion_move_origin(struct motion *m, int32_t counts);
/* The supply the limits are worked out for: the measured one, 7.4 V until
 * there is one. */
uint16_t motion_supply_mv(const struct motion *m);
/* The current limit and the supply-scaled gains (divides: on changes only). */
void motion_update_limits(struct motion *m);
/* Starts the profile's clock at its tick 0, in real time. */
void motion_clock_restart(struct motion *m);
/* The braking duty the output can count on moving in direction dir. */
int32_t motion_brake_duty(const struct motion *m, int32_t dir);
/* The running command has finished: answer, release or hold, next one. */
void motion_finish(struct motion *m);

#endif
