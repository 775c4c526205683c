/* Controller gains and limits, in one place, with their units.
 *
 * The controller works on position error e (decidegrees, Q8), planned
 * velocity v (decidegrees per tick, Q8) and measured velocity w (same), and
 * outputs a duty in Q15 (32767 = full supply). Each gain is "duty per unit
 * of its input"; a term is (input_q8 * GAIN) >> 8.
 *
 * Tuned on the reference plant (hal/ports/host/plant.c: 7.4 V, 2 ohm,
 * 200:1 gear, about 420 deg/s at full duty, no load). */
#ifndef MOTION_GAINS_H
#define MOTION_GAINS_H

/* Proportional: full duty at 6.0 degrees of error. */
#define GAIN_KP 546
/* Integral, per tick: removes the steady error a load leaves. */
#define GAIN_KI 4
/* Integral term bound, Q15 duty: a quarter of full. */
#define INTEGRAL_LIMIT_Q15 8192
/* Velocity feed-forward: the duty that holds the planned speed unloaded
 * (32767 at 4.2 decideg per tick). */
#define GAIN_KV 7800
/* Damping on measured velocity, applied while following a profile. */
#define GAIN_KD 2000
/* Damping mode (packet 9): braking duty per unit of measured velocity. */
#define GAIN_DAMPING 8000

/* Winding resistance for turning a power limit (mW) into a duty limit:
 * P = (d V)^2 / R, so d = sqrt(P R) / V. */
#define MOTOR_RESISTANCE_MOHM 2000u
/* Supply assumed until the first voltage reading. */
#define NOMINAL_SUPPLY_MV 7400u

#endif
