/* Trapezoidal motion profile in fixed point.
 *
 * Units: time in control ticks (MOTION_TICK_HZ); positions in Q32
 * decidegrees (int64, 1 decideg = 2^32); velocities in Q32 decidegrees per
 * tick; the two ramp coefficients in Q40 decidegrees per tick squared; a
 * streamed segment's cubic coefficient in Q40 decidegrees per tick cubed.
 *
 * A profile has three phases of whole ticks: acceleration (N1 ticks, from the
 * start velocity v0 to the cruise velocity V), cruise (Nc) and deceleration
 * (N3, from V to rest at the target). V follows from the phase lengths so the
 * move covers exactly target - start:
 *     V = (2 D - v0 N1) / (N1 + 2 Nc + N3)
 * Planning uses 64-bit division; evaluating a tick uses two multiplies and
 * shifts, no division. The last tick's setpoint is the target exactly. */
#ifndef MOTION_PROFILE_H
#define MOTION_PROFILE_H

#include <stdbool.h>
#include <stdint.h>

#define MOTION_TICK_HZ 1000u
/* 1 decidegree in the Q32 position format. */
#define DECIDEG_Q32 ((int64_t)1 << 32)
/* Fastest setpoint the planner makes, 16384 decideg per tick (1 638 400
 * deg/s, far beyond any servo): a move that would need more takes longer. It
 * keeps every product of planning and evaluation within int64. */
#define PROFILE_MAX_VELOCITY ((int64_t)16384 << 32)
/* Longest cruise, in ticks (24.8 days). */
#define PROFILE_MAX_CRUISE 0x7FFFFFFFu
/* Longest ramp, in ticks (the protocol's u16 ms). */
#define PROFILE_MAX_RAMP 65535u

/* The Cortex-M0 image (SERVO_SIZE_FIRST) has no room for smoothing: its
 * profiles are trapezoids, and the code that walks a window folds away,
 * and so do its fields (struct profile): the motion state's hot fields sit
 * 36 bytes nearer its start, where the M0 reaches them in one instruction. */
#ifdef SERVO_SIZE_FIRST
#define PROFILE_SMOOTHING 0
#else
#define PROFILE_SMOOTHING 1
#endif

struct profile {
    int64_t start;        /* position at tick 0 */
    int64_t target;       /* position from total_ticks on */
    int64_t v0;           /* velocity at tick 0 */
    int64_t cruise;       /* V */
    int64_t accel_k;      /* (V - v0) / (2 N1), Q40 */
    int64_t accel_j;      /* the first phase's cubic term, Q40: a streamed segment's (else 0) */
    int64_t decel_k;      /* V / (2 N3), Q40 */
    uint32_t accel_ticks; /* N1 */
    uint32_t cruise_end;  /* N1 + Nc */
    uint32_t total_ticks; /* N1 + Nc + N3; UINT32_MAX cruises for ever */
#if PROFILE_SMOOTHING
    uint32_t smooth_ticks; /* T: the window the trapezoid is averaged over; 0: none */
    /* A jerk-limited move (profile_smooth): each phase's second
     * difference / T and its sixth, Q40 per tick cubed; 0 before the
     * start, in the cruise and after the end. */
    int64_t smooth_jerk[2][2]; /* [accel, decel][jerk, jerk / 6] */
#endif
};

/* Phase lengths in ticks. */
struct profile_timing {
    uint32_t accel;
    uint32_t cruise;
    uint32_t decel;
};

/* A move from start (moving at v0) to target with the given phase lengths.
 * accel and decel must not exceed PROFILE_MAX_RAMP. If the cruise velocity
 * would exceed PROFILE_MAX_VELOCITY, the cruise is lengthened. */
void profile_plan(struct profile *p, int64_t start, int64_t v0, int64_t target,
                  struct profile_timing timing);

/* Accelerate from v0 to velocity over accel ticks, then cruise for ever
 * (wheel mode). */
void profile_plan_endless(struct profile *p, int64_t start, int64_t v0, int64_t velocity,
                          uint32_t accel);

/* A streamed segment: the cubic (Hermite) from start moving at v0 to
 * target moving at v1 in ticks ticks, then on at v1 for ever (v1 = 0: the
 * profile ends there, as a move's does). Positions
 * and speeds in the control tick's Q8 (decideg, decideg per tick), within
 * PROFILE_MAX_SEGMENT_DISTANCE of each other and PROFILE_MAX_SEGMENT_SPEED;
 * 1 <= ticks <= PROFILE_MAX_SEGMENT. */
#define PROFILE_MAX_SEGMENT 1000u
#define PROFILE_MAX_SEGMENT_DISTANCE (1 << 22) /* 16384 decideg */
#define PROFILE_MAX_SEGMENT_SPEED (1 << 16)    /* 256 decideg per tick */
void profile_plan_segment(struct profile *p, int32_t start_q8, int32_t v0_q8, int32_t target_q8,
                          int32_t v1_q8, uint32_t ticks);

