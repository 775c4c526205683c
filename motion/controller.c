#include "motion/controller.h"

#include <stdbool.h>
#include <stddef.h>
#include <string.h>

#include "motion/div64.h"
#include "motion/gains.h"
#include "motion/saturate.h"
#include "hal/size_first.h"

#if !defined(__ARM_FEATURE_SAT) && defined(SERVO_SIZE_FIRST)
__attribute__((noinline)) int32_t sat_q(int32_t v, int32_t limit)
{
    return sat_q_inline(v, limit);
}
#endif

/* Input ranges that keep every product within int32 with the gains at
 * their items' most (kp and ki < 2^10, kd < 2^15, damping < 2^16) and the
 * derived kv and viscous each clamped below 2^16; the output saturates far
 * inside each. */
enum {
    ERROR_LIMIT_Q8 = 1 << 21,      /* 8192 decideg: KP x it is 4.4 x full duty */
    VELOCITY_LIMIT_Q8 = 1 << 13,   /* 32 decideg per tick, 3200 deg/s */
    SPEED_LIMIT_Q8 = 1 << 15,      /* measured: 128 decideg per tick */
    SLIP_LIMIT_Q8 = 1 << 16,       /* planned - measured */
    OUTPUT_LIMIT = 1 << 20,
};

void controller_reset(struct controller *c)
{
    c->integral_q15 = 0;
    c->at_limit = 0;
}

static inline int16_t limit(int32_t duty, int32_t measured_velocity_q8, const struct drive_limits *lim)
{
    int32_t emf = (sat_q(measured_velocity_q8, SPEED_LIMIT_Q8) * lim->kv) >> 8;
    emf = emf > 32767 ? 32767 : emf < -32767 ? -32767 : emf;
    int32_t lo = emf - lim->duty_limit;
    int32_t hi = emf + lim->duty_limit;
    int32_t d = duty < lo ? lo : duty > hi ? hi : duty;
    return (int16_t)(d > 32767 ? 32767 : d < -32767 ? -32767 : d);
}

int16_t controller_limit(int32_t duty, int32_t measured_velocity_q8, const struct drive_limits *lim)
{
    return limit(duty, measured_velocity_q8, lim);
}

int16_t controller_position(struct controller *c, const struct controller_input *in,
                            const struct drive_limits *lim)
{
    if (in->push != 0) {
        /* The setpoint waits for the horn: all the current the limit allows,
         * nothing integrated (the error is the motor's, no load's). */
        c->at_limit = in->push;
        return limit(in->push > 0 ? OUTPUT_LIMIT : -OUTPUT_LIMIT, in->measured_velocity_q8, lim);
    }
    int32_t e = sat_q(in->error_q8, ERROR_LIMIT_Q8);
    int32_t p = (e * lim->kp) >> 8;
    /* Within one encoder count of the setpoint nothing is integrated: the
     * error there is the encoder's rounding, and integrating it would wind
     * the output up through static friction and back (a limit cycle). */
    bool in_count = e < INTEGRAL_DEADBAND_Q8 && e > -INTEGRAL_DEADBAND_Q8;
    int32_t integral = c->integral_q15;
    if (!in_count) {
        integral = sat_q(integral + ((e * lim->ki) >> 8), INTEGRAL_LIMIT_Q15);
    }
    int32_t v = sat_q(in->velocity_q8, VELOCITY_LIMIT_Q8);
    int32_t drag = v > 0 ? lim->friction : v < 0 ? -lim->friction : 0;
    int32_t ff = ((v * (lim->kv + lim->viscous)) >> 8) + in->acceleration_duty + drag;
    int32_t d = (sat_q(in->velocity_q8 - in->measured_velocity_q8, SLIP_LIMIT_Q8) * lim->kd) >> 8;
    int32_t out = sat_q(p + integral + ff + d, OUTPUT_LIMIT);
    int16_t limited = limit(out, in->measured_velocity_q8, lim);
    /* Anti-windup: no integrating while the limit holds the output back in
     * the direction the error asks for. */
    bool pushing = (out > limited && e > 0) || (out < limited && e < 0);
    if (!pushing) {
        c->integral_q15 = integral;
    }
    c->at_limit = (int8_t)(out > limited ? 1 : out < limited ? -1 : 0);
    return limited;
}

int16_t controller_damping(int32_t measured_velocity_q8, int16_t open_duty_q15, const struct drive_limits *lim)
{
    int32_t duty = open_duty_q15;
    if (duty == 0) {
        duty = -((sat_q(measured_velocity_q8, SPEED_LIMIT_Q8) * lim->damping) >> 8);
    }
    return limit(duty, measured_velocity_q8, lim);
}

/* The feed-forward from the drive train (items 80-85), each a duty in
 * Q15. Motor torque T takes the current T / kt, and the duty T R / (kt V);
 * so with kt in uN m/A, R in mOhm and V in mV, a torque in units u gives
 * u x R / (kt V) x SCALE, SCALE = 32768 x u / 1e-6. One decideg per tick is
 * 1.7453 rad/s at the output, ratio times that at the motor; one decideg
 * per tick^2 is 1745.3 rad/s^2. Rounded scales: 0.01 % at most. */
