/* The application's part of a firmware update (docs/packets.md, 0x50-0x55):
 * restarting into the bootloader, and saying who answers. */
#include "protocol/packet_table.h"
#include "protocol/wire.h"

enum { UPDATE_STATUS_ANSWER_LENGTH = 16, MODE_APPLICATION = 0 };

/* UpdateEnter's reason byte (docs/packets.md). */
enum update_enter_reason {
    ENTER_RESTARTING = 0,
    ENTER_OUTPUT_DRIVEN = 1, /* a move, the wheel, hold, damping or a queued move */
    ENTER_NO_BOOTLOADER = 2,
};

enum packet_outcome handle_update_enter(const struct packet_call *c, struct response *r)
{
    /* Only a released servo: the restart lets go of the output, and a
     * held load would fall. The restart itself waits for the answer to
     * leave (servo.c). */
    enum update_enter_reason reason =
        c->d->bootloader_present == 0u       ? ENTER_NO_BOOTLOADER
        : !motion_is_idle(c->d->motion)      ? ENTER_OUTPUT_DRIVEN
                                             : ENTER_RESTARTING;
    bool ok = reason == ENTER_RESTARTING;
    c->result->enter_bootloader = ok;
    enum packet_outcome outcome = answer_result(c, r, ok);
    r->content[2] = (uint8_t)reason;
    r->length = 3;
    return outcome;
}

enum packet_outcome handle_update_status(const struct packet_call *c, struct response *r)
{
    uint8_t *p = r->content;
    for (unsigned i = 0; i < UPDATE_STATUS_ANSWER_LENGTH; i++) {
        p[i] = 0; /* the slot's geometry is the bootloader's to tell */
    }
    p[0] = c->content[0];
    p[1] = MODE_APPLICATION;
    le_put_u16(&p[5], c->d->regs->status.firmware_version);
    le_put_u16(&p[7], c->d->board);
    r->length = UPDATE_STATUS_ANSWER_LENGTH;
    return OUTCOME_OK;
}
