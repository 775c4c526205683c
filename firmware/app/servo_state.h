/* The servo core's state (struct servo): the main loop's own, and each
 * job's (safety, the store's upkeep, the bus's turns) beside the modules
 * it wires together. Only servo.c and the builds around it (boards, tests)
 * use it; a job is handed what it needs. The operations: servo.h. */
#ifndef APP_SERVO_STATE_H
#define APP_SERVO_STATE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "app/servo_safety.h"
#include "app/servo_store.h"
#include "app/servo_turns.h"
#include "hal/hal_port.h"
#include "motion/motion.h"
#include "protection/protection.h"
#include "protocol/dispatcher.h"
#include "protocol/frame_rx.h"
#include "registers/registers.h"
#include "sensors/scaling.h"
#include "storage/config_store.h"
#include "storage/fault_log.h"

/* Ticks a late main loop catches up before it drops the rest. */
#define SERVO_MAX_CATCH_UP 4u
/* While the line has been heard this recently the main loop does not sleep:
 * a request is framed as its bytes land, and its answer leaves within two
 * byte times of its end (docs/sleep.md, "The first answer"). */
#define SERVO_AWAKE_AFTER_LINE_US UNSOLICITED_QUIET_US
/* Control tick period. */
#define CONTROL_TICK_US (1000000u / MOTION_TICK_HZ)

/* What two places call, as one copy on the Cortex-M0, whose flash is full
 * (a call more on the answer's path); inlined elsewhere. */
#if defined(__ARM_ARCH_6M__)
#define SERVO_ONE_COPY __attribute__((noinline))
#else
#define SERVO_ONE_COPY inline __attribute__((always_inline))
#endif

/* servo.c hands the fault log's read to the dispatcher: an entry is its
 * ReadFaults bytes. */
_Static_assert(FAULT_ENTRY_BYTES == READ_FAULTS_ENTRY_BYTES, "a logged fault is its ReadFaults bytes");

/* servo.c copies the readings into the status area at once. */
_Static_assert(offsetof(struct status_area, current_ma) - offsetof(struct status_area, voltage_mv) ==
                   offsetof(struct sensor_readings, current_ma) &&
               offsetof(struct status_area, power_mw) - offsetof(struct status_area, voltage_mv) ==
                   offsetof(struct sensor_readings, power_mw) &&
               offsetof(struct status_area, temperature_adc) - offsetof(struct status_area, voltage_mv) ==
                   offsetof(struct sensor_readings, temperature_adc) &&
               offsetof(struct sensor_readings, voltage_mv) == 0 &&
               sizeof(struct sensor_readings) == 8,
               "the status area's IDs 1-4 lie as struct sensor_readings");

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
    uint8_t guard_seen;          /* protection.act_changes the motion has */
    uint32_t polled_us;          /* the last pass's clock reading */
    uint32_t ticks_dropped;      /* control ticks skipped by a late main loop */
    uint32_t sync_turns_abandoned; /* Sync Monitor answers dropped for a new request */
    uint32_t rx_lost;            /* bytes the DMA wrote over before the main loop took them */
    uint32_t answers_dropped;    /* answers not sent: they would have left late */
    /* The jobs, each its own state: the safety parts, the store's upkeep,
     * the bus's turns. */
    struct servo_safety safety;
    struct servo_store saving;
    struct servo_tx tx;
    struct frame_rx rx;
    struct registers regs;
    struct motion motion;
    struct dispatcher dispatcher;
    struct config_store store;
    struct sensor_filter sensors;
    struct protection protection;
    struct fault_log faults;
};

/* The control loop's next tick is due at next_tick_us: the turns' deadline,
 * and the dispatcher's stamp for the state the last tick left (set when the
 * schedule moves, not at each request: a request's path stays short). */
static inline void tick_scheduled(struct servo *s)
{
    s->tick_due_us = s->next_tick_us;
    dispatcher_note_tick(&s->dispatcher, s->next_tick_us - CONTROL_TICK_US);
}

#endif
