/* The application's part of a firmware update (docs/packets.md, 0x50-0x55):
 * restarting into the bootloader, and saying who answers. */
#include "protocol/packet_table.h"
#include "protocol/wire.h"

enum { UPDATE_STATUS_ANSWER_LENGTH = 16, MODE_APPLICATION = 0 };

enum packet_outcome handle_update_enter(const struct packet_call *c, struct response *r)
{
    /* Not while a move runs: the restart lets go of the output. The
     * restart itself waits for the answer to leave (servo.c). */
    bool ok = c->d->bootloader_present != 0u && !motion_is_moving(c->d->motion);
    c->result->enter_bootloader = ok;
    return answer_result(c, r, ok);
}

enum packet_outcome handle_update_status(const struct packet_call *c, struct response *r)
{
    uint8_t *p = r->content;
    for (unsigned i = 0; i < UPDATE_STATUS_ANSWER_LENGTH; i++) {
        p[i] = 0; /* the slot's geometry is the bootloader's to tell */
    }
    p[0] = c->content[0];
    p[1] = MODE_APPLICATION;
    wire_put_u16(&p[5], c->d->regs->status.firmware_version);
    wire_put_u16(&p[7], c->d->board);
    r->length = UPDATE_STATUS_ANSWER_LENGTH;
    return OUTCOME_OK;
}
