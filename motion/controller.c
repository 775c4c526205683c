#include "motion/controller.h"

#include "motion/gains.h"

static int32_t clamp32(int64_t v, int32_t limit)
{
    return v > limit ? limit : v < -limit ? -limit : (int32_t)v;
}

void controller_reset(struct controller *c)
{
    c->integral_q15 = 0;
}

int16_t controller_position(struct controller *c, const struct controller_input *in)
{
    /* Beyond 2^22 (16 384 decideg) the output is saturated anyway. */
    int32_t e = clamp32(in->error_q8, 1 << 22);
    int64_t p = ((int64_t)e * GAIN_KP) >> 8;
    c->integral_q15 = clamp32(c->integral_q15 + (((int64_t)e * GAIN_KI) >> 8), INTEGRAL_LIMIT_Q15);
    int64_t ff = ((int64_t)in->velocity_q8 * GAIN_KV) >> 8;
    int64_t d = ((int64_t)in->measured_velocity_q8 * GAIN_KD) >> 8;
    return (int16_t)clamp32(p + c->integral_q15 + ff - d, in->duty_limit);
}

int16_t controller_damping(int32_t measured_velocity_q8, int16_t duty_limit)
{
    return (int16_t)clamp32(-(((int64_t)measured_velocity_q8 * GAIN_DAMPING) >> 8), duty_limit);
}

static uint32_t isqrt32(uint32_t x)
{
    uint32_t root = 0;
    for (uint32_t bit = 1u << 30; bit != 0; bit >>= 2) {
        if (x >= root + bit) {
            x -= root + bit;
            root = (root >> 1) + bit;
        } else {
            root >>= 1;
        }
    }
    return root;
}

int16_t duty_limit_for_power(uint16_t power_mw, uint16_t supply_mv)
{
    if (supply_mv == 0u) {
        supply_mv = NOMINAL_SUPPLY_MV;
    }
    uint32_t root = isqrt32((uint32_t)power_mw * MOTOR_RESISTANCE_MOHM);
    uint32_t duty = (root << 15) / supply_mv;
    return (int16_t)(duty > 32767u ? 32767u : duty);
}
