/* The application's part of a firmware update (docs/packets.md, 0x50-0x55):
 * restarting into the bootloader, and saying who answers. */
#include "protocol/packet_table.h"
#include "protocol/update_status.h"
#include "protocol/wire.h"

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
    enum packet_outcome outcome = answer_result(r, ok);
    r->content[2] = (uint8_t)reason;
    r->length = 3;
    return outcome;
}

enum packet_outcome handle_update_status(const struct packet_call *c, struct response *r)
{
    const struct update_status status = {.mode = UPDATE_MODE_APPLICATION,
                                         .app_version = c->d->regs->status.firmware_version,
                                         .board = c->d->board};
    r->length = update_status_encode(&status, r->content);
    return OUTCOME_OK;
}
