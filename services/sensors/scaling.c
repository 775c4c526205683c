#include "sensors/scaling.h"

/* The per-tick helpers inline where speed comes first; one copy of each
 * where size does (SERVO_SIZE_FIRST: the Cortex-M0). */
#ifdef SERVO_SIZE_FIRST
#define TICK_HELPER static
#else
#define TICK_HELPER static inline __attribute__((always_inline))
#endif

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
TICK_HELPER uint16_t scale_q12(uint16_t counts, uint16_t q12)
{
    return saturate16(((uint32_t)counts * q12 + 2048u) >> 12);
}

static uint16_t voltage_mv(const struct sensor_calibration *cal, uint16_t supply_counts)
{
    return scale_q12(supply_counts, cal->supply_mv_q12);
}

/* Below the amplifier's zero: no current, not a wrap-around. */
TICK_HELPER uint16_t current_ma(const struct sensor_calibration *cal, uint16_t zero, uint16_t current_counts)
{
    return scale_q12(current_counts > zero ? (uint16_t)(current_counts - zero) : 0u,
                     cal->current_ma_q12);
}

/* One sample moves a reading by 1/2^shift of its jump: an eighth for the
 * current at 1 kHz (time constant 8 ms), a quarter for the slow readings at
 * 200 Hz (17 ms). Rounds towards the state, so steady samples bring it back
 * exactly. */
enum { CURRENT_SHIFT = 3, SLOW_SHIFT = 2 };

TICK_HELPER uint16_t follow(uint32_t *state_q4, uint16_t sample, unsigned shift)
{
    uint32_t target = (uint32_t)sample << 4;
    uint32_t state = *state_q4;
    state = target >= state ? state + ((target - state) >> shift) : state - ((state - target) >> shift);
    *state_q4 = state;
    return (uint16_t)((state + 8u) >> 4);
}

/* The slow reading of slot. */
TICK_HELPER void refresh(struct sensor_filter *f, const struct sensor_calibration *cal,
                         const struct sensor_raw *raw, enum sense_slot slot, unsigned shift)
{
    struct sensor_readings *out = &f->out;
    if (slot == SENSE_VOLTAGE) {
        out->voltage_mv = follow(&f->voltage_q4, voltage_mv(cal, raw->supply), shift);
    } else if (slot == SENSE_POWER) {
        out->power_mw = power_mw(out->voltage_mv, out->current_ma);
    } else if (slot == SENSE_TEMPERATURE) {
        out->temperature_adc = follow(&f->temperature_q4, raw->ntc, shift);
    }
}

/* The first tick: every reading as it is (a shift of 0 takes the sample),
 * the power after the supply. */
__attribute__((cold, noinline)) static void prime(struct sensor_filter *f,
                                                  const struct sensor_calibration *cal,
                                                  const struct sensor_raw *raw, uint16_t ma)
{
    f->current_q4 = (uint32_t)ma << 4;
    f->out.current_ma = ma;
    for (unsigned slot = SENSE_VOLTAGE; slot <= SENSE_TEMPERATURE; slot++) {
        refresh(f, cal, raw, (enum sense_slot)slot, 0u);
    }
    f->primed = 1;
}

enum sense_slot sensors_update(struct sensor_filter *f, const struct sensor_calibration *cal,
                               const struct sensor_raw *raw)
{
    uint16_t ma = current_ma(cal, f->current_zero, raw->current);
    if (!f->primed) {
        prime(f, cal, raw, ma);
    }
    f->out.current_ma = follow(&f->current_q4, ma, CURRENT_SHIFT);
    enum sense_slot slot = (enum sense_slot)f->slot;
    f->slot = (uint8_t)(slot + 1 == SENSE_ROUND_TICKS ? 0 : slot + 1);
    refresh(f, cal, raw, slot, SLOW_SHIFT);
    return slot;
}
