#include "ports/host/thermal.h"

#include <math.h>

const struct thermal_params thermal_reference = {
    .winding_case_k_per_w = 3.1,
    .winding_tau_s = 12.0,
    .case_ambient_k_per_w = 14.0,
    .case_tau_s = 612.0,
};

void thermal_init(struct thermal *t, double ambient_c)
{
    t->p = thermal_reference;
    thermal_soak(t, ambient_c);
}

void thermal_soak(struct thermal *t, double temp_c)
{
    t->ambient_c = temp_c;
    t->winding_c = temp_c;
    t->case_c = temp_c;
}

/* Explicit Euler in steps far below the winding's time constant (at
 * least 1 s in any plant file). Capacities are time constant / resistance. */
void thermal_step(struct thermal *t, double heat_w, double dt)
{
    const struct thermal_params *p = &t->p;
    const double max_step = 0.01;
    double winding_j_per_k = p->winding_tau_s / p->winding_case_k_per_w;
    double case_j_per_k = p->case_tau_s / p->case_ambient_k_per_w;
    while (dt > 0.0) {
        double h = dt < max_step ? dt : max_step;
        double to_case = (t->winding_c - t->case_c) / p->winding_case_k_per_w;
        double to_air = (t->case_c - t->ambient_c) / p->case_ambient_k_per_w;
        t->winding_c += (heat_w - to_case) / winding_j_per_k * h;
        t->case_c += (to_case - to_air) / case_j_per_k * h;
        dt -= h;
    }
}

unsigned thermal_ntc_adc(const struct thermal *t)
{
    double rt = 10000.0 * exp(3435.0 * (1.0 / (273.15 + t->case_c) - 1.0 / (273.15 + 25.0)));
    double adc = rt * 4096.0 / (rt + 10000.0);
    return adc < 0 ? 0u : adc > 4095 ? 4095u : (unsigned)lround(adc);
}
