/* The controller's fixed constants, with their units. The gains and the
 * drive train's constants are data items 80-89 (protocol/servo_schema: their
 * factory values are the reference servo's, hal/ports/host/plants/
 * reference_st3215.toml), stored with the user area and turned into the
 * feed-forward when one changes (controller.c, drive_limits_for_supply).
 *
 * The controller works on position error e (decideg, Q8), planned velocity
 * v (decideg per tick, Q8) and measured velocity w (same), and outputs a
 * duty in Q15 (32767 = full supply). */
#ifndef MOTION_GAINS_H
#define MOTION_GAINS_H

/* No integrating within one encoder count (3600 / 4096 decideg, Q8). */
#define INTEGRAL_DEADBAND_Q8 225
/* Integral term bound, Q15 duty: full (-32768..32767, one SSAT on the
 * Cortex-M3), so a load near the stall torque at the lowest supply can be
 * held (anti-windup keeps it from running away). */
#define INTEGRAL_LIMIT_Q15 32768

/* Supply the feed-forward is worked out at until the first reading. */
#define NOMINAL_SUPPLY_MV 7400u
/* The supply-scaled feed-forward stops growing below this: nothing moves
 * there anyway, under any sane low-voltage limit (39). */
#define GAIN_MIN_SUPPLY_MV 2000u

#endif
