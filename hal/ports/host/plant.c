#include "ports/host/plant.h"

#include <math.h>

#define PI 3.14159265358979323846

/* The reference servo is a 20 kg cm class bus servo at 7.4 V (its plant
 * file, plants/reference_st3215.toml, holds the same numbers). Its published
 * figures (DFRobot SER0069 / Feetech ST3215 product data, 7.4 V version):
 *   stall torque 19.5 kg cm (1.912 N m), no-load speed 0.192 s/60 deg
 *   (312.5 deg/s), no-load current 150 mA, gear train 1:345, and a stall
 *   (locked-rotor) current of 2.7 A (Feetech's STS3215 specification).
 * Everything else follows from those five numbers:
 *   R   = 7.4 V / 2.7 A                                  = 2.741 ohm
 *   kt  = (7.4 V - 0.15 A R) / (5.454 rad/s x 345)        = 3.714 mN m/A
 *   drag at no-load speed = kt x 0.15 A = 0.557 mN m, split half Coulomb,
 *   half viscous (maxon's catalogue treats the no-load current as friction
 *   of brushes and bearings that grows slowly with speed);
 *   efficiency = 1.912 N m / (345 (kt 2.7 A - Coulomb))    = 0.569,
 *   about 0.9 per stage over the five stages of a 1:345 spur train.
 * kt agrees with a real motor of this size: maxon RE 16 (118725, 4.8 V)
 * has 3.48 mN m/A.
 * The rotor inertia is an estimate for a 16-20 mm brushed motor (1 g cm^2);
 * the randomized motion test runs with it halved and doubled too. Body
 * diodes: 0.7 V, a MOSFET's typical forward drop. */
void plant_init(struct plant *pl)
{
    *pl = (struct plant){
        .p = {
            .supply_v = 7.4,
            .resistance_ohm = 2.741,
            .kt = 3.714e-3,
            .gear_ratio = 345.0,
            .efficiency = 0.569,
            .rotor_inertia = 1.0e-7,
            .drag_coulomb = 2.786e-4,
            .drag_viscous = 1.481e-7,
            .diode_v = 0.7,
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

double plant_output_inertia(const struct plant *pl)
{
    return pl->p.rotor_inertia * pl->p.gear_ratio * pl->p.gear_ratio + pl->payload_inertia;
}

double plant_stall_torque(const struct plant *pl)
{
    const struct plant_params *p = &pl->p;
    return p->gear_ratio * p->efficiency * (p->kt * p->supply_v / p->resistance_ohm - p->drag_coulomb);
}

double plant_no_load_speed(const struct plant *pl)
{
    const struct plant_params *p = &pl->p;
    double k2 = p->kt * p->kt / p->resistance_ohm;
    return (p->kt * p->supply_v / p->resistance_ohm - p->drag_coulomb) / (k2 + p->drag_viscous) /
           p->gear_ratio;
}

/* Winding current. Released, the bridge is open: no current flows until
 * the back-EMF exceeds the supply plus two diode drops, then the motor
 * feeds the supply through the body diodes and brakes. */
static double winding_current(const struct plant *pl, double emf)
{
    const struct plant_params *p = &pl->p;
    if (!pl->coast) {
        return (p->supply_v * pl->duty - emf) / p->resistance_ohm;
    }
    double clamp = p->supply_v + 2.0 * p->diode_v;
    if (emf > clamp) {
        return -(emf - clamp) / p->resistance_ohm;
    }
    if (emf < -clamp) {
        return -(emf + clamp) / p->resistance_ohm;
    }
    return 0.0;
}

/* The motor-side torque (reflected to the output) that carries the load
 * through the gearbox while turning in direction dir: lifting a load costs
 * load / efficiency, a load driving the output arrives reduced by it. */
static double load_through_gears(const struct plant *pl, double dir)
{
    double t = pl->load_torque;
    bool lifting = t * dir > 0.0;
    return lifting ? t / pl->p.efficiency : t * pl->p.efficiency;
}

static void step(struct plant *pl, double dt)
{
    const struct plant_params *p = &pl->p;
    double n = p->gear_ratio;
    double motor_speed = pl->velocity * n;
    pl->current = winding_current(pl, p->kt * motor_speed);
    double drive = n * p->kt * pl->current;
    double coulomb = n * p->drag_coulomb;
    double viscous = n * n * p->drag_viscous * pl->velocity;
    double dir = pl->velocity > 0.0 ? 1.0 : pl->velocity < 0.0 ? -1.0 : 0.0;
    if (dir == 0.0) {
        /* At rest, static friction and the gears hold against anything
         * between what it takes to back-drive and to lift. */
        double up = load_through_gears(pl, 1.0) + coulomb;
        double down = load_through_gears(pl, -1.0) - coulomb;
        if (drive <= up && drive >= down) {
            return;
        }
        dir = drive > up ? 1.0 : -1.0;
    }
    double net = drive - load_through_gears(pl, dir) - dir * coulomb - viscous;
    double before = pl->velocity;
    pl->velocity += net / plant_output_inertia(pl) * dt;
    if ((before > 0 && pl->velocity < 0) || (before < 0 && pl->velocity > 0)) {
        pl->velocity = 0.0; /* friction stops, it does not reverse */
    }
    /* The output moves with the gears once they are through the play; a
     * load holds it against the flank that carries it. With no play this
     * is angle += velocity dt. */
    double half = 0.5 * p->backlash_deg * PI / 180.0;
    double lo = pl->load_torque > 0.0 ? half : -half;
    double hi = pl->load_torque < 0.0 ? -half : half;
    double ahead = pl->play + pl->velocity * dt;
    double play = ahead < lo ? lo : ahead > hi ? hi : ahead;
    pl->angle += ahead - play;
    pl->play = play;
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
