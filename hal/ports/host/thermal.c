#include "thermal.h"

#include <math.h>

void thermal_init(struct thermal *t, double ambient_c)
{
    t->ambient_c = ambient_c;
    t->winding_c = ambient_c;
}

void thermal_step(struct thermal *t, double heat_w, double dt)
{
    double cooling = (t->winding_c - t->ambient_c) / THERMAL_RESISTANCE_K_PER_W;
    t->winding_c += (heat_w - cooling) / THERMAL_CAPACITY_J_PER_K * dt;
}

unsigned thermal_ntc_adc(const struct thermal *t)
{
    double rt = 10000.0 * exp(3435.0 * (1.0 / (273.15 + t->winding_c) - 1.0 / (273.15 + 25.0)));
    double adc = rt * 4096.0 / (rt + 10000.0);
    return adc < 0 ? 0u : adc > 4095 ? 4095u : (unsigned)lround(adc);
}
