#include "protection/winding.h"

#include "sensors/ntc.h"
#include "sensors/scaling.h"

_Static_assert(WINDING_SAMPLES * SENSE_ROUND_TICKS == 80u,
               "a model step is the 80 ms board_derived.h's BOARD_WINDING_STEP_K takes");

/* The rise's target is clamped here (500 degC, Q16): every product below
 * then stays within 32 bits. */
#define RISE_MAX_Q16 (500 * 65536)

void winding_init(struct winding_model *w)
{
    /* The first sample completes a step: an estimate (the case's reading,
     * nothing risen yet) from the first sensor round on. */
    *w = (struct winding_model){.level = DERATE_LEVELS, .samples = WINDING_SAMPLES - 1u};
}

/* Sixteenths of the power limit left at temperature t (decideg) below
 * limit: all of it a band below, DERATE_FLOOR at the limit and past it. */
static int32_t level_below(int32_t limit, int32_t t, unsigned band_shift)
{
    int32_t level = (limit - t) >> band_shift;
    return level > DERATE_LEVELS ? DERATE_LEVELS : level < DERATE_FLOOR ? DERATE_FLOOR : level;
}

bool winding_step(struct winding_model *w, const struct sensor_calibration *cal,
                  uint16_t case_adc, uint16_t case_limit_adc)
{
    /* The mean I^2 (mA^2 / 16) of the step's samples, to the rise it
     * settles at (degC Q16): x heat_k / 256 (board_derived.h). */
    uint32_t mean = w->heat_sum / WINDING_SAMPLES;
    w->heat_sum = 0;
    w->samples = 0;
    uint32_t target = ((mean >> 4) * cal->winding_heat_k) >> 4;
    int32_t settle = target > RISE_MAX_Q16 ? RISE_MAX_Q16 : (int32_t)target;
    /* One step of the first-order lag: step_k = 65536 x step / tau. */
    w->rise_q16 += ((settle - w->rise_q16) >> 8) * (int32_t)cal->winding_step_k >> 8;
    int32_t case_decic = ntc_decicelsius(case_adc);
    int32_t winding = case_decic + ((w->rise_q16 >> 8) * 10 >> 8);
    w->winding_decic = (int16_t)(winding > INT16_MAX ? INT16_MAX : winding);
    int32_t by_winding = cal->winding_heat_k != 0u
                             ? level_below(cal->winding_limit_decic, winding, DERATE_WINDING_BAND_SHIFT)
                             : DERATE_LEVELS; /* no model: the case alone */
    int32_t by_case = level_below(ntc_decicelsius(case_limit_adc), case_decic, DERATE_CASE_BAND_SHIFT);
    uint8_t level = (uint8_t)(by_winding < by_case ? by_winding : by_case);
    if (level == w->level) {
        return false;
    }
    w->level = level;
    return true;
}

uint16_t winding_power_cap(const struct winding_model *w, uint16_t power_limit_mw)
{
    if (w->level >= DERATE_LEVELS) {
        return 0;
    }
    uint32_t cap = ((uint32_t)power_limit_mw * w->level) >> 4;
    return (uint16_t)(cap != 0u ? cap : 1u);
}
