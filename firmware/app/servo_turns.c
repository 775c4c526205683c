/* Bus turn-taking (servo_turns.h): an answer goes out at once, after the
 * servos listed before this one in a Sync Monitor, or in this ID's slot
 * for a finished move. */
#include "app/servo_turns.h"

#include <stdbool.h>
#include <stddef.h>

static void start_send(struct servo_tx *t, const struct hal_port *hal)
{
    t->waiting = 0;
    t->sending = 1;
    hal->bus.send(hal->ctx, frame_tx_bytes(&t->frame), frame_tx_size(&t->frame));
}

/* Sync Monitor: each listed servo answers after the ones listed before it.
 * A turn passes when their response has gone by, or when the line has been
 * silent for SYNC_SLOT_SILENCE_US (that servo is absent). */
uint32_t turns_wait(struct servo_tx *t, const struct hal_port *hal,
                    const struct frame_rx *rx, uint8_t guard_bytes, uint32_t now)
{
    uint32_t seen = rx->stats.responses_skipped - t->responses_base;
    uint32_t last_byte = hal->rx->heard_us;
    if (now - last_byte < now - t->silence_from_us) {
        t->silence_from_us = last_byte; /* the line was busy since */
    }
    /* The answer on the line is the last before this turn and ends sooner
     * than a tick and a pass take: a tick started now would hold the turn
     * back (on the M0 a tick is 4 byte times at 1 Mbaud), so a tick due
     * waits for this servo's answer to start, a tick and a pass at most
     * (the schedule stays: the tick after is due on time). */
    bool imminent = seen + 1u >= t->turns_left && frame_rx_skip_ends_within(rx, guard_bytes);
    if (seen >= t->turns_left) {
        start_send(t, hal);
    } else if (now - t->silence_from_us >= SYNC_SLOT_SILENCE_US) {
        t->turns_left--;
        t->silence_from_us = now;
    }
    return imminent ? hal->tick_and_pass_us : 0u;
}

void turns_queue(struct servo_tx *t, const struct hal_port *hal, const struct frame_rx *rx,
                 uint8_t wait, uint32_t responses_base, uint32_t now)
{
    if (wait == 0u) {
        start_send(t, hal); /* the turn's bookkeeping is for a wait only */
        return;
    }
    t->turns_left = wait;
    t->responses_base = responses_base;
    t->requests_base = rx->stats.requests_seen;
    t->silence_from_us = now;
    t->waiting = 1;
}

/* Nobody asked for a "move finished" answer just now, so nobody has left
 * the line free for it: it goes out in this ID's slot (servo_turns.h).
 * Divides while an answer waits, once a pass. */
static bool in_unsolicited_slot(const struct servo_tx *t, const struct hal_port *hal, uint32_t now)
{
    uint32_t heard = now - hal->rx->heard_us;
    uint32_t said = now - t->ended_us;
    uint32_t quiet = heard < said ? heard : said;
    if (quiet < t->first_slot_us) {
        return false;
    }
    uint32_t cycle = UNSOLICITED_SLOTS * t->slot_us;
    return (quiet - t->first_slot_us) % cycle < UNSOLICITED_WINDOW_US;
}

void turns_answer_finished_move(struct servo_tx *t, const struct hal_port *hal,
                                struct motion *m, uint8_t id, uint32_t now)
{
    if (!motion_has_finished(m) || !in_unsolicited_slot(t, hal, now)) {
        return;
    }
    uint8_t packet = motion_take_finished(m);
    if (packet == 0u) {
        return;
    }
    struct response *r = &t->frame;
    r->code = packet;
    r->length = 2;
    r->content[0] = id;
    r->content[1] = 1;
    (void)frame_tx_seal(r);
    turns_queue(t, hal, NULL, 0, 0, now);
}
