#include "protocol/dispatcher.h"

#include <stddef.h>

#include "protocol/packet_codes.h"
#include "protocol/packet_table.h"
#include "protocol/wire.h"

void dispatcher_init(struct dispatcher *d, struct registers *regs, struct motion *motion,
                     const volatile uint8_t *own_id)
{
    d->regs = regs;
    d->motion = motion;
    d->own_id = own_id;
}

static void set_command_error(struct dispatcher *d, bool on)
{
    uint8_t s = d->regs->status.status;
    d->regs->status.status =
        on ? (uint8_t)(s | STATUS_COMMAND_ERROR) : (uint8_t)(s & ~STATUS_COMMAND_ERROR);
}

static bool answers(const struct dispatcher *d, uint8_t flags)
{
    return (flags & PF_ANSWERS) ||
           ((flags & PF_ANSWERS_IF_CONTROL_RESPONSE) && d->regs->user.control_response);
}

/* Runs one packet for this servo: a frame's, or the record a SyncCommand
 * carries for it. */
static void dispatch_packet(const struct packet_desc *desc, struct packet_call *call,
                            struct response *response, struct packet_origin origin)
{
    /* origin: the caller's copy, in registers (the call's escapes to the
     * handler, so each of its fields would be loaded again after a store). */
    call->origin = origin;
    struct dispatcher *d = call->d;
    d->heard++;
    /* Answering packets would make every servo talk at once. */
    if (origin.broadcast && !(desc->flags & PF_BROADCAST)) {
        return;
    }
    bool alone = !origin.broadcast && !origin.from_sync;
    call->code = desc->code;
    call->answer_when_done = alone && d->regs->user.control_response;
    response->code = desc->code;
    /* Every answer starts with the ID its request carried (content points
     * into a frame or a sync record, never at less than one byte). */
    response->content[0] = call->content[0];

    enum packet_outcome outcome = desc->handler(call, response);
    if (outcome == OUTCOME_NONE) {
        return;
    }
    bool failed = outcome == OUTCOME_FAILED || outcome == OUTCOME_ERROR;
    if (failed || !(desc->flags & PF_QUERY)) {
        set_command_error(d, failed);
    }
    /* Sync records answer only where the packet always answers (Monitor). */
    bool may_answer = alone || (origin.from_sync && (desc->flags & PF_ANSWERS)) ||
                      (origin.broadcast && (desc->flags & PF_ONE_ANSWERS));
    struct dispatch_result *result = call->result;
    result->answer = may_answer && answers(d, desc->flags) &&
                     (outcome == OUTCOME_OK || outcome == OUTCOME_FAILED);
    if (result->answer) {
        (void)frame_tx_seal(response); /* ready to go: the caller may hold it for a turn */
    }
    if (origin.from_sync) {
        result->wait_responses = origin.sync_index;
    }
}

static bool length_ok(const struct packet_desc *desc, const struct rx_frame *frame)
{
    /* Saturated: a bounded max is below LENGTH_UNBOUNDED, so a longer
     * length is still over it, and no min is above it. */
    uint32_t length = frame->length < LENGTH_UNBOUNDED ? frame->length : LENGTH_UNBOUNDED;
    return length >= desc->length.min && length <= desc->length.max &&
           !(frame->flags & (FRAME_TRUNCATED | FRAME_BAD_SYNC));
}

void dispatch(struct dispatcher *d, const struct rx_frame *frame, struct response *response,
              struct dispatch_result *result)
{
    *result = (struct dispatch_result){0};
    const struct packet_desc *desc = packet_find(frame->code);
    struct packet_origin origin = {.sync_index = frame->sync_index};

    /* Unknown packets are judged by the ID position every addressed packet
     * uses, so a packet meant for another servo flags nothing here. */
    if (desc == NULL || (desc->flags & PF_ADDRESSED)) {
        if (frame->stored == 0u) {
            if (desc != NULL) {
                set_command_error(d, true); /* addressed packet with no ID */
            }
            return;
        }
        uint8_t id = frame->content[0];
        if (id != *d->own_id && id != WIRE_BROADCAST_ID) {
            return;
        }
        origin.broadcast = id == WIRE_BROADCAST_ID;
    }
    if (desc == NULL || !length_ok(desc, frame)) {
        set_command_error(d, true);
        return;
    }
    /* Field by field: an initializer would clear the rest by a call to
     * memset (the M0), and dispatch_packet() sets the rest. */
    struct packet_call call;
    call.d = d;
    call.content = frame->content;
    call.length = frame->length;
    call.result = result;
    if (desc->flags & PF_CARRIES_RECORDS) {
        /* SyncCommand: this servo's record is the packet. It carries no ID,
         * so its origin is never a broadcast: the record's is a sync. */
        if (frame->sync_index == FRAME_SYNC_NO_RECORD) {
            return; /* no record for this servo */
        }
        desc = packet_find(frame->content[0]);
        if (desc == NULL || !(desc->flags & PF_SYNCABLE) || frame->content[1] != desc->length.min) {
            set_command_error(d, true);
            return;
        }
        call.content = &frame->content[3];
        call.length = frame->content[1];
        origin.from_sync = true;
    } else {
        /* An answer's length unless its handler sets one. A sync record
         * answers only with Monitor's, whose handler does: its header may
         * be on its way out already (servo.c, send_ahead), and no byte
         * there changes while it goes. */
        response->length = 0;
    }
    dispatch_packet(desc, &call, response, origin);
}
