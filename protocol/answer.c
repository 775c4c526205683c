/* What many handlers answer, and the handler of a packet an application
 * leaves to the bootloader. */
#include "protocol/packet_table.h"

enum packet_outcome answer_result(struct response *r, bool ok)
{
    r->content[1] = ok ? 1u : 0u;
    r->length = 2;
    return ok ? OUTCOME_OK : OUTCOME_FAILED;
}

enum packet_outcome handle_ignored(const struct packet_call *c, struct response *r)
{
    (void)c;
    (void)r;
    return OUTCOME_NONE;
}
