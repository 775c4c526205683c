/* The motion layer: turns decoded motion commands into profiles, runs the
 * control loop every tick and answers for position and state. Units at this
 * interface are the protocol's (0.1 degree, ms, mW); docs/protocol.md, "Moves",
 * says what each command does. */
#ifndef MOTION_MOTION_H
#define MOTION_MOTION_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_port.h"
#include "motion/controller.h"
#include "motion/encoder.h"
#include "motion/profile.h"
#include "registers/registers.h"
#include "registers/field_ranges.h"
#include "hal/must_check.h"

/* What holds the output back at this instant (item 67, ReadMotion's
 * motion_flags bits 5-7), the first that applies in this order: the
 * watchdog has acted; a protection releases it (the supply, heat); the
 * controller is at its limit, and which limit that is; a target was
 * clamped to the angle limits. */
enum limiter {
    LIMITER_NONE = 0,
    LIMITER_POWER = 1,    /* the power limit (42, the move's power) */
    LIMITER_CURRENT = 2,  /* the current limit (43), or halved by over-current */
    LIMITER_STALL = 3,    /* the stall cap (38), or released by a stall (37 = 1) */
    LIMITER_SUPPLY = 4,   /* full duty (the supply's voltage), or out of range */
    LIMITER_HEAT = 5,     /* derated for heat, or released by over-temperature */
    LIMITER_ANGLE = 6,    /* the target was clamped to items 51 and 52 */
    LIMITER_WATCHDOG = 7, /* the bus watchdog acted (64, 65) */
    LIMITER_SHIFT = 5,    /* its place in ReadMotion's motion_flags */
};

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

/* Packet 7 method: direction | action. */
enum wheel_method {
    WHEEL_CLOCKWISE = 0x80, /* else counter-clockwise: increasing angle */
    WHEEL_STOP = 0x00,
    WHEEL_RUN = 0x01,
    WHEEL_TURNS = 0x02,
    WHEEL_TIME = 0x03,
};

/* Packet 24 method. */
enum stop_method {
    STOP_RELEASE = 0x10,
    STOP_HOLD = 0x11,
    STOP_DAMPING = 0x12,
};

/* One motion request as it arrived, fields not yet clamped. */
struct motion_command {
    uint8_t packet;           /* request packet number, for the finish answer */
    uint8_t kind;             /* enum motion_kind */
    uint8_t profile;          /* enum motion_profile */
    uint8_t multi_turn;       /* packets 13-15 */
    uint8_t answer_when_done; /* control response on, sent to this servo alone */
    uint8_t method;           /* enum wheel_method or enum stop_method */
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
    MOTION_QUEUE_FULL, /* the queue (control response on) or async buffer is full */
    MOTION_REFUSED,    /* a protection inhibits motion (voltage, temperature) */
};

struct motion_angle {
    int32_t multi_turn_decideg;  /* ReadMultiTurnAngle / Monitor angle */
    int16_t turns;               /* whole turns in multi_turn_decideg */
    int16_t single_turn_decideg; /* ReadAngle: -1800..1799 */
};

/* Motion commands waiting with control response on, run one after another. */
#define MOTION_QUEUE_DEPTH 8u
/* Commands buffered between BeginAsync and EndAsync. */
#define MOTION_ASYNC_DEPTH 8u
/* Finish answers not yet sent. */
#define MOTION_ANSWERS_DEPTH 4u

/* A BeginAsync block: open, it buffers commands; cut short by motion_stop
 * (the bus watchdog), it refuses them until the next BeginAsync or
 * EndAsync. */
enum async_block {
    ASYNC_NONE,
    ASYNC_OPEN,
    ASYNC_CUT,
};

/* Released and damping first: motion_is_released() is one comparison. */
enum motion_mode {
    MODE_RELEASED,  /* output off, turns freely */
    MODE_DAMPING,   /* braking in proportion to speed (packet 9): never drives */
    MODE_POSITION,  /* following a profile, then holding its end */
    MODE_OPEN_LOOP, /* DriveDuty: damping's tick with open_duty in place of the brake */
};

