/* The rules across a request's fields: a SyncCommand's records. */
#include "servobus/servobus.h"

/* A SyncCommand: records of a syncable packet at its length, as many as it says. */
static sb_error records_fit(const sb_value *v)
{
    const sb_packet_desc *cmd = sb_packet((uint8_t)v[0].n);
    const char *wrong = NULL;
    if (cmd == NULL || !(cmd->flags & SB_PF_SYNCABLE) || v[1].n != cmd->length_min || v[1].n != cmd->length_max)
        wrong = "cmd";
    else if (v[2].n == 0)
        wrong = "count";
    else if (v[3].len != (size_t)v[1].n * (size_t)v[2].n)
        wrong = "records";
    return wrong != NULL ? sb_error_of(SB_E_USAGE, -1, SB_PKT_SYNC_COMMAND, wrong) : sb_ok();
}

sb_error sb_check_request(uint8_t code, const sb_value *v, size_t count)
{
    const sb_packet_desc *p = sb_packet(code);
    if (p == NULL || count != p->request_count)
        return sb_error_of(p == NULL ? SB_E_UNKNOWN_PACKET : SB_E_USAGE, -1, code, NULL);
    return code == SB_PKT_SYNC_COMMAND ? records_fit(v) : sb_ok();
}
