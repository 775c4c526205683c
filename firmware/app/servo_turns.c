/* Bus turn-taking (servo_jobs.h): an answer goes out at once, after the
 * servos listed before this one in a Sync Monitor, or in this ID's slot
 * for a finished move. */
#include <stdbool.h>

#include "app/servo_jobs.h"

static void start_send(struct servo *s)
{
    s->tx.waiting = 0;
    s->tx.sending = 1;
    s->hal->bus.send(s->hal->ctx, frame_tx_bytes(&s->tx.frame), frame_tx_size(&s->tx.frame));
}

/* Sync Monitor: each listed servo answers after the ones listed before it.
 * A turn passes when their response has gone by, or when the line has been
 * silent for SYNC_SLOT_SILENCE_US (that servo is absent). */
SERVO_JOB void servo_wait_for_turn(struct servo *s, uint32_t now)
{
    uint32_t seen = s->rx.stats.responses_skipped - s->tx.responses_base;
    uint32_t last_byte = s->hal->rx->heard_us;
    if (now - last_byte < now - s->tx.silence_from_us) {
        s->tx.silence_from_us = last_byte; /* the line was busy since */
    }
    /* The answer on the line is the last before this turn and ends sooner
     * than a tick and a pass take: a tick started now would hold the turn
     * back (on the M0 a tick is 4 byte times at 1 Mbaud), so a tick due
     * waits for this servo's answer to start, a tick and a pass at most
     * (the schedule stays: the tick after is due on time). */
    bool imminent = seen + 1u >= s->tx.turns_left &&
                    frame_rx_skip_ends_within(&s->rx, s->turn_guard_bytes);
    s->tick_due_us = s->next_tick_us + (imminent ? s->hal->tick_and_pass_us : 0u);
    if (seen >= s->tx.turns_left) {
        start_send(s);
    } else if (now - s->tx.silence_from_us >= SYNC_SLOT_SILENCE_US) {
        s->tx.turns_left--;
        s->tx.silence_from_us = now;
    }
}

/* s->tx.frame holds the response, sealed. */
SERVO_JOB void servo_queue_response(struct servo *s, uint8_t wait, uint32_t responses_base, uint32_t now)
{
    if (wait == 0u) {
        start_send(s); /* the turn's bookkeeping is for a wait only */
        return;
    }
    s->tx.turns_left = wait;
    s->tx.responses_base = responses_base;
    s->tx.requests_base = s->rx.stats.requests_seen;
    s->tx.silence_from_us = now;
    s->tx.waiting = 1;
}

/* Nobody asked for a "move finished" answer just now, so nobody has left
 * the line free for it: it goes out in this ID's slot (servo.h). Divides
 * while an answer waits, once a pass. */
static bool in_unsolicited_slot(const struct servo *s, uint32_t now)
{
    uint32_t heard = now - s->hal->rx->heard_us;
    uint32_t said = now - s->tx.ended_us;
    uint32_t quiet = heard < said ? heard : said;
    if (quiet < s->unsolicited_first_us) {
        return false;
    }
    uint32_t cycle = UNSOLICITED_SLOTS * s->unsolicited_slot_us;
    return (quiet - s->unsolicited_first_us) % cycle < UNSOLICITED_WINDOW_US;
}

SERVO_JOB void servo_answer_finished_move(struct servo *s, uint32_t now)
{
    if (!motion_has_finished(&s->motion) || !in_unsolicited_slot(s, now)) {
        return;
    }
    uint8_t packet = motion_take_finished(&s->motion);
    if (packet == 0u) {
        return;
    }
    struct response *r = &s->tx.frame;
    r->code = packet;
    r->length = 2;
    r->content[0] = s->active_id;
    r->content[1] = 1;
    (void)frame_tx_seal(r);
    servo_queue_response(s, 0, 0, now);
}
