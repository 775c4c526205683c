/* The servo core's safety parts (servo_safety.c, docs/safety.md): the bus
 * watchdog, the winding's model and its derating, what holds the output
 * back (item 67) and what goes into the fault history. Its state is its
 * own (struct servo_safety); the register file and the motion are handed
 * in at each call; the port, the monitors, the fault history and the
 * operating time once (safety_init). */
#ifndef APP_SERVO_SAFETY_H
#define APP_SERVO_SAFETY_H

#include <stdint.h>

#include "hal/hal_port.h"
#include "motion/motion.h"
#include "protection/bus_watchdog.h"
#include "protection/protection.h"
#include "protection/winding.h"
#include "registers/registers.h"
#include "storage/fault_log.h"
#include "storage/save_policy.h"

/* Fault resets in a row (hal_reset.in_row) that put the servo in safe
 * mode: the output held off, the bus answered (item 75, docs/safety.md). */
#define SAFE_MODE_RESETS HAL_SAFE_MODE_RESETS

/* What the safety parts log a fault into: the history, and the operating
 * time its entries carry. */
struct safety_log {
    struct fault_log *faults;
    const struct save_policy *clock;
};

struct servo_safety {
    uint16_t heat_cap_mw;        /* the derating's power cap; 0 = none */
    uint8_t heat_ticks;          /* ticks towards the winding's next sample */
    uint8_t fault_bits_seen;     /* status bits 2-7 as the fault history last saw them */
    struct bus_watchdog watchdog;
    struct winding_model winding;
    /* Handed in once (safety_init): the port (its calibration and stack
     * watch), the monitors (a new cap of the derating's redoes their guard:
     * protection_note_act_change), where faults are logged. */
    const struct hal_port *hal;
    struct protection *protection;
    struct safety_log log;
};

/* After the fault history's load: what it is handed, the winding's model,
 * the reset the board read (hal->reset: logged, counted into regs; safe
 * mode, which p's guard takes at the first tick). */
void safety_init(struct servo_safety *sf, struct registers *regs, struct protection *p,
                 struct safety_log log, const struct hal_port *hal);
/* After a frame, while the watchdog has acted: a motion command (commands,
 * the motion's count) clears it at once (what item 67 and ReadMotion say
 * with it). */
void safety_after_frame(struct servo_safety *sf, struct registers *regs, uint32_t commands);
/* In the pass of each control tick, after it. heard: the frames for this
 * servo so far (the dispatcher's count), the bus watchdog's food. */
void safety_tend(struct servo_safety *sf, struct registers *regs, struct motion *m, uint32_t heard);
/* The protection's action changed: the output's guard (the tighter of the
 * stall's and the derating's caps) and what holds it back, from bits
 * (status bits 2-7). */
void safety_guard(const struct servo_safety *sf, struct registers *regs, struct motion *m,
                  const struct protection *p, uint8_t bits);

#endif