/* What the servo does once a profile has run out. */
enum motion_end {
    END_HOLD,
    END_RELEASE,
};

struct motion_queue {
    struct motion_command slots[MOTION_QUEUE_DEPTH];
    uint8_t head;
    uint8_t count;
};

/* What the drive limits were last worked out for (the supply: within
 * SUPPLY_HYSTERESIS_MV of the measured one). */
struct drive_inputs {
    uint16_t power_mw;
    uint16_t supply_mv;
    uint16_t current_limit_ma;
    uint8_t derate;
};

struct motion {
    const struct registers *regs;
    const struct hal_port *hal;
    /* Where a byte's offset is small, the M0 loads it in one instruction. */
    uint8_t async_open;        /* enum async_block */
    uint8_t inhibit;           /* set by the protection monitors (motion_guard) */
    uint8_t mode;              /* enum motion_mode */
    uint8_t braking;           /* the profile is the braking guard's: left alone */
    uint8_t answers_count;     /* finished moves owed an answer (answers) */
    uint8_t endless;           /* wheel run, stream: finished once at speed */
    uint8_t end;               /* enum motion_end */
    uint8_t drive_limiter;     /* enum limiter: what sets the duty limit */
    uint8_t streaming;         /* a stream runs: 1 after its first setpoint, 2 after more */
    uint8_t angle_clamped;     /* the running move's target was clamped (51, 52) */
    uint8_t running;           /* a command runs: status bit 0 */
    struct encoder_track encoder;
    int32_t origin_counts;     /* encoder counts of angle 0 (before offset 53) */
    /* The tick works in Q8 decidegrees (int32): the multi-turn range, +-3 686 400
     * decideg x 256, and a target saturated to +-2^30 stay within int32 in
     * every difference the tick takes. The profile itself is planned in Q32. */
    int32_t measured_q8;       /* the horn, relative to the origin */
    int32_t measured_velocity_q8; /* tracked, decideg per tick */
    int32_t track_residual_q12; /* tracked position less the encoder's, decideg Q12 */
    int32_t track_velocity_q12;
    struct profile profile;
    /* The profile's own clock: whole ticks and a Q8 fraction. It runs at
     * clock_rate (Q8, 256 = real time) and slows while the horn cannot
     * follow, so the setpoint never runs away from the horn. */
    uint32_t tick;
    uint16_t tick_frac;
    uint16_t clock_rate;
    int32_t lead_q8;           /* setpoint ahead of the horn, low-passed, decideg Q8 */
    int32_t profile_at_tick_q8;      /* profile position at tick */
    int32_t profile_at_next_tick_q8; /* and at tick + 1 */
    int32_t setpoint_q8;
    int32_t last_setpoint_q8;
    int32_t target_q8;         /* the profile's target, saturated to +-TARGET_LIMIT_Q8 */
    struct profile_walk walk;  /* the profile walked to tick + 1 */
    /* The acceleration feed-forward, as a duty: the profile's second
     * difference over the last three setpoints, which is the walk's phase
     * two ticks after the walk enters it (accel_from), which equals the
     * closed form's second difference. Worked out when a phase begins or the
     * limits change. */
    int32_t accel_duty;
    int32_t accel_duty_next;
    uint32_t accel_from;       /* the tick accel_duty_next takes over */
    struct controller controller;
    struct drive_limits drive; /* current margin (power, 43, protection), kv, ka */
    int32_t brake_floor_duty;  /* the least braking duty a load leaves (motion_brake_duty) */
    struct drive_inputs drive_inputs;
    uint8_t cap_limiter;       /* enum limiter: whose power_cap_mw it is */
    uint16_t power_mw;         /* the running command's power, 0 = 42's value */
    /* An endless profile is looked at again at this tick: a wheel's clock
     * restarts, a stream whose next setpoint has not come brakes. */
    uint32_t endless_until;
    uint16_t stream_host_ms;   /* the host's stamp of the last setpoint */
    uint16_t stream_period_q4; /* learned from the stamps, ms Q4 */
    uint16_t stream_clock_ms;  /* the servo's clock, a tick a ms (stream.c) */
    uint32_t stream_offset_q16; /* the servo's clock less the host's, followed, ms Q16 */
    uint8_t answer_packet;     /* owed when the running command finishes */
    uint8_t soft_start_pending;
    struct motion_queue queue;
    struct motion_queue async;
    uint8_t answers[MOTION_ANSWERS_DEPTH];
    /* Set by the protection monitors (motion_guard). */
    uint8_t derate;
    uint16_t power_cap_mw;
    uint32_t commands;         /* motion commands received */
    uint32_t runaway_ticks;    /* motion_runs_away's count: 2 a tick away, -1 a tick near */
    /* Open loop (DriveDuty, MODE_OPEN_LOOP): this duty instead of the
     * brake, for open_ticks more ticks. */
    int16_t open_duty_q15;
    uint16_t open_ticks;
    int16_t damping_duty_q15;  /* what damping or open loop gave the bridge last; 0 in other modes */
};

