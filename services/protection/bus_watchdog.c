#include "protection/bus_watchdog.h"

/* A tick is 1 ms, so the count of silent ticks is the silence in ms, to
 * within the tick the last frame fell in: the watchdog acts within
 * timeout + 1 tick of the last frame. */
bool bus_watchdog_tick(struct bus_watchdog *w, uint16_t timeout_ms, bool driven, uint32_t heard,
                       uint32_t commands)
{
    if (heard != w->heard_seen) {
        w->heard_seen = heard;
        w->silent_ticks = 0;
    } else if (w->silent_ticks != UINT16_MAX) {
        w->silent_ticks++;
    }
    if (timeout_ms == 0u || !driven || w->fired || w->silent_ticks < timeout_ms) {
        return false;
    }
    w->fired = 1;
    w->commands_at_fire = commands;
    return true;
}
