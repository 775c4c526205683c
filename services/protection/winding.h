/* The winding's temperature, estimated, and the power derating it and the
 * case's temperature call for.
 *
 * Two nodes: the case, which the NTC measures, and the winding, which
 * nothing measures and which heats with a time constant of seconds (the
 * case's is minutes). The winding's rise over the case follows its I^2 R
 * heat through the board's thermal resistance and time constant:
 *   d(rise)/dt = (P x R_wc - rise) / tau,  P = I^2 x R_motor
 * and the estimate is the case's reading plus that rise. The case's own
 * heating is measured, not modelled, so the estimate stays anchored to the
 * NTC whatever the ambient does.
 *
 * Fixed point: the rise in degC Q16 (int32, +-32 000 degC), the heat as the
 * mean of I^2 in mA^2/16 over WINDING_SAMPLES current samples, one sample a
 * sensor round (5 ms), one model step every WINDING_SAMPLES rounds (80 ms,
 * 1/150 of the reference motor's 12 s). */
#ifndef PROTECTION_WINDING_H
#define PROTECTION_WINDING_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_sensors.h"

#define WINDING_SAMPLES 16u /* rounds a model step: a power of two (the mean is a shift) */
/* A current sample is clamped here: its square / 16 x 16 samples fits 32 bits. */
#define WINDING_CURRENT_MAX_MA 16383u
/* Derating: the power limit falls in sixteenths, linearly from full at
 * DERATE_*_BAND below a limit to DERATE_FLOOR sixteenths at it; the
 * temperature protection (41) still trips if the case reaches its limit.
 * Bands in decidegrees as powers of two (a shift, no division): 25.6 degC
 * below the winding's limit (it moves within seconds), 12.8 below 41's. */
#define DERATE_WINDING_BAND_SHIFT 4 /* 256 decideg / 16 levels */
#define DERATE_CASE_BAND_SHIFT 3    /* 128 decideg / 16 levels */
#define DERATE_LEVELS 16
#define DERATE_FLOOR 1

struct winding_model {
    int32_t rise_q16;     /* winding above case, degC Q16 */
    uint32_t heat_sum;    /* sum of (I_mA^2 / 16) this step */
    uint8_t samples;      /* in heat_sum */
    uint8_t level;        /* the derating now: DERATE_FLOOR..DERATE_LEVELS sixteenths */
    int16_t winding_decic; /* the estimate, 0.1 degC */
};

void winding_init(struct winding_model *w);

/* One sensor round's current sample; true when a model step is due
 * (winding_step). */
static inline bool winding_sample(struct winding_model *w, uint16_t current_ma)
{
    uint32_t i = current_ma < WINDING_CURRENT_MAX_MA ? current_ma : WINDING_CURRENT_MAX_MA;
    w->heat_sum += (i * i) >> 4;
    w->samples++;
    return w->samples == WINDING_SAMPLES;
}

/* A model step: the rise, the estimate from the case's NTC reading, and the
 * derating level against the winding's limit and the case's (item 41, as
 * an NTC reading). Returns whether the level changed. */
bool winding_step(struct winding_model *w, const struct sensor_calibration *cal,
                  uint16_t case_adc, uint16_t case_limit_adc);

/* The power cap a derating level leaves of power_limit_mw; 0 = none. */
uint16_t winding_power_cap(const struct winding_model *w, uint16_t power_limit_mw);

#endif
