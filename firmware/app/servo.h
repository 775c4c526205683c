/* The servo core: framer, dispatcher, register file, motion and config
 * store wired together over one hal_port. Every build of the firmware (MCU
 * image, host simulator, fuzzer, benchmark) runs this same code. */
#ifndef APP_SERVO_H
#define APP_SERVO_H

#include <stdbool.h>
#include <stdint.h>

#include "config_store.h"
#include "hal/hal_port.h"
#include "protection.h"
#include "scaling.h"
#include "motion/motion.h"
#include "protocol/dispatcher.h"
#include "protocol/frame_rx.h"
#include "protocol/frame_tx.h"
#include "protocol/registers.h"

/* Silence after which a SyncCommand Monitor turn-taker stops waiting for a
 * servo listed before it that does not answer. */
#define SYNC_SLOT_SILENCE_US 3000u
/* Ticks a late main loop catches up before it drops the rest. */
#define SERVO_MAX_CATCH_UP 4u
/* Control tick period. */
#define CONTROL_TICK_US (1000000u / MOTION_TICK_HZ)

struct servo_tx {
    uint8_t frame[RESPONSE_FRAME_MAX];
    uint8_t size;
    uint8_t sending;           /* handed to the UART, not yet off the wire */
    uint8_t waiting;           /* ready, waiting for its turn (sync Monitor) */
    uint8_t turns_left;        /* other responses still to let pass */
    uint32_t responses_base;   /* framer's response count at the request */
    uint32_t silence_from_us;  /* start of the current wait for a turn */
};

struct servo {
    const struct hal_port *hal;
    struct frame_rx rx;
    struct registers regs;
    struct motion motion;
    struct dispatcher dispatcher;
    struct config_store store;
    struct servo_tx tx;
    struct sensor_filter sensors;
    struct protection protection;
    uint32_t next_tick_us;       /* when the next control tick is due */
    uint32_t ticks_dropped;      /* control ticks skipped by a late main loop */
    volatile uint8_t active_id;  /* the ID answered to now */
    uint8_t active_baud_index;
    uint8_t config_dirty;
};

void servo_init(struct servo *s, const struct hal_port *hal);

/* Receive interrupt: one byte off the wire. */
static inline void servo_on_rx_byte(struct servo *s, uint8_t byte, uint32_t now_us)
{
    frame_rx_feed(&s->rx, byte, now_us);
}

/* Main loop: one pass over every pending job, the control tick when it is
 * due among them. Never blocks. */
void servo_poll(struct servo *s);

/* One control tick: sensors, protection, motion. servo_poll runs it every
 * CONTROL_TICK_US. */
void servo_control_tick(struct servo *s);

#endif
