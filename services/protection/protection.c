#include "protection/protection.h"

#include <stddef.h>

#include "sensors/ntc.h"

void protection_init(struct protection *p)
{
    *p = (struct protection){0};
}

/* One row per threshold monitor: which reading, which limit, which way it
 * trips, and the level it must come back to. */
struct threshold {
    uint8_t reading; /* offset in struct sensor_readings */
    uint8_t limit;   /* offset in struct user_config */
    uint8_t bit;
    uint8_t inclusive;     /* the limit itself trips */
    uint16_t turn;         /* TRIPS_ABOVE or TRIPS_BELOW: see facing() */
    uint16_t (*clear_level)(uint16_t limit);
};

enum { TRIPS_ABOVE = 0x0000, TRIPS_BELOW = 0xFFFF };

/* Saturates: a limit near 65535 must not wrap its clear level to near 0. */
static uint16_t up_voltage(uint16_t limit)
{
    uint32_t level = (uint32_t)limit + VOLTAGE_HYSTERESIS_MV;
    return level > UINT16_MAX ? UINT16_MAX : (uint16_t)level;
}

static uint16_t down_voltage(uint16_t limit)
{
    return limit > VOLTAGE_HYSTERESIS_MV ? (uint16_t)(limit - VOLTAGE_HYSTERESIS_MV) : 0u;
}

static uint16_t down_current(uint16_t limit)
{
    return limit > CURRENT_HYSTERESIS_MA ? (uint16_t)(limit - CURRENT_HYSTERESIS_MA) : 0u;
}

static uint16_t down_power(uint16_t limit)
{
    return limit > POWER_HYSTERESIS_MW ? (uint16_t)(limit - POWER_HYSTERESIS_MW) : 0u;
}

/* The temperature limit is an ADC value that falls as it heats: the clear
 * level is the ADC value 5 degC cooler. */
static uint16_t cooler_temperature(uint16_t limit)
{
    return ntc_adc((int16_t)(ntc_decicelsius(limit) - TEMPERATURE_HYSTERESIS_DECIC));
}

#define READING(field) (uint8_t) offsetof(struct sensor_readings, field)
#define LIMIT(field) (uint8_t) offsetof(struct user_config, field)

static const struct threshold thresholds[] = {
    [MON_CURRENT] = {READING(current_ma), LIMIT(current_limit_ma), STATUS_OVER_CURRENT, 0,
                     TRIPS_ABOVE, down_current},
    [MON_LOW_VOLTAGE] = {READING(voltage_mv), LIMIT(low_voltage_mv), STATUS_LOW_VOLTAGE, 0,
                         TRIPS_BELOW, up_voltage},
    [MON_HIGH_VOLTAGE] = {READING(voltage_mv), LIMIT(high_voltage_mv), STATUS_HIGH_VOLTAGE, 0,
                          TRIPS_ABOVE, down_voltage},
    [MON_POWER] = {READING(power_mw), LIMIT(power_limit_mw), STATUS_OVER_POWER, 0, TRIPS_ABOVE,
                   down_power},
    [MON_TEMPERATURE] = {READING(temperature_adc), LIMIT(temperature_limit_adc),
                         STATUS_OVER_TEMPERATURE, 1, TRIPS_BELOW, cooler_temperature},
};

/* The rows each slow slot judges, [first, end) of thresholds[]; a slot
 * without rows judges the current alone. */
static const uint8_t slot_rows[SENSE_ROUND_TICKS][2] = {
    [SENSE_VOLTAGE] = {MON_LOW_VOLTAGE, MON_HIGH_VOLTAGE + 1},
    [SENSE_POWER] = {MON_POWER, MON_POWER + 1},
    [SENSE_TEMPERATURE] = {MON_TEMPERATURE, MON_TEMPERATURE + 1},
};

/* Samples in a row that trip and clear: every tick, or once a round. */
_Static_assert(PROTECT_TRIP_TICKS % SENSE_ROUND_TICKS == 0 &&
                   PROTECT_CLEAR_TICKS % SENSE_ROUND_TICKS == 0,
               "a slow monitor's debounce is whole rounds");
static const uint16_t samples_every_tick[2] = {PROTECT_TRIP_TICKS, PROTECT_CLEAR_TICKS};
static const uint16_t samples_once_a_round[2] = {PROTECT_TRIP_TICKS / SENSE_ROUND_TICKS,
                                                 PROTECT_CLEAR_TICKS / SENSE_ROUND_TICKS};

/* The uint16_t member at offset (the table's offsetof): a load, where a
 * memcpy is a call on the size-first Cortex-M0 build. */
static uint16_t field_u16(const void *base, uint8_t offset)
{
    return *(const uint16_t *)(const void *)((const uint8_t *)base + offset);
}

/* One comparison for every kind: a monitor that trips below compares the
 * values turned over (x ^ 0xFFFF reverses their order, without a branch),
 * and an inclusive one compares against the limit less one. */
static int32_t facing(const struct threshold *t, uint16_t x)
{
    return (int32_t)(uint16_t)(x ^ t->turn);
}

static bool beyond(const struct threshold *t, uint16_t value, uint16_t limit)
{
    return facing(t, value) > facing(t, limit) - (int32_t)t->inclusive;
}

