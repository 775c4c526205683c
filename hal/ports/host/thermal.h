/* First-order thermal model of the winding: I^2 R heats it, it cools towards
 * ambient through THERMAL_RESISTANCE. The time constant is kept short (1 s)
 * so that injected heat shows within a test's patience. */
#ifndef HOST_THERMAL_H
#define HOST_THERMAL_H

#define THERMAL_RESISTANCE_K_PER_W 10.0
#define THERMAL_CAPACITY_J_PER_K 0.1

struct thermal {
    double ambient_c;
    double winding_c;
};

void thermal_init(struct thermal *t, double ambient_c);
void thermal_step(struct thermal *t, double heat_w, double dt);
/* The NTC divider's ADC value at the winding temperature (appendix 5.1). */
unsigned thermal_ntc_adc(const struct thermal *t);

#endif
