#include "motion/controller.h"

#include <stdbool.h>

#include "motion/div64.h"
#include "motion/gains.h"

static inline int32_t clamp32(int64_t v, int32_t limit)
{
    return v > limit ? limit : v < -limit ? -limit : (int32_t)v;
}

void controller_reset(struct controller *c)
{
    c->integral_q15 = 0;
    c->at_limit = 0;
}

static inline int16_t limit(int32_t duty, int32_t measured_velocity_q8, const struct drive_limits *lim)
{
    int32_t emf = clamp32(((int64_t)measured_velocity_q8 * lim->kv) >> 8, 32767);
    int32_t lo = emf - lim->duty_limit;
    int32_t hi = emf + lim->duty_limit;
    int32_t d = duty < lo ? lo : duty > hi ? hi : duty;
    return (int16_t)clamp32(d, 32767);
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
        return limit(in->push > 0 ? 1 << 20 : -(1 << 20), in->measured_velocity_q8, lim);
    }
    /* Beyond 2^22 (16 384 decideg) the output is saturated anyway. */
    int32_t e = clamp32(in->error_q8, 1 << 22);
    int64_t p = ((int64_t)e * GAIN_KP) >> 8;
    /* Within one encoder count of the setpoint nothing is integrated: the
     * error there is the encoder's rounding, and integrating it would wind
     * the output up through static friction and back (a limit cycle). */
    bool in_count = e < INTEGRAL_DEADBAND_Q8 && e > -INTEGRAL_DEADBAND_Q8;
    int32_t integral = in_count ? c->integral_q15
                                : clamp32(c->integral_q15 + (((int64_t)e * GAIN_KI) >> 8),
                                          INTEGRAL_LIMIT_Q15);
    int32_t drag = in->velocity_q8 > 0 ? lim->friction : in->velocity_q8 < 0 ? -lim->friction : 0;
    int64_t ff = (((int64_t)in->velocity_q8 * (lim->kv + lim->viscous)) >> 8) +
                 (((int64_t)in->acceleration_q16 * lim->ka) >> 16) + drag;
    int64_t d = ((int64_t)(in->velocity_q8 - in->measured_velocity_q8) * GAIN_KD) >> 8;
    int32_t out = clamp32(p + integral + ff + d, 1 << 20);
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

int16_t controller_damping(int32_t measured_velocity_q8, const struct drive_limits *lim)
{
    int32_t brake = clamp32(-(((int64_t)measured_velocity_q8 * GAIN_DAMPING) >> 8), 1 << 20);
    return limit(brake, measured_velocity_q8, lim);
}

void drive_limits_for_supply(struct drive_limits *lim, uint16_t supply_mv)
{
    if (supply_mv == 0u) {
        supply_mv = NOMINAL_SUPPLY_MV;
    }
    lim->kv = (int32_t)(((uint32_t)GAIN_KV * NOMINAL_SUPPLY_MV) / supply_mv);
    lim->ka = (int32_t)div64_u((uint64_t)GAIN_KA * NOMINAL_SUPPLY_MV, supply_mv);
    lim->friction = (int32_t)(((uint32_t)GAIN_FRICTION * NOMINAL_SUPPLY_MV) / supply_mv);
    lim->viscous = (int32_t)(((uint32_t)GAIN_VISCOUS * NOMINAL_SUPPLY_MV) / supply_mv);
}

int16_t duty_limit_for_power(uint16_t power_mw, uint16_t supply_mv)
{
    if (supply_mv == 0u) {
        supply_mv = NOMINAL_SUPPLY_MV;
    }
    uint64_t num = (uint64_t)power_mw * MOTOR_RESISTANCE_MOHM << 15;
    uint64_t duty = div64_u(num, (uint32_t)supply_mv * supply_mv);
    return (int16_t)(duty > 32767u ? 32767u : duty);
}

int16_t duty_limit_for_current(uint16_t current_ma, uint16_t supply_mv)
{
    if (supply_mv == 0u) {
        supply_mv = NOMINAL_SUPPLY_MV;
    }
    uint64_t num = div64_u((uint64_t)current_ma * MOTOR_RESISTANCE_MOHM << 15, 1000u);
    uint64_t duty = div64_u(num, supply_mv);
    return (int16_t)(duty > 32767u ? 32767u : duty);
}
