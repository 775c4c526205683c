/* Physical model of the servo's drive train for the host port and tests:
 * a DC motor behind a gearbox, driven by a PWM duty, with viscous and
 * Coulomb friction, back-EMF, an external load and an optional hard stop,
 * read through a 12-bit absolute encoder on the output. Host code: double
 * precision is fine here; none of this runs on the MCU. */
#ifndef HOST_PLANT_H
#define HOST_PLANT_H

#include <stdbool.h>
#include <stdint.h>

struct plant_params {
    double supply_v;        /* bridge supply */
    double resistance_ohm;  /* winding */
    double kt;              /* torque constant = back-EMF constant, motor side, N m/A */
    double gear_ratio;      /* motor turns per output turn */
    double inertia;         /* at the output, kg m^2 (rotor reflected + horn) */
    double viscous;         /* at the output, N m s/rad */
    double coulomb;         /* at the output, N m */
};

struct plant {
    struct plant_params p;
    double angle;        /* output, rad, multi-turn, counter-clockwise positive */
    double velocity;     /* output, rad/s */
    double current;      /* winding, A */
    double duty;         /* -1..1 */
    bool coast;          /* bridge off */
    double load_torque;  /* external, N m, opposing positive motion if positive */
    bool has_stop;       /* a hard stop at stop_angle, from below */
    double stop_angle;
};

/* The reference servo the gains were tuned on: 7.4 V, 2 ohm, 200:1,
 * 0.005 kg m^2 at the output, about 420 deg/s unloaded at full duty,
 * 3.7 N m stall. */
void plant_init(struct plant *pl);
void plant_drive(struct plant *pl, int16_t duty_q15);
void plant_coast(struct plant *pl);
/* Advances the model by dt seconds (internally in steps of at most 50 us). */
void plant_step(struct plant *pl, double dt);
uint16_t plant_encoder(const struct plant *pl);
double plant_angle_deg(const struct plant *pl);

#endif
