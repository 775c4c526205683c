/* The servo core's state (struct servo) and its timing constants: what
 * servo.c and servo_safety.c share. The operations: servo.h. */
#ifndef APP_SERVO_STATE_H
#define APP_SERVO_STATE_H

#include <stdbool.h>
#include <stdint.h>

#include "storage/config_store.h"
#include "storage/fault_log.h"
#include "storage/save_policy.h"
#include "hal/hal_port.h"
#include "protection/bus_watchdog.h"
#include "protection/protection.h"
#include "protection/winding.h"
#include "sensors/scaling.h"
#include "motion/motion.h"
#include "protocol/dispatcher.h"
#include "protocol/frame_rx.h"
#include "protocol/frame_tx.h"
#include "registers/registers.h"

/* Silence after which a SyncCommand Monitor turn-taker stops waiting for a
 * servo listed before it that does not answer. */
#define SYNC_SLOT_SILENCE_US 3000u
/* Unsolicited answers (a finished move, 33 = 1) go out in time slots, one
 * per ID, counted from the end of the last activity on the line, so two
 * servos never start together (docs/decisions.md, "Sharing the bus"):
 *   slot of ID i, cycle k:  last activity + QUIET + (k x 254 + i) x SLOT
 * QUIET is longer than a Sync Monitor slot, so a round in progress is never
 * cut into. A servo starts only within the first UNSOLICITED_WINDOW_US of
 * its slot (longer than the main loop's longest pass, a tick and an
 * answer); SLOT adds two byte times, by which the next ID has heard the
 * first byte, and a guard for the drift of two crystals. */
#define UNSOLICITED_QUIET_US (SYNC_SLOT_SILENCE_US + 1000u)
#define UNSOLICITED_WINDOW_US 300u
#define UNSOLICITED_DRIFT_GUARD_US 50u
#define UNSOLICITED_SLOTS 254u
/* The other flash page is erased, a 20-40 ms CPU stall (DS5319, tERASE),
 * only at power-up and while the output is released (nothing held against
 * a load) and the line has been quiet for STORE_ERASE_QUIET_US; never on a
 * host's schedule. A change that needs it meanwhile is refused with its
 * reason (docs/decisions.md, "The config store"). The DMA goes on writing
 * through the stall, but the laps it completes then cannot be counted: at
 * a baud rate whose STORE_ERASE_MAX_US of bytes the ring cannot hold (the
 * Cortex-M0 board above 115200), what came in is dropped and counted as
 * lost once the ring has wrapped (after_erase). */
#define STORE_ERASE_QUIET_US 100000u
#define STORE_ERASE_MAX_US 40000u
/* Ticks a late main loop catches up before it drops the rest. */
#define SERVO_MAX_CATCH_UP 4u
/* While the line has been heard this recently the main loop does not sleep:
 * a request is framed as its bytes land, and its answer leaves within two
 * byte times of its end (docs/sleep.md, "The first answer"). */
#define SERVO_AWAKE_AFTER_LINE_US UNSOLICITED_QUIET_US
/* Control tick period. */
#define CONTROL_TICK_US (1000000u / MOTION_TICK_HZ)

struct servo_tx {
    uint8_t sending;           /* handed to the UART, not yet off the wire */
    uint8_t waiting;           /* ready, waiting for its turn (sync Monitor) */
    uint8_t turns_left;        /* other responses still to let pass */
    uint32_t responses_base;   /* framer's response count at the request */
    uint32_t requests_base;    /* framer's request count when it began to wait */
    uint32_t silence_from_us;  /* start of the current wait for a turn */
    uint32_t ended_us;         /* when the last response left the wire */
    struct response frame;     /* built in place, sent from here */
};

/* The scalars first, then the small structs, then the large ones: on the
 * Cortex-M0 a field is reached by an immediate offset only within the
 * first 32 bytes (a byte), 64 (a half-word) or 128 (a word) of the struct;
 * one further away costs a literal and a register at each use. */
struct servo {
    const struct hal_port *hal;
    uint32_t next_tick_us;       /* the control tick's schedule */
    uint32_t tick_due_us;        /* when it runs: later while a Sync Monitor turn is near */
    uint32_t rx_idle_us;         /* line idle this long drops a partial frame */
    struct dispatch_result dispatched; /* the last frame's (servo.c, handle_next_frame) */
    volatile uint8_t active_id;  /* the ID answered to now */
    uint8_t active_baud_index;
    uint8_t link_settings_pending; /* the user area changed: ID or baud may have */
    uint8_t enter_bootloader;    /* UpdateEnter taken: restart once the answer is out */
    uint8_t erase_passed;        /* a page erase stalled the CPU in the last pass */
    uint8_t ring_covers_erase;   /* the ring holds an erase's bytes at this baud */
    uint8_t turn_guard_bytes;    /* a tick and a pass, in byte times at this baud */
    uint8_t heat_ticks;          /* ticks towards the winding's next sample */
    uint8_t fault_bits_seen;     /* status bits 2-7 as the fault history last saw them */
    uint8_t guard_seen;          /* protection.act_changes the motion has */
    uint16_t heat_cap_mw;        /* the derating's power cap; 0 = none */
    uint32_t erase_from;         /* the ring's written count as the erase began */
    uint32_t polled_us;          /* the last pass's clock reading */
    uint32_t ticks_dropped;      /* control ticks skipped by a late main loop */
    uint32_t sync_turns_abandoned; /* Sync Monitor answers dropped for a new request */
    uint32_t rx_lost;            /* bytes the DMA wrote over before the main loop took them */
    uint32_t answers_dropped;    /* answers not sent: they would have left late */
    uint32_t unsolicited_slot_us;  /* slot length at this baud */
    uint32_t unsolicited_first_us; /* quiet ahead of this ID's first slot */
    struct bus_watchdog watchdog;
    struct save_policy saver;
    struct servo_tx tx;
    struct frame_rx rx;
    struct registers regs;
    struct motion motion;
    struct dispatcher dispatcher;
    struct config_store store;
    struct sensor_filter sensors;
    struct protection protection;
    struct winding_model winding;
    struct fault_log faults;
};

#endif
