#include "scaling.h"

static uint16_t saturate16(uint32_t v)
{
    return v > 0xFFFFu ? 0xFFFFu : (uint16_t)v;
}

/* mV x mA / 1000 without a division: the volts in Q10 (mV x 1.024, to
 * within 1/1024 V), times the mA. A supply above 64 V counts as 64 V (the
 * power saturates there anyway), so both products fit 32 bits. */
enum { POWER_MV_MAX = 64000 };

static uint16_t power_mw(uint16_t mv, uint16_t ma)
{
    uint32_t v = mv < POWER_MV_MAX ? mv : POWER_MV_MAX;
    uint32_t volts_q10 = (v * 67109u + 32768u) >> 16;
    return saturate16((volts_q10 * ma + 512u) >> 10);
}

/* counts x a Q12 scale: at most 65535 x 65535, within 32 bits. */
static uint16_t scale_q12(uint16_t counts, uint16_t q12)
{
    return saturate16(((uint32_t)counts * q12 + 2048u) >> 12);
}

void sensors_scale(const struct sensor_calibration *cal, const struct sensor_raw *raw,
                   struct sensor_readings *out)
{
    uint16_t current = raw->current > cal->current_zero_counts
                           ? (uint16_t)(raw->current - cal->current_zero_counts)
                           : 0u;
    out->voltage_mv = scale_q12(raw->supply, cal->supply_mv_q12);
    out->current_ma = scale_q12(current, cal->current_ma_q12);
    out->temperature_adc = raw->ntc;
    out->power_mw = 0; /* the filter's, from the filtered readings */
}

enum { FILTER_SHIFT = 3 };

static uint32_t follow(uint32_t state_q4, uint16_t sample)
{
    int32_t diff = (int32_t)((uint32_t)sample << 4) - (int32_t)state_q4;
    return (uint32_t)((int32_t)state_q4 + diff / (1 << FILTER_SHIFT));
}

static uint16_t value_of(uint32_t q4)
{
    return (uint16_t)((q4 + 8u) >> 4);
}

void sensors_filter(struct sensor_filter *f, const struct sensor_readings *in,
                    struct sensor_readings *out)
{
    if (!f->primed) {
        f->voltage_q4 = (uint32_t)in->voltage_mv << 4;
        f->current_q4 = (uint32_t)in->current_ma << 4;
        f->temperature_q4 = (uint32_t)in->temperature_adc << 4;
        f->primed = 1;
    } else {
        f->voltage_q4 = follow(f->voltage_q4, in->voltage_mv);
        f->current_q4 = follow(f->current_q4, in->current_ma);
        f->temperature_q4 = follow(f->temperature_q4, in->temperature_adc);
    }
    out->voltage_mv = value_of(f->voltage_q4);
    out->current_ma = value_of(f->current_q4);
    out->temperature_adc = value_of(f->temperature_q4);
    out->power_mw = power_mw(out->voltage_mv, out->current_ma);
}
