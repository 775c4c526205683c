/* The fault history's packets: ReadFaults (0x43) and ClearFaults (0x44). */
#include "protocol/packet_table.h"
#include "protocol/wire.h"

enum { READ_FAULTS_ANSWER_LENGTH = 27 };
_Static_assert(ANSWER_AT_(ANSWER_READ_FAULTS_NUMBER) == 4u && 4u + READ_FAULTS_ENTRY_BYTES == READ_FAULTS_ANSWER_LENGTH,
               "the entry fills the answer after id, count and not_logged");
_Static_assert(READ_FAULTS_ANSWER_LENGTH <= RESPONSE_CONTENT_MAX, "ReadFaults fits a response");

enum packet_outcome handle_read_faults(const struct packet_call *c, struct response *r)
{
    const struct dispatcher *d = c->d;
    const struct store_health *h = &d->regs->store;
    uint8_t *p = r->content;
    p[1] = h->fault_count;
    le_put_u16(&p[2], h->faults_not_logged);
    /* The entry's bytes go straight into the answer: they are its wire image. */
    if (d->read_fault == NULL || !d->read_fault(d->read_fault_ctx, c->content[1], &p[4])) {
        for (unsigned i = 0; i < READ_FAULTS_ENTRY_BYTES; i++) {
            p[4u + i] = 0; /* what 0: none at this index */
        }
    }
    r->length = READ_FAULTS_ANSWER_LENGTH;
    return OUTCOME_OK;
}

enum packet_outcome handle_clear_faults(const struct packet_call *c, struct response *r)
{
    const struct dispatcher *d = c->d;
    return answer_result(r, d->clear_faults != NULL && d->clear_faults(d->faults_ctx));
}
