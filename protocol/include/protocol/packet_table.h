/* One row per packet: request size rule, handler and answering rules.
 * Internal to the protocol stack. */
#ifndef PROTOCOL_PACKET_TABLE_H
#define PROTOCOL_PACKET_TABLE_H

#include <stdbool.h>
#include <stdint.h>

#include "protocol/dispatcher.h"
#include "protocol/packet_codes.h"
#include "protocol/packet_rows.h"

enum packet_flags {
    PF_ADDRESSED = 1u << 0,   /* content starts with the servo ID */
    PF_ANSWERS = 1u << 1,     /* always answers (so never on broadcast) */
    PF_ANSWERS_IF_CONTROL_RESPONSE = 1u << 2, /* answers only with 33 on */
    PF_BROADCAST = 1u << 3,   /* runs on every servo when sent to 0xFF */
    PF_QUERY = 1u << 4,       /* reads only: leaves the command-error bit */
    PF_SYNCABLE = 1u << 5,    /* may be a SyncCommand record */
    /* Broadcast, and answered by the one servo it selects (AssignId, by
     * serial number): one answer at most. */
    PF_ONE_ANSWERS = 1u << 6,
    /* Carries records, each a syncable packet for one servo (SyncCommand):
     * the dispatcher runs this servo's record; no handler. */
    PF_CARRIES_RECORDS = 1u << 7,
};

enum packet_outcome {
    OUTCOME_OK,       /* done; answer now if the flags say so */
    OUTCOME_FAILED,   /* refused (result 0); answer now if due */
    OUTCOME_DEFERRED, /* accepted; any answer comes when the move finishes */
    OUTCOME_ERROR,    /* malformed or dropped: no answer, command error */
    OUTCOME_NONE,     /* not for this servo, or already handled: nothing */
};

/* Where a request came from. */
struct packet_origin {
    bool broadcast;     /* sent to 0xFF */
    bool from_sync;     /* a SyncCommand record */
    uint8_t sync_index; /* SyncCommand: position of this servo's record */
};

/* What a handler sees of the request it runs. */
struct packet_call {
    struct dispatcher *d;
    const uint8_t *content;
    uint16_t length;
    struct packet_origin origin;
    /* Set by the dispatcher: */
    uint8_t code;
    bool answer_when_done; /* control response on and addressed to us alone */
    struct dispatch_result *result;
};

typedef enum packet_outcome (*packet_handler)(const struct packet_call *call,
                                              struct response *response);

/* A request's content length, inclusive both ends, a byte each (a row is
 * 8 bytes, not 12: the M0's flash); max LENGTH_UNBOUNDED: no upper bound
 * (the dispatcher compares a length saturated to it). */
enum { LENGTH_UNBOUNDED = 0xFF };
struct length_rule {
    uint8_t min;
    uint8_t max;
};

struct packet_desc {
    uint8_t code;
    uint8_t flags; /* enum packet_flags */
    struct length_rule length;
    packet_handler handler;
};

const struct packet_desc *packet_find(uint8_t code);
/* Every handler a packet table names (protocol/servo_schema). */
PACKET_HANDLERS_DECLARED

/* The "id, result" answer most packets give (the dispatcher has put the
 * ID in already). */
enum packet_outcome answer_result(struct response *r, bool ok);

#endif
