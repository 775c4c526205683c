/* Two-node thermal model of the motor: I^2 R heats the winding, which
 * passes heat to the case, which loses it to the ambient air. The NTC sits
 * on the case (where servo makers glue it), so it reads the case, and the
 * winding runs hotter than the reading while it is loaded.
 *
 * Parameters: maxon RE 25 (118743) datasheet, "Thermal data":
 *   thermal resistance winding-housing  3.1 K/W,  time constant winding  12.0 s
 *   thermal resistance housing-ambient   14 K/W,  time constant motor     612 s
 * Capacities follow as time constant / resistance: 3.87 J/K (winding) and
 * 43.7 J/K (case). A plant file (plant_model.h) may give other figures. The RE 25 is a little larger than a 20 kg cm servo's
 * motor; the servo's plastic case keeps its heat in at least as well. */
#ifndef HOST_THERMAL_H
#define HOST_THERMAL_H

struct thermal_params {
    double winding_case_k_per_w;
    double winding_tau_s;        /* the winding's time constant */
    double case_ambient_k_per_w;
    double case_tau_s;           /* the motor's (case) time constant */
};

struct thermal {
    struct thermal_params p;
    double ambient_c;
    double winding_c;
    double case_c;
};

/* The reference servo's figures above. */
extern const struct thermal_params thermal_reference;

/* The reference servo's parameters, everything at ambient_c. */
void thermal_init(struct thermal *t, double ambient_c);
/* Everything at temp_c at once: the servo has soaked in that air. */
void thermal_soak(struct thermal *t, double temp_c);
void thermal_step(struct thermal *t, double heat_w, double dt);
/* The NTC divider's ADC value at the case temperature (appendix 5.1). */
unsigned thermal_ntc_adc(const struct thermal *t);

#endif