/* Reads the encoder and takes the power-on state (46). regs and hal must
 * outlive m; the user area in regs is read live (limits, offset, ...). */
void motion_init(struct motion *m, const struct registers *regs, const struct hal_port *hal);
/* One control tick (1/MOTION_TICK_HZ s): encoder, profile, controller, motor. */
void motion_tick(struct motion *m);

MUST_CHECK enum motion_submit_result motion_submit(struct motion *m, const struct motion_command *cmd);

/* A streamed setpoint (StreamSetpoint, 0x45): where the horn should be, how
 * fast it should move there, and the host's time it is for. */
struct motion_setpoint {
    int32_t angle_decideg;      /* multi-turn, as ReadMultiTurnAngle */
    int16_t velocity_decideg_s;
    uint16_t host_ms;           /* wraps; its steps are the host's period */
};

/* Interpolates from where the setpoint is to sp in one period (item 69, or
 * learned from the stamps): a cubic at the tick rate, then on at sp's
 * speed; a period late, it brakes to a hold. It takes over from any
 * command, and drops what is queued (docs/streaming.md). */
MUST_CHECK enum motion_submit_result motion_stream(struct motion *m, const struct motion_setpoint *sp);
/* Open loop (DriveDuty, 0x46): the bridge at duty_q15 (of the supply) for
 * ms (1..MOTION_OPEN_LOOP_MAX_MS), then released. The output's current
 * limit and the protections hold it; the angle limits do not. Refused
 * while the protections hold the output. */
#define MOTION_OPEN_LOOP_MAX_MS FIELD_DRIVE_DUTY_TIME_MAX
_Static_assert(FIELD_DRIVE_DUTY_TIME_MIN == 1u, "DriveDuty refuses a time of 0 only");
MUST_CHECK enum motion_submit_result motion_drive_duty(struct motion *m, int16_t duty_q15, uint16_t ms);
/* Nothing drives the output: released, or damping (a brake that only
 * resists motion). Under position control or an applied duty (DriveDuty)
 * it is driven: the bus watchdog watches it, the origin stays put
 * (docs/safety.md). */
static inline bool motion_is_released(const struct motion *m)
{
    return m->mode <= MODE_DAMPING;
}
void motion_read_angle(const struct motion *m, struct motion_angle *out);
/* ResetMultiTurnAngle (17), SetOriginPoint (23): false unless released. */
bool motion_reset_multi_turn(struct motion *m);

/* One instant of the motion state, for tuning (ReadMotion, 0x40). Angles in
 * 0.1 deg in the frame of ReadMultiTurnAngle. */
struct motion_diagnostics {
    int32_t angle_decideg;           /* the horn */
    int32_t setpoint_decideg;        /* where the profile puts it now */
    int32_t target_decideg;          /* where the profile ends */
    int16_t velocity_decideg_s;      /* the horn's speed, measured */
    int16_t tracking_error_centideg; /* setpoint - horn, 0.01 deg, saturated */
    uint8_t flags;                   /* enum motion_diagnostic_flag */
    int16_t duty_q15;                /* damping or open loop's duty; 0 otherwise */
};

