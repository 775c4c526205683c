/* Command dispatcher: checks a received request against the packet table
 * (addressing, length, broadcast rules), runs its handler and says what to
 * send back. Owns status bit 1 (command error). */
#ifndef PROTOCOL_DISPATCHER_H
#define PROTOCOL_DISPATCHER_H

#include <stdbool.h>
#include <stdint.h>

#include "motion/motion.h"
#include "protocol/frame_rx.h"
#include "protocol/frame_tx.h"
#include "protocol/packet_fields.h"
#include "registers/registers.h"

struct dispatcher {
    struct registers *regs;
    struct motion *motion;
    const volatile uint8_t *own_id; /* the ID the servo answers to right now */
    /* Makes a changed user area durable before the write is answered:
     * false refuses the write (result 0) and the user area stays as it
     * was, so what the host reads is what a boot loads. NULL where nothing
     * is stored (the change is kept in RAM). */
    bool (*persist)(void *ctx, const struct user_config *cfg);
    void *persist_ctx;
    /* A bootloader is there to restart into (UpdateEnter), and the board
     * images are built for (UpdateStatus). */
    uint8_t bootloader_present;
    uint16_t board;
    /* When the control tick that computed the motion's state ran:
     * ReadMotion stamps its snapshot with it. Handed in by the control
     * loop's owner whenever its schedule moves (dispatcher_note_tick); 0
     * where none runs. */
    uint32_t tick_us;
    /* Frames for this servo so far (its ID, a broadcast, its SyncCommand
     * record): the bus watchdog's food. */
    uint32_t heard;
    /* The fault history (ReadFaults, ClearFaults): the index-th newest
     * fault's READ_FAULTS_ENTRY_BYTES (the log's entry image) into out, false beyond
     * the count (store_health has the count); and a clear. NULL where none
     * is kept. Each with its own context: the read is the store's own
     * function, called straight. */
    bool (*read_fault)(void *ctx, uint8_t index, uint8_t *out);
    void *read_fault_ctx;
    bool (*clear_faults)(void *ctx);
    void *faults_ctx;
};

/* A fault's bytes in ReadFaults' answer, `number` to `what` (the schema's
 * layout): the fault log's entry is copied there whole, so its image must
 * be this long (the application holds the two together). */
#define READ_FAULTS_ENTRY_BYTES (ANSWER_AT_(ANSWER_READ_FAULTS_WHAT) + 1u - ANSWER_AT_(ANSWER_READ_FAULTS_NUMBER))
#define ANSWER_AT_(field) ANSWER_AT_OFFSET_(field)
#define ANSWER_AT_OFFSET_(offset, size, sign) (offset##u)

struct dispatch_result {
    /* Word-aligned: cleared by one store, not a call (the M0's memset). */
    _Alignas(uint32_t) bool answer; /* response holds a frame to send */
    bool config_changed;    /* the user area changed (and is durable) */
    /* Sync Monitor: let this many other servos' responses pass first. */
    uint8_t wait_responses;
    /* UpdateEnter: restart into the bootloader once the answer has left. */
    bool enter_bootloader;
};

void dispatcher_init(struct dispatcher *d, struct registers *regs, struct motion *motion,
                     const volatile uint8_t *own_id);

/* The time of the control tick the motion's state is from, for the
 * requests dispatched next (ReadMotion's stamp). */
static inline void dispatcher_note_tick(struct dispatcher *d, uint32_t tick_us)
{
    d->tick_us = tick_us;
}

void dispatch(struct dispatcher *d, const struct rx_frame *frame, struct response *response,
              struct dispatch_result *result);

#endif
