/* Position/velocity controller: PI on position error, feed-forward of the
 * planned velocity, damping on the measured one; output a Q15 duty bounded
 * by the running command's power. Gains: motion/gains.h. */
#ifndef MOTION_CONTROLLER_H
#define MOTION_CONTROLLER_H

#include <stdint.h>

struct controller {
    int32_t integral_q15;
};

struct controller_input {
    int32_t error_q8;             /* setpoint - measured, decideg Q8 */
    int32_t velocity_q8;          /* planned velocity, decideg per tick Q8 */
    int32_t measured_velocity_q8; /* decideg per tick Q8 */
    int16_t duty_limit;           /* Q15, 0..32767 */
};

void controller_reset(struct controller *c);
int16_t controller_position(struct controller *c, const struct controller_input *in);
/* Damping mode: a braking duty proportional to the measured velocity. */
int16_t controller_damping(int32_t measured_velocity_q8, int16_t duty_limit);
/* The duty at which the winding dissipates power_mw from supply_mv at
 * stall: d = sqrt(P R) / V, Q15. */
int16_t duty_limit_for_power(uint16_t power_mw, uint16_t supply_mv);

#endif