enum motion_diagnostic_flag {
    DIAG_PROFILE_ENDED = 1u << 0, /* the setpoint is at the target */
    DIAG_CLOCK_SLOWED = 1u << 1,  /* the horn cannot follow: the move runs late */
    DIAG_BRAKING = 1u << 2,       /* braking within the output's limit */
    DIAG_AT_LIMIT = 1u << 3,      /* the output is at its current or supply limit */
    DIAG_RELEASED = 1u << 4,      /* motion_is_released(): nothing drives the output */
    /* bits 5-7: motion_limiter() (LIMITER_SHIFT) */
};

void motion_read_diagnostics(const struct motion *m, struct motion_diagnostics *out);
bool motion_set_origin(struct motion *m);
void motion_begin_async(struct motion *m);
void motion_end_async(struct motion *m, bool cancel);
/* A finished move is owed an answer. */
static inline bool motion_has_finished(const struct motion *m)
{
    return m->answers_count != 0u;
}
/* Packet number of a finished move that must be answered, 0 if none. */
uint8_t motion_take_finished(struct motion *m);
/* True while a motion command runs (status bit 0). */
static inline bool motion_is_executing(const struct motion *m)
{
    return m->running != 0u;
}

/* A move runs, or the wheel turns on (its command finished at speed). */
static inline bool motion_is_moving(const struct motion *m)
{
    return m->running != 0u || m->endless != 0u;
}

/* Released, nothing running, queued or buffered: letting go of the output
 * (a restart) changes nothing. */
bool motion_is_idle(const struct motion *m);

/* What the protection monitors require of the output: inhibit releases it
 * and refuses motion until lifted; derate halves the current it may draw;
 * power_cap_mw (0 = none) bounds every move's power, and cap_limiter (enum
 * limiter) says whose cap it is. */
void motion_guard(struct motion *m, bool inhibit, bool derate, uint16_t power_cap_mw,
                  uint8_t cap_limiter);
/* Stops now as StopOnControlMode's method does (enum stop_method), dropping
 * what is queued or buffered and cutting an open BeginAsync block short;
 * no answer is owed and no command counted (the bus watchdog, a late
 * stream). */
void motion_stop(struct motion *m, uint8_t method);
/* The oscillation monitor's detector (drive.c), once a control tick: true
 * once the ticks the horn has moved away from its setpoint, beyond
 * RUNAWAY_AMPLITUDE_Q8 and faster than a creep, less half those it has been
 * back within the amplitude, reach limit_ms (not 0). */
#define RUNAWAY_AMPLITUDE_Q8 (100 << 8) /* 10 deg: above a move's overshoot on every shipped plant */
#define RUNAWAY_CREEP_Q8 13             /* 5 deg/s, decideg per tick Q8: the stall monitor's */
bool motion_runs_away(struct motion *m, uint16_t limit_ms);
/* What holds the output back at this tick (enum limiter, item 67): a
 * protection or the watchdog (the registers' held_by), else the limit the
 * controller is at, else a clamped target, else none. */
/* The motion's own part, under position control: the limit the controller
 * is at, else a clamped target, else none. */
static inline uint8_t motion_own_limiter(const struct motion *m)
{
    return m->controller.at_limit != 0 ? m->drive_limiter
                                       : (uint8_t)(m->angle_clamped ? LIMITER_ANGLE : LIMITER_NONE);
}

static inline uint8_t motion_limiter(const struct motion *m)
{
    uint8_t held = m->regs->held_by;
    if (held != 0u || m->mode != MODE_POSITION) {
        return held;
    }
    return motion_own_limiter(m);
}
/* The encoder's raw count now, 0-4095 (item 71). */
static inline uint16_t motion_encoder_count(const struct motion *m)
{
    return m->encoder.last;
}
/* Releases the output now (a stall in release mode). */
void motion_release(struct motion *m);
/* A drive item (80-91) was written: the gains and feed-forward follow. */
void motion_drive_train_changed(struct motion *m);
/* The controller's output was held back by its limit on the last tick:
 * the way it wanted to drive (+1/-1), else 0. Every tick asks: inline. */
static inline int8_t motion_output_at_limit(const struct motion *m)
{
    return m->mode == MODE_POSITION ? m->controller.at_limit : 0;
}

#endif
