/* The bus watchdog (items 64 and 65): a host that stops talking to a
 * driven servo does not leave it driving. Fed by every frame for this
 * servo (its ID, a broadcast, its SyncCommand record); checked once a
 * control tick. Off (64 = 0) it costs a load and a branch a tick. */
#ifndef PROTECTION_BUS_WATCHDOG_H
#define PROTECTION_BUS_WATCHDOG_H

#include <stdbool.h>
#include <stdint.h>

enum watchdog_action {
    WATCHDOG_HOLD = 0,
    WATCHDOG_DAMP = 1,
    WATCHDOG_RELEASE = 2,
};

struct bus_watchdog {
    uint32_t heard;        /* frames for this servo so far (the dispatcher's count) */
    uint32_t heard_seen;   /* the count at the last tick */
    uint16_t silent_ticks; /* ticks since the count last moved */
    uint8_t fired;         /* acted; the caller clears it at the next motion command */
    uint32_t commands_at_fire; /* motion commands when it acted */
};

/* One control tick. timeout_ms: item 64 (0 off); driven: the output is
 * under position control; heard: frames for this servo so far; commands:
 * motion commands so far (kept with the act, so that the caller can tell
 * a new one). True once, on the tick the watchdog acts: the caller then
 * stops the motion as item 65 says. */
bool bus_watchdog_tick(struct bus_watchdog *w, uint16_t timeout_ms, bool driven, uint32_t heard,
                       uint32_t commands);

/* Another monitor acted for it (the oscillation monitor): the latch is
 * set as if it had, until a motion command after commands. */
static inline void bus_watchdog_latch(struct bus_watchdog *w, uint32_t commands)
{
    w->fired = 1;
    w->commands_at_fire = commands;
}

/* After a frame while the latch is set: a motion command since it acted
 * clears it. True if it did. */
static inline bool bus_watchdog_command(struct bus_watchdog *w, uint32_t commands)
{
    if (commands == w->commands_at_fire) {
        return false;
    }
    w->fired = 0;
    return true;
}

#endif
