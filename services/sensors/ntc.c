#include "sensors/ntc.h"

enum { LAST = NTC_TABLE_SIZE - 1 };

static int16_t celsius10_at(int i)
{
    return (int16_t)((ntc_first_celsius + i * ntc_step_celsius) * 10);
}

int16_t ntc_decicelsius(uint16_t adc)
{
    if (adc >= ntc_adc_at[0]) {
        return celsius10_at(0);
    }
    if (adc <= ntc_adc_at[LAST]) {
        return celsius10_at(LAST);
    }
    /* The table falls: find i with adc_at[i] > adc >= adc_at[i + 1]. */
    int lo = 0;
    int hi = LAST;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (ntc_adc_at[mid] > adc) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    int32_t span = ntc_adc_at[lo] - ntc_adc_at[hi];
    int32_t into = ntc_adc_at[lo] - adc;
    int32_t step10 = ntc_step_celsius * 10;
    /* Every quotient here is of numbers >= 0: unsigned, so the size-first
     * image links no signed division (60 B on the Cortex-M0). */
    return (int16_t)(celsius10_at(lo) + (int32_t)((uint32_t)(into * step10 + span / 2) / (uint32_t)span));
}

uint16_t ntc_adc(int16_t decicelsius)
{
    int32_t from_first = decicelsius - celsius10_at(0);
    int32_t step10 = ntc_step_celsius * 10;
    if (from_first <= 0) {
        return ntc_adc_at[0];
    }
    int32_t i = (int32_t)((uint32_t)from_first / (uint32_t)step10);
    if (i >= LAST) {
        return ntc_adc_at[LAST];
    }
    int32_t frac = from_first - i * step10;
    int32_t a = ntc_adc_at[i];
    int32_t b = ntc_adc_at[i + 1];
    return (uint16_t)(a - (int32_t)((uint32_t)((a - b) * frac + step10 / 2) / (uint32_t)step10));
}