/* Phase lengths of a velocity-based move (packets 12, 15): peak |velocity|
 * vmax, ramps of accel and decel ticks. The cruise time is rounded to whole
 * ticks; a stroke too short for a cruise shrinks both ramps in their ratio
 * (each rounded down) and keeps the total within a tick of the exact one. distance and v0 in Q32, vmax in Q32 per tick (> 0). */
struct profile_timing profile_velocity_timing(int64_t distance, int64_t v0, int64_t vmax,
                                              uint32_t accel, uint32_t decel);

/* Jerk-limited (S-curve) moves: the trapezoid averaged over a window of T
 * ticks. The average of a trapezoid is C2 and piecewise cubic: each ramp
 * gains jerk phases of T ticks on either side and the move takes T ticks
 * longer; the acceleration never exceeds the trapezoid's, and the
 * trapezoid's phases (its short-stroke rescaling) are unchanged. The
 * window's jerk is the change of the trapezoid's acceleration across it,
 * / T. A trapezoid moving at v0 from start is planned from
 * start + v0 T / 2 (profile_smooth_shift) so that its average starts at
 * start, moving at v0. */
#define PROFILE_MAX_SMOOTH 4096u /* T's ceiling: 4.1 s */

/* T of p (0 where there is no smoothing). */
static inline uint32_t profile_window(const struct profile *p)
{
#if PROFILE_SMOOTHING
    return p->smooth_ticks;
#else
    (void)p;
    return 0u;
#endif
}

/* T for a jerk limit in Q24 decideg per tick cubed (> 0): the least that
 * keeps every jump of the trapezoid's acceleration across a window within
 * it, or PROFILE_MAX_SMOOTH; 0 for a move without acceleration. */
uint32_t profile_smooth_ticks(const struct profile *p, uint32_t jerk_q24);

/* Averages p over smooth_ticks ticks (0: leaves the trapezoid). */
void profile_smooth(struct profile *p, uint32_t smooth_ticks);

/* What planning adds to a start moving at v0 for a window of T ticks. */
static inline int64_t profile_smooth_shift(int64_t v0, uint32_t smooth_ticks)
{
    return (v0 * (int64_t)smooth_ticks) >> 1;
}

/* Where the move starts (tick 0). */
static inline int64_t profile_origin(const struct profile *p)
{
    uint32_t window = profile_window(p);
    return window != 0u ? p->start - profile_smooth_shift(p->v0, window) : p->start;
}

/* A profile walked tick by tick with additions only, for the control tick:
 * within a phase the step between two ticks changes by a constant (a
 * segment's cubic: the change changes by a constant) (Q40, so exact); each
 * phase starts from the position the last one reached, and the end is the
 * target exactly. The walk stays within two Q32 units a tick of the closed
 * form (tests/support/profile_closed_form.c) and that form's own rounding
 * where its phases meet (test_profile.c). */
struct profile_walk {
    int64_t at;         /* position at tick, Q32 */
    int64_t step_q40;   /* to the position at tick + 1 (less rounding), Q40 */
    int64_t change_q40; /* of step_q40 a tick: the phase's second difference */
    int64_t jerk_q40;   /* of change_q40 a tick: a cubic phase's third difference */
    int64_t jerk6_q40;  /* a smoothed move's jerk / 6, as profile_smooth rounds it */
    uint32_t tick;
    uint32_t phase_end; /* the tick the next phase starts */
};

/* Starts a walk at tick (also where a phase starts). A smoothed move's
 * phases are its window's: where both its ends lie in one phase of the
 * trapezoid, the walk is that phase's, half a window late; where they lie
 * in two, the walk goes on with the jerk changed (the average is C2). */
void profile_walk_start(struct profile_walk *w, const struct profile *p, uint32_t tick);

/* Starts a walk at tick 1, from tick 0 at profile_origin. */
void profile_walk_begin(struct profile_walk *w, const struct profile *p);

/* Moves the walk on a tick; true when a phase started. Where size comes
 * first (SERVO_SIZE_FIRST: the Cortex-M0) a call, profile.c. */
#ifdef SERVO_SIZE_FIRST
bool profile_walk_next(struct profile_walk *w, const struct profile *p);
#else
#define profile_walk_next profile_walk_next_inline
#endif
static inline bool profile_walk_next_inline(struct profile_walk *w, const struct profile *p)
{
    w->at += w->step_q40 >> 8;
    w->step_q40 += w->change_q40;
    w->change_q40 += w->jerk_q40;
    if (++w->tick < w->phase_end) {
        return false;
    }
    profile_walk_start(w, p, w->tick);
    return true;
}

static inline bool profile_done(const struct profile *p, uint32_t tick)
{
    /* A smoothed move is finite: no wrap. */
    return tick >= p->total_ticks + profile_window(p);
}

#endif
