/* Controller gains and the drive train's constants, in one place, with
 * their units.
 *
 * The controller works on position error e (decidegrees, Q8), planned
 * velocity v (decidegrees per tick, Q8) and measured velocity w (same), and
 * outputs a duty in Q15 (32767 = full supply). Each gain is "duty per unit
 * of its input"; a term is (input_q8 * GAIN) >> 8.
 *
 * The drive-train constants are the reference servo's (hal/ports/host/
 * plant.c says where each number comes from): a 20 kg cm class servo, 7.4 V,
 * 2.741 ohm, kt 3.714 mN m/A, 1:345, rotor 1 g cm^2, 312 deg/s unloaded. */
#ifndef MOTION_GAINS_H
#define MOTION_GAINS_H

/* Proportional: full duty at 6.0 degrees of error. */
#define GAIN_KP 546
/* Integral, per tick: removes the steady error a load leaves. */
#define GAIN_KI 8
/* No integrating within one encoder count (3600 / 4096 decideg, Q8). */
#define INTEGRAL_DEADBAND_Q8 225
/* Integral term bound, Q15 duty: full, so a load near the stall torque at
 * the lowest supply can be held (anti-windup keeps it from running away). */
#define INTEGRAL_LIMIT_Q15 32767
/* Velocity feed-forward at the nominal supply: the back-EMF duty of a speed,
 * kt x 345 x (100 deg/s in rad/s) / 7.4 V = 0.3022 -> 9902 per decideg per
 * tick. The current limit works around the same duty. Scaled by
 * nominal / measured supply (motion.c). */
#define GAIN_KV 9902
/* Acceleration feed-forward at the nominal supply, per decideg per tick^2
 * (Q16 input): the duty whose current accelerates the rotor, 1 g cm^2 x
 * 345 x 1745 rad/s^2 / kt x R / 7.4 V = 6.005 -> 196770. */
#define GAIN_KA 196770
/* Friction feed-forward at the nominal supply, in the planned direction:
 * the duty whose current carries the motor's Coulomb drag, 0.279 mN m / kt
 * x R / 7.4 V = 0.0278 -> 911. */
#define GAIN_FRICTION 911
/* Viscous drag feed-forward at the nominal supply, per decideg per tick:
 * 0.148 uN m s/rad x 345 x 1.745 rad/s / kt x R / 7.4 V = 0.0089 -> 291.
 * Apart from GAIN_KV, which is the back-EMF alone (the current limit). */
#define GAIN_VISCOUS 291
/* Derivative, on velocity error (planned - measured): damps without
 * braking against the feed-forward. */
#define GAIN_KD 3000
/* Damping mode (packet 9): braking duty per unit of measured velocity. */
#define GAIN_DAMPING 8000

/* Winding plus bridge resistance for turning a power limit (mW) into a
 * current limit: I = P / V, and a duty margin of I R / V = P R / V^2. */
#define MOTOR_RESISTANCE_MOHM 2741u
/* Supply the gains are given at, and assumed until the first reading. */
#define NOMINAL_SUPPLY_MV 7400u
/* The supply-scaled gains stop growing below this (kv, the largest, stays
 * below 2^16 so the controller's products fit int32): nothing moves there
 * anyway, under any sane low-voltage limit (39). */
#define GAIN_MIN_SUPPLY_MV 2000u

#endif
