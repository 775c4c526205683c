#include "plant.h"

#include <math.h>

#define PI 3.14159265358979323846

void plant_init(struct plant *pl)
{
    *pl = (struct plant){
        .p = {
            .supply_v = 7.4,
            .resistance_ohm = 2.0,
            .kt = 0.005,
            .gear_ratio = 200.0,
            .inertia = 0.005,
            .viscous = 0.001,
            .coulomb = 0.05,
        },
        .coast = true,
    };
}

void plant_drive(struct plant *pl, int16_t duty_q15)
{
    pl->duty = duty_q15 / 32767.0;
    pl->coast = false;
}

void plant_coast(struct plant *pl)
{
    pl->duty = 0.0;
    pl->coast = true;
}

static void step(struct plant *pl, double dt)
{
    const struct plant_params *p = &pl->p;
    double motor_speed = pl->velocity * p->gear_ratio;
    /* Coasting: the bridge is open and no current flows (the back-EMF stays
     * below the supply, so the flyback diodes do not conduct). */
    pl->current = pl->coast ? 0.0
                            : (p->supply_v * pl->duty - p->kt * motor_speed) / p->resistance_ohm;
    double drive = p->kt * pl->current * p->gear_ratio - pl->load_torque;
    double friction = p->viscous * pl->velocity;
    if (fabs(pl->velocity) < 1e-6 && fabs(drive) <= p->coulomb) {
        pl->velocity = 0.0; /* static friction holds */
        return;
    }
    friction += pl->velocity > 0 ? p->coulomb : pl->velocity < 0 ? -p->coulomb
                                            : (drive > 0 ? p->coulomb : -p->coulomb);
    double before = pl->velocity;
    pl->velocity += (drive - friction) / p->inertia * dt;
    if ((before > 0 && pl->velocity < 0) || (before < 0 && pl->velocity > 0)) {
        pl->velocity = 0.0; /* friction stops, it does not reverse */
    }
    pl->angle += pl->velocity * dt;
    if (pl->has_stop && pl->angle > pl->stop_angle) {
        pl->angle = pl->stop_angle;
        pl->velocity = 0.0;
    }
}

void plant_step(struct plant *pl, double dt)
{
    const double max_step = 50e-6;
    while (dt > 0.0) {
        double h = dt < max_step ? dt : max_step;
        step(pl, h);
        dt -= h;
    }
}

uint16_t plant_encoder(const struct plant *pl)
{
    double counts = floor(pl->angle / (2.0 * PI) * 4096.0 + 0.5);
    double wrapped = fmod(counts, 4096.0);
    if (wrapped < 0) {
        wrapped += 4096.0;
    }
    return (uint16_t)wrapped;
}

double plant_angle_deg(const struct plant *pl)
{
    return pl->angle * 180.0 / PI;
}
