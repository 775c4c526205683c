/* The oscillation monitor (item 72, docs/safety.md): a horn that runs or
 * swings away from its setpoint is out of control whatever the cause (drive
 * items that do not match the motor, gains that make the loop unstable, a
 * loose encoder): the caller releases it and logs FAULT_OSCILLATION.
 *
 * Each tick under position control it counts the ticks the horn moves away
 * from its setpoint, more than OSCILLATION_AMPLITUDE_Q8 off it and faster
 * than STALL_SPEED_Q8; OSCILLATION_QUIET_TICKS in a row back within the
 * amplitude start the count again. It trips when the count reaches the
 * item's time (1 tick = 1 ms): a runaway within that time of passing the
 * amplitude, a swing when its outward halves add up to it. A load stronger
 * than the motor that turns the horn back while the output pushes back at
 * its limit is the stall monitor's (protection.h), not this one's. */
#ifndef PROTECTION_OSCILLATION_H
#define PROTECTION_OSCILLATION_H

#include <stdbool.h>
#include <stdint.h>

/* 10 deg, decideg Q8: above a move's overshoot on every shipped plant with
 * the factory gains (the 60 kg cm plant's 4-5 deg, docs/bring-up.md). */
#define OSCILLATION_AMPLITUDE_Q8 (100 << 8)
#define OSCILLATION_QUIET_TICKS 200u /* 200 ms */

struct oscillation_monitor {
    uint16_t away_ticks; /* ticks counted towards item 72's time */
    uint8_t quiet_ticks; /* ticks in a row within the amplitude */
    uint8_t fired;       /* released; the caller clears it at the next motion command */
    uint32_t commands_at_fire;
};

/* One tick under position control. error_q8: setpoint - horn, decideg Q8;
 * velocity_q8: the horn's, decideg per tick Q8; at_limit: the controller's
 * (+1/-1 the way the limit held it back); kv, duty_limit: struct
 * drive_limits' (the limit's band around the back-EMF); limit_ms: item 72,
 * not 0. True on the tick the count reaches limit_ms. */
bool oscillation_watch(struct oscillation_monitor *o, int32_t error_q8, int32_t velocity_q8,
                       int8_t at_limit, int32_t kv, int32_t duty_limit, uint16_t limit_ms);

#endif
