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
/* Integral term bound, Q15 duty: half of full. */
#define INTEGRAL_LIMIT_Q15 16384
/* Velocity feed-forward: the duty that holds the planned speed unloaded
 * (32767 at 4.2 decideg per tick); also the back-EMF duty of a speed, used
 * by the current limit. */
#define GAIN_KV 7800
/* Acceleration feed-forward, per decideg per tick^2 (Q16 input): the duty
 * whose current accelerates the reflected inertia (0.005 kg m^2). */
#define GAIN_KA 77400
/* Derivative, on velocity error (planned - measured): damps without
 * braking against the feed-forward. */
#define GAIN_KD 3000
/* Damping mode (packet 9): braking duty per unit of measured velocity. */
#define GAIN_DAMPING 8000

/* Winding resistance for turning a power limit (mW) into a current limit:
 * I = P / V, and a duty margin of I R / V = P R / V^2. */
#define MOTOR_RESISTANCE_MOHM 2000u
/* Supply assumed until the first voltage reading. */
#define NOMINAL_SUPPLY_MV 7400u

#endif
