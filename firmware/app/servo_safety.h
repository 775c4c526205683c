/* The servo core's safety parts (servo_safety.c, docs/safety.md): the bus
 * watchdog, the winding's model and its derating, what holds the output
 * back (item 67) and the fault history. */
#ifndef APP_SERVO_SAFETY_H
#define APP_SERVO_SAFETY_H

#include <stdint.h>

#include "app/servo_state.h"

/* Fault resets in a row (hal_reset.in_row) that put the servo in safe
 * mode: the output held off, the bus answered (item 75, docs/safety.md). */
#define SAFE_MODE_RESETS HAL_SAFE_MODE_RESETS

/* After the store's load and the dispatcher's init: the fault history,
 * the reset the board read (logged, counted; safe mode) and the history's
 * packets' hooks. */
void safety_init(struct servo *s);
/* After a frame, while the watchdog has acted: a motion command clears it
 * at once (what item 67 and ReadMotion say with it). */
void safety_after_frame(struct servo *s);
/* In the pass of each control tick, after it. */
void safety_tend(struct servo *s);
/* The protection's action changed: the output's guard (the tighter of the
 * stall's and the derating's caps) and what holds it back, from bits
 * (status bits 2-7). */
void safety_guard(struct servo *s, uint8_t bits);

#endif
