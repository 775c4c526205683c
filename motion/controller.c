#include "motion/controller.h"

#include <stdbool.h>

#include "motion/div64.h"
#include "motion/gains.h"
#include "motion/saturate.h"

#if !defined(__ARM_FEATURE_SAT) && defined(SERVO_SIZE_FIRST)
__attribute__((noinline)) int32_t sat_q(int32_t v, int32_t limit)
{
    return sat_q_inline(v, limit);
}
#endif

/* Input ranges that keep every product within int32 (the gains: kv +
 * viscous < 2^15.3 down to GAIN_MIN_SUPPLY_MV, KP < 2^10, KD and DAMPING
 * < 2^13); the output saturates far inside each. */
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
    int32_t p = (e * GAIN_KP) >> 8;
    /* Within one encoder count of the setpoint nothing is integrated: the
     * error there is the encoder's rounding, and integrating it would wind
     * the output up through static friction and back (a limit cycle). */
    bool in_count = e < INTEGRAL_DEADBAND_Q8 && e > -INTEGRAL_DEADBAND_Q8;
    int32_t integral = c->integral_q15;
    if (!in_count) {
        integral += (e * GAIN_KI) >> 8;
        integral = integral > INTEGRAL_LIMIT_Q15 ? INTEGRAL_LIMIT_Q15
                   : integral < -INTEGRAL_LIMIT_Q15 ? -INTEGRAL_LIMIT_Q15 : integral;
    }
    int32_t v = sat_q(in->velocity_q8, VELOCITY_LIMIT_Q8);
    int32_t drag = v > 0 ? lim->friction : v < 0 ? -lim->friction : 0;
    int32_t ff = ((v * (lim->kv + lim->viscous)) >> 8) + in->acceleration_duty + drag;
    int32_t d = (sat_q(in->velocity_q8 - in->measured_velocity_q8, SLIP_LIMIT_Q8) * GAIN_KD) >> 8;
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
        duty = -((sat_q(measured_velocity_q8, SPEED_LIMIT_Q8) * GAIN_DAMPING) >> 8);
    }
    return limit(duty, measured_velocity_q8, lim);
}

void drive_limits_for_supply(struct drive_limits *lim, uint16_t supply_mv)
{
    if (supply_mv == 0u) {
        supply_mv = NOMINAL_SUPPLY_MV;
    } else if (supply_mv < GAIN_MIN_SUPPLY_MV) {
        supply_mv = GAIN_MIN_SUPPLY_MV;
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
