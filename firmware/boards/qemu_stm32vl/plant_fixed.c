#include "plant_fixed.h"

/* The reference servo of hal/ports/host/plant.c, where each number comes
 * from: 312.5 deg/s unloaded at 7.4 V, mechanical time constant
 * J R / (kt N)^2 = 0.0119 x 2.741 / (3.714e-3 x 345)^2 = 20 ms. */
enum {
    NO_LOAD_Q8 = 910,     /* 3.556 counts per ms = 312.5 deg/s, Q8 */
    DRIVE_TAU_TICKS = 20, /* mechanical time constant while driven */
    COAST_TAU_TICKS = 200,/* friction alone */
    SUPPLY_MV = 7400,
    RESISTANCE_MOHM = 2741,
};

void plant_fixed_step(struct plant_fixed *p)
{
    int32_t target = p->coast ? 0 : (int32_t)p->duty * NO_LOAD_Q8 / 32767;
    int32_t tau = p->coast ? COAST_TAU_TICKS : DRIVE_TAU_TICKS;
    p->velocity_q8 += (target - p->velocity_q8) / tau;
    p->position_q8 += p->velocity_q8;
}

uint16_t plant_fixed_encoder(const struct plant_fixed *p)
{
    return (uint16_t)((uint32_t)(p->position_q8 >> 8) & 4095u);
}

uint16_t plant_fixed_current_ma(const struct plant_fixed *p)
{
    if (p->coast) {
        return 0;
    }
    int32_t drive_mv = (int32_t)p->duty * SUPPLY_MV / 32767;
    int32_t emf_mv = p->velocity_q8 * SUPPLY_MV / NO_LOAD_Q8;
    int32_t ma = (drive_mv - emf_mv) * 1000 / RESISTANCE_MOHM;
    return (uint16_t)(ma < 0 ? -ma : ma);
}
