#include "ports/host/thermal.h"

#include <math.h>

void thermal_init(struct thermal *t, double ambient_c)
{
    thermal_soak(t, ambient_c);
}

void thermal_soak(struct thermal *t, double temp_c)
{
    t->ambient_c = temp_c;
    t->winding_c = temp_c;
    t->case_c = temp_c;
}

/* Explicit Euler in steps far below the winding's 12 s time constant. */
void thermal_step(struct thermal *t, double heat_w, double dt)
{
    const double max_step = 0.01;
    while (dt > 0.0) {
        double h = dt < max_step ? dt : max_step;
        double to_case = (t->winding_c - t->case_c) / THERMAL_WINDING_CASE_K_PER_W;
        double to_air = (t->case_c - t->ambient_c) / THERMAL_CASE_AMBIENT_K_PER_W;
        t->winding_c += (heat_w - to_case) / THERMAL_WINDING_J_PER_K * h;
        t->case_c += (to_case - to_air) / THERMAL_CASE_J_PER_K * h;
        dt -= h;
    }
}

unsigned thermal_ntc_adc(const struct thermal *t)
{
    double rt = 10000.0 * exp(3435.0 * (1.0 / (273.15 + t->case_c) - 1.0 / (273.15 + 25.0)));
    double adc = rt * 4096.0 / (rt + 10000.0);
    return adc < 0 ? 0u : adc > 4095 ? 4095u : (unsigned)lround(adc);
}
