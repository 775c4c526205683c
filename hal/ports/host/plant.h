/* Physical model of the servo's drive train for the host port and tests:
 * a brushed DC motor behind a spur gearbox, driven by a PWM H-bridge, read
 * through a 12-bit absolute encoder on the output. Host code: double
 * precision is fine here; none of this runs on the MCU.
 *
 * What it models, because a real servo fails that way:
 * - the winding current (V d - back-EMF) / R, so speed and torque both
 *   saturate at the supply;
 * - gear losses that grow with the transmitted torque (efficiency), so a
 *   load back-drives the output only through the gearbox's losses;
 * - the bridge's body diodes: released, the motor turns into a generator
 *   once its back-EMF exceeds the supply plus two diode drops, which brakes
 *   a back-driven output hard;
 * - motor drag (the no-load current), Coulomb and viscous;
 * - the gears' play (backlash): the output, on the far side of the
 *   encoder, stays put while the gears cross it, unless a load holds it
 *   against one flank; its own inertia is neglected there;
 * - a hard stop, and an external load torque.
 * The parameters and where each number comes from: plant.c. */
#ifndef HOST_PLANT_H
#define HOST_PLANT_H

#include <stdbool.h>
#include <stdint.h>

struct plant_params {
    double supply_v;        /* bridge supply */
    double resistance_ohm;  /* winding plus bridge */
    double kt;              /* torque constant = back-EMF constant, motor side, N m/A, V s/rad */
    double gear_ratio;      /* motor turns per output turn */
    double efficiency;      /* gearbox, each way */
    double rotor_inertia;   /* motor side, kg m^2 (the horn's is negligible beside it x ratio^2) */
    double drag_coulomb;    /* motor side, N m */
    double drag_viscous;    /* motor side, N m s/rad */
    double diode_v;         /* one body diode's forward drop */
    double backlash_deg;    /* the gears' play at the output, degrees (0: none) */
};

struct plant {
    struct plant_params p;
    double angle;        /* output, rad, multi-turn, counter-clockwise positive */
    double velocity;     /* gears at the output, rad/s: the output's, but in the play */
    double play;         /* gears ahead of the output, rad, within +-backlash/2 */
    double current;      /* winding, A (negative: braking, or regenerating released) */
    double duty;         /* -1..1 */
    bool coast;          /* bridge off */
    double load_torque;  /* external, at the output, N m, opposing positive motion if positive */
    double payload_inertia; /* on the horn, kg m^2 (added to the output's) */
    bool has_stop;       /* a hard stop at stop_angle, from below */
    double stop_angle;
};

/* The reference servo: a 20 kg cm class bus servo at 7.4 V. */
void plant_init(struct plant *pl);
void plant_drive(struct plant *pl, int16_t duty_q15);
void plant_coast(struct plant *pl);
/* Advances the model by dt seconds (internally in steps of at most 50 us). */
void plant_step(struct plant *pl, double dt);
uint16_t plant_encoder(const struct plant *pl);
double plant_angle_deg(const struct plant *pl);

/* Figures of the parameters, at the output: stall torque (N m) at duty 1
 * and the present supply; no-load speed (rad/s); inertia (kg m^2, the
 * payload's included). */
double plant_stall_torque(const struct plant *pl);
double plant_no_load_speed(const struct plant *pl);
double plant_output_inertia(const struct plant *pl);

#endif