/* Never true while the value is still beyond the limit: at the ends of the
 * range (or through the NTC table's clamping) the clear level can land on the
 * wrong side of the limit, and the bit would then flap every 100 ms. */
static bool back_inside(const struct threshold *t, struct monitor *m, uint16_t value,
                        uint16_t limit)
{
    if (!m->level_known || m->limit != limit) {
        m->limit = limit;
        m->clear_level = t->clear_level(limit);
        m->level_known = 1;
    }
    return facing(t, value) <= facing(t, m->clear_level) && !beyond(t, value, limit);
}

/* Debounce: trip after samples[0] samples beyond, clear after samples[1]
 * back inside. towards: the sample counts towards the other state (beyond
 * while clear, back inside while set); the caller works out only that one.
 * Returns whether the state changed. */
static bool step(struct monitor *m, bool towards, const uint16_t samples[2])
{
    if (!towards) { /* most ticks */
        m->count = 0;
        return false;
    }
    m->count = (uint16_t)(m->count + 1u);
    if (m->count < samples[m->active]) {
        return false;
    }
    m->active = (uint8_t)!m->active;
    m->count = 0;
    return true;
}

static void judge(struct protection *p, const struct user_config *cfg,
                  const struct sensor_readings *readings, unsigned row, const uint16_t samples[2])
{
    const struct threshold *t = &thresholds[row];
    uint16_t value = field_u16(readings, t->reading);
    uint16_t limit = field_u16(cfg, t->limit);
    struct monitor *m = &p->mon[row];
    if (step(m, m->active ? back_inside(t, m, value, limit) : beyond(t, value, limit), samples)) {
        p->threshold_bits = (uint8_t)(p->threshold_bits ^ t->bit);
        p->act_changes++;
    }
}

/* Stalled: at the limit and slower than STALL_SPEED_Q8 the way it pushes,
 * which takes in turning the other way (a load stronger than the motor) as
 * well as standing still. */
uint8_t protection_watch_stall(struct protection *p, const struct user_config *cfg,
                               int8_t output_at_limit, int32_t speed_q8, uint32_t motion_commands)
{
    static const uint16_t stall_samples[2] = {STALL_TICKS, PROTECT_CLEAR_TICKS};
    int32_t pushed_way = output_at_limit > 0 ? speed_q8 : -speed_q8;
    bool stalled = output_at_limit != 0 && pushed_way < STALL_SPEED_Q8;
    if (!stalled && !p->stall_busy) {
        return 0; /* at the limit and moving: nothing counted, set or latched */
    }
    struct monitor *stall = &p->stall;
    bool was_stalled = stall->active;
    bool tripped = step(stall, was_stalled ? !stalled : stalled, stall_samples) && !was_stalled;
    p->act.release_now = false; /* once */
    uint16_t cap = 0;
    if (!cfg->stall_release) {
        p->stall_latched = 0;
        cap = stall->active ? cfg->stall_power_mw : 0u;
    } else if (tripped) {
        /* Released, nothing pushes and the stall cannot be seen to end: the
         * bit holds until the next motion command. */
        p->stall_latched = 1;
        p->commands_at_stall = motion_commands;
        p->act.release_now = true;
    } else if (p->stall_latched && motion_commands != p->commands_at_stall) {
        p->stall_latched = 0;
        *stall = (struct monitor){0};
    }
    if (p->act.power_cap_mw != cap) {
        p->act.power_cap_mw = cap;
        p->act_changes++;
    }
    p->stall_busy = (stall->count | stall->active | p->stall_latched) != 0u;
    uint8_t shown = cfg->stall_release ? p->stall_latched : stall->active;
    if (shown != p->stall_shown) {
        p->stall_shown = shown;
        p->act_changes++; /* what holds the output back may have changed */
    }
    return shown ? STATUS_STALL : 0u;
}

/* The quiet case inline where speed comes first (a clear monitor, its
 * reading within the limit: most ticks), the rest in judge(); all of it in
 * judge() where size does (SERVO_SIZE_FIRST: the Cortex-M0). */
#ifdef SERVO_SIZE_FIRST
#define watch judge
#else
static inline __attribute__((always_inline)) void watch(struct protection *p,
                                                        const struct user_config *cfg,
                                                        const struct sensor_readings *readings,
                                                        unsigned row, const uint16_t samples[2])
{
    const struct threshold *t = &thresholds[row];
    struct monitor *m = &p->mon[row];
    if (!m->active && !beyond(t, field_u16(readings, t->reading), field_u16(cfg, t->limit))) {
        m->count = 0;
        return;
    }
    judge(p, cfg, readings, row, samples);
}
#endif

uint8_t protection_update(struct protection *p, const struct user_config *cfg,
                          const struct sensor_readings *readings, enum sense_slot slot)
{
    watch(p, cfg, readings, MON_CURRENT, samples_every_tick);
    const uint8_t *rows = slot_rows[slot];
    for (unsigned row = rows[0]; row < rows[1]; row++) {
        watch(p, cfg, readings, row, samples_once_a_round);
    }
    return p->threshold_bits;
}
