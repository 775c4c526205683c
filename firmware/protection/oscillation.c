#include "protection/oscillation.h"

#include "protection/protection.h"

bool oscillation_watch(struct oscillation_monitor *o, int32_t error_q8, int32_t velocity_q8,
                       int8_t at_limit, int32_t kv, int32_t duty_limit, uint16_t limit_ms)
{
    int8_t back = error_q8 > 0 ? 1 : -1; /* the way to the setpoint */
    if (error_q8 * back <= OSCILLATION_AMPLITUDE_Q8) {
        if (++o->quiet_ticks >= OSCILLATION_QUIET_TICKS) {
            o->quiet_ticks = 0;
            o->away_ticks = 0;
        }
        return false;
    }
    o->quiet_ticks = 0;
    int32_t away = -velocity_q8 * back;
    if (away <= STALL_SPEED_Q8) {
        return false;
    }
    /* The output pushing back at its limit, below the speed where the
     * limit's band (the back-EMF of kv, +-duty_limit) turns the duty the
     * way the horn runs: a stronger load, the stall monitor's. */
    away = away > UINT16_MAX ? UINT16_MAX : away;
    if (at_limit == back && (int32_t)(((uint32_t)away * (uint32_t)kv) >> 8) <= duty_limit) {
        return false;
    }
    return ++o->away_ticks >= limit_ms;
}
