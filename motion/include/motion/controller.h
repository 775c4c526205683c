/* Position/velocity controller: PI on position error, D on velocity error,
 * feed-forward of the planned velocity and acceleration;
 * output a Q15 duty kept within the running command's power. The gains and
 * the drive train are data items 80-89 (struct user_config's drive area), turned into
 * struct drive_limits when one of them or the supply changes.
 *
 * All in int32: each input is saturated to a power of two (one SSAT on the
 * Cortex-M3) that keeps its product with the gain within 31 bits, well
 * beyond where the output saturates anyway.
 *
 * The power limit is a current limit, |I| <= P / V: the winding current is
 * (V d - back-EMF) / R, so the duty may stray from the back-EMF duty of the
 * present speed by at most P R / V^2 either way. */
#ifndef MOTION_CONTROLLER_H
#define MOTION_CONTROLLER_H

#include <stdbool.h>
#include <stdint.h>

#include "registers/registers.h"

struct controller {
    int32_t integral_q15;
    int8_t at_limit; /* the last output was held back by the limit: the way
                      * it wanted to go (+1/-1), else 0 */
};

/* What the drive can do at the present supply, worked out when the supply,
 * the limit or the drive train changes (it divides), used every tick. Every
 * duty is Q15 (32767 = the supply); a gain's input is Q8 unless it says. */
struct drive_limits {
    int32_t kv;         /* back-EMF duty per decideg per tick, Q8 input */
    int32_t ka;         /* duty per decideg per tick^2, Q16 input */
    int32_t friction;   /* duty that carries the Coulomb drag */
    int32_t viscous;    /* and the viscous drag, per decideg per tick */
    /* Items 86-89 as they are in struct user_config (one copy). */
    uint16_t kp;        /* duty per decideg of error */
    uint16_t ki;        /* duty per decideg of error, each tick */
    uint16_t kd;        /* duty per decideg per tick of velocity error */
    uint16_t damping;   /* damping mode's duty per decideg per tick */
    uint8_t reversed;   /* item 82 negative: the bridge is driven the other way */
    int16_t duty_limit; /* Q15 duty of the current limit, 0..32767 */
};

struct controller_input {
    int32_t error_q8;             /* setpoint - measured, decideg Q8 */
    int32_t velocity_q8;          /* planned velocity, decideg per tick Q8 */
    int32_t acceleration_duty;    /* the planned acceleration's feed-forward, duty */
    int32_t measured_velocity_q8; /* decideg per tick Q8 */
    int8_t push;                  /* +1/-1: drive at the limit that way (the
                                   * motor is the bottleneck); 0: control */
};

void controller_reset(struct controller *c);
int16_t controller_position(struct controller *c, const struct controller_input *in,
                            const struct drive_limits *lim);
/* Damping mode: a braking duty proportional to the measured velocity, or
 * (open_duty_q15 not 0) that duty, open loop; within the limits either way. */
int16_t controller_damping(int32_t measured_velocity_q8, int16_t open_duty_q15, const struct drive_limits *lim);
/* Keeps duty within the duty limit of the back-EMF duty at this speed. */
int16_t controller_limit(int32_t duty, int32_t measured_velocity_q8, const struct drive_limits *lim);
/* The gains, and kv, ka and the drag of the drive train dt at supply_mv (not
 * 0: motion_supply_mv; below GAIN_MIN_SUPPLY_MV, that). Planning-time: it
 * divides. */
void drive_limits_for_supply(struct drive_limits *lim, const struct user_config *dt,
                             uint16_t supply_mv);
/* Items 80-89 as dt has them make a loop the controller can hold (the
 * rules: controller.c). Planning-time: it divides. */
bool drive_items_stable(const struct user_config *dt);
/* The duty that drives the current limit P / V through the winding (of
 * resistance r_mohm) at standstill: P R / V^2, Q15; supply_mv not 0.
 * Planning-time: it divides. */
int16_t duty_limit_for_power(uint16_t power_mw, uint16_t supply_mv, uint16_t r_mohm);
/* The duty that drives current_ma through the winding at standstill:
 * I R / V, Q15; supply_mv not 0. Planning-time: it divides. */
int16_t duty_limit_for_current(uint16_t current_ma, uint16_t supply_mv, uint16_t r_mohm);

#endif
