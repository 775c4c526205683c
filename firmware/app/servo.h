/* The servo core: framer, dispatcher, register file, motion and config
 * store wired together over one hal_port. Every build of the firmware (MCU
 * image, host simulator, fuzzer, benchmark) runs this same code. */
#ifndef APP_SERVO_H
#define APP_SERVO_H

#include <stdbool.h>
#include <stdint.h>

#include "app/servo_state.h"

void servo_init(struct servo *s, const struct hal_port *hal);

/* A byte off the wire into the port's receive ring, as a receive
 * interrupt would put it (simulator, tests). */
static inline void servo_on_rx_byte(struct servo *s, uint8_t byte, uint32_t now_us)
{
    hal_rx_ring_put(s->hal->rx, byte, now_us);
}

/* Main loop: one pass over every pending job, the control tick when it is
 * due among them. Never blocks. */
void servo_poll(struct servo *s);

/* Whether the main loop may sleep until the next interrupt: nothing left
 * for a pass to do before one comes. Call it with interrupts masked and
 * sleep (WFI) in the same masked stretch, so that an interrupt after the
 * check still ends the sleep. */
bool servo_may_sleep(struct servo *s);
/* Whether the main loop, awake, has nothing to do but frame bytes as they
 * land (servo_may_sleep's answer but for a line in use): a simulator need
 * run no pass until a byte lands, the tick or a transmission's end. */
bool servo_awaits_bytes(struct servo *s);

/* One control tick: sensors, protection, motion. servo_poll runs it every
 * CONTROL_TICK_US. */
void servo_control_tick(struct servo *s);

#endif