enum {
    KV_SCALE_Q6 = 3660,    /* back-EMF: kt ratio x 1.7453e-6 x 32768e3 / V = 57.19 x 64 */
    KA_SCALE = 5719,       /* inertia in 1e-10 kg m^2 x ratio x 1745.3 rad/s^2 */
    FRICTION_SCALE = 3277, /* Coulomb drag in 1e-7 N m */
    VISCOUS_SCALE_Q5 = 183, /* viscous drag in 1e-10 N m s/rad x ratio x 1.7453 rad/s: 5.719 x 32 */
    DERIVED_MAX = 65535,   /* kv, friction and viscous: see the input ranges above */
    KA_MAX = 1 << 30,
};

/* The gains' four items, kp to damping, side by side in both structs. */
#define GAINS_SIZE (4u * sizeof(uint16_t))
_Static_assert(offsetof(struct user_config, gain_damping) - offsetof(struct user_config, gain_kp) ==
                       offsetof(struct drive_limits, damping) - offsetof(struct drive_limits, kp) &&
                   offsetof(struct drive_limits, damping) - offsetof(struct drive_limits, kp) ==
                       GAINS_SIZE - sizeof(uint16_t),
               "gains: items 86-89 in order, as struct drive_limits has them");

/* a x b / den, at most most: each factor within 32 bits (the items' 16-bit
 * ranges see to it), the product within 64. */
static int32_t derived(uint32_t a, uint32_t b, uint32_t den, int32_t most)
{
    uint64_t q = div64_u((uint64_t)a * b, den);
    return q > (uint64_t)most ? most : (int32_t)q;
}

void drive_limits_for_supply(struct drive_limits *lim, const struct user_config *dt, uint16_t supply_mv)
{
    if (supply_mv < GAIN_MIN_SUPPLY_MV) {
        supply_mv = GAIN_MIN_SUPPLY_MV;
    }
    const uint32_t r = dt->resistance_mohm;
    const uint32_t ratio = (uint32_t)(dt->gear_ratio < 0 ? -dt->gear_ratio : dt->gear_ratio);
    const uint32_t per_torque = (uint32_t)dt->kt_un_m_per_a * supply_mv; /* kt V */
    lim->kv = derived(dt->kt_un_m_per_a * ratio, KV_SCALE_Q6, (uint32_t)supply_mv << 6, DERIVED_MAX);
    int32_t ka = derived(dt->inertia_mg_cm2 * ratio, r * KA_SCALE, per_torque, KA_MAX);
    lim->ka = ka | 1; /* never 0: planning divides by what it gives */
    lim->friction = derived(dt->coulomb_dun_m * r, FRICTION_SCALE, per_torque, DERIVED_MAX);
    lim->viscous = derived(dt->viscous_100pn_m_s * ratio, (r * VISCOUS_SCALE_Q5) >> 5, per_torque, DERIVED_MAX);
    memcpy(&lim->kp, &dt->gain_kp, GAINS_SIZE);
    lim->reversed = dt->gear_ratio < 0;
}

/* The drive items' own check (docs/safety.md, "Drive items the loop
 * refuses"): the plant items 80-85 declare and the gains 86-88, at the
 * nominal supply, as the controller would use them:
 *  - kv within its fixed point (not clamped): the output's no-load speed at
 *    least 50 deg/s at 7.4 V (kt x ratio at most 8.48 N m/A);
 *  - ka >= kv: the motor's mechanical time constant (J R / kt^2) at least
 *    the 1 ms tick the velocity feedback and the limit's back-EMF work at;
 *  - the PID loop on that plant stable with margin: ka s^3 + (kv + viscous
 *    + kd) s^2 + kp s + ki, by Hurwitz, (kv + viscous + kd) kp >= 2 ka ki.
 * Ratio 0 declares no plant (no feed-forward): nothing to judge. Divides:
 * for a write only. */
bool drive_items_stable(const struct user_config *dt)
{
    struct drive_limits lim;
    drive_limits_for_supply(&lim, dt, NOMINAL_SUPPLY_MV);
    uint32_t damping = (uint32_t)(lim.kv + lim.viscous) + lim.kd; /* < 2^18 */
    return dt->gear_ratio == 0 ||
           (lim.kv < DERIVED_MAX && lim.ka >= lim.kv &&
            ((uint32_t)lim.ka >> 10) * lim.ki <= (damping * lim.kp) >> 11);
}

/* x R << 15 / den, at most full duty (32767). On the M0 called by both limits, not
 * inlined in each (on a change of the limits only). */
SIZE_FIRST_CALLED static int16_t duty_of(uint32_t x, uint16_t r_mohm, uint32_t den)
{
    uint64_t duty = div64_u((uint64_t)x * r_mohm << 15, den);
    return (int16_t)(duty > 32767u ? 32767u : duty);
}

int16_t duty_limit_for_power(uint16_t power_mw, uint16_t supply_mv, uint16_t r_mohm)
{
    return duty_of(power_mw, r_mohm, (uint32_t)supply_mv * supply_mv); /* P R / V^2 */
}

int16_t duty_limit_for_current(uint16_t current_ma, uint16_t supply_mv, uint16_t r_mohm)
{
    return duty_of(current_ma, r_mohm, (uint32_t)supply_mv * 1000u); /* I R / V, the current in mA */
}
