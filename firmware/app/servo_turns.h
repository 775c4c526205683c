/* Bus turn-taking (servo_turns.c): an answer goes out at once, after the
 * servos listed before this one in a Sync Monitor, or in this ID's slot
 * for a finished move. Its state is its own (struct servo_tx); what it
 * reads of the port, the framer and the motion is handed in. */
#ifndef APP_SERVO_TURNS_H
#define APP_SERVO_TURNS_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_port.h"
#include "motion/motion.h"
#include "protocol/frame_rx.h"
#include "protocol/frame_tx.h"

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

struct servo_tx {
    uint8_t sending;           /* handed to the UART, not yet off the wire */
    uint8_t waiting;           /* ready, waiting for its turn (sync Monitor) */
    uint8_t turns_left;        /* other responses still to let pass */
    uint32_t responses_base;   /* framer's response count at the request */
    uint32_t requests_base;    /* framer's request count when it began to wait */
    uint32_t silence_from_us;  /* start of the current wait for a turn */
    uint32_t ended_us;         /* when the last response left the wire */
    uint32_t slot_us;          /* a finished move's slot length at this baud */
    uint32_t first_slot_us;    /* quiet ahead of this ID's first slot */
    struct response frame;     /* built in place, sent from here */
};

/* A new ID or byte time (us, rounded up): the finished move's slots. */
static inline void turns_set_link(struct servo_tx *t, uint8_t id, uint32_t byte_us)
{
    t->slot_us = UNSOLICITED_WINDOW_US + 2u * byte_us + UNSOLICITED_DRIFT_GUARD_US;
    t->first_slot_us = UNSOLICITED_QUIET_US + (uint32_t)id * t->slot_us;
}

/* The UART says the response has left the wire. */
static inline void turns_sent(struct servo_tx *t, uint32_t now)
{
    t->sending = 0;
    t->ended_us = now;
}

/* A new request while a Sync Monitor answer waits: the host has given up
 * on that round; the answer is dropped. */
static inline void turns_abandon(struct servo_tx *t)
{
    t->waiting = 0;
}

/* Nothing on its way or waiting, and nothing sent for quiet_us. */
static inline bool turns_quiet_for(const struct servo_tx *t, uint32_t now, uint32_t quiet_us)
{
    return !t->sending && !t->waiting && now - t->ended_us >= quiet_us;
}

/* t->frame holds the response, sealed: it goes out now (wait 0) or after
 * wait other servos' responses (Sync Monitor); rx: the framer, whose
 * request count a wait starts from. */
void turns_queue(struct servo_tx *t, const struct hal_port *hal, const struct frame_rx *rx,
                 uint8_t wait, uint32_t responses_base, uint32_t now);
/* A queued response waits for its Sync Monitor turn: once a pass.
 * guard_bytes: a tick and a pass in byte times. Returns how long a control
 * tick due waits (0, or a tick and a pass while this turn is imminent). */
uint32_t turns_wait(struct servo_tx *t, const struct hal_port *hal,
                    const struct frame_rx *rx, uint8_t guard_bytes, uint32_t now);
/* A finished move's answer, in this ID's slot of a quiet line. */
void turns_answer_finished_move(struct servo_tx *t, const struct hal_port *hal,
                                struct motion *m, uint8_t id, uint32_t now);

#endif
