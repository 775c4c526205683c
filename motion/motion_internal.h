/* What the motion layer's parts share (motion.c lists them); private to
 * the layer. The tick's positions are Q8 decidegrees in
 * int32, the profile's Q32 in int64; speeds are decidegrees per tick in the
 * same formats (motion.h). */
#ifndef MOTION_INTERNAL_H
#define MOTION_INTERNAL_H

#include <stdint.h>

#include "motion/motion.h"
#include "motion/saturate.h"
#include "registers/field_ranges.h"

enum {
    MULTI_TURN_LIMIT = FIELD_MOVE_MULTI_TURN_ANGLE_MAX, /* the schema's, +-: docs/protocol.md, "Moves" */
    DECIDEG_PER_TURN = 3600,
    SUPPLY_HYSTERESIS_MV = 128, /* the limits follow the supply past this */
    CLOCK_REAL_TIME = 256,      /* clock_rate, Q8 */
    ACCEL_DUTY_LIMIT = 1 << 20, /* the controller's output range */
};

/* Setpoint and horn agree within these: 0.5 degree, 25 deg/s. A new profile
 * starts from the setpoint then, else from the horn; a move has arrived
 * only slower than FOLLOW_SPEED. */
enum { FOLLOW_GAP_Q8 = 5 << 8, FOLLOW_SPEED_Q8 = 64 };

/* The profile as the tick sees it: beyond the multi-turn range (a wheel run
 * of many turns, a horn a load has turned back thousands of turns) a
 * position counts as +-2^30, which no horn within the range reaches
 * (3 686 400 x 256 < 2^30) and whose distance from the horn still fits
 * int32, with the right sign. */
#define TARGET_LIMIT_Q8 (1 << 30)

/* A wheel's endless_until: its clock restarts there (control_tick.c). */
enum { REBASE_TICKS = 1u << 24 };

/* A stream's period until the host's stamps tell: 50 Hz (stream.c). */
enum { STREAM_DEFAULT_PERIOD_MS = 20 };

/* The profile's clock (control_tick.c, "the profile's clock"). */
enum {
    LEAD_FREE_Q8 = 5 << 8, /* 0.5 degree */
    LEAD_SPAN_SHIFT = 3,   /* (lead - free) >> 3: 256 at 8 decideg */
    LEAD_FILTER_SHIFT = 2, /* time constant 4 ticks */
    CLOCK_SLOWING = 64,    /* the clock stops within 4 ticks */
    CLOCK_RECOVERY = 8,    /* a stopped clock is back to real time in 32 ticks */
};

static inline int32_t counts_to_q8(int32_t counts)
{
    return counts * DECIDEG_Q8_PER_COUNT;
}

static inline int64_t q8_to_q32(int32_t v)
{
    return (int64_t)v * ((int64_t)1 << 24);
}

/* Q32 to Q8 (decideg, or decideg per tick), saturated to +-TARGET_LIMIT. */
static inline int32_t q32_to_q8_sat_inline(int64_t v)
{
    int64_t q8 = v >> 24;
    return q8 > TARGET_LIMIT_Q8 ? TARGET_LIMIT_Q8 : q8 < -TARGET_LIMIT_Q8 ? -TARGET_LIMIT_Q8 : (int32_t)q8;
}
/* A call where size comes first (SERVO_SIZE_FIRST: the Cortex-M0):
 * setpoint.c. */
#ifdef SERVO_SIZE_FIRST
int32_t q32_to_q8_sat(int64_t v);
#else
#define q32_to_q8_sat q32_to_q8_sat_inline
#endif

static inline int32_t clamp_i32(int32_t v, int32_t lo, int32_t hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

/* The center offset (53), decideg Q8: protocol angles are measured minus this. */
static inline int32_t motion_center_offset_q8(const struct motion *m)
{
    return (int32_t)m->regs->user.center_offset_decideg * 256;
}

/* ---- setpoint.c ---- */
/* The tick's copies of the profile (Q8, saturated): at tick (at_tick, Q32),
 * at tick + 1 (where the walk is), the target, and the setpoint between
 * them at the clock's fraction. */
void motion_take_profile_q8(struct motion *m, int64_t at_tick);
/* Starts the profile's clock at its tick 0, in real time. */
void motion_clock_restart(struct motion *m);
/* The acceleration feed-forward of the walk's phase at the present ka,
 * from tick on. */
void motion_take_accel_duty(struct motion *m, uint32_t tick);

/* ---- position.c ---- */
/* Moves the origin by counts the way the angle grows: every position the
 * motion layer holds (horn, setpoint, profile) moves with it, so a move in
 * flight goes on unchanged. The encoder's count and the origin are kept
 * within a turn of each other's whole turns, so neither outgrows int32. */
void motion_move_origin(struct motion *m, int32_t counts);

/* ---- drive.c ---- */
/* The supply the limits are worked out for: the measured one, 7.4 V until
 * there is one. */
uint16_t motion_supply_mv(const struct motion *m);
/* The current limit and the supply-scaled gains for the running command's
 * power (power_mw) (divides: on changes only). */
void motion_update_limits(struct motion *m);
/* A command that takes the output over at once (a streamed setpoint,
 * DriveDuty): counted, the queue and a move's answer dropped, the limits
 * at the power item 42 allows (no move's own). */
void motion_take_over(struct motion *m);
/* The braking duty the output can count on moving in direction dir. */
int32_t motion_brake_duty(const struct motion *m, int32_t dir);
/* Lets the output go (released, turning freely); the command ends. */
void motion_coast(struct motion *m);

/* ---- planning.c ---- */
/* Runs a command now: its profile, or the mode it sets. */
void motion_run(struct motion *m, const struct motion_command *cmd);
/* The angle modes' top speed, 0.1 deg/s, and their shortest ramp, ms
 * (the schema's ranges: docs/protocol.md, "Moves"). */
enum {
    MAX_VELOCITY = FIELD_MOVE_ANGLE_BY_VELOCITY_TARGET_VELOCITY_MAX,
    MIN_RAMP_MS = FIELD_MOVE_ANGLE_BY_INTERVAL_ACC_INTERVAL_MIN,
};
/* The one clamp of every position target (planning.c): angle_decideg
 * (protocol frame) within +-range, then, where item 48 is at least from,
 * the angle limits (51, 52) in the frame whose zero is base (decideg); sets
 * angle_clamped. Q8 from the origin. */
int32_t motion_target_q8(struct motion *m, int32_t angle_decideg, int32_t range, int32_t base,
                         uint8_t from);
/* Item 48's values, the least from which a kind of target keeps to the
 * limits: 1 (the maker's "on") single-turn moves and streamed setpoints; 2
 * multi-turn moves too, which the maker's servo never limits (its limits
 * are of angle mode; its SDK moves a factory servo, limits on, to 720 deg). */
enum { LIMITS_ON = 1, LIMITS_ALL_TARGETS = 2 };
/* Starts following the profile just planned; then end (enum motion_end). */
void motion_begin_profile(struct motion *m, uint8_t end);

/* ---- command_queue.c ---- */
/* The running command has finished: answer, release or hold, next one. */
void motion_finish(struct motion *m);

#endif
